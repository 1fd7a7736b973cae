"""The corrected outcome model over a repertoire, fed by executed primitives (pure code).

The repertoire's recorded outcomes are the prior: what each primitive does over the
evaluation time ``T`` (``(dx m, dy m, dheading rad)`` in its start frame). Observations of
what an executed primitive actually did correct it through a Gaussian process
(:mod:`evorbc_ros.adaptation.gp`), and the network's choice is matched against the
corrected outcomes, so the arbitrator network runs as evolved (docs/design.md section 24).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from evorbc_ros.adaptation import gp

#: Bounds of :class:`AdaptationSettings` ``capacity``: observations kept.
MAX_CAPACITY = 256
#: How the network's choice is matched against the corrected outcomes.
MATCHES = ("outcome", "point")
#: Which cycles are settled (:mod:`evorbc_ros.adaptation.cycles`, ``STEADY_*``).
STEADY_RULES = ("agree", "held")


@dataclass(frozen=True)
class AdaptationSettings:
    """How the outcome model learns (docs/design.md section 24).

    Attributes:
        capacity: observations kept (the ring's ``K``); the oldest goes first.
        length_scale: the kernel's reach over the outcome space, as a fraction of the
            repertoire's extent in each of ``dx``, ``dy`` and ``dheading`` (unitless).
        noise: observation noise variance over the prior variance (unitless, > 0).
        settle_cycles: a cycle is observed only after the primitive ran at least this many
            cycles before it, so that the actuators could reach its command.
        steady_tolerance: and only if its motion, extended to ``T``, is within this
            fraction of the repertoire's extent of the cycle before's (position, and
            heading over its extent): the actuators have settled (unitless). A cycle that
            translates less than that over ``T`` is not observed.
        window: settled cycles summed into one observation (at most; a switch ends it).
        steady: which cycles are settled: ``agree``, those whose motion agrees with the
            cycle before's (a wheeled robot whose actuators hold the command); ``held``,
            every cycle after ``settle_cycles`` (a gait, whose 0.1 s cycles never agree:
            its oscillation within a period averages out over ``min_cycles``).
        min_cycles: the fewest settled cycles an observation sums; a shorter execution
            is not observed.
        average: the most observations of one primitive its slot averages (a running
            mean, exponential beyond; the slot's noise is ``noise`` over their number).
            1: the latest observation stands alone.
        match: ``outcome``: the primitive whose corrected outcome is nearest the
            recorded outcome of the primitive the grid chose (what the network asked
            for), each dimension over the repertoire's extent in it; ``point``: the one
            whose corrected ``(dx, dy)`` is nearest the mapping's point (measured to fail
            on a mismatched robot: docs/design.md section 24).
    """

    capacity: int = 32
    length_scale: float = 0.5
    noise: float = 0.05
    settle_cycles: int = 1
    steady_tolerance: float = 0.02
    window: int = 5
    match: str = "outcome"
    steady: str = "agree"
    min_cycles: int = 1
    average: int = 1

    def __post_init__(self) -> None:
        checks = (
            ("capacity", 1 <= self.capacity <= MAX_CAPACITY, f"between 1 and {MAX_CAPACITY}"),
            ("length_scale", 0.0 < self.length_scale <= 10.0, "in (0, 10]"),
            ("noise", 0.0 < self.noise <= 100.0, "in (0, 100]"),
            ("settle_cycles", 0 <= self.settle_cycles <= 1000, "between 0 and 1000"),
            ("steady_tolerance", 0.0 <= self.steady_tolerance <= 10.0, "in [0, 10]"),
            ("window", 1 <= self.window <= 1000, "between 1 and 1000"),
            ("min_cycles", 1 <= self.min_cycles <= self.window, "between 1 and window"),
            ("average", 1 <= self.average <= 1000, "between 1 and 1000"),
        )
        if self.match not in MATCHES:
            raise ValueError(f"adaptation match must be one of {', '.join(MATCHES)}")
        if self.steady not in STEADY_RULES:
            raise ValueError(f"adaptation steady must be one of {', '.join(STEADY_RULES)}")
        for name, ok, what in checks:
            if not ok:
                raise ValueError(f"adaptation {name} must be {what}, got {getattr(self, name)!r}")


#: A legged robot's settings: its 0.1 s cycles never agree within ``steady_tolerance`` (the
#: body sways and yaws within each gait period), so every held cycle after the first is
#: summed and an observation is a whole ``min_cycles`` = ``window`` = 5 cycles (0.5 s, half
#: to more than one period of a 1-2.5 Hz gait). One such execution scatters about its
#: primitive's mean by six times the repertoire's spacing (the gait's phase, the primitive
#: before), so a slot keeps the running mean of its primitive's observations (up to 10,
#: then exponential, weight 1/10 on the newest) with the prior's variance as one
#: reading's noise. Chosen on the training mazes, never the
#: held-out ones (docs/design/adaptation.md, "Legged robots", "Repeated observations").
LEGGED_SETTINGS = AdaptationSettings(steady="held", window=5, min_cycles=5, noise=1.0, average=10)


#: The registry's families whose robots walk (docs/legged.md).
LEGGED_FAMILIES = ("hexapod", "legged")


def settings_for(family: str) -> AdaptationSettings:
    """The default settings of a robot of ``family`` (the registry's): legged or not."""
    return LEGGED_SETTINGS if family in LEGGED_FAMILIES else AdaptationSettings()


def outcome_table(behaviour: np.ndarray, heading: np.ndarray) -> np.ndarray:
    """``(n, 3)`` outcomes ``(dx m, dy m, dheading rad)`` from a repertoire's columns."""
    return np.column_stack([behaviour[:, 0], behaviour[:, 1], heading]).astype(np.float64)


def scaled_features(recorded: np.ndarray, length_scale: float) -> np.ndarray:
    """``(n, 3)`` GP inputs: outcomes over ``length_scale`` x each dimension's extent.

    A dimension with no extent (every primitive the same) gets scale 1 in its unit.
    """
    extent = recorded.max(axis=0) - recorded.min(axis=0)
    scale = np.where(extent > 0.0, extent * length_scale, 1.0)
    return np.ascontiguousarray(recorded / scale)


class OutcomeModel:
    """The corrected outcomes of a repertoire's primitives.

    Args:
        recorded: ``(n, 3)`` the repertoire's outcomes over ``T`` (prior, and the GP input).
        expected: ``(n, 3)`` what an observation of each primitive should read on the
            robot the repertoire was made on, over ``T`` (default: ``recorded``).
        settings: :class:`AdaptationSettings`.
        functions: :mod:`~evorbc_ros.adaptation.gp`'s functions by name, plain (default)
            or compiled (:func:`~evorbc_ros.adaptation.gp.compiled`): the same bits.
    """

    def __init__(
        self,
        recorded: np.ndarray,
        settings: AdaptationSettings,
        expected: np.ndarray | None = None,
        functions: dict | None = None,
    ):
        self.settings = settings
        self.gp = functions or {name: getattr(gp, name) for name in gp.FUNCTIONS}
        self.recorded = np.ascontiguousarray(recorded, dtype=np.float64)
        n = len(self.recorded)
        self.expected = self.recorded if expected is None else np.asarray(expected, np.float64)
        if self.recorded.shape != (n, 3) or self.expected.shape != (n, 3):
            raise ValueError(f"outcomes must be (n, 3) arrays, got {self.expected.shape}")
        self.features = scaled_features(self.recorded, settings.length_scale)
        extent = self.recorded.max(axis=0) - self.recorded.min(axis=0)
        self.weight = np.where(extent > 0.0, 1.0 / np.where(extent > 0.0, extent, 1.0), 1.0)
        k = settings.capacity
        self.kzx = np.zeros((k, n))
        self.slots = np.full(k, -1, dtype=np.int64)
        self.residual = np.zeros((k, 3))
        self.inverse = np.zeros((k, k))
        self.alpha = np.zeros((k, 3))
        self.correction = np.zeros((3, n))
        self.corrected = self.recorded.copy()
        #: ``[used, next_slot, observations, average, hits per slot...]`` (:data:`gp.USED`
        #: ...): int64, so that the compiled :func:`gp.observe` updates them in place.
        self.counts = gp.new_counts(k, settings.average)

    @property
    def used(self) -> int:
        """Slots holding an observation."""
        return int(self.counts[gp.USED])

    @property
    def observations(self) -> int:
        """Observations taken since the last reset."""
        return int(self.counts[gp.OBSERVATIONS])

    def __len__(self) -> int:
        return len(self.recorded)

    def reset(self) -> None:
        """Forget every observation: the corrected outcomes are the prior again, exactly."""
        self.slots[:] = -1
        self.residual[:] = 0.0
        self.correction[:] = 0.0
        self.corrected[:] = self.recorded
        self.counts[:] = gp.new_counts(self.settings.capacity, self.settings.average)

    def arrays(self) -> tuple:
        """The arrays :func:`gp.observe` takes, in its order, up to ``counts``."""
        return (
            self.features,
            self.recorded,
            self.expected,
            self.kzx,
            self.slots,
            self.residual,
            self.inverse,
            self.alpha,
            self.correction,
            self.corrected,
            self.counts,
        )

    def observe(self, index: int, outcome: np.ndarray) -> None:
        """Take what primitive ``index`` did, as ``(dx, dy, dheading)`` over ``T``.

        A primitive already in the ring updates its slot's running mean (the latest
        observation alone with ``average`` 1; its kernel column is unchanged); another
        takes the next slot, pushing out the oldest when the ring is full
        (:func:`gp.observe`).
        """
        o0, o1, o2 = (float(v) for v in outcome)
        self.gp["observe"](*self.arrays(), self.settings.noise, int(index), o0, o1, o2)

    def nearest(self, x: float, y: float) -> int:
        """The primitive whose corrected ``(dx, dy)`` is nearest the point ``(x, y)`` (m)."""
        return self.gp["nearest"](self.corrected, x, y)

    def nearest_outcome(self, index: int) -> int:
        """The primitive whose corrected outcome is nearest ``index``'s recorded one.

        Each dimension is measured over the repertoire's extent in it (unitless).
        """
        return self.gp["nearest_outcome"](self.corrected, self.recorded[index], self.weight)

    def uncertainty(self, index: int) -> float:
        """Primitive ``index``'s posterior variance over the prior's (1 with no observation)."""
        if self.used == 0 or index < 0:
            return 1.0
        return self.gp["variance"](self.kzx, index, self.used, self.inverse)

    def mean_correction(self) -> tuple[float, float]:
        """Mean ``|(dx, dy)|`` correction (m) and mean ``|dheading|`` correction (rad)."""
        c = self.correction
        return float(np.mean(np.hypot(c[0], c[1]))), float(np.mean(np.abs(c[2])))
