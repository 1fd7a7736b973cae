"""The corrected outcome model's arithmetic: a Gaussian process over the outcome space.

Plain functions on float64/int64 arrays, so that the offline kernels can compile them with
``numba.njit`` and the onboard controller can call them as they are (numpy only; docs/design.md
section 24). Every value is computed by the same IEEE operations in the same order in both:
additions, multiplications, divisions and ``sqrt`` (correctly rounded everywhere), no
``exp``, no BLAS and no reduction whose order numpy chooses, so a jitted and a plain call
give the same bits.

Outcomes are ``(dx m, dy m, dheading rad)`` per primitive over the repertoire's evaluation
time, in the primitive's start frame (x forward, y left). The GP's input is a primitive's
recorded outcome divided by the length scales (``features``, unitless); its output is the
residual ``observed - expected`` (same units as outcomes). The kernel is Wendland's
``(1 - r)^4 (4 r + 1)`` for ``r < 1`` (positive definite in up to 3 dimensions, 1 at
``r = 0``, exactly 0 beyond ``r = 1``), so an observation corrects only primitives within
one length scale of it, and the prior stays exact elsewhere.

The observations sit in a ring of ``K`` slots, one per primitive observed. ``kzx[s]`` is
the kernel row between slot ``s``'s primitive and every primitive; adding an observation
computes one row (O(n)), solves the slots' kernel system (O(K^3), K = 32) and corrects
every primitive (O(n K)). A slot holds the running mean of its primitive's observations,
an exponential one (weight ``1 / average`` on the newest) once ``average`` came, with the
noise variance divided by their number up to ``average`` (the variance of a mean of
independent readings); ``average`` 1 keeps the latest alone (docs/design/adaptation.md,
"Repeated observations").
"""

from __future__ import annotations

import numpy as np


def wendland(d2: np.ndarray) -> np.ndarray:
    """Wendland's C2 kernel of squared scaled distances ``d2`` (any shape), in [0, 1]."""
    r = np.minimum(np.sqrt(d2), 1.0)
    u = 1.0 - r
    u2 = u * u
    return u2 * u2 * (4.0 * r + 1.0)


def kernel_row(features: np.ndarray, j: int, out: np.ndarray) -> None:
    """``out[i] = k(features[i], features[j])`` for every primitive ``i``.

    Args:
        features: ``(n, 3)`` scaled outcomes (unitless).
        j: the observed primitive's row.
        out: ``(n,)`` written in place (a row of the ``(K, n)`` slot kernel ``kzx``).
    """
    d0 = features[:, 0] - features[j, 0]
    d1 = features[:, 1] - features[j, 1]
    d2 = features[:, 2] - features[j, 2]
    out[:] = wendland(d0 * d0 + d1 * d1 + d2 * d2)


def gauss_jordan(a: np.ndarray, m: int, rhs: np.ndarray, inverse: np.ndarray, x: np.ndarray):
    """Solve ``a[:m, :m] x = rhs[:m]`` and invert ``a[:m, :m]`` (symmetric positive definite).

    Gauss-Jordan elimination without pivoting (the diagonal of a kernel matrix plus noise
    stays positive), one whole-matrix update per column, so every sum has a fixed order.

    Args:
        a: ``(>=m, >=m)``; rhs: ``(>=m, c)``.
        inverse: ``(K, K)``, ``[:m, :m]`` written.
        x: ``(K, c)``, ``[:m]`` written.
    """
    c = rhs.shape[1]
    w = np.zeros((m, m + c + m))
    w[:, :m] = a[:m, :m]
    w[:, m : m + c] = rhs[:m]
    for j in range(m):
        w[j, m + c + j] = 1.0
    for j in range(m):
        w[j] /= w[j, j]
        f = w[:, j].copy()
        f[j] = 0.0
        w -= f[:, None] * w[j][None, :]
    x[:m] = w[:, m : m + c]
    inverse[:m, :m] = w[:, m + c :]


def refit(
    kzx: np.ndarray,
    slots: np.ndarray,
    residual: np.ndarray,
    m: int,
    noise: float,
    hits: np.ndarray,
    inverse: np.ndarray,
    alpha: np.ndarray,
    correction: np.ndarray,
) -> None:
    """The posterior after the slots changed: its weights and every primitive's correction.

    Args:
        kzx: ``(K, n)`` kernel rows of the slots.
        slots: ``(K,)`` primitive rows of the slots (the first ``m`` used).
        residual: ``(K, 3)`` observed minus expected outcome per slot (the mean of its
            ``hits`` observations).
        m: slots in use (1..K).
        noise: observation noise variance over the prior's (unitless, > 0).
        hits: ``(K,)`` int64 observations averaged in each slot (>= 1 where used): the
            slot's noise is ``noise / hits`` (``noise`` itself for 1, bit for bit).
        inverse: ``(K, K)`` written: ``(Kzz + diag(noise / hits))^-1`` in ``[:m, :m]``.
        alpha: ``(K, 3)`` written: that inverse times ``residual``.
        correction: ``(3, n)`` written: the posterior mean residual of every primitive.
    """
    a = np.empty((m, m))
    for s in range(m):
        a[:, s] = kzx[s, slots[:m]]
        a[s, s] += noise / hits[s]
    alpha[:] = 0.0
    gauss_jordan(a, m, residual, inverse, alpha)
    correction[:] = 0.0
    for s in range(m):
        for c in range(3):
            correction[c] += kzx[s] * alpha[s, c]


def variance(kzx: np.ndarray, i: int, m: int, inverse: np.ndarray) -> float:
    """Posterior variance of primitive ``i`` over the prior's: 1 unknown, 0 certain."""
    k = kzx[:m, i].copy()
    u = np.zeros(m)
    for t in range(m):
        u += inverse[:m, t] * k[t]
    total = 0.0
    for s in range(m):
        total += k[s] * u[s]
    return max(1.0 - total, 0.0)


def nearest(points: np.ndarray, x: float, y: float) -> int:
    """Row of the ``(n, >=2)`` ``points`` whose ``(dx, dy)`` is nearest ``(x, y)`` (m).

    Ties go to the lower row (``argmin``), as the lookup grid's do.
    """
    ex = points[:, 0] - x
    ey = points[:, 1] - y
    return int(np.argmin(ex * ex + ey * ey))


def nearest_outcome(outcomes: np.ndarray, target: np.ndarray, weight: np.ndarray) -> int:
    """Row of the ``(n, 3)`` ``outcomes`` nearest ``target`` ``(3,)``, in ``weight`` units.

    The distance is ``sum_c ((outcomes[:, c] - target[c]) * weight[c])^2`` (``weight``:
    1 / m, 1 / m, 1 / rad); ties go to the lower row.
    """
    e0 = (outcomes[:, 0] - target[0]) * weight[0]
    e1 = (outcomes[:, 1] - target[1]) * weight[1]
    e2 = (outcomes[:, 2] - target[2]) * weight[2]
    return int(np.argmin(e0 * e0 + e1 * e1 + e2 * e2))


#: Rows of a model's ``counts`` (int64 ``(HITS + K,)``): slots in use, the ring's next slot,
#: observations taken since the last reset, the most observations a slot averages (the
#: settings' ``average``, kept by a reset), then each slot's averaged observations.
USED, NEXT_SLOT, OBSERVATIONS, AVERAGE, HITS = 0, 1, 2, 3, 4


def new_counts(capacity: int, average: int) -> np.ndarray:
    """A model's ``counts`` with nothing observed: ``(HITS + capacity,)`` int64."""
    counts = np.zeros(HITS + capacity, dtype=np.int64)
    counts[AVERAGE] = average
    return counts


def observe(
    features,
    recorded,
    expected,
    kzx,
    slots,
    residual,
    inverse,
    alpha,
    correction,
    corrected,
    counts,
    noise,
    index,
    o0,
    o1,
    o2,
):
    """Take what primitive ``index`` did, ``(o0 m, o1 m, o2 rad)`` over ``T``, and refit.

    A primitive already in the ring updates its slot (its kernel row is unchanged): the
    slot's residual becomes the running mean of its last ``counts[AVERAGE]`` observations
    (the latest alone for 1), an exponential one once more came. Another takes
    ``counts[NEXT_SLOT]``, pushing out the oldest when the ring of ``K = len(slots)`` is
    full.

    Args:
        features, recorded, expected: ``(n, 3)`` (see the module and
            :class:`~evorbc_ros.adaptation.model.OutcomeModel`).
        kzx, slots, residual, inverse, alpha, correction: as :func:`refit`, updated.
        corrected: ``(n, 3)`` written: ``recorded`` plus the correction (m, m, rad).
        counts: ``(HITS + K,)`` int64 (:data:`USED` ... :data:`HITS`), updated.
        noise: as :func:`refit`.
    """
    used = counts[USED]
    s = -1
    for k in range(used):
        if slots[k] == index:
            s = k
            break
    if s < 0:
        s = counts[NEXT_SLOT]
        counts[NEXT_SLOT] = (s + 1) % slots.shape[0]
        used = max(used, s + 1)
        counts[USED] = used
        slots[s] = index
        kernel_row(features, index, kzx[s])
        counts[HITS + s] = 0
    h = min(counts[HITS + s] + 1, counts[AVERAGE])
    counts[HITS + s] = h
    r0 = o0 - expected[index, 0]
    r1 = o1 - expected[index, 1]
    r2 = o2 - expected[index, 2]
    if h <= 1:  # the latest stands: assigned, not averaged, so its bits are the reading's
        residual[s, 0] = r0
        residual[s, 1] = r1
        residual[s, 2] = r2
    else:
        residual[s, 0] += (r0 - residual[s, 0]) / h
        residual[s, 1] += (r1 - residual[s, 1]) / h
        residual[s, 2] += (r2 - residual[s, 2]) / h
    counts[OBSERVATIONS] += 1
    refit(kzx, slots, residual, used, noise, counts[HITS:], inverse, alpha, correction)
    # Whole columns: one IEEE addition per element either way, and plain numpy pays per
    # call, not per element (as a loop over elements it cost 9 ms a refit at 10,000).
    for c in range(3):
        corrected[:, c] = recorded[:, c] + correction[c]


#: The functions above, callees first (each may call only those before it).
FUNCTIONS = (
    "wendland",
    "new_counts",
    "kernel_row",
    "gauss_jordan",
    "refit",
    "variance",
    "nearest",
    "nearest_outcome",
    "observe",
)


def compiled(jit) -> dict:
    """The functions of this module compiled by ``jit`` (``numba.njit`` or one with options).

    Each compiled function calls the compiled versions of the others: a plain function's
    globals name the plain ones, which numba cannot call. The onboard package does not
    need numba; the offline kernels pass it in.

    Returns:
        name -> compiled function, for every name in :data:`FUNCTIONS`.
    """
    return compile_together(jit, globals(), FUNCTIONS)


def compile_together(jit, space: dict, names, plain: dict | None = None) -> dict:
    """Compile the functions ``names`` (callees first), each calling the others' compiled forms.

    Args:
        jit: ``numba.njit`` or one with options.
        space: the globals the clones see (copied; the compiled functions replace the
            plain ones in it by name).
        names: the functions' names, callees first.
        plain: name -> plain function (default: ``space``'s).

    Returns:
        name -> compiled function.
    """
    import types

    space = dict(space)
    plain = space if plain is None else plain
    out = {}
    for name in names:
        fn = plain[name]
        clone = types.FunctionType(fn.__code__, space, name, fn.__defaults__)
        clone.__doc__ = fn.__doc__
        out[name] = space[name] = jit(clone)
    return out
