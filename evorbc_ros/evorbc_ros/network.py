"""NEAT networks as plain data, compiled to arrays and evaluated onboard.

A :class:`NetworkSpec` is what an arbitrator file stores: nodes (bias, response,
activation, aggregation), connections (source, target, weight, enabled) and the input and
output keys, with neat-python's conventions (inputs have keys -1, -2, ...; outputs 0, 1,
...). :meth:`NetworkSpec.compile` turns it into flat arrays in evaluation order, the form
both this module's pure-Python :meth:`CompiledNetwork.activate` (onboard, 10 Hz) and the
numba kernels of the offline evolution run.

Semantics follow neat-python's ``FeedForwardNetwork``: only nodes that some output
depends on are evaluated, each as ``activation(bias + response * aggregation(inputs))``
over its enabled incoming connections in file order; a needed node with no enabled input
outputs ``activation(bias + response * aggregation([]))``.

A network marked ``recurrent`` (evolved with neat-python's ``feed_forward = False``) follows
neat-python's ``RecurrentNetwork`` instead (docs/design.md section 8): two value buffers;
each activation sets the inputs, then every evaluated node computes from the *previous*
activation's values, so a signal crosses one connection per activation (one control
cycle). Cycles are allowed; values start at 0 and :meth:`CompiledNetwork.reset` sets them
to 0 again (the start of an episode). Needed nodes without an enabled incoming connection
are never evaluated there and stay at 0.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property, reduce
from operator import add
from typing import ClassVar

import numpy as np

from evorbc_ros.limits import NETWORK_CONNECTIONS, NETWORK_NODES


def _clamp(z: float, lo: float, hi: float) -> float:
    return max(lo, min(hi, z))


def _inv(z: float) -> float:
    return 1.0 / z if z != 0.0 else 0.0


# neat-python's activation functions (same definitions, clamps and constants). The order
# fixes the integer ids the compiled kernels use.
ACTIVATIONS = {
    "sigmoid": lambda z: 1.0 / (1.0 + math.exp(-_clamp(5.0 * z, -60.0, 60.0))),
    "tanh": lambda z: math.tanh(_clamp(2.5 * z, -60.0, 60.0)),
    "sin": lambda z: math.sin(_clamp(5.0 * z, -60.0, 60.0)),
    "gauss": lambda z: math.exp(-5.0 * _clamp(z, -3.4, 3.4) ** 2),
    "relu": lambda z: z if z > 0.0 else 0.0,
    "elu": lambda z: z if z > 0.0 else math.exp(z) - 1.0,
    "lelu": lambda z: z if z > 0.0 else 0.005 * z,
    "selu": lambda z: (
        1.0507009873554804934193349852946 * z
        if z > 0.0
        else 1.0507009873554804934193349852946
        * 1.6732632423543772848170429916717
        * (math.exp(z) - 1.0)
    ),
    "softplus": lambda z: 0.2 * math.log(1.0 + math.exp(_clamp(5.0 * z, -60.0, 60.0))),
    "identity": lambda z: z,
    "clamped": lambda z: _clamp(z, -1.0, 1.0),
    "inv": _inv,
    "log": lambda z: math.log(max(1e-7, z)),
    "exp": lambda z: math.exp(_clamp(z, -60.0, 60.0)),
    "abs": abs,
    "hat": lambda z: max(0.0, 1.0 - abs(z)),
    "square": lambda z: z * z,
    "cube": lambda z: z * z * z,
}
ACTIVATION_IDS = {name: k for k, name in enumerate(ACTIVATIONS)}


def _median(values: list[float]) -> float:
    n = len(values)
    if n <= 2:
        return sum(values) / n
    # NaN last, as numpy sorts (the compiled kernels): sorted() leaves it where it was.
    finite = [x for x in values if x == x]
    v = sorted(finite) + [math.nan] * (n - len(finite))
    return v[n // 2] if n % 2 else (v[n // 2 - 1] + v[n // 2]) / 2.0


def _sum(x: list[float]) -> float:
    """The terms added one at a time in order, as the compiled kernels add them.

    Not builtin ``sum``: from Python 3.12 on it compensates the rounding of a sum of plain
    floats (not of numpy scalars), so its last bit would depend on the Python version.
    """
    return reduce(add, x, 0.0)


# neat-python's aggregations, with its values for a node without inputs.
AGGREGATIONS = {
    "sum": _sum,
    "product": lambda x: math.prod(x, start=1.0),
    "max": lambda x: max(x) if x else 0.0,
    "min": lambda x: min(x) if x else 0.0,
    "maxabs": lambda x: max(x, key=abs) if x else 0.0,
    "mean": lambda x: _sum(x) / len(x) if x else 0.0,
    "median": lambda x: _median(x) if x else 0.0,
}
AGGREGATION_IDS = {name: k for k, name in enumerate(AGGREGATIONS)}


class NetworkError(ValueError):
    """A network description is inconsistent; the message says what is wrong."""


@dataclass(frozen=True)
class NodeSpec:
    """A hidden or output node."""

    key: int
    bias: float
    response: float
    activation: str
    aggregation: str


@dataclass(frozen=True)
class ConnectionSpec:
    """A connection gene; disabled connections are kept but not evaluated."""

    source: int
    target: int
    weight: float
    enabled: bool = True


@dataclass(frozen=True)
class NetworkSpec:
    """A network in neat-python's terms: feed-forward, or ``recurrent`` (see the module)."""

    input_keys: tuple[int, ...]
    output_keys: tuple[int, ...]
    nodes: tuple[NodeSpec, ...]
    connections: tuple[ConnectionSpec, ...]
    recurrent: bool = False

    def to_dict(self) -> dict:
        """Plain-data form used in arbitrator files.

        ``"recurrent": true`` is written only for a recurrent network: a feed-forward one
        is written exactly as before the key existed, and a file without it is read as
        feed-forward.
        """
        extra = {"recurrent": True} if self.recurrent else {}
        return {
            "inputs": list(self.input_keys),
            "outputs": list(self.output_keys),
            "nodes": [
                {
                    "key": n.key,
                    "bias": n.bias,
                    "response": n.response,
                    "activation": n.activation,
                    "aggregation": n.aggregation,
                }
                for n in self.nodes
            ],
            "connections": [
                {"source": c.source, "target": c.target, "weight": c.weight, "enabled": c.enabled}
                for c in self.connections
            ],
            **extra,
        }

    @classmethod
    def from_dict(cls, data: dict) -> NetworkSpec:
        """Build from :meth:`to_dict`'s form; raises :class:`NetworkError` if malformed.

        The numbers of nodes and connections are checked against
        :data:`~evorbc_ros.limits.NETWORK_NODES` and ``NETWORK_CONNECTIONS`` before anything
        is built, so a file cannot ask for unbounded work (docs/design.md section 12).
        """
        if not isinstance(data, dict):
            raise NetworkError(f"the network must be an object, got {type(data).__name__}")
        for key in ("inputs", "outputs", "nodes", "connections"):
            if key in data and not isinstance(data[key], list):
                raise NetworkError(f"{key} must be a list, got {type(data[key]).__name__}")
        for limit, key in ((NETWORK_NODES, "nodes"), (NETWORK_CONNECTIONS, "connections")):
            problem = limit.problem(len(data.get(key, ())), f"in network.{key}")
            if problem:
                raise NetworkError(problem)
        try:
            spec = cls(
                input_keys=tuple(_int(k, "inputs") for k in data["inputs"]),
                output_keys=tuple(_int(k, "outputs") for k in data["outputs"]),
                nodes=tuple(
                    NodeSpec(
                        _int(n["key"], "nodes.key"),
                        _num(n["bias"], "bias"),
                        _num(n["response"], "response"),
                        str(n["activation"]),
                        str(n["aggregation"]),
                    )
                    for n in data["nodes"]
                ),
                connections=tuple(
                    ConnectionSpec(
                        _int(c["source"], "connections.source"),
                        _int(c["target"], "connections.target"),
                        _num(c["weight"], "weight"),
                        _bool(c["enabled"]),
                    )
                    for c in data["connections"]
                ),
                recurrent=_flag(data.get("recurrent", False), "recurrent"),
            )
        except KeyError as e:
            raise NetworkError(f"missing key {e.args[0]!r} in the network") from None
        except (TypeError, AttributeError) as e:
            raise NetworkError(f"malformed network ({e})") from None
        spec.compile()  # validates structure
        return spec

    def compile(self) -> CompiledNetwork:
        """Arrays in evaluation order (see :class:`CompiledNetwork`).

        A recurrent network compiles to a :class:`CompiledRecurrentNetwork`, with its
        state at 0; each call gives a fresh state.

        Raises:
            NetworkError: unknown activation/aggregation, duplicate or missing nodes,
                connections to unknown nodes, or (feed-forward only) a cycle among the
                needed nodes.
        """
        return _compile(self)


@dataclass(frozen=True)
class CompiledNetwork:
    """A network flattened for evaluation.

    Value slots: inputs first (in ``input_keys`` order), then outputs (``output_keys``
    order), then the needed hidden nodes. Node ``k`` of the evaluation order writes slot
    ``node_slot[k]`` from links ``link_start[k]:link_start[k + 1]`` (source slot, weight).
    """

    n_inputs: int
    n_outputs: int
    n_slots: int
    node_slot: np.ndarray  # (n_eval,) int64
    bias: np.ndarray  # (n_eval,)
    response: np.ndarray  # (n_eval,)
    activation: np.ndarray  # (n_eval,) int64 ids into ACTIVATIONS
    aggregation: np.ndarray  # (n_eval,) int64 ids into AGGREGATIONS
    link_start: np.ndarray  # (n_eval + 1,) int64
    link_source: np.ndarray  # (n_links,) int64 slots
    link_weight: np.ndarray  # (n_links,)
    #: Whether activations carry state (:class:`CompiledRecurrentNetwork`).
    recurrent: ClassVar[bool] = False

    def reset(self) -> None:
        """Forget the state of earlier activations: nothing to forget in a feed-forward one."""

    def activate(self, inputs) -> np.ndarray:
        """Evaluate the network on ``inputs`` (length ``n_inputs``); returns the outputs."""
        values = [0.0] * self.n_slots
        if len(inputs) != self.n_inputs:
            raise ValueError(f"expected {self.n_inputs} inputs, got {len(inputs)}")
        values[: self.n_inputs] = [float(v) for v in inputs]
        activations = list(ACTIVATIONS.values())
        aggregations = list(AGGREGATIONS.values())
        for slot, bias, response, activation, aggregation, links in self._plan:
            s = aggregations[aggregation]([values[source] * weight for source, weight in links])
            values[slot] = activations[activation](bias + response * s)
        return np.array(values[self.n_inputs : self.n_inputs + self.n_outputs])

    @cached_property
    def _plan(self) -> tuple[tuple, ...]:
        """The evaluation order as plain Python numbers, one tuple per evaluated node.

        Each holds the node's slot, bias, response, activation and aggregation ids, and
        its ``(source slot, weight)`` links in file order. Indexing numpy arrays one
        element at a time costs far more than the arithmetic (the 37-output standard
        network took about 90 us per activation, 42 us like this); the values are the
        same IEEE doubles, so the outputs are the same bits (sums: see ``_sum``).
        """
        start, source = self.link_start.tolist(), self.link_source.tolist()
        weight = self.link_weight.tolist()
        return tuple(
            (
                slot,
                bias,
                response,
                activation,
                aggregation,
                tuple(zip(source[lo:hi], weight[lo:hi], strict=True)),
            )
            for slot, bias, response, activation, aggregation, lo, hi in zip(
                self.node_slot.tolist(),
                self.bias.tolist(),
                self.response.tolist(),
                self.activation.tolist(),
                self.aggregation.tolist(),
                start[:-1],
                start[1:],
                strict=True,
            )
        )


@dataclass(frozen=True)
class CompiledRecurrentNetwork(CompiledNetwork):
    """A recurrent network with its state: neat-python's ``RecurrentNetwork`` semantics.

    The same arrays as :class:`CompiledNetwork`, but the nodes are the evaluated ones in
    no particular order (each reads only the previous activation's values) and may form
    cycles. The state is two buffers of ``n_slots`` values, 0 at first and after
    :meth:`reset`; an arbitrator resets it at the start of every episode.
    """

    recurrent: ClassVar[bool] = True

    def __post_init__(self) -> None:
        self.reset()

    def reset(self) -> None:
        """Set every value to 0, as at the start of an episode."""
        object.__setattr__(self, "_buffers", ([0.0] * self.n_slots, [0.0] * self.n_slots))

    def activate(self, inputs) -> np.ndarray:
        """One step: inputs set, every node from the previous step's values; the outputs.

        Args:
            inputs: ``(n_inputs,)`` this control cycle's readings.

        Returns:
            ``(n_outputs,)`` the output nodes' new values.
        """
        if len(inputs) != self.n_inputs:
            raise ValueError(f"expected {self.n_inputs} inputs, got {len(inputs)}")
        previous, current = self._buffers
        values = [float(v) for v in inputs]
        previous[: self.n_inputs] = values
        current[: self.n_inputs] = values
        activations = list(ACTIVATIONS.values())
        aggregations = list(AGGREGATIONS.values())
        for slot, bias, response, activation, aggregation, links in self._plan:
            s = aggregations[aggregation]([previous[source] * weight for source, weight in links])
            current[slot] = activations[activation](bias + response * s)
        object.__setattr__(self, "_buffers", (current, previous))
        return np.array(current[self.n_inputs : self.n_inputs + self.n_outputs])


def _num(value, what: str) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise NetworkError(f"{what} must be a finite number, got {value!r}")
    return float(value)


def _int(value, what: str) -> int:
    if isinstance(value, bool) or not isinstance(value, int):
        raise NetworkError(f"{what} must be an integer, got {value!r}")
    return value


def _bool(value) -> bool:
    return _flag(value, "connections.enabled")


def _flag(value, what: str) -> bool:
    if not isinstance(value, bool):
        raise NetworkError(f"{what} must be true or false, got {value!r}")
    return value


def _needed_nodes(inputs: set[int], outputs: list[int], edges: list[tuple[int, int]]) -> set:
    """Nodes some output depends on (outputs included, inputs excluded).

    A walk back from the outputs over each edge once: linear in nodes and edges.
    """
    sources: dict[int, list[int]] = {}
    for a, b in edges:
        sources.setdefault(b, []).append(a)
    needed = set(outputs)
    stack = list(outputs)
    while stack:
        for a in sources.get(stack.pop(), ()):
            if a not in needed and a not in inputs:
                needed.add(a)
                stack.append(a)
    return needed


def topological_order(needed: set[int], edges: list[tuple[int, int]]) -> list[int]:
    """The needed nodes in waves of Kahn's algorithm, each wave sorted by key.

    Iterative and linear in edges (plus the sorting of each wave), so a chain of any
    length cannot exhaust the stack or take quadratic time. In a DAG every order gives
    the same values; sorting makes it deterministic.

    Raises:
        NetworkError: the needed nodes form a cycle.
    """
    targets: dict[int, list[int]] = {n: [] for n in needed}
    indegree = dict.fromkeys(needed, 0)
    for a, b in set(edges):  # a repeated edge is one dependency
        if a in needed and b in needed:
            targets[a].append(b)
            indegree[b] += 1
    wave = sorted(n for n, d in indegree.items() if d == 0)
    order: list[int] = []
    while wave:
        order.extend(wave)
        ready = []
        for a in wave:
            for b in targets[a]:
                indegree[b] -= 1
                if indegree[b] == 0:
                    ready.append(b)
        wave = sorted(ready)
    if len(order) < len(needed):
        stuck = min(n for n, d in indegree.items() if d > 0)
        raise NetworkError(
            f"the network has a cycle (through node {stuck}); only feed-forward networks run here"
        )
    return order


def _compile(spec: NetworkSpec) -> CompiledNetwork:
    nodes = {}
    for n in spec.nodes:
        if n.key in nodes:
            raise NetworkError(f"node {n.key} is defined twice")
        if n.activation not in ACTIVATION_IDS:
            raise NetworkError(
                f"node {n.key}: unknown activation {n.activation!r}; "
                f"supported: {', '.join(ACTIVATIONS)}"
            )
        if n.aggregation not in AGGREGATION_IDS:
            raise NetworkError(
                f"node {n.key}: unknown aggregation {n.aggregation!r}; "
                f"supported: {', '.join(AGGREGATIONS)}"
            )
        nodes[n.key] = n
    inputs = list(spec.input_keys)
    outputs = list(spec.output_keys)
    if not inputs or not outputs:
        raise NetworkError("a network needs inputs and outputs")
    if len(set(inputs)) != len(inputs) or len(set(outputs)) != len(outputs):
        raise NetworkError("input and output keys must be unique")
    if set(inputs) & set(nodes):
        raise NetworkError("input keys must not be node keys")
    missing = [k for k in outputs if k not in nodes]
    if missing:
        raise NetworkError(f"output node {missing[0]} has no node definition")
    input_set = set(inputs)
    for c in spec.connections:
        if c.source not in nodes and c.source not in input_set:
            raise NetworkError(f"connection {c.source}->{c.target} starts at an unknown node")
        if c.target not in nodes:
            raise NetworkError(f"connection {c.source}->{c.target} ends at an unknown node")
    enabled = [c for c in spec.connections if c.enabled]
    edges = [(c.source, c.target) for c in enabled]
    needed = _needed_nodes(input_set, outputs, edges)
    if spec.recurrent:
        # Every node reads the previous step's values, so any order gives the same values;
        # a needed node without an enabled incoming connection is never evaluated and stays
        # at 0, as in neat-python's RecurrentNetwork.
        targets = {b for _, b in edges}
        order = sorted(n for n in needed if n in targets)
        idle = sorted(n for n in needed if n not in targets)
        return _arrays(spec, nodes, inputs, outputs, order, idle, enabled, needed)

    order = topological_order(needed, edges)
    return _arrays(spec, nodes, inputs, outputs, order, [], enabled, needed)


def _arrays(spec, nodes, inputs, outputs, order, idle, enabled, needed) -> CompiledNetwork:
    """The flat arrays of the nodes ``order`` (evaluated) and ``idle`` (slots only)."""
    input_set = set(inputs)
    slots = {k: i for i, k in enumerate(inputs)}
    slots.update({k: len(inputs) + i for i, k in enumerate(outputs)})
    for k in [*order, *idle]:
        slots.setdefault(k, len(slots))
    incoming: dict[int, list[ConnectionSpec]] = {}
    for c in enabled:  # grouped by target in one pass, each group in file order
        incoming.setdefault(c.target, []).append(c)
    link_start, link_source, link_weight = [0], [], []
    for k in order:
        # Links in file order: the same summation order as neat-python.
        for c in incoming.get(k, ()):
            if c.source in needed or c.source in input_set:
                link_source.append(slots[c.source])
                link_weight.append(c.weight)
        link_start.append(len(link_source))
    kind = CompiledRecurrentNetwork if spec.recurrent else CompiledNetwork
    return kind(
        n_inputs=len(inputs),
        n_outputs=len(outputs),
        n_slots=len(slots),
        node_slot=np.array([slots[k] for k in order], dtype=np.int64),
        bias=np.array([nodes[k].bias for k in order], dtype=np.float64),
        response=np.array([nodes[k].response for k in order], dtype=np.float64),
        activation=np.array([ACTIVATION_IDS[nodes[k].activation] for k in order], np.int64),
        aggregation=np.array([AGGREGATION_IDS[nodes[k].aggregation] for k in order], np.int64),
        link_start=np.array(link_start, dtype=np.int64),
        link_source=np.array(link_source, dtype=np.int64),
        link_weight=np.array(link_weight, dtype=np.float64),
    )
