"""Telling a restarted node from one that only dropped out of DDS discovery.

The lockstep bridge sends a state again only to a node that missed it: one that left the
graph and came back as a new node, with new endpoint GIDs. A node whose DDS lease lapsed
on a loaded machine drops out of discovery and comes back with its old GIDs; its reliable
connections lost nothing, and a second state would be answered twice (docs/design/
ros-graph.md, "One graph per domain").

The GIDs a node comes back with are compared with every GID seen since the graph
connected, not with those visible when the cycle began: a lease can lapse across a cycle
boundary, and a node absent at that moment would otherwise look new when it returns. They
are also learned while nothing is missing: an endpoint discovered after the graph connected
(a subscriber the run does not wait for, or one found late under load) would otherwise look
new after its node's first lapse, and the state sent again would be answered twice.
"""

from __future__ import annotations


class RejoinWatch:
    """Follows the graph's endpoints across cycles and says when a node came back new.

    Endpoints are hashable ``(topic, GID)`` pairs, as ``BridgeNode.endpoints`` gives them.
    """

    def __init__(self, endpoints: frozenset) -> None:
        """Start from the endpoints of the connected graph."""
        self.seen: frozenset = frozenset(endpoints)
        self.away = False  # a node is missing and has not come back yet

    def check(self, gone: list[str], endpoints) -> str:
        """One look at the graph: ``gone`` are the topics that lack a node now.

        ``endpoints`` is a callable returning the visible endpoints; it is called when
        nothing is missing (to learn endpoints discovered late) and when a missing node is
        back.

        Returns:
            ``"left"`` when a node has just been found missing, ``"new"`` when a missing
            node is back with endpoints never seen before (a restart, which missed the
            state), ``"back"`` when it is back with endpoints seen before (it lost
            nothing), else ``""``.
        """
        if gone:
            left, self.away = not self.away, True
            return "left" if left else ""
        if not self.away:
            self.seen |= frozenset(endpoints())
            return ""
        self.away = False
        back = frozenset(endpoints())
        new = bool(back - self.seen)
        self.seen |= back
        return "new" if new else "back"
