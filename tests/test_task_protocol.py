"""Arbitrator evolution on any task that implements the task protocol (ArbitratorTask)."""

import math

import numpy as np
import pytest
from conftest import SMALL_TASK

from evorbc_ros.arbitrator import ArbitratorFile
from evorbc_ros.mapping import NO_PRIMITIVE, MappingFunction, PrimitiveLookup, choose_primitive
from evorbc_ros.sensors import SensorLayout, goal_bearing_reading
from offline_evolution.arbitrator.evolve import (
    EvolutionSettings,
    arbitrator_file,
    evolve,
    file_sha256,
)
from offline_evolution.checkpoint import Interrupted
from offline_evolution.maze_task.base import MazeTaskBase, MazeTaskSettings, eq5_fitness
from offline_evolution.maze_task.hexapod_task import HexapodMazeTask
from offline_evolution.maze_task.task import MazeTask
from offline_evolution.task_protocol import ArbitratorTask, EpisodeResult


class OpenFieldTask:
    """No maze: reach a point 1 m away, sensing only its bearing (a task of one's own).

    The robot moves each 0.1 s cycle by the chosen primitive's displacement scaled to the
    cycle (a crude model, enough to exercise the protocol); start rows are the goal's
    bearing from the start, rad.
    """

    layout = SensorLayout(goal_bearing=True)
    dt = 0.1
    n_cycles = 40
    parameter_specs = ()  # EvoRBC arbitrators only: no standard controller
    closed = False

    def controller(self, kind, repertoire=None, mapping=None):
        assert kind == "evorbc"
        fn = MappingFunction.for_behaviours(mapping, repertoire.behaviour)
        scale = self.dt / repertoire.eval_time
        step = repertoire.behaviour * scale
        turn = repertoire.heading * scale
        return fn, PrimitiveLookup.build(repertoire.behaviour, fn.domain()), step, turn

    def sample_starts(self, rng):
        return rng.uniform(-math.pi, math.pi, size=(3, 1))

    def nominal_starts(self):
        return np.zeros((1, 1))

    def evaluate(self, networks, controller, starts, record=False):
        fn, lookup, step, turn = controller
        reached, cycles, final, initial = [], [], [], []
        for network in networks:
            net = network.compile()
            for (bearing,) in starts:
                goal = np.array([math.cos(bearing), math.sin(bearing)])
                x = y = heading = 0.0
                n = self.n_cycles
                for cycle in range(self.n_cycles):
                    b = math.atan2(goal[1] - y, goal[0] - x) - heading
                    m = net.activate([goal_bearing_reading(math.remainder(b, 2 * math.pi))])
                    k = choose_primitive(fn, lookup, m[0], m[1])[0]
                    if k != NO_PRIMITIVE:
                        dx, dy = step[k]
                        x += dx * math.cos(heading) - dy * math.sin(heading)
                        y += dx * math.sin(heading) + dy * math.cos(heading)
                        heading += turn[k]
                    if math.hypot(goal[0] - x, goal[1] - y) < 0.1:
                        n = cycle + 1
                        break
                reached.append(n < self.n_cycles or math.hypot(*(goal - (x, y))) < 0.1)
                cycles.append(n)
                final.append(math.hypot(goal[0] - x, goal[1] - y))
                initial.append(1.0)
        reached, cycles, final, initial = map(np.array, (reached, cycles, final, initial))
        fitness = eq5_fitness(reached, cycles * self.dt, final, initial, self.n_cycles * self.dt)
        return EpisodeResult(reached, cycles, final, initial, fitness)

    def describe(self):
        return None

    def close(self):
        self.closed = True


def settings(neat_file, generations=3) -> EvolutionSettings:
    return EvolutionSettings(
        kind="evorbc",
        robot="4ws-5",
        generations=generations,
        seed=3,
        neat_file=str(neat_file),
        neat_sha256=file_sha256(neat_file),
        task={"name": "open field"},
        mapping="polar",
        hall_of_fame=5,
        post_samples=2,
    )


def test_both_maze_tasks_and_a_task_of_ones_own_implement_the_protocol():
    maze = MazeTask(MazeTaskSettings(**SMALL_TASK), "4ws-5")
    hexapod = HexapodMazeTask(MazeTaskSettings.load("config/tasks/maze-hexapod.yaml"), workers=1)
    for task in (maze, hexapod, OpenFieldTask()):
        assert isinstance(task, ArbitratorTask)
    hexapod.close()
    # Settings, mazes, starts and eq. 5 come from one place, not a copy per robot.
    for name in ("sample_starts", "nominal_starts", "fitness", "episode_result"):
        assert getattr(MazeTask, name) is getattr(HexapodMazeTask, name)
        assert getattr(MazeTask, name) is getattr(MazeTaskBase, name)


def test_an_arbitrator_evolves_on_a_task_of_ones_own(small_repertoire, small_neat_file, tmp_path):
    task = OpenFieldTask()
    result = evolve(settings(small_neat_file), small_repertoire, task=task)
    assert len(result.history) == 3 and not task.closed  # the caller's task stays open
    assert result.post_evaluation.episodes == 1 + 2 * 3  # nominal start, then 2 draws of 3
    again = evolve(settings(small_neat_file), small_repertoire, task=OpenFieldTask())
    assert again.best_fitness == result.best_fitness
    assert again.selected_network == result.selected_network
    # Its file records the task's sensors and loads like any other.
    path = tmp_path / "a.json"
    arbitrator_file(result, task, small_repertoire).save(path)
    arb = ArbitratorFile.load(path)
    assert arb.sensors == task.layout and arb.evolution["task"] == {"name": "open field"}


def test_a_run_on_ones_own_task_resumes_to_the_uninterrupted_result(
    small_repertoire, small_neat_file, tmp_path
):
    whole = evolve(settings(small_neat_file), small_repertoire, task=OpenFieldTask())
    checkpoint = tmp_path / "run.checkpoint.json"
    with pytest.raises(Interrupted):
        evolve(
            settings(small_neat_file),
            small_repertoire,
            task=OpenFieldTask(),
            checkpoint=checkpoint,
            should_stop=lambda: True,
        )
    resumed = evolve(
        settings(small_neat_file), small_repertoire, task=OpenFieldTask(), checkpoint=checkpoint
    )
    assert resumed.selected_network == whole.selected_network
    assert [h.best for h in resumed.history] == [h.best for h in whole.history]
