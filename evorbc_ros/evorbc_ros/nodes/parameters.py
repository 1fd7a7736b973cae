"""Declaring a node's parameters from its table (:mod:`evorbc_ros.node_parameters`).

Every parameter gets a descriptor with its description, its range (``ros2 param
describe``) and, in ``additional_constraints``, its choices and when it is read. Values are
checked the same way at start-up and when set.

A parameter that is not ``live`` is read once: at start-up, or at configure for a
lifecycle node. Setting it to another value afterwards is refused with the reason (a
lifecycle node takes any valid value while unconfigured: ``ros2 lifecycle set NODE
cleanup``, set, configure), so ``ros2 param set`` never claims a success that changes
nothing; setting it to the value it has succeeds, so ``ros2 param load`` of the shipped
file works on a running node (docs/design.md section 9).
"""

from __future__ import annotations

from collections.abc import Callable, Iterable

from rcl_interfaces.msg import (
    FloatingPointRange,
    IntegerRange,
    ParameterDescriptor,
    SetParametersResult,
)
from rclpy.node import Node
from rclpy.parameter import Parameter

from evorbc_ros.node_parameters import INT64_MAX, ParamSpec, removed_problem
from evorbc_ros.nodes.common import StartupError


def descriptor(spec: ParamSpec, read_when: str) -> ParameterDescriptor:
    """The ROS descriptor of ``spec``: description, range, choices and when it is read."""
    when = "at start-up" if spec.at_start else read_when
    constraints = ["applied live" if spec.live else f"read {when}"]
    if spec.choices:
        constraints.append(f"one of: {', '.join(spec.choices)}")
    d = ParameterDescriptor(
        description=spec.description,
        additional_constraints="; ".join(constraints),
        # A float parameter takes a whole number too (-p rate:=100): checked by the table.
        dynamic_typing=spec.kind is float,
    )
    if spec.kind is float:
        d.floating_point_range = [
            FloatingPointRange(
                from_value=-1e308 if spec.minimum is None else float(spec.minimum),
                to_value=1e308 if spec.maximum is None else float(spec.maximum),
                step=0.0,
            )
        ]
    elif spec.kind is int:
        d.integer_range = [
            IntegerRange(
                from_value=-INT64_MAX if spec.minimum is None else int(spec.minimum),
                to_value=INT64_MAX if spec.maximum is None else int(spec.maximum),
                step=1,
            )
        ]
    return d


def given_parameters(node: Node) -> set[str]:
    """The names of the parameters set for ``node`` from outside (``-p``, a params file)."""
    # rclpy keeps them on the node and offers no public accessor.
    return set(getattr(node, "_parameter_overrides", {}))


def declare_all(
    node: Node, specs: Iterable[ParamSpec], read_when: str, removed: dict[str, str]
) -> dict:
    """Declare ``specs`` on ``node`` and return their checked values by name.

    Args:
        read_when: "at start-up" or "at configure" (the descriptors say it).
        removed: the node's removed parameters -> their remapping
            (:data:`~evorbc_ros.node_parameters.REMOVED`); by the node's kind, not its
            name, which a user may change (``-r __node:=left_arbitrator``).

    Raises:
        StartupError: one line naming a removed parameter and its remapping, or a value
            of the wrong type or out of range.

    """
    problem = removed_problem(given_parameters(node), removed)
    if problem:
        raise StartupError(problem)
    values = {}
    for spec in specs:
        default = list(spec.default) if spec.kind is tuple else spec.default
        if default == []:  # rclpy cannot tell an empty list's type: say it
            default = Parameter.Type.STRING_ARRAY
        try:
            raw = node.declare_parameter(spec.name, default, descriptor(spec, read_when)).value
            if raw is None:  # declared by type only, and not given
                node.set_parameters([Parameter(spec.name, Parameter.Type.STRING_ARRAY, [])])
                raw = []
        except Exception as e:  # rclpy: another type, or out of the descriptor's range
            given = getattr(node, "_parameter_overrides", {}).get(spec.name)
            problem = spec.problem(given.value) if given is not None else ""
            raise StartupError(problem or f"parameter {spec.name}: {e}") from None
        try:
            values[spec.name] = spec.value(raw)
        except ValueError as e:
            raise StartupError(str(e)) from None
    return values


class ParameterGuard:
    """Refuses changes to parameters that are read once; checks and applies live ones.

    Args:
        node: the node; its parameters must be declared already.
        specs: the node's table.
        read_when: "at start-up" or "at configure".
        is_open: for a lifecycle node, True while every parameter may change
            (unconfigured); None: never after start-up.
        apply: called with (name, checked value) for a live parameter once accepted.

    """

    def __init__(
        self,
        node: Node,
        specs: Iterable[ParamSpec],
        read_when: str,
        is_open: Callable[[], bool] | None = None,
        apply: Callable[[str, object], None] | None = None,
    ) -> None:
        self.node = node
        self.specs = {s.name: s for s in specs}
        self.read_when = read_when
        self.is_open = is_open or (lambda: False)
        self.apply = apply
        node.add_on_set_parameters_callback(self.on_set)
        # Applied once rclpy has taken the new values, so what the node uses is always what
        # ros2 param get shows, whatever other callback might still refuse the change.
        node.add_post_set_parameters_callback(self.after_set)

    def on_set(self, params: list[Parameter]) -> SetParametersResult:
        """Accept a valid value of a live or an open parameter, or the value it has."""
        for p in params:
            spec = self.specs.get(p.name)
            if spec is None:
                continue  # rclpy's own (use_sim_time)
            problem = spec.problem(p.value)
            if problem:
                return SetParametersResult(successful=False, reason=problem)
            current = self.node.get_parameter(p.name).value
            if spec.live or (self.is_open() and not spec.at_start) or _same(p.value, current):
                continue
            when = "at start-up" if spec.at_start else self.read_when
            how = (
                "deactivate, clean up, set it and configure again"
                if when == "at configure"
                else "restart the node with the new value"
            )
            return SetParametersResult(
                successful=False, reason=f"parameter {p.name} is read {when}: {how}"
            )
        return SetParametersResult(successful=True)

    def after_set(self, params: list[Parameter]) -> None:
        """Apply the live parameters just set."""
        if self.apply is None:
            return
        for p in params:
            spec = self.specs.get(p.name)
            if spec is not None and spec.live:
                self.apply(p.name, spec.value(p.value))


def _same(a, b) -> bool:
    """Equal values; 0 equals 0.0 (a whole number for a float), but true never equals 1."""
    if isinstance(a, bool) or isinstance(b, bool):
        return a is b
    if isinstance(a, (list, tuple)) and isinstance(b, (list, tuple)):
        return list(a) == list(b)
    return a == b
