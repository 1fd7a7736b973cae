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

from rclpy.duration import Duration
from rclpy.lifecycle import LifecycleNode, LifecycleState, TransitionCallbackReturn

from evorbc_ros.health import ERROR, WARN, Health
from evorbc_ros.node_parameters import PARAMETERS, REMOVED, ParamSpec
from evorbc_ros.nodes.common import RELIABLE, StartupError, logged_startup
from evorbc_ros.nodes.diagnostics import DiagnosticsPublisher
from evorbc_ros.nodes.parameters import ParameterGuard, declare_all

SUCCESS, FAILURE = TransitionCallbackReturn.SUCCESS, TransitionCallbackReturn.FAILURE
#: s to wait, at the end of the process, for the subscribers to acknowledge the last
#: (stop) messages before the publishers go.
LAST_WORDS = 0.5


class ManagedNode(LifecycleNode):
    """A lifecycle node that reads its table of parameters at configure.

    Subclasses set :attr:`NAME` (the node's name, and the key of its parameter table and
    removed parameters, whatever it is renamed to) and implement :meth:`configure` (load,
    check, create publishers and subscriptions; raise :class:`StartupError`),
    :meth:`activate`, :meth:`deactivate` (stop the robot), :meth:`release` (undo
    :meth:`configure`, safe to call twice) and :meth:`report` (their part of the health
    report).
    """

    NAME = ""

    def __init__(self, **kwargs) -> None:
        super().__init__(self.NAME, **kwargs)
        self.specs: tuple[ParamSpec, ...] = PARAMETERS[self.NAME]
        self.made: list = []  # publishers, subscriptions and timers configure made
        self.state = "unconfigured"
        self.configure_error = ""  # why the last configure (or activate) failed
        self._quiet_failure = False  # autostart reports it as the FATAL start-up line
        with logged_startup(self):
            start = declare_all(self, self.specs, "at configure", REMOVED[self.NAME])
        ParameterGuard(
            self,
            self.specs,
            "at configure",
            is_open=lambda: self.state == "unconfigured",
            apply=self.apply_live,
        )
        self.diagnostics = DiagnosticsPublisher(self, start["diagnostics_period"], self.health)
        if start["autostart"]:
            with logged_startup(self):
                self._quiet_failure = True
                if self.trigger_configure() != SUCCESS or self.trigger_activate() != SUCCESS:
                    raise StartupError(self.configure_error)
                self._quiet_failure = False

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
        return {s.name: s.value(self.get_parameter(s.name).value) for s in self.specs}

    def _failed(self, step: str, error: Exception) -> None:
        """Note why ``step`` failed, and log it unless autostart reports it."""
        expected = isinstance(error, (StartupError, ValueError))
        self.configure_error = str(error) if expected else f"{type(error).__name__}: {error}"
        if not self._quiet_failure:
            self.get_logger().error(f"cannot {step}: {self.configure_error}")

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

    # Every transition catches what its step raises: rclpy would turn it into an error
    # transition without a word, and the node would fall back to unconfigured unexplained.

    def on_configure(self, state: LifecycleState) -> TransitionCallbackReturn:
        """Read the parameters and load the files; FAILURE (unconfigured) on a bad one."""
        try:
            self.configure(self.parameters())
        except Exception as e:
            self._failed("configure", e)
            self.release()
            return FAILURE
        self.configure_error = ""
        self.state = "inactive"
        return SUCCESS

    def on_activate(self, state: LifecycleState) -> TransitionCallbackReturn:
        """Enable the publishers, then act on what is held; FAILURE (inactive) if it fails."""
        super().on_activate(state)
        self.state = "active"
        try:
            self.activate()
        except Exception as e:
            self._failed("activate", e)
            super().on_deactivate(state)
            self.state = "inactive"
            return FAILURE
        return SUCCESS

    def on_deactivate(self, state: LifecycleState) -> TransitionCallbackReturn:
        """Stop the robot, then disable the publishers."""
        self._stop_robot()
        super().on_deactivate(state)
        self.state = "inactive"
        return SUCCESS

    def on_cleanup(self, state: LifecycleState) -> TransitionCallbackReturn:
        """Release what configure made."""
        self._release()
        self.state = "unconfigured"
        return SUCCESS

    def on_shutdown(self, state: LifecycleState) -> TransitionCallbackReturn:
        """Stop the robot if commanding (and let the stop arrive), release everything."""
        if self.active:
            self._stop_robot()
            for pub in self.made:
                if hasattr(pub, "wait_for_all_acked"):
                    pub.wait_for_all_acked(Duration(seconds=LAST_WORDS))
        self._release()
        self.state = "finalized"
        return SUCCESS

    def on_error(self, state: LifecycleState) -> TransitionCallbackReturn:
        """A transition failed unexpectedly: release and go back to unconfigured."""
        self._release()
        self.state = "unconfigured"
        return SUCCESS

    def _stop_robot(self) -> None:
        """:meth:`deactivate`, logged if it fails (the node goes on deactivating)."""
        try:
            self.deactivate()
        except Exception as e:
            self.get_logger().error(f"stopping the robot failed: {type(e).__name__}: {e}")

    def _release(self) -> None:
        """:meth:`release`, logged if it fails."""
        try:
            self.release()
        except Exception as e:
            self.get_logger().error(f"releasing failed: {type(e).__name__}: {e}")

    def finish(self) -> None:
        """At the end of the process: stop the robot if active (Ctrl-C stops it too)."""
        if self.state in ("unconfigured", "inactive", "active"):
            self.trigger_shutdown()
