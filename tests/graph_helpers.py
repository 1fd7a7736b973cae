"""The simulated ROS 2 graph as separate processes, for tests (localhost discovery)."""

import json
import os
import signal
import subprocess
from pathlib import Path

import numpy as np
from ros_domains import claim_domain

from evorbc_ros.defaults import default_arbitrator
from sim_bridge.bringup import NODES, node_command


def children(pid: int) -> list[int]:
    """The processes whose parent is ``pid``."""
    out = []
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            fields = stat.read_text().rsplit(")", 1)[1].split()
        except OSError:
            continue  # gone meanwhile
        if int(fields[1]) == pid:
            out.append(int(stat.parent.name))
    return out


def cmdline(pid: int) -> str:
    """The command line of process ``pid``, words joined by spaces ("" once it is gone)."""
    try:
        return Path(f"/proc/{pid}/cmdline").read_bytes().replace(b"\0", b" ").decode()
    except OSError:
        return ""


def graph_env(domain: int) -> dict:
    """The environment of a graph's processes: localhost discovery, in ``domain`` if no
    other suite on the machine uses it, else in a spare domain (:mod:`ros_domains`)."""
    domain = claim_domain(domain)
    env = dict(
        os.environ,
        ROS_AUTOMATIC_DISCOVERY_RANGE="LOCALHOST",
        PYTHONUNBUFFERED="1",
        ROS_DOMAIN_ID=str(domain),
    )
    return env


class GraphRun:
    """The five processes of the simulated graph; the arbitrator records its choices."""

    def __init__(
        self,
        tmp_path,
        domain,
        maze,
        mode="lockstep",
        episode_time=120.0,
        arbitrator=None,
        repertoire="",
        robot="4ws-5",
        bridge=None,
        arbitrator_params=None,
    ):
        """``bridge``: more parameters of the bridge (e.g. the ``laser_range`` that
        :func:`sim_bridge.graph.sim_graph` gives a large robot's controller);
        ``arbitrator_params``: more of the arbitrator node (e.g. ``adaptation``)."""
        self.env = graph_env(domain)
        self.result = tmp_path / f"{maze}-{mode}.json"
        self.log = open(tmp_path / f"{maze}-{mode}.log", "w")  # noqa: SIM115
        self.arb = str(arbitrator or default_arbitrator())
        self.choices = tmp_path / f"{maze}-{mode}.choices.jsonl"
        self.procs = {}
        for name, module in NODES.items():
            params = {"use_sim_time": True}
            if name in ("laser_sensor", "radar_sensor", "arbitrator") and mode == "lockstep":
                # As sim_bridge.graph sets it: a best-effort reader drops what reaches it
                # before its side of the match completes (in a loaded CI run an adapting
                # arbitrator chose as if it had seen no odometry for ~40 cycles;
                # docs/design/ros-graph.md, "Messages and QoS").
                params["input_qos"] = "reliable"
            if name in ("laser_sensor", "radar_sensor"):
                params["sensor_layout"] = self.arb
            if name == "arbitrator":
                params.update(
                    record_file=str(self.choices), arbitrator=self.arb, repertoire=str(repertoire)
                )
                params.update(arbitrator_params or {})
            if name == "primitive_executor":
                # As sim_bridge.graph sets it: every command answers a primitive.
                params.update(robot=robot, lockstep=mode == "lockstep")
            self.start(name, module, params)
        self.bridge = self.start(
            "sim_bridge",
            "sim_bridge.bridge_node",
            {
                "maze": maze,
                "robot": robot,
                "mode": mode,
                "result_file": str(self.result),
                "episode_time": episode_time,
                **(bridge or {}),  # more bridge parameters (a perturbation set, its seed)
            },
        )

    def start(self, name, module, params):
        proc = subprocess.Popen(
            node_command(module, params),
            env=self.env,
            stdout=self.log,
            stderr=subprocess.STDOUT,
            start_new_session=True,
        )
        self.procs[name] = proc
        return proc

    def wait(self, timeout):
        self.bridge.wait(timeout)
        return json.loads(self.result.read_text())

    def finish(self, timeout):
        """The bridge's episode result; every process is stopped whatever happens."""
        try:
            return self.wait(timeout)
        finally:
            self.stop()

    def recorded_choices(self):
        """The primitive the arbitrator chose at each cycle (its record file)."""
        rows = [json.loads(line) for line in self.choices.read_text().splitlines()]
        return np.array([int(r[4]) for r in rows])

    def stop(self):
        for p in self.procs.values():
            if p.poll() is None:
                p.send_signal(signal.SIGINT)
        for p in self.procs.values():
            try:
                p.wait(5)
            except subprocess.TimeoutExpired:
                p.kill()
                p.wait()
        self.log.close()


def assert_same_choices(choices, result, k=0):
    """The graph chose offline episode ``k``'s primitive at each of its cycles.

    The bridge's final state may draw one more choice, which is never applied. Returns the
    episode's number of cycles.
    """
    cycles = int(result.cycles[k])
    assert len(choices) in (cycles, cycles + 1)
    np.testing.assert_array_equal(choices[:cycles], result.choice[k, :cycles])
    return cycles


def switching_arbitrator(task, rep, robot, neat_path, tries=20, evolution=None):
    """An EvoRBC arbitrator of random NEAT genomes whose replay from the maze's nominal start
    switches among at least 3 primitives (the first of ``tries`` seeds that does).

    Returns ``(arbitrator, outcome, result)``: the file and the offline episode's outcome
    and recorded result.
    """
    from neat_helpers import neat_config, network_spec, random_genomes

    from evorbc_ros.arbitrator import ArbitratorFile
    from offline_evolution.maze_task.replay import replay

    config = neat_config(task.layout.n_inputs, 2, path=neat_path)
    for seed in range(tries):
        network = network_spec(random_genomes(config, 1, seed=seed)[0], config)
        arb = ArbitratorFile(
            kind="evorbc",
            robot=robot,
            network=network,
            sensors=task.layout,
            mapping="polar",
            repertoire={"fingerprint": rep.fingerprint(), "robot": robot, "count": len(rep)},
            evolution=evolution or {},
        )
        outcomes, result = replay(arb, task, task.nominal_starts(), rep)
        if len(set(result.choice[0, : result.cycles[0]].tolist())) >= 3:
            break
    return arb, outcomes[0], result


def assert_lockstep_reproduces(
    tmp_path, domain, robot, maze, controller, episode_time, timeout=120.0
):
    """Run the lockstep graph with ``controller`` (the fixture's arbitrator, repertoire,
    offline outcome and result) and assert it reproduces the offline episode: the same
    primitive at every cycle, at least 3 different ones, identical poses (bit for bit),
    the same robot and fitness. Returns the graph's trajectory ``(cycles + 1, 3)``."""
    import pytest

    arb_path, rep_path, outcome, result = controller
    run = GraphRun(
        tmp_path,
        domain,
        maze,
        episode_time=episode_time,
        arbitrator=arb_path,
        repertoire=rep_path,
        robot=robot,
    )
    got = run.finish(timeout=timeout)
    choices = run.recorded_choices()
    cycles = assert_same_choices(choices, result)
    assert len(set(choices.tolist())) >= 3  # the arbitrator switched primitives
    trajectory = np.array(got["trajectory"])
    np.testing.assert_array_equal(trajectory, result.pose[0, : cycles + 1])  # bit for bit
    assert got["robot"] == robot and got["fitness"] == pytest.approx(outcome.fitness)
    assert got["reached"] == outcome.reached
    return trajectory
