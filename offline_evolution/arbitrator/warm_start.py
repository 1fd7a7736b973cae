"""Start a NEAT run from an evolved network (``--init-from``): fine-tuning a controller.

A run usually starts from neat-python's random minimal networks. Started from a
controller instead (an arbitrator file), its first population is that network once,
unchanged, and ``pop_size - 1`` copies mutated once each by the run's own NEAT settings,
as children of it would be. From there it is an ordinary run: the same selection,
speciation, checkpoints and post-evaluation. This is how a controller evolved on one task
(the paper protocol's single start, say) is carried on to a harder one (random starts
anywhere in the maze) without losing what it already does (docs/design.md section 8,
"Starting from a controller").

The network's inputs are matched to the run's sensor layout **by name** (``range_000``,
``goal_bearing``, ...; a range input's name holds its beam angle): a layout that adds inputs
(the motion input, more beams) starts with them unconnected, and one that lacks an input the
network reads is refused. So is a layout in which an input of the same name would measure
something else (another range, beam width or goal-sector width). Its hidden nodes keep
their keys; new nodes are numbered after them.
"""

from __future__ import annotations

import hashlib
import json
import math
import os
from itertools import count

import neat

from evorbc_ros.arbitrator import ArbitratorError, ArbitratorFile
from evorbc_ros.config import ConfigError
from evorbc_ros.controller_kinds import ControllerKind, controller_kind
from evorbc_ros.json_files import first_difference
from evorbc_ros.network import ConnectionSpec, NetworkError, NetworkSpec
from evorbc_ros.sensors import SensorLayout


def network_fingerprint(network: NetworkSpec) -> str:
    """SHA-256 of a network's plain-data form: what a run starts from, wherever it is kept."""
    return hashlib.sha256(json.dumps(network.to_dict(), sort_keys=True).encode()).hexdigest()


def load_initial_network(
    path: str | os.PathLike,
    robot: str,
    kind: ControllerKind | str,
    mapping: str | None,
    layout: SensorLayout,
    config: neat.Config | None = None,
    neat_source: str = "the NEAT settings",
) -> NetworkSpec:
    """The network of an arbitrator file, with its inputs renumbered for ``layout``.

    Args:
        path: an arbitrator file (JSON, validated as every reader validates it).
        robot, kind, mapping: the run's; the file's must be the same (a network's outputs
            are a point of that robot's behaviour space under that mapping, or its
            locomotion parameters for the standard-NEAT baseline).
        layout: the run's sensor layout; input ``-(i + 1)`` is its ``i``-th input name.
        config: the run's NEAT settings, which the network must fit (see
            :func:`check_fits`); ``neat_source`` names them in errors.

    Raises:
        ConfigError: one line naming the file and what does not fit.
    """
    kind = controller_kind(kind)
    try:
        arb = ArbitratorFile.load(path)
    except ArbitratorError as e:
        raise ConfigError(str(e)) from None
    for what, theirs, ours in (("robot", arb.robot, robot), ("kind", arb.kind.name, kind.name)):
        if theirs != ours:
            raise ConfigError(f"{path}: its {what} is {theirs!r}, this run's is {ours!r}")
    if kind.uses_repertoire and arb.mapping != mapping:
        raise ConfigError(
            f"{path}: its mapping is {arb.mapping!r}, this run's is {mapping!r} "
            "(give --mapping to match)"
        )
    for where, named in ((str(path), arb.sensors), ("the run's sensor layout", layout)):
        names = named.input_names()
        twice = sorted({n for n in names if names.count(n) > 1})
        if twice:
            raise ConfigError(f"{path}: {where} has two inputs named {', '.join(twice)}")
    theirs, ours = arb.sensors.input_names(), layout.input_names()
    missing = [name for name in theirs if name not in ours]
    if missing:
        raise ConfigError(
            f"{path}: the network reads {', '.join(missing)}, which the run's sensor layout "
            f"does not give (it gives {', '.join(ours)})"
        )
    differs = _measured_differently(arb.sensors, layout)
    if differs:
        raise ConfigError(f"{path}: {differs}, so inputs of the same name measure differently")
    net = arb.network
    # The file's i-th input key reads its i-th input name; here that name's place in the
    # run's layout gives the key (neat-python's input i is key -(i + 1)).
    key = {k: -(ours.index(n) + 1) for k, n in zip(net.input_keys, theirs, strict=True)}
    hidden = [n.key for n in net.nodes if n.key < 0]
    if hidden:
        raise ConfigError(f"{path}: node keys must be 0 or more (neat-python's), got {hidden}")
    network = NetworkSpec(
        input_keys=tuple(-(i + 1) for i in range(len(ours))),
        output_keys=net.output_keys,
        nodes=net.nodes,
        connections=tuple(
            ConnectionSpec(key.get(c.source, c.source), c.target, c.weight, c.enabled)
            for c in net.connections
        ),
        recurrent=net.recurrent,
    )
    try:
        network.compile()
    except NetworkError as e:
        raise ConfigError(f"{path}: network: {e}") from None
    if config is not None:
        problem = check_fits(network, config, neat_source)
        if problem:
            raise ConfigError(f"{path}: {problem}")
    return network


def check_fits(network: NetworkSpec, config: neat.Config, neat_source: str) -> str | None:
    """Why ``network`` cannot start a run of ``config`` (in words), or None if it can."""
    gc = config.genome_config
    if tuple(network.input_keys) != tuple(gc.input_keys):
        return f"the network has {len(network.input_keys)} inputs, the run {gc.num_inputs}"
    if tuple(network.output_keys) != tuple(gc.output_keys):
        return (
            f"the network's outputs are keyed {list(network.output_keys)}, {neat_source} key "
            f"them {list(gc.output_keys)}"
        )
    if network.recurrent == gc.feed_forward:
        kind = "recurrent" if network.recurrent else "feed-forward"
        return f"the network is {kind}, and {neat_source} set feed_forward = {gc.feed_forward}"
    for node in network.nodes:
        for attribute, options in (
            ("activation", gc.activation_options),
            ("aggregation", gc.aggregation_options),
        ):
            value = getattr(node, attribute)
            if value not in options:
                return (
                    f"node {node.key} has {attribute} {value!r}, which {neat_source} do not "
                    f"offer ({attribute}_options: {' '.join(options)})"
                )
    return None


#: Sensor settings that say which inputs a group has (their directions), not what each
#: input measures: they may differ between a network's layout and the run's.
_WHICH_INPUTS = ("angles_deg", "centres_deg")


def _directions(layout: SensorLayout) -> dict[str, float]:
    """Each direction-named input's exact direction (rad; names round it to a degree)."""
    angles = list(layout.rangefinders.angles) if layout.rangefinders else []
    angles += list(layout.goal_sectors.centres) if layout.goal_sectors else []
    return dict(zip(layout.input_names(), angles, strict=False))


def _measured_differently(theirs: SensorLayout, ours: SensorLayout) -> str | None:
    """The first sensor setting of ``theirs`` that ``ours`` sets otherwise, said in words."""

    def measures(layout: SensorLayout, groups) -> dict:
        data = layout.to_dict()
        return {
            g: {k: v for k, v in data[g].items() if k not in _WHICH_INPUTS}
            if isinstance(data.get(g), dict)
            else data.get(g)
            for g in groups
        }

    groups = list(theirs.to_dict())
    differs = first_difference(measures(theirs, groups), measures(ours, groups), "the file")
    if differs:
        return differs.removesuffix(" now") + " in the run's sensor layout"
    ours_at = _directions(ours)
    for name, angle in _directions(theirs).items():
        if abs(math.remainder(angle - ours_at[name], math.tau)) > 1e-9:
            return (
                f"its {name} points at {math.degrees(angle):g} deg, the run's at "
                f"{math.degrees(ours_at[name]):g} deg"
            )
    return None


def genome_from_network(network: NetworkSpec, key: int, config: neat.Config):
    """A neat-python genome that computes ``network`` (genes in the network's order).

    Connections get the innovation numbers of ``config``'s tracker for an initial
    connection between the same nodes, so all copies of one network line up in
    crossover. Call it after the population (and so the tracker) exists.

    The network must fit ``config`` (:func:`check_fits`; :func:`seed_population` checks).
    """
    gc = config.genome_config
    genome = config.genome_type(key)
    for n in network.nodes:
        node = gc.node_gene_type(n.key)
        # Attributes a NetworkSpec does not hold (neat-python's CTRNN time constant) are
        # drawn as for a new node: they do not change what a network of these settings
        # computes.
        node.init_attributes(gc)
        for name in ("bias", "response", "activation", "aggregation"):
            setattr(node, name, getattr(n, name))
        genome.nodes[n.key] = node
    for c in network.connections:
        innovation = gc.innovation_tracker.get_innovation_number(
            c.source, c.target, "initial_connection"
        )
        conn = gc.connection_gene_type((c.source, c.target), innovation=innovation)
        conn.init_attributes(gc)
        conn.weight, conn.enabled = c.weight, c.enabled
        genome.connections[conn.key] = conn
    return genome


def seed_population(
    population: neat.Population, network: NetworkSpec, compatibility_threshold: float
) -> None:
    """Replace a new population's genomes with ``network`` and mutated copies of it.

    ``population`` is one ``neat.Population(config, seed=...)`` has just made (generation
    0, its random state seeded by the run): the first genome key gets ``network`` as it
    is, every other key a copy mutated once. The species are then formed anew, from
    ``compatibility_threshold``, the settings' value before the discarded random
    population was speciated (a species set that steers the threshold moved it then).
    Seeded: the same run seed and network give the same population.

    Raises:
        ConfigError: the network is inconsistent or does not fit the NEAT settings
            (:func:`check_fits`).
    """
    config = population.config
    gc = config.genome_config
    try:
        network.compile()  # every connection joins nodes the network has
    except NetworkError as e:
        raise ConfigError(f"the initial network: {e}") from None
    problem = check_fits(network, config, "the NEAT settings")
    if problem:
        raise ConfigError(problem)
    # New nodes are numbered after every node the network already has.
    highest = max([n.key for n in network.nodes] + list(gc.output_keys))
    pending = None if gc.node_indexer is None else next(gc.node_indexer)
    gc.node_indexer = count(max(highest + 1, pending or 0))
    genomes = {}
    for i, key in enumerate(sorted(population.population)):
        genome = genome_from_network(network, key, config)
        if i:
            genome.mutate(gc)
        genomes[key] = genome
    population.population = genomes
    config.species_set_config.compatibility_threshold = compatibility_threshold
    population.species = config.species_set_type(config.species_set_config, population.reporters)
    population.species.speciate(config, population.population, population.generation)
