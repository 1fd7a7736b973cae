"""``evorbc-evolve replay`` and ``evorbc-sim`` say an episode's outcome alike (issue 41).

Both print it through :mod:`sim_bridge.verdict`: a fall is "fell over after 11.7 s", by
the cycles the episode ran, where replay used to print ``fell 30.0`` in a table.
"""

from offline_evolution.commands import replay as replay_command
from offline_evolution.maze_task.replay import MazeOutcome
from sim_bridge import bridge_node, bringup, verdict


def outcome(**changes) -> MazeOutcome:
    values = dict(
        maze="gaps",
        reached=False,
        time=11.7,
        fitness=0.17,
        final_distance=3.2,
        start=(0.0, 0.0, 0.0),
        switches_per_cycle=0.1,
        fell=True,
    )
    return MazeOutcome(**{**values, **changes})


def bridge_result(o: MazeOutcome) -> dict:
    """What the simulation bridge writes for the same episode (its result file's keys)."""
    return {
        "reached": o.reached,
        "fell": o.fell,
        "interrupted": False,
        "time": o.time,
        "fitness": o.fitness,
        "final_distance": o.final_distance,
        "initial_distance": 4.0,
    }


def test_replay_prints_each_episode_as_evorbc_sim_does(capsys):
    episodes = [
        outcome(),
        outcome(maze="obstacle", reached=True, fell=False, time=23.45, fitness=1.805),
        outcome(maze="zigzag", fell=False, time=120.0, fitness=0.42, final_distance=1.234),
    ]
    replay_command._print_episodes(episodes)
    lines = capsys.readouterr().out.splitlines()
    assert lines == [
        "gaps: fell over after 11.7 s (3.20 m left), fitness 0.170",
        "obstacle: reached the target in 23.4 s, fitness 1.805",
        "zigzag: did not reach the target (1.23 m left after 120.0 s), fitness 0.420",
    ]
    # evorbc-sim's line for the same episode starts with the same words and numbers.
    for o, line in zip(episodes, lines, strict=True):
        assert verdict.episode_line(o.maze, bridge_result(o)) == line


def test_one_phrase_serves_the_bridge_evorbc_sim_and_replay():
    assert bridge_node.episode_verdict is verdict.episode_verdict
    assert bringup.episode_line is verdict.episode_line is replay_command.episode_line
    interrupted = {**bridge_result(outcome(fell=False)), "interrupted": True}
    assert verdict.episode_line("gaps", interrupted) == (
        "gaps: interrupted after 11.7 s (3.20 m left)"  # no fitness: the episode did not end
    )
