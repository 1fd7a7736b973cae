"""Many networks in flat arrays, and their compiled evaluation.

:func:`pack_networks` concatenates :class:`~evorbc_ros.network.CompiledNetwork` arrays of a
whole generation so that one numba kernel can run all genomes; :func:`activate` evaluates
feed-forward network ``g`` of a pack, :func:`activate_recurrent` one step of recurrent
network ``g`` with its two value buffers (neat-python's ``RecurrentNetwork`` semantics,
docs/design.md section 8). The activation and aggregation codes follow
:data:`evorbc_ros.network.ACTIVATIONS` and :data:`~evorbc_ros.network.AGGREGATIONS`.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import NamedTuple

import numba as nb
import numpy as np

from evorbc_ros.network import ACTIVATION_IDS, AGGREGATION_IDS, CompiledNetwork, NetworkSpec

# Codes as plain integers: numba freezes module-level ints, not dicts.
A_SIGMOID = ACTIVATION_IDS["sigmoid"]
A_TANH = ACTIVATION_IDS["tanh"]
A_SIN = ACTIVATION_IDS["sin"]
A_GAUSS = ACTIVATION_IDS["gauss"]
A_RELU = ACTIVATION_IDS["relu"]
A_ELU = ACTIVATION_IDS["elu"]
A_LELU = ACTIVATION_IDS["lelu"]
A_SELU = ACTIVATION_IDS["selu"]
A_SOFTPLUS = ACTIVATION_IDS["softplus"]
A_IDENTITY = ACTIVATION_IDS["identity"]
A_CLAMPED = ACTIVATION_IDS["clamped"]
A_INV = ACTIVATION_IDS["inv"]
A_LOG = ACTIVATION_IDS["log"]
A_EXP = ACTIVATION_IDS["exp"]
A_ABS = ACTIVATION_IDS["abs"]
A_HAT = ACTIVATION_IDS["hat"]
A_SQUARE = ACTIVATION_IDS["square"]
A_CUBE = ACTIVATION_IDS["cube"]
G_SUM = AGGREGATION_IDS["sum"]
G_PRODUCT = AGGREGATION_IDS["product"]
G_MAX = AGGREGATION_IDS["max"]
G_MIN = AGGREGATION_IDS["min"]
G_MAXABS = AGGREGATION_IDS["maxabs"]
G_MEAN = AGGREGATION_IDS["mean"]
G_MEDIAN = AGGREGATION_IDS["median"]


class NetworkPack(NamedTuple):
    """Networks ``0..n-1`` in flat arrays (numba-friendly)."""

    node_start: np.ndarray  # (n + 1,) int64: nodes of network g are node_start[g]:[g + 1]
    node_slot: np.ndarray  # (total nodes,) int64, slot within the network
    bias: np.ndarray
    response: np.ndarray
    activation: np.ndarray  # int64 codes
    aggregation: np.ndarray  # int64 codes
    link_start: np.ndarray  # (total nodes + 1,) int64, global offsets into the links
    link_source: np.ndarray  # int64, slot within the network
    link_weight: np.ndarray
    n_slots: np.ndarray  # (n,) int64
    recurrent: np.ndarray  # (n,) bool: network g keeps state (activate_recurrent)
    n_inputs: int
    n_outputs: int


def pack_networks(networks: Sequence[CompiledNetwork | NetworkSpec]) -> NetworkPack:
    """Concatenate networks that share their numbers of inputs and outputs."""
    nets = [n.compile() if isinstance(n, NetworkSpec) else n for n in networks]
    if not nets:
        raise ValueError("no networks to pack")
    n_in, n_out = nets[0].n_inputs, nets[0].n_outputs
    if any(n.n_inputs != n_in or n.n_outputs != n_out for n in nets):
        raise ValueError("all networks of a pack need the same inputs and outputs")
    node_counts = [len(n.node_slot) for n in nets]
    link_base = np.cumsum([0] + [len(n.link_source) for n in nets])
    link_start = np.concatenate(
        [n.link_start[:-1] + base for n, base in zip(nets, link_base[:-1], strict=True)]
        + [[link_base[-1]]]
    ).astype(np.int64)
    return NetworkPack(
        node_start=np.concatenate([[0], np.cumsum(node_counts)]).astype(np.int64),
        node_slot=np.concatenate([n.node_slot for n in nets]).astype(np.int64),
        bias=np.concatenate([n.bias for n in nets]),
        response=np.concatenate([n.response for n in nets]),
        activation=np.concatenate([n.activation for n in nets]).astype(np.int64),
        aggregation=np.concatenate([n.aggregation for n in nets]).astype(np.int64),
        link_start=link_start,
        link_source=np.concatenate([n.link_source for n in nets]).astype(np.int64),
        link_weight=np.concatenate([n.link_weight for n in nets]),
        n_slots=np.array([n.n_slots for n in nets], dtype=np.int64),
        recurrent=np.array([n.recurrent for n in nets], dtype=np.bool_),
        n_inputs=n_in,
        n_outputs=n_out,
    )


@nb.njit(cache=True)
def _clamp(z, lo, hi):
    return max(lo, min(hi, z))


@nb.njit(cache=True)
def activation_function(code, z):
    """neat-python's activation ``code`` (see ACTIVATIONS) at ``z``."""
    if code == A_SIGMOID:
        return 1.0 / (1.0 + math.exp(-_clamp(5.0 * z, -60.0, 60.0)))
    if code == A_TANH:
        return math.tanh(_clamp(2.5 * z, -60.0, 60.0))
    if code == A_SIN:
        return math.sin(_clamp(5.0 * z, -60.0, 60.0))
    if code == A_GAUSS:
        c = _clamp(z, -3.4, 3.4)
        return math.exp(-5.0 * c * c)
    if code == A_RELU:
        return z if z > 0.0 else 0.0
    if code == A_ELU:
        return z if z > 0.0 else math.exp(z) - 1.0
    if code == A_LELU:
        return z if z > 0.0 else 0.005 * z
    if code == A_SELU:
        lam = 1.0507009873554804934193349852946
        alpha = 1.6732632423543772848170429916717
        return lam * z if z > 0.0 else lam * alpha * (math.exp(z) - 1.0)
    if code == A_SOFTPLUS:
        return 0.2 * math.log(1.0 + math.exp(_clamp(5.0 * z, -60.0, 60.0)))
    if code == A_IDENTITY:
        return z
    if code == A_CLAMPED:
        return _clamp(z, -1.0, 1.0)
    if code == A_INV:
        return 1.0 / z if z != 0.0 else 0.0
    if code == A_LOG:
        return math.log(max(1e-7, z))
    if code == A_EXP:
        return math.exp(_clamp(z, -60.0, 60.0))
    if code == A_ABS:
        return abs(z)
    if code == A_HAT:
        return max(0.0, 1.0 - abs(z))
    if code == A_SQUARE:
        return z * z
    return z * z * z  # cube


@nb.njit(cache=True)
def _aggregate(code, values, sources, weights, lo, hi):
    """neat-python's aggregation ``code`` over links ``lo:hi`` (in file order)."""
    n = hi - lo
    if code in (G_SUM, G_MEAN):
        s = 0.0
        for j in range(lo, hi):
            s += values[sources[j]] * weights[j]
        if code == G_MEAN:
            return s / n if n > 0 else 0.0
        return s
    if code == G_PRODUCT:
        p = 1.0
        for j in range(lo, hi):
            p *= values[sources[j]] * weights[j]
        return p
    if n == 0:
        return 0.0
    if code == G_MEDIAN:
        terms = np.empty(n)
        for j in range(lo, hi):
            terms[j - lo] = values[sources[j]] * weights[j]
        if n <= 2:
            s = 0.0
            for t in terms:
                s += t
            return s / n
        terms.sort()
        if n % 2 == 1:
            return terms[n // 2]
        return (terms[n // 2 - 1] + terms[n // 2]) / 2.0
    best = values[sources[lo]] * weights[lo]
    for j in range(lo + 1, hi):
        v = values[sources[j]] * weights[j]
        if code == G_MAX:
            if v > best:
                best = v
        elif code == G_MIN:
            if v < best:
                best = v
        elif abs(v) > abs(best):  # maxabs: the first of equal magnitudes wins
            best = v
    return best


@nb.njit(cache=True)
def activate(g, inputs, values, out, net):
    """Evaluate network ``g`` of the :class:`NetworkPack` ``net``; outputs go to ``out``.

    ``values`` is scratch of at least the network's slot count. Slots are written in
    evaluation order, so only the inputs need setting first.
    """
    # Fields as locals: numba does not hoist NamedTuple loads out of the loop.
    node_start, node_slot, bias, response = net.node_start, net.node_slot, net.bias, net.response
    activation, aggregation = net.activation, net.aggregation
    link_start, link_source, link_weight = net.link_start, net.link_source, net.link_weight
    n_in = inputs.shape[0]
    for i in range(n_in):
        values[i] = inputs[i]
    for k in range(node_start[g], node_start[g + 1]):
        s = _aggregate(
            aggregation[k], values, link_source, link_weight, link_start[k], link_start[k + 1]
        )
        values[node_slot[k]] = activation_function(activation[k], bias[k] + response[k] * s)
    for o in range(out.shape[0]):
        out[o] = values[n_in + o]


@nb.njit(cache=True)
def activate_recurrent(g, inputs, buffers, p, out, net):
    """One step of recurrent network ``g`` of ``net``: read ``buffers[p]``, write the other.

    ``buffers`` is ``(2, >= n_slots)``, all 0 at the start of an episode; the caller
    alternates ``p`` (0, 1, 0, ...). The inputs go into both rows, then every evaluated
    node computes from row ``p`` (the previous step's values) into row ``1 - p``, so a
    signal crosses one connection per step (neat-python's ``RecurrentNetwork``).
    """
    node_start, node_slot, bias, response = net.node_start, net.node_slot, net.bias, net.response
    activation, aggregation = net.activation, net.aggregation
    link_start, link_source, link_weight = net.link_start, net.link_source, net.link_weight
    previous = buffers[p]
    current = buffers[1 - p]
    n_in = inputs.shape[0]
    for i in range(n_in):
        previous[i] = inputs[i]
        current[i] = inputs[i]
    for k in range(node_start[g], node_start[g + 1]):
        s = _aggregate(
            aggregation[k], previous, link_source, link_weight, link_start[k], link_start[k + 1]
        )
        current[node_slot[k]] = activation_function(activation[k], bias[k] + response[k] * s)
    for o in range(out.shape[0]):
        out[o] = current[n_in + o]


def activate_packed(pack: NetworkPack, g: int, inputs) -> np.ndarray:
    """Evaluate feed-forward network ``g`` of ``pack`` from Python (tests and tools)."""
    values = np.zeros(int(pack.n_slots.max()))
    out = np.zeros(pack.n_outputs)
    activate(g, np.asarray(inputs, dtype=np.float64), values, out, pack)
    return out


def activate_packed_sequence(pack: NetworkPack, g: int, inputs) -> np.ndarray:
    """Network ``g`` of ``pack`` over ``inputs (T, n_inputs)``, from a zero state.

    Returns ``(T, n_outputs)``. Recurrent networks carry their state from row to row;
    feed-forward ones do not (tests and tools).
    """
    rows = np.asarray(inputs, dtype=np.float64)
    buffers = np.zeros((2, int(pack.n_slots.max())))
    out = np.zeros((rows.shape[0], pack.n_outputs))
    for t, x in enumerate(rows):
        if pack.recurrent[g]:
            activate_recurrent(g, x, buffers, t % 2, out[t], pack)
        else:
            activate(g, x, buffers[0], out[t], pack)
    return out
