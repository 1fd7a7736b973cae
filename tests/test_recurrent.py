"""Recurrent arbitrator networks (NEAT ``feed_forward = False``, docs/design.md section 8):
settings, file format, and bit-identity with neat-python's RecurrentNetwork in every
evaluator (the numba kernel, the onboard network, the legged episode runner)."""

import json

import neat
import numpy as np
import pytest
from neat_helpers import neat_config, network_spec, random_genomes

from evorbc_ros.arbitrator import ArbitratorError, ArbitratorFile
from evorbc_ros.config import config_dir
from evorbc_ros.network import ConnectionSpec, NetworkError, NetworkSpec, NodeSpec
from offline_evolution.arbitrator.compiled import activate_packed_sequence, pack_networks

RECURRENT_4WS = config_dir() / "neat" / "4ws-recurrent.ini"


def bits(a):
    """The IEEE bits of float64 values, so NaN and -0.0 compare exactly."""
    return np.asarray(a, dtype=np.float64).view(np.int64)


def cycles_among_needed(spec: NetworkSpec) -> tuple[bool, bool]:
    """Whether the enabled connections that feed outputs hold a self-loop and a 2-cycle."""
    from evorbc_ros.network import _needed_nodes

    edges = {(c.source, c.target) for c in spec.connections if c.enabled}
    needed = _needed_nodes(set(spec.input_keys), list(spec.output_keys), sorted(edges))
    inner = {(a, b) for a, b in edges if a in needed and b in needed}
    self_loop = any(a == b for a, b in inner)
    two_cycle = any(a != b and (b, a) in inner for a, b in inner)
    return self_loop, two_cycle


def recurrent_genomes(n=40, seed=3):
    config = neat_config(path=RECURRENT_4WS)
    genomes = random_genomes(config, n, seed=seed)
    return config, genomes, [network_spec(g, config) for g in genomes]


def test_the_recurrent_settings_differ_from_4ws_only_in_feed_forward():
    shipped = (config_dir() / "neat" / "4ws.ini").read_text()
    recurrent = RECURRENT_4WS.read_text()

    def settings(text):
        return [
            line.split("#")[0].strip() for line in text.splitlines() if line.split("#")[0].strip()
        ]

    a, b = settings(shipped), settings(recurrent)
    changed = [(x, y) for x, y in zip(a, b, strict=True) if x != y]
    assert [tuple(" ".join(s.split()) for s in pair) for pair in changed] == [
        ("feed_forward = True", "feed_forward = False")
    ]


@pytest.mark.parametrize(
    ("path", "n_outputs"),
    [("4ws.ini", 2), ("4ws.ini", 5), ("hexapod.ini", 2), ("a1.ini", 2)],
    ids=["4ws", "standard", "hexapod", "a1"],
)
def test_feed_forward_false_is_accepted_for_every_robot(tmp_path, path, n_outputs):
    text = (config_dir() / "neat" / path).read_text()
    assert "feed_forward          = True" in text
    ini = tmp_path / "r.ini"
    ini.write_text(text.replace("feed_forward          = True", "feed_forward          = False"))
    config = neat_config(10, n_outputs, path=ini)
    assert not config.genome_config.feed_forward
    genome = random_genomes(config, 1, seed=1)[0]
    assert network_spec(genome, config).recurrent


def test_kernel_onboard_and_neat_python_agree_bit_for_bit_over_50_cycles():
    config, genomes, specs = recurrent_genomes()
    found = [cycles_among_needed(s) for s in specs]
    assert any(s for s, _ in found) and any(t for _, t in found)  # self-loops and 2-cycles
    assert all(s.recurrent for s in specs)
    pack = pack_networks(specs)
    rng = np.random.default_rng(7)
    inputs = rng.uniform(-1.0, 1.5, (50, 10))
    for k, (genome, spec) in enumerate(zip(genomes, specs, strict=True)):
        reference = neat.nn.RecurrentNetwork.create(genome, config)
        want = np.array([reference.activate(list(x)) for x in inputs])
        onboard = spec.compile()
        got = np.array([onboard.activate(x) for x in inputs])
        np.testing.assert_array_equal(bits(got), bits(want), err_msg=f"onboard, genome {k}")
        kernel = activate_packed_sequence(pack, k, inputs)
        np.testing.assert_array_equal(bits(kernel), bits(want), err_msg=f"kernel, genome {k}")
        # reset: the first outputs again, as after neat-python's reset
        onboard.reset()
        reference.reset()
        again = np.array([onboard.activate(x) for x in inputs[:5]])
        np.testing.assert_array_equal(bits(again), bits(want[:5]))
        np.testing.assert_array_equal(
            bits(again), bits([reference.activate(list(x)) for x in inputs[:5]])
        )
    # memory matters: some network answers the same readings differently later on
    repeated = np.tile(inputs[:1], (6, 1))
    assert any(
        not np.array_equal(out[0], out[-1])
        for out in (activate_packed_sequence(pack, k, repeated) for k in range(len(specs)))
    )


def test_a_signal_crosses_one_connection_per_step():
    """Input -> hidden -> output: the input reaches the output on the second step."""
    spec = NetworkSpec(
        input_keys=(-1,),
        output_keys=(0,),
        nodes=(NodeSpec(0, 0.0, 1.0, "identity", "sum"), NodeSpec(5, 0.0, 1.0, "identity", "sum")),
        connections=(
            ConnectionSpec(-1, 5, 2.0),
            ConnectionSpec(5, 0, 3.0),
            ConnectionSpec(0, 0, 0.5),
        ),
        recurrent=True,
    )
    net = spec.compile()
    outs = [float(net.activate([1.0])[0]) for _ in range(4)]
    assert outs == [0.0, 6.0, 9.0, 10.5]  # 0, 2*3, 6*0.5 + 6, 9*0.5 + 6
    pack = pack_networks([spec])
    assert activate_packed_sequence(pack, 0, np.ones((4, 1)))[:, 0].tolist() == outs


def arbitrator_dict(network: NetworkSpec) -> dict:
    """The paper-protocol 4ws-5 file (the paper's layout, as ``network``'s) with ``network``."""
    from evorbc_ros.defaults import paper_arbitrator

    data = json.loads(paper_arbitrator().read_text())
    n_in = len(data["network"]["inputs"])
    assert n_in == len(network.input_keys)
    data["network"] = network.to_dict()
    return data


def test_the_file_records_recurrent_and_old_files_load_unchanged(tmp_path):
    _, _, specs = recurrent_genomes(n=10)
    spec = next(s for s in specs if any(cycles_among_needed(s)))
    assert spec.to_dict()["recurrent"] is True
    feed_forward = NetworkSpec(spec.input_keys, spec.output_keys, spec.nodes[:2], ())
    assert "recurrent" not in feed_forward.to_dict()  # feed-forward files as before
    assert NetworkSpec.from_dict(feed_forward.to_dict()) == feed_forward
    path = tmp_path / "a.json"
    path.write_text(json.dumps(arbitrator_dict(spec)))
    loaded = ArbitratorFile.load(path)
    assert loaded.network == spec and loaded.network.compile().recurrent
    # The same network said to be feed-forward: its cycle is refused in one line.
    data = arbitrator_dict(spec)
    del data["network"]["recurrent"]
    path.write_text(json.dumps(data))
    with pytest.raises(ArbitratorError) as e:
        ArbitratorFile.load(path)
    assert "cycle" in str(e.value) and str(path) in str(e.value) and "\n" not in str(e.value)
    data["network"]["recurrent"] = "yes"
    path.write_text(json.dumps(data))
    with pytest.raises(ArbitratorError, match="recurrent must be true or false"):
        ArbitratorFile.load(path)


def test_recurrent_needed_nodes_without_inputs_stay_at_zero():
    """neat-python's RecurrentNetwork never evaluates a node without enabled inputs."""
    spec = NetworkSpec(
        input_keys=(-1,),
        output_keys=(0, 1),
        nodes=(NodeSpec(0, 0.7, 1.0, "sigmoid", "sum"), NodeSpec(1, 0.2, 1.0, "sigmoid", "sum")),
        connections=(ConnectionSpec(-1, 0, 1.0), ConnectionSpec(-1, 1, 1.0, enabled=False)),
    )
    rec = NetworkSpec(**{**vars(spec), "recurrent": True}).compile()
    assert rec.activate([0.5])[1] == 0.0 and rec.activate([0.5])[1] == 0.0
    assert spec.compile().activate([0.5])[1] == pytest.approx(1 / (1 + np.exp(-1.0)))


def test_episodes_reset_the_state_and_the_fixed_point_exit_stays_exact():
    """In the 4WS kernel: every episode starts from a zero state (the same episode twice
    in one call gives the same result), and episodes that stop early at a fixed point
    (pose and network state unchanged) end as the recorded full episodes do."""
    from evorbc_ros.defaults import default_repertoire
    from evorbc_ros.repertoire import Repertoire
    from offline_evolution.maze_task.task import MazeTask, MazeTaskSettings

    task = MazeTask(MazeTaskSettings(("obstacle", "gaps"), 30.0), "4ws-5")
    config = neat_config(task.layout.n_inputs, 2, path=RECURRENT_4WS)
    specs = [network_spec(g, config) for g in random_genomes(config, 24, seed=5)]
    controller = task.controller("evorbc", Repertoire.load(default_repertoire("4ws-5")), "polar")
    starts = np.repeat(task.nominal_starts(), 2, axis=0)  # each start twice
    fast = task.evaluate(specs, controller, starts)
    full = task.evaluate(specs, controller, starts, record=True)
    for key in ("reached", "cycles", "final_distance", "fitness"):
        np.testing.assert_array_equal(getattr(fast, key), getattr(full, key))
    np.testing.assert_array_equal(full.choice[0::2], full.choice[1::2])
    np.testing.assert_array_equal(bits(full.outputs[0::2]), bits(full.outputs[1::2]))
    assert len({tuple(r) for r in full.choice[:, :50].tolist()}) > 2  # they drive about


def ramp_network(n_inputs: int, flip_at: float = 0.6) -> NetworkSpec:
    """A standard-NEAT 4WS controller with a clock: hidden node 10 ramps by 0.01 a cycle
    (a clamped self-loop); the speed gene is +1 until the ramp passes ``flip_at`` (cycle
    60), then -1; the other genes are 0 (straight wheels)."""
    nodes = [NodeSpec(k, 0.0, 1.0, "sigmoid", "sum") for k in range(1, 5)]
    nodes += [
        NodeSpec(0, 1000.0 * flip_at, 1.0, "sigmoid", "sum"),
        NodeSpec(10, 0.01, 1.0, "clamped", "sum"),
    ]
    connections = [ConnectionSpec(-1, k, 0.0) for k in range(1, 5)]
    connections += [ConnectionSpec(10, 10, 1.0), ConnectionSpec(10, 0, -1000.0)]
    inputs = tuple(-i - 1 for i in range(n_inputs))
    return NetworkSpec(inputs, tuple(range(5)), tuple(nodes), tuple(connections), True)


def test_a_robot_stuck_while_its_network_still_changes_is_not_stopped_early():
    """The robot drives into a wall and stands (pose, speed and wheels unchanged) while
    the network's clock runs on; at cycle 60 it reverses. A fixed-point exit that looked at
    the robot alone would end the episode at the wall."""
    from offline_evolution.maze_task.task import MazeTask, MazeTaskSettings

    task = MazeTask(MazeTaskSettings(("corridors", "gaps"), 30.0), "4ws-5")
    controller = task.controller("standard", None, None)
    spec = ramp_network(task.layout.n_inputs)
    fast = task.evaluate([spec], controller, task.nominal_starts())
    full = task.evaluate([spec], controller, task.nominal_starts(), record=True)
    for key in ("reached", "cycles", "final_distance", "fitness"):
        np.testing.assert_array_equal(getattr(fast, key), getattr(full, key))
    for e in range(2):
        moved = np.any(np.diff(full.pose[e], axis=0) != 0.0, axis=1)
        assert not moved[45:60].any() and moved[62:70].any()  # stuck, then backs away


def test_feed_forward_networks_in_files_still_refuse_cycles():
    spec = NetworkSpec(
        input_keys=(-1,),
        output_keys=(0,),
        nodes=(NodeSpec(0, 0.0, 1.0, "sigmoid", "sum"),),
        connections=(ConnectionSpec(0, 0, 1.0),),
    )
    with pytest.raises(NetworkError, match="cycle"):
        NetworkSpec.from_dict(spec.to_dict())
    assert NetworkSpec.from_dict({**spec.to_dict(), "recurrent": True}).recurrent
