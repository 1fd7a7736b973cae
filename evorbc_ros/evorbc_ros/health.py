"""What a node reports about its health on ``/diagnostics`` (pure code).

A node counts its inputs with one :class:`Meter` each and, once a second (wall time), turns
them into a :class:`Health`: a level (OK, WARN, ERROR, as diagnostic_msgs/DiagnosticStatus
has them), a one-line message, and key-value pairs. Times are seconds on the node's clock
(simulated time when ``use_sim_time`` is set), so in a lockstep run an input that comes
every 0.1 s of simulated time shows 10 Hz however fast the simulation goes. Counting costs
one addition and one store per message; everything else is done at report time
(docs/design.md section 9, "Diagnostics").
"""

from __future__ import annotations

from dataclasses import dataclass, field

#: diagnostic_msgs/DiagnosticStatus levels.
OK, WARN, ERROR = 0, 1, 2


class Meter:
    """Arrivals of one input or event: how many, the last one's time, the rate."""

    __slots__ = ("_since_count", "_since_time", "count", "last")

    def __init__(self) -> None:
        self.count = 0  # since start
        self.last: float | None = None  # s, node clock, of the last arrival
        self._since_count = 0
        self._since_time: float | None = None

    def tick(self, now: float) -> None:
        """One arrival at ``now`` (s)."""
        self.count += 1
        self.last = now

    def age(self, now: float) -> float | None:
        """Seconds since the last arrival; None before the first."""
        return None if self.last is None else max(0.0, now - self.last)

    def rate(self, now: float) -> float | None:
        """Arrivals per second since the previous call.

        None the first time, or if the clock stood still or went back.
        """
        since_count, since_time = self._since_count, self._since_time
        self._since_count, self._since_time = self.count, now
        if since_time is None or now <= since_time:
            return None
        return (self.count - since_count) / (now - since_time)

    def new_since_report(self) -> int:
        """Arrivals since the previous :meth:`rate` call (before calling it)."""
        return self.count - self._since_count


@dataclass
class Health:
    """One node's report: level, a one-line message, and values (text) by key."""

    level: int = OK
    message: str = "ok"
    values: dict[str, str] = field(default_factory=dict)

    def worse(self, level: int, message: str) -> None:
        """Raise the level to ``level`` with ``message`` if that is worse than now."""
        if level > self.level:
            self.level, self.message = level, message

    def add(self, key: str, value) -> None:
        """One value, as text (floats to 3 decimals, None as "none")."""
        if value is None:
            text = "none"
        elif isinstance(value, float):
            text = f"{value:.3f}"
        else:
            text = str(value)
        self.values[key] = text


def report_input(health: Health, name: str, meter: Meter, now: float, stale: float) -> None:
    """Add an input's rate and age, and WARN if it never came or is older than ``stale``."""
    age = meter.age(now)
    health.add(f"{name} rate (Hz)", meter.rate(now))
    health.add(f"{name} age (s)", age)
    if age is None:
        health.worse(WARN, f"no {name} yet")
    elif age > stale:
        health.worse(WARN, f"{name} is {age:.2f} s old")


def report_skipped(health: Health, name: str, meter: Meter, now: float) -> None:
    """Add a count of skipped messages; WARN if some were skipped since the last report."""
    new = meter.new_since_report()
    meter.rate(now)
    health.add(f"{name} skipped", meter.count)
    if new:
        health.worse(WARN, f"{new} {name} message(s) skipped")
