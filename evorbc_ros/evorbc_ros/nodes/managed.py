"""Lifecycle (managed) nodes as nav2 and ros2_control run them: the arbitrator, the executor.

* configure reads the parameters and loads and checks the files; it fails, and the node
  stays unconfigured, on a bad file or setting (logged in one line);
* activate starts commanding: the node acts on the inputs it already holds at once (in a
  lockstep run the first state may have come while it was inactive);
* deactivate stops the robot (zero commands, or an empty primitive), then stops
  publishing;
* cleanup releases what configure made (files, publishers, subscriptions).

Parameters are declared at start-up, so ``ros2 param`` works in every state; the ones read
at configure take any valid value while the node is unconfigured. With ``autostart``
(default) the node configures and activates itself, so ``ros2 run`` stays a one-liner and
a failed configure is its one FATAL start-up line and status 2; without it, ``ros2
lifecycle set`` or a launch file drives the transitions (docs/design.md section 9).
"""

from __future__ import annotations

from rclpy.lifecycle import LifecycleNode, LifecycleState, TransitionCallbackReturn

from evorbc_ros.health import ERROR, WARN, Health
from evorbc_ros.node_parameters import ParamSpec
from evorbc_ros.nodes.common import RELIABLE, StartupError, logged_startup
from evorbc_ros.nodes.diagnostics import DiagnosticsPublisher
from evorbc_ros.nodes.parameters import ParameterGuard, declare_all

SUCCESS, FAILURE = TransitionCallbackReturn.SUCCESS, TransitionCallbackReturn.FAILURE


class ManagedNode(LifecycleNode):
    """A lifecycle node that reads its table of parameters at configure.

    Subclasses set :attr:`SPECS` and implement :meth:`configure` (load, check, create
    publishers and subscriptions; raise :class:`StartupError`), :meth:`activate`,
    :meth:`deactivate` (stop the robot), :meth:`release` (undo :meth:`configure`, safe to
    call twice) and :meth:`report` (their part of the health report).
    """

    SPECS: tuple[ParamSpec, ...] = ()

    def __init__(self, name: str, hardware_id: str = "", **kwargs) -> None:
        super().__init__(name, **kwargs)
        self.made: list = []  # publishers, subscriptions and timers configure made
        self.state = "unconfigured"
        self.configure_error = ""  # why the last configure failed
        self._quiet_failure = False  # autostart reports it as the FATAL start-up line
        with logged_startup(self):
            start = declare_all(self, self.SPECS, "at configure")
        ParameterGuard(
            self,
            self.SPECS,
            "at configure",
            is_open=lambda: self.state == "unconfigured",
            apply=self.apply_live,
        )
        self.diagnostics = DiagnosticsPublisher(
            self, start["diagnostics_period"], self.health, hardware_id
        )
        if start["autostart"]:
            with logged_startup(self):
                self._quiet_failure = True
                if self.trigger_configure() != SUCCESS:
                    raise StartupError(self.configure_error)
                self._quiet_failure = False
                self.trigger_activate()

    # -- what subclasses do -------------------------------------------------------------

    def configure(self, params: dict) -> None:
        """Load and check everything ``params`` name; create publishers and subscriptions."""

    def activate(self) -> None:
        """Start acting on what is already held."""

    def deactivate(self) -> None:
        """Stop the robot before the publishers stop."""

    def release(self) -> None:
        """Undo :meth:`configure` (called twice is fine)."""

    def apply_live(self, name: str, value) -> None:
        """A live parameter changed to ``value`` (already checked)."""

    def report(self, health: Health, now: float) -> None:
        """Add the node's own values to its health report."""

    # -- helpers ------------------------------------------------------------------------

    @property
    def active(self) -> bool:
        """True while the node may command."""
        return self.state == "active"

    def lifecycle_publisher(self, msg_type, topic: str, qos=RELIABLE):
        """A publisher that sends only while the node is active (made at configure)."""
        pub = self.create_lifecycle_publisher(msg_type, topic, qos)
        self.made.append(pub)
        return pub

    def subscription(self, msg_type, topic: str, callback, qos=RELIABLE):
        """A subscription that cleanup removes (made at configure)."""
        sub = self.create_subscription(msg_type, topic, callback, qos)
        self.made.append(sub)
        return sub

    def timer(self, period: float, callback):
        """A timer on the node's clock that cleanup removes (made at configure)."""
        timer = self.create_timer(period, callback)
        self.made.append(timer)
        return timer

    def release_made(self) -> None:
        """Destroy what the publisher, subscription and timer helpers made."""
        while self.made:
            entity = self.made.pop()
            if entity in self.publishers:
                self.destroy_lifecycle_publisher(entity)
            elif entity in self.subscriptions:
                self.destroy_subscription(entity)
            else:
                self.destroy_timer(entity)

    def parameters(self) -> dict:
        """Every parameter of the table, checked, by name (their values now)."""
        return {s.name: s.value(self.get_parameter(s.name).value) for s in self.SPECS}

    def health(self, now: float) -> Health:
        """The lifecycle state and the subclass's report."""
        h = Health()
        h.add("state", self.state)
        if self.state == "unconfigured" and self.configure_error:
            h.worse(ERROR, f"cannot configure: {self.configure_error}")
        elif self.state != "active":
            h.worse(WARN, f"{self.state}: not commanding")
        if self.state in ("inactive", "active"):
            self.report(h, now)
        return h

    # -- transitions --------------------------------------------------------------------

    def on_configure(self, state: LifecycleState) -> TransitionCallbackReturn:
        """Read the parameters and load the files; FAILURE (unconfigured) on a bad one."""
        try:
            self.configure(self.parameters())
        except (StartupError, ValueError) as e:
            self.release()
            self.configure_error = str(e)
            if not self._quiet_failure:
                self.get_logger().error(f"cannot configure: {e}")
            return FAILURE
        self.configure_error = ""
        self.state = "inactive"
        return SUCCESS

    def on_activate(self, state: LifecycleState) -> TransitionCallbackReturn:
        """Enable the publishers, then act on what is held."""
        super().on_activate(state)
        self.state = "active"
        self.activate()
        return SUCCESS

    def on_deactivate(self, state: LifecycleState) -> TransitionCallbackReturn:
        """Stop the robot, then disable the publishers."""
        self.deactivate()
        super().on_deactivate(state)
        self.state = "inactive"
        return SUCCESS

    def on_cleanup(self, state: LifecycleState) -> TransitionCallbackReturn:
        """Release what configure made."""
        self.release()
        self.state = "unconfigured"
        return SUCCESS

    def on_shutdown(self, state: LifecycleState) -> TransitionCallbackReturn:
        """Stop the robot if commanding, and release everything."""
        if self.active:
            self.deactivate()
        self.release()
        self.state = "finalized"
        return SUCCESS

    def on_error(self, state: LifecycleState) -> TransitionCallbackReturn:
        """A transition raised: release and go back to unconfigured."""
        self.release()
        self.state = "unconfigured"
        return SUCCESS

    def finish(self) -> None:
        """At the end of the process: stop the robot if active (Ctrl-C stops it too)."""
        if self.state in ("unconfigured", "inactive", "active"):
            self.trigger_shutdown()
