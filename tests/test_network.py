"""Networks: the onboard and compiled evaluations equal neat-python's activate."""

import neat
import numpy as np
import pytest
from neat_helpers import neat_config, network_spec, random_genomes

from evorbc_ros.network import ConnectionSpec, NetworkError, NetworkSpec, NodeSpec
from offline_evolution.arbitrator.compiled import activate_packed, pack_networks


@pytest.mark.parametrize("all_functions", [False, True])
def test_compiled_networks_equal_neat_python(all_functions):
    config = neat_config(all_functions=all_functions)
    genomes = random_genomes(config, 40, seed=1 + all_functions)
    assert sum(len(g.nodes) > 2 for g in genomes) >= 30  # most have hidden nodes
    specs = [network_spec(g, config) for g in genomes]
    pack = pack_networks(specs)
    rng = np.random.default_rng(5)
    used = set()
    for k, (genome, spec) in enumerate(zip(genomes, specs, strict=True)):
        reference = neat.nn.FeedForwardNetwork.create(genome, config)
        onboard = spec.compile()
        used |= {(n.activation, n.aggregation) for n in spec.nodes}
        for _ in range(25):
            x = rng.uniform(-1.0, 1.5, 10)
            want = np.array(reference.activate(list(x)))
            np.testing.assert_allclose(onboard.activate(x), want, rtol=1e-12, atol=1e-12)
            np.testing.assert_allclose(activate_packed(pack, k, x), want, rtol=1e-12, atol=1e-12)
    if all_functions:
        assert len({a for a, _ in used}) >= 12 and len({g for _, g in used}) >= 6


def test_spec_round_trip_and_only_needed_nodes_are_evaluated():
    spec = NetworkSpec(
        input_keys=(-1, -2),
        output_keys=(0,),
        nodes=(
            NodeSpec(0, 0.1, 1.0, "sigmoid", "sum"),
            NodeSpec(5, 0.3, 1.0, "tanh", "sum"),
            NodeSpec(7, 0.0, 1.0, "relu", "sum"),
        ),  # 7 feeds nothing
        connections=(
            ConnectionSpec(-1, 5, 0.5),
            ConnectionSpec(5, 0, 2.0),
            ConnectionSpec(-2, 0, -1.0),
            ConnectionSpec(-2, 7, 1.0),
            ConnectionSpec(-1, 0, 9.0, enabled=False),
        ),
    )
    assert NetworkSpec.from_dict(spec.to_dict()) == spec
    net = spec.compile()
    assert list(net.node_slot) == [3, 2]  # hidden node 5 (slot 3), then output 0 (slot 2)
    h = np.tanh(2.5 * (0.3 + 0.5 * 0.4))
    want = 1 / (1 + np.exp(-5 * (0.1 + 2.0 * h - 1.0 * 0.7)))
    assert net.activate([0.4, 0.7])[0] == pytest.approx(want, rel=1e-15)


@pytest.mark.parametrize(
    ("change", "message"),
    [
        (lambda d: d["nodes"][0].update(activation="swish"), "unknown activation 'swish'"),
        (
            lambda d: d["connections"].append(
                {"source": 3, "target": 0, "weight": 1.0, "enabled": True}
            ),
            "starts at an unknown node",
        ),
        (
            lambda d: d["connections"].extend(
                [
                    {"source": 0, "target": 1, "weight": 1.0, "enabled": True},
                    {"source": 1, "target": 0, "weight": 1.0, "enabled": True},
                ]
            ),
            "cycle",
        ),
        (lambda d: d["nodes"].pop(), "output node 1 has no node definition"),
        (lambda d: d["connections"][0].update(weight=float("nan")), "finite number"),
    ],
)
def test_bad_networks_are_refused(change, message):
    spec = NetworkSpec(
        (-1,),
        (0, 1),
        (NodeSpec(0, 0.0, 1.0, "sigmoid", "sum"), NodeSpec(1, 0.0, 1.0, "sigmoid", "sum")),
        (ConnectionSpec(-1, 0, 1.0), ConnectionSpec(-1, 1, 1.0)),
    )
    data = spec.to_dict()
    change(data)
    with pytest.raises(NetworkError, match=message):
        NetworkSpec.from_dict(data)
