"""The lockstep bridge's rule for sending a state again (sim_bridge/rejoins.py): only a
node that came back with endpoints never seen is sent it, however its absence falls
across cycles."""

from sim_bridge.rejoins import RejoinWatch

ARB = frozenset({("scan", b"laser"), ("odom", b"radar"), ("primitive", b"arb")})
LAPSED = ARB - {("primitive", b"arb")}  # the arbitrator's DDS lease lapsed
RESTARTED = LAPSED | {("primitive", b"arb-2")}  # the arbitrator restarted: a new GID


def looks(watch, *steps):
    """What the watch says at each ``(gone, visible endpoints)`` look."""
    return [watch.check(gone, lambda v=visible: v) for gone, visible in steps]


def test_a_lapse_within_a_cycle_is_not_a_restart():
    watch = RejoinWatch(ARB)
    assert looks(watch, ([], ARB), (["primitive"], LAPSED), ([], ARB)) == ["", "left", "back"]


def test_a_lapse_across_a_cycle_boundary_is_not_a_restart():
    # The bridge once took its endpoints afresh at each cycle: a node absent at that
    # moment looked new when it came back, and got the state twice (one choice too many).
    watch = RejoinWatch(ARB)
    assert looks(watch, (["primitive"], LAPSED)) == ["left"]
    # next cycle: still away, then back with its old GID
    assert looks(watch, (["primitive"], LAPSED), ([], ARB)) == ["", "back"]


def test_a_restart_is_sent_the_state_again():
    watch = RejoinWatch(ARB)
    assert looks(watch, (["primitive"], LAPSED), ([], RESTARTED)) == ["left", "new"]
    # once seen, the restarted node's endpoints are known: a later lapse is not a restart
    assert looks(watch, (["primitive"], LAPSED), ([], RESTARTED)) == ["left", "back"]


def test_a_node_missing_from_the_start_is_new_when_it_comes():
    watch = RejoinWatch(LAPSED)  # the bridge started without the arbitrator
    assert looks(watch, (["primitive"], LAPSED), ([], ARB)) == ["left", "new"]


def test_an_endpoint_discovered_after_the_start_is_not_new_after_a_lapse():
    # A second odom subscription (here the recorder's) was discovered only after the graph
    # connected. Unlearned, its node's first lapse made it look restarted, and the state
    # sent again was answered twice by every other node.
    late = ARB | {("odom", b"recorder")}
    watch = RejoinWatch(ARB)
    assert looks(watch, ([], late), (["odom"], ARB), ([], late)) == [
        "",
        "left",
        "back",
    ]
