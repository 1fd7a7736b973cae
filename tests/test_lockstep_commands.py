"""In lockstep, every command the executor sends answers one primitive.

The bridge steps the world once per set of commands, so a command of the executor's own
(the keep-alive repeat, or a stop for inputs that look stale) would be taken for the next
cycle's, and the run would no longer be the offline episode (docs/design.md section 9).
Under load the executor can handle a primitive before the ``/clock`` message of the same
cycle, so its own clock says the primitive came a cycle early; at the next cycle the
keep-alive saw 0.2 s since the last command and sent the old primitive again.
"""

from std_msgs.msg import Float64MultiArray

from evorbc_ros.nodes.common import vector_message
from evorbc_ros.nodes.primitive_executor import PrimitiveExecutorNode

GENES = [1.0, 0.5, 0.5, -0.5, -0.5]


def run_cycles(ros, lockstep: bool) -> tuple[int, int]:
    """Primitives sent and commands received, with the clock lagging at every other cycle."""
    ros.make(PrimitiveExecutorNode, sim_time=True, robot="4ws-5", lockstep=lockstep)
    wheels = ros.listen(Float64MultiArray, "wheel_velocity_controller/commands")
    prim, rf, gs = ros.executor_inputs()
    sent = 0

    def answer():
        nonlocal sent
        rf.publish(vector_message([0.0] * 6))
        gs.publish(vector_message([1, 0, 0, 0]))
        prim.publish(vector_message(GENES))
        sent += 1
        assert ros.spin_until(lambda: len(wheels) >= sent)

    t = 1.0
    ros.set_clock(t)
    answer()
    for k in range(8):
        t = round(t + 0.1, 3)
        if k % 2:
            ros.set_clock(t)  # the usual order: the state's clock, then the answer
            answer()
        else:
            answer()  # the answer is handled before the same cycle's clock
            ros.set_clock(t)
        ros.spin_until(lambda: False, timeout=0.05)  # let any command of its own go out
    return sent, len(wheels)


def test_in_lockstep_the_executor_sends_one_command_per_primitive(ros):
    sent, commands = run_cycles(ros, lockstep=True)
    assert commands == sent == 9


def test_in_realtime_the_keep_alive_repeats_a_late_primitive(ros):
    # Realtime keeps the controllers fed: with the clock a cycle behind, the repeat shows.
    sent, commands = run_cycles(ros, lockstep=False)
    assert commands > sent
