"""Training on generated mazes (issue 21 item 2, docs/design.md section 22).

Fresh draws and pools, the same draw for every genome, exact resume, held-out refusals,
validation mazes in the post-selection, and the 4WS kernel taking a new set of mazes
every generation without compiling again.
"""

import numpy as np
import pytest
import yaml
from conftest import SMALL_TASK, evolution_settings

from evorbc_ros.config import ConfigError
from offline_evolution.arbitrator.evolve import EvolutionSettings, evolve, file_sha256
from offline_evolution.arbitrator.selection import post_evaluation_starts
from offline_evolution.checkpoint import Interrupted
from offline_evolution.maze_task import kernel
from offline_evolution.maze_task.task import MazeTask, MazeTaskSettings
from offline_evolution.maze_task.training import TrainingMazes, TrainingSettings
from offline_evolution.maze_task.world import pack_mazes
from offline_evolution.mazes.generator import generate_maze, spec_for_robot
from offline_evolution.reporters import Reporter

TRAINING = {"generated": 2, "starts": 1, "pool": 0, "maze_seed": 5, "post_mazes": 2}


def task_dict(**training):
    return {**SMALL_TASK, "training": {**TRAINING, **training}}


run_settings = evolution_settings


def training_task(**training) -> MazeTask:
    task = MazeTask(MazeTaskSettings.from_dict(task_dict(**training), "t.yaml"), "4ws-5")
    task.start_training("4ws-5", seed=3)
    return task


def interrupt(settings, repertoire, checkpoint, after: int) -> None:
    """Run ``settings`` until its ``after``-th stop poll, leaving ``checkpoint``."""
    polls = []
    with pytest.raises(Interrupted):
        evolve(
            settings,
            repertoire,
            checkpoint=checkpoint,
            checkpoint_every=100,
            should_stop=lambda: polls.append(1) or len(polls) == after,
        )


def histories(result):
    out = []
    for h in result.history:
        d = h.as_dict()
        d.pop("seconds"), d.pop("evaluation_seconds")
        out.append(d)
    return out


def test_generations_draw_new_proven_mazes_seeded_by_generation():
    task = training_task()
    starts, world = task.generation_episodes(np.random.default_rng([3, 0]))
    assert world is None
    first = [m.name for m in task.mazes]
    # The task's two mazes (one start each), then 2 generated mazes x 1 start.
    assert first[:2] == ["obstacle", "gaps"] and len(first) == 4
    assert all(n.startswith("train5-") for n in first[2:])
    assert starts[:, 0].tolist() == [0, 1, 2, 3]
    task.generation_episodes(np.random.default_rng([3, 1]))
    assert [m.name for m in task.mazes][2:] != first[2:]  # fresh mazes the next generation
    again, _ = task.generation_episodes(np.random.default_rng([3, 0]))
    assert [m.name for m in task.mazes] == first and np.array_equal(again, starts)
    # Each is the generator's maze of that seed and index: proven solvable by it.
    index = int(first[2].split("-")[1])
    made = generate_maze(spec_for_robot("4ws-5"), 5, index, "train").maze
    assert np.array_equal(made.walls, task.mazes[2].walls)


def test_a_pool_samples_its_own_mazes_and_validation_uses_others():
    task = training_task(pool=6, generated=3, starts=2)
    seen = set()
    for g in range(8):
        starts, _ = task.generation_episodes(np.random.default_rng([3, g]))
        names = [m.name for m in task.mazes[2:]]
        assert len(set(names)) == 3 and len(starts) == 2 + 3 * 2
        seen.update(int(n.split("-")[1]) for n in names)
    assert seen <= set(range(6)) and len(seen) > 3
    rows = post_evaluation_starts(task, seed=3, samples=2)
    validation = [int(m.name.split("-")[1]) for m in task.mazes[2:]]
    assert len(validation) == 2 and min(validation) >= 6  # never a pool maze
    # Nominal starts, 2 x the task mazes' random starts, 2 starts per validation maze.
    assert rows[:, 0].tolist() == [0, 1, 0, 1, 0, 1, 2, 2, 3, 3]


def test_task_mazes_can_be_left_out_and_training_can_be_perturbed(small_repertoire):
    task = training_task(task_mazes=False, perturb="realistic", starts=3)
    starts, world = task.generation_episodes(np.random.default_rng([1, 2]))
    assert sorted(set(starts[:, 0].astype(int))) == [2, 3] and len(world) == len(starts) == 6
    controller = task.controller("evorbc", small_repertoire, "polar")
    result = task.evaluate([_net()], controller, starts, world=world)
    assert len(result.reached) == 6
    # The nominal starts (post-selection, nominal watch) stay the task's own mazes.
    assert task.nominal_starts()[:, 0].tolist() == [0, 1]


def test_kernel_takes_new_mazes_without_compiling_or_repacking_old_ones(small_repertoire):
    task = training_task(generated=3)
    controller = task.controller("evorbc", small_repertoire, "polar")
    net = _net()
    task.evaluate([net], controller, task.nominal_starts())
    compiled = len(kernel.run_episodes.signatures)
    fixed = task._pieces
    for g in range(3):
        starts, _ = task.generation_episodes(np.random.default_rng([9, g]))
        task.evaluate([net], controller, starts)
        # The pack is what packing every current maze from scratch gives.
        fresh = pack_mazes(task.mazes, task.reach)
        for name in fresh._fields:
            a, b = getattr(fresh, name), getattr(task.pack, name)
            assert np.array_equal(a, b) if isinstance(a, np.ndarray) else a == b, name
    assert len(kernel.run_episodes.signatures) == compiled  # no new compilation
    assert task._pieces is fixed and len(task._generated_pieces) == 9
    # A maze drawn again reuses its packed grid instead of building it again.
    again = task._generated_pieces[task.mazes[2].name]
    task.use_mazes(task.mazes[2:3])
    assert task._generated_pieces[task.mazes[2].name] is again


def _tiny_network():
    """A network of the 4ws layout's 10 inputs driving 2 outputs through constant biases."""
    from evorbc_ros.config import config_dir
    from evorbc_ros.sensors import SensorLayout

    n = SensorLayout.load(config_dir() / "sensors/4ws.yaml").n_inputs
    return {
        "inputs": [-(k + 1) for k in range(n)],
        "outputs": [0, 1],
        "nodes": [
            {"key": 0, "bias": 0.3, "response": 1.0, "activation": "sigmoid", "aggregation": "sum"},
            {"key": 1, "bias": 0.8, "response": 1.0, "activation": "sigmoid", "aggregation": "sum"},
        ],
        "connections": [{"source": -1, "target": 0, "weight": 0.5, "enabled": True}],
    }


@pytest.mark.parametrize(
    "variant",
    [
        {"pool": 0},  # fresh draws
        {"pool": 6},  # a pool sampled by generation
        {"perturb": "realistic"},  # per-episode worlds seeded by generation
        {"distance": "path"},  # path-length fitness
    ],
    ids=["fresh", "pool", "perturbed", "path"],
)
def test_every_genome_sees_the_same_draw_and_resume_is_exact(
    tmp_path, small_neat_file, small_repertoire, variant
):
    s = run_settings(small_neat_file, small_repertoire, task_dict(**variant))
    straight = evolve(s, small_repertoire)
    if variant != {"pool": 0}:  # the variant changes the run, so it was taken into account
        fresh = run_settings(small_neat_file, small_repertoire, task_dict(pool=0))
        assert histories(evolve(fresh, small_repertoire)) != histories(straight)
    ckpt = tmp_path / "run.checkpoint.json"
    interrupt(s, small_repertoire, ckpt, after=2)
    resumed = evolve(s, small_repertoire, checkpoint=ckpt)
    assert histories(resumed) == histories(straight)
    assert resumed.best_network == straight.best_network
    assert resumed.selected_network == straight.selected_network
    # The paper protocol on the same mazes gives another run: the generated mazes count.
    paper = evolve(
        run_settings(small_neat_file, small_repertoire, dict(SMALL_TASK)), small_repertoire
    )
    assert histories(paper) != histories(straight)


def test_every_genome_of_a_generation_runs_the_same_draw(small_neat_file, small_repertoire):
    """One evaluate() call per generation, all genomes from the same rows and mazes."""
    calls = []

    class Spy(MazeTask):
        def evaluate(self, networks, controller, starts, record=False, world=None):
            calls.append((len(networks), starts.copy(), [m.name for m in self.mazes]))
            return super().evaluate(networks, controller, starts, record, world)

    s = run_settings(small_neat_file, small_repertoire, task_dict(), generations=3)
    task = Spy(MazeTaskSettings(**s.task), "4ws-5")
    evolve(s, small_repertoire, task=task)
    # One call per generation with the whole population, then the post-selection's
    # batches (post_scores.py), each on the same starts in the same mazes.
    assert [n for n, _, _ in calls[:3]] == [24, 24, 24] and len(calls) > 3
    post = calls[3:]
    assert all(np.array_equal(c[1], post[0][1]) and c[2] == post[0][2] for c in post)
    for g, (_, starts, names) in enumerate(calls[:3]):
        expected = training_task()
        rows, _ = expected.generation_episodes(np.random.default_rng([3, g]))
        assert np.array_equal(starts, rows) and names == [m.name for m in expected.mazes]
    validation = calls[3][2][2:]
    assert len(validation) == 2 and not set(validation) & {n for c in calls[:3] for n in c[2]}


def _net():
    from evorbc_ros.network import NetworkSpec

    return NetworkSpec.from_dict(_tiny_network())


@pytest.mark.parametrize(
    ("training", "message"),
    [
        ({"maze_seed": 21021}, "maze_seed 21021 is the held-out mazes' seed"),
        ({"pool": 1}, "pool 1 holds fewer mazes than generated 2"),
        ({"generated": 0}, "generated must be >= 1"),
        ({"perturb": "nosuch"}, "perturb: unknown perturbation set 'nosuch'"),
        ({"pools": 3}, "unknown setting 'pools' \\(did you mean 'pool'\\?\\)"),
        ({"serpentine": 1.0}, "serpentine must be <= 0.9"),
        ({"adapt": True, "adapt_expected": "nosuch"}, "adapt_expected 'nosuch': expected one"),
        ({"post_perturb": True}, "post_perturb needs a perturb set"),
        ({"fall_penalty": -1.0}, "fall_penalty must be >= 0"),
    ],
)
def test_bad_training_settings_are_one_line_errors(tmp_path, training, message):
    path = tmp_path / "task.yaml"
    path.write_text(yaml.safe_dump(task_dict(**training)))
    with pytest.raises(ConfigError, match=message) as info:
        MazeTaskSettings.load(path)
    assert str(path) in str(info.value) and "\n" not in str(info.value)


def test_training_refuses_the_held_out_seed_and_held_out_maze_files(tmp_path):
    task = MazeTask(MazeTaskSettings.from_dict(task_dict(), "t"), "4ws-5")
    with pytest.raises(ConfigError, match="--seed 21021 is the held-out mazes' seed"):
        task.start_training("4ws-5", 21021)
    task.start_training("4ws-5", 21022)  # any other seed is fine
    from offline_evolution.mazes.files import save_maze

    held = generate_maze(spec_for_robot("4ws-5"), 21021, 4).maze
    save_maze(held, tmp_path / "held.yaml")
    values = {**SMALL_TASK, "mazes": ["obstacle", str(tmp_path / "held.yaml")]}
    paper = MazeTask(MazeTaskSettings.from_dict(values, "t.yaml"), "4ws-5")
    with pytest.raises(ConfigError, match=r"t\.yaml: mazes: gen21021-004 is a held-out maze"):
        paper.start_training("4ws-5", 1, source="t.yaml")


def test_settings_record_training_only_when_set():
    assert "training" not in MazeTaskSettings.from_dict(dict(SMALL_TASK), "t").as_dict()
    s = MazeTaskSettings.from_dict(task_dict(), "t")
    assert isinstance(s.training, TrainingSettings)
    again = MazeTaskSettings(**s.as_dict())  # as a checkpoint restores it
    assert again.training == s.training and again.as_dict() == s.as_dict()
    # A setting added later is recorded only when set, so older checkpoints still resume.
    assert "serpentine" not in s.as_dict()["training"]
    winding = MazeTaskSettings.from_dict(task_dict(serpentine=0.3), "t")
    assert winding.as_dict()["training"]["serpentine"] == 0.3
    assert MazeTaskSettings(**winding.as_dict()).training.serpentine == 0.3


def test_serpentine_training_refuses_a_robot_whose_mazes_cannot_hold_them():
    values = {"mazes": ["hexapod"], "episode_time": 30.0, "sensors": "sensors/hexapod.yaml"}
    settings = MazeTaskSettings.from_dict(
        {**values, "training": {"generated": 1, "serpentine": 0.2}}, "t.yaml"
    )
    with pytest.raises(ConfigError, match="hexapod's mazes cannot hold serpentines"):
        TrainingMazes(settings.training, "hexapod")


def test_serpentine_training_draws_its_mazes_from_the_winding_mix():
    task = training_task(serpentine=0.5)
    task.generation_episodes(np.random.default_rng([3, 0]))
    for maze in task.mazes[2:]:
        index = int(maze.name.split("-")[1])
        made = generate_maze(spec_for_robot("4ws-5"), 5, index, "train", 0.5)
        assert np.array_equal(made.maze.walls, maze.walls)


class _FakeSim:
    def __init__(self, boxes):
        self.boxes, self.closed = boxes, False

    def close(self):
        self.closed = True


def test_a_worker_keeps_a_few_generated_mazes_simulations():
    from sim_bridge.legged.maze_sims import KEEP, MazeSims

    spec = spec_for_robot("4ws-5")
    own = [generate_maze(spec, 7, 0).maze]
    sims = MazeSims(own, _FakeSim)
    maze, sim = sims.get(0)
    assert maze is own[0] and sims.get(0)[1] is sim  # a task maze: by index, kept
    made = []
    for k in range(KEEP + 1):
        m = generate_maze(spec, 7, k + 1).maze
        got, s = sims.get(m)
        assert got is m and np.array_equal(s.boxes, m.boxes)
        made.append(s)
    assert made[0].closed and not any(s.closed for s in made[1:])  # the oldest closed
    assert len(sims.values()) == KEEP + 1 and not sim.closed


def test_hexapod_episodes_in_a_generated_maze_match_the_maze_as_a_file(tmp_path):
    """A generated maze sent with the job runs the episode its saved file runs."""
    from evorbc_ros.arbitrator import ArbitratorFile
    from evorbc_ros.defaults import default_arbitrator, default_repertoire
    from evorbc_ros.repertoire import Repertoire
    from offline_evolution.maze_task.task import make_task
    from offline_evolution.mazes.files import save_maze

    arb = ArbitratorFile.load(default_arbitrator("hexapod"))
    repertoire = Repertoire.load(default_repertoire("hexapod"))
    sensors = arb.evolution["task"]["sensors"]  # the controller's own layout, whichever ships
    values = {"mazes": ["hexapod"], "episode_time": 2.0, "sensors": sensors}
    training = {"generated": 1, "starts": 1, "task_mazes": False, "maze_seed": 3}
    task = make_task(
        MazeTaskSettings.from_dict({**values, "training": training}, "t"), "hexapod", 1
    )
    try:
        task.start_training("hexapod", 1)
        starts, _ = task.generation_episodes(np.random.default_rng([1, 0]))
        assert starts[:, 0].tolist() == [1]  # the generated maze, after the task's own
        controller = task.controller("evorbc", repertoire, arb.mapping)
        generated = task.evaluate([arb.network], controller, starts)
        save_maze(task.mazes[1], tmp_path / "g.yaml")
    finally:
        task.close()
    values["mazes"] = [str(tmp_path / "g.yaml")]
    plain = make_task(MazeTaskSettings.from_dict(values, "t"), "hexapod", 1)
    try:
        rows = starts.copy()
        rows[:, 0] = 0
        from_file = plain.evaluate([arb.network], controller, rows)
    finally:
        plain.close()
    assert generated.final_distance[0] == from_file.final_distance[0]
    assert generated.cycles[0] == from_file.cycles[0] == 20


def test_generated_episodes_count_in_the_memory_check(monkeypatch):
    from offline_evolution import memory

    monkeypatch.setattr(memory, "machine_memory", lambda: 24 << 30)
    settings = MazeTaskSettings.from_dict(task_dict(generated=20, starts=50000), "t.yaml")
    memory.check_evolution_memory(
        MazeTaskSettings.from_dict(dict(SMALL_TASK), "t"), 150, "4ws-5", "t", 75, 10
    )
    with pytest.raises(ConfigError) as info:
        memory.check_evolution_memory(settings, 150, "4ws-5", "t.yaml", 75, 10)
    message = str(info.value)
    assert "150 genomes x (2 mazes x 1 starts + 20 generated mazes x 50000)" in message
    assert message.startswith("t.yaml: training.starts 50000 (150,000,300 episodes a generation")


@pytest.mark.parametrize("name", ["maze-4ws-generated.yaml", "maze-hexapod-generated.yaml"])
def test_shipped_generated_training_tasks_load(name):
    from evorbc_ros.config import config_dir

    settings = MazeTaskSettings.load(config_dir() / "tasks" / name)
    assert settings.training is not None and settings.training.maze_seed != 21021


def test_perturbed_training_needs_a_simulation_that_takes_perturbations():
    task = MazeTask(MazeTaskSettings.from_dict(task_dict(perturb="realistic"), "t"), "4ws-5")
    task.start_training("4ws-5", 1, source="t.yaml")  # the kinematic kernel takes them
    task.perturbations_applied = ()  # as a robot's task's task without perturbed worlds
    with pytest.raises(ConfigError, match=r"t\.yaml: training: perturb realistic: 4ws-5's"):
        task.start_training("4ws-5", 1, source="t.yaml")


@pytest.mark.slow
def test_hexapod_generated_maze_training_resumes_exactly(tmp_path):
    """PyBullet episodes in fresh generated mazes, 2 workers: an interrupted run resumes
    to the uninterrupted run's history and genomes (docs/design.md section 22)."""
    from evorbc_ros.arbitrator import ArbitratorFile
    from evorbc_ros.config import config_dir
    from evorbc_ros.defaults import default_arbitrator, default_repertoire
    from evorbc_ros.repertoire import Repertoire

    shipped = (config_dir() / "neat" / "hexapod.ini").read_text()
    neat = tmp_path / "small.ini"
    neat.write_text(shipped.replace("pop_size              = 150", "pop_size              = 24"))
    assert "pop_size              = 24" in neat.read_text()
    repertoire = Repertoire.load(default_repertoire("hexapod"))
    # The shipped controller's own sensor layout, whichever ships.
    sensors = ArbitratorFile.load(default_arbitrator("hexapod")).evolution["task"]["sensors"]
    task = {
        "mazes": ["hexapod"],
        "episode_time": 1.0,
        "samples_per_maze": 1,
        "sensors": sensors,
        "training": {"generated": 1, "starts": 1, "pool": 0, "maze_seed": 5, "post_mazes": 1},
    }
    s = EvolutionSettings(
        kind="evorbc", robot="hexapod", generations=3, seed=3, neat_file=str(neat),
        neat_sha256=file_sha256(neat), task=task, mapping="polar",
        repertoire_fingerprint=repertoire.fingerprint(), hall_of_fame=2, post_samples=1,
    )  # fmt: skip
    straight = evolve(s, repertoire, workers=2)
    ckpt = tmp_path / "run.checkpoint.json"
    polls = []
    with pytest.raises(Interrupted):
        evolve(
            s, repertoire, checkpoint=ckpt, checkpoint_every=100, workers=2,
            should_stop=lambda: polls.append(1) or len(polls) == 1,
        )  # fmt: skip
    reports = []  # the post-evaluation's progress (docs/design.md section 15)

    class Episodes(Reporter):
        def post_evaluation(self, done, total, finalists):
            reports.append((done, total))

    resumed = evolve(s, repertoire, checkpoint=ckpt, workers=2, reporters=[Episodes()])
    assert histories(resumed) == histories(straight)
    assert resumed.best_network == straight.best_network
    assert resumed.selected_network == straight.selected_network
    total = resumed.post_evaluation.candidates * resumed.post_evaluation.episodes
    assert reports == [(done, total) for done in range(total + 1)]
