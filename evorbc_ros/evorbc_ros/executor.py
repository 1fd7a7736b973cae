"""What the primitive executor commands, and when it stops the robot (pure code).

The executor runs the current primitive: it turns the primitive's genes into wheel
commands with the robot's own mapping (:mod:`evorbc_ros.robots.four_ws`). It watches when
its inputs last arrived; if the primitive or any sensor input is older than
``stale_timeout`` it commands zero wheel speed (steering held where it is) until they come
back. Times are seconds on the node's clock (simulated or wall); if that clock goes back,
everything is forgotten and the robot stops until a new primitive arrives.

An empty primitive message is the arbitrator's "no primitive" (its network's outputs were
not finite): the robot stops at once, as for stale inputs, until the next primitive. The
offline episodes stop the same way for such a cycle, so a lockstep run still equals the
offline replay cycle by cycle (docs/design.md section 7).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from evorbc_ros.laser import InputError
from evorbc_ros.robots.four_ws import FourWSGeometry, FourWSType

#: Why the robot stands after an empty primitive message: the arbitrator's network gave
#: outputs that are not finite, or the arbitrator was deactivated (it says which).
NO_PRIMITIVE_REASON = "the arbitrator sent no primitive (outputs not finite, or it was deactivated)"


@dataclass(frozen=True)
class WheelCommand:
    """One command for a 4WS robot."""

    steering: np.ndarray  # (4,) rad, fl, fr, rl, rr
    speed: float  # m/s, shared by all wheels
    stopped: bool  # True when this is the safety stop
    reason: str = ""  # why the robot is stopped

    def wheel_velocities(self, wheel_radius: float) -> np.ndarray:
        """(4,) wheel angular velocities (rad/s) for ros2_control velocity joints."""
        return np.full(4, self.speed / wheel_radius)


class InputWatch:
    """The current primitive's genes and the freshness of every input (any robot)."""

    def __init__(self, robot_name: str, n_parameters: int, inputs: list[str], stale_timeout):
        self.robot_name = robot_name
        self.n_parameters = n_parameters
        self.stale_timeout = stale_timeout
        self.last_seen: dict[str, float | None] = dict.fromkeys(["primitive", *inputs])
        self.first_event: float | None = None  # when the first input of any kind arrived
        self.genes: np.ndarray | None = None
        self.halted = False  # the arbitrator's latest message was "no primitive"

    def on_primitive(self, genes, now: float) -> None:
        """A new primitive from the arbitrator; no genes at all means "no primitive".

        Raises:
            InputError: wrong number of genes, or values that are not finite or outside
                [-1, 1] (the robot's genes map linearly onto its parameter ranges).
        """
        g = np.asarray(genes, dtype=np.float64)
        if g.size == 0:
            # The arbitrator is alive and says: stop now. The last genes are kept (the
            # hexapod's gait clock and held targets need them) but not run.
            self.check_clock(now)
            self.halted = True
            self.on_input("primitive", now)
            return
        if g.shape != (self.n_parameters,):
            raise InputError(
                f"primitive has {g.size} values, robot {self.robot_name} expects "
                f"{self.n_parameters}"
            )
        if not np.all(np.isfinite(g)) or np.any(np.abs(g) > 1.0 + 1e-9):
            raise InputError(f"primitive genes must be finite and in [-1, 1], got {g.tolist()}")
        self.check_clock(now)  # before taking the genes: a reset would drop them
        self.genes = g
        self.halted = False
        self.on_input("primitive", now)

    def check_clock(self, now: float) -> bool:
        """Forget everything if the clock went back (a restarted ``/clock``, a looped bag).

        Ages would be negative, so nothing would ever count as stale; after a reset the
        robot stands until a new primitive and fresh inputs arrive. Returns True on reset.
        """
        latest = max((t for t in self.last_seen.values() if t is not None), default=None)
        if latest is None or now >= latest - 1e-6:
            return False
        self.reset()
        return True

    def reset(self) -> None:
        """Back to the start-up state: no primitive, no input seen."""
        self.last_seen = dict.fromkeys(self.last_seen)
        self.first_event = None
        self.genes = None
        self.halted = False

    def on_input(self, name: str, now: float) -> None:
        """A sensor input arrived (only its time matters here)."""
        self.check_clock(now)
        if self.first_event is None:
            self.first_event = now
        self.last_seen[name] = now

    def stale(self, now: float) -> list[str]:
        """Inputs older than the timeout.

        An input that has not arrived yet only counts once the timeout has passed since the
        first input of any kind: at start-up the streams arrive in any order. "Older" allows
        1 us for rounding: clock stamps are integer nanoseconds and an age of exactly the
        timeout must not count as stale.
        """
        limit = self.stale_timeout + 1e-6
        out = []
        for name, t in self.last_seen.items():
            since = t if t is not None else self.first_event
            if since is not None and now - since > limit:
                out.append(name)
        return out

    def stop_reason(self, now: float) -> str:
        """Why the robot must stand still now ("" if it may run the primitive)."""
        if self.check_clock(now):
            return "the clock went back: waiting for a new primitive"
        if self.genes is None and not self.halted:
            return "no primitive yet"
        stale = self.stale(now)
        if stale:
            return f"stale input: {', '.join(stale)}"
        return NO_PRIMITIVE_REASON if self.halted else ""


class PrimitiveExecutor(InputWatch):
    """The 4WS executor: the current primitive as steering angles and a wheel speed."""

    def __init__(
        self,
        robot: FourWSType,
        geometry: FourWSGeometry,
        inputs: list[str],
        stale_timeout: float = 0.3,
    ):
        super().__init__(robot.name, robot.n_parameters, inputs, stale_timeout)
        self.robot = robot
        self.geometry = geometry
        self.steering = np.zeros(4)  # last commanded angles, held while stopped

    def command(self, now: float) -> WheelCommand:
        """The command to send at time ``now``."""
        reason = self.stop_reason(now)
        if reason:
            return WheelCommand(self.steering.copy(), 0.0, True, reason)
        c = self.robot.commands(self.genes, self.geometry)
        self.steering = c[1:5].copy()
        return WheelCommand(self.steering.copy(), float(c[0]), False)
