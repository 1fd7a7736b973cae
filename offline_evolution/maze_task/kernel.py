"""The compiled episode kernel: many (controller, maze, start) episodes in one parallel loop.

Each control cycle (0.1 s) of an episode: read the sensors at the robot's pose, evaluate the
controller's network, turn its outputs into a command, and step the robot's motion model
(with wall contact): the 4WS model or the differential-drive one, chosen at compile time by
the type of the limits (:mod:`sim_bridge.kinematics`). An EvoRBC controller maps its two
outputs to a behaviour-space point and runs the nearest primitive (grid lookup); a
standard-NEAT controller's outputs are the robot's genes. The episode ends when the
robot's centre is within the target radius or after ``n_cycles`` cycles.

A cycle whose network outputs are not finite (or, for EvoRBC, map to no finite point) runs
no primitive, as onboard (:func:`evorbc_ros.mapping.choose_primitive`, the executor's empty
message): zero wheel speed with the steering held at its last command (4WS), a zero twist
(differential drive).

A motion input (docs/design.md section 5) compares the position with the one ``W`` cycles
earlier (the episode's first before that), kept in a ring of the last ``W + 1`` positions.

Episodes are independent, so results do not depend on the number of threads. A recurrent
network (docs/design.md section 8) keeps its state in its episode's own two value buffers,
carried from cycle to cycle and 0 at the start of the episode.

A perturbed world (docs/design.md section 21, :mod:`~offline_evolution.maze_task.perturbation`)
scales the commanded wheel speed, delays commands by whole cycles, adds noise to the
rangefinder readings and loses some of them; the noise of each episode comes from its own
key through a counter-based hash, so it does not depend on threads or on other episodes.
With every factor 1 and every noise 0 the episode is the unperturbed one, bit for bit.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numba as nb
import numpy as np

from evorbc_ros import mapping as onboard_mapping
from evorbc_ros.adaptation import cycles as adaptation_cycles
from evorbc_ros.goal import quaternion_yaw
from offline_evolution.arbitrator.compiled import activate, activate_recurrent
from sim_bridge.four_ws.motion import HEADING, STATE_SIZE, X, Y, speed_through_wheels
from sim_bridge.geometry import grid_candidates, planar_quaternion
from sim_bridge.hashing import hash_uniform as _hash_uniform
from sim_bridge.kinematics import halt, step_model, step_model_damaged
from sim_bridge.sensors import read_sensors

map_point = nb.njit(cache=True)(onboard_mapping.map_point)
clamped_cell = nb.njit(cache=True)(onboard_mapping.clamped_cell)
NO_PRIMITIVE = onboard_mapping.NO_PRIMITIVE
# The onboard controller's adaptation (docs/design/adaptation.md), compiled: the same bits.
_ADAPT = adaptation_cycles.compiled(nb.njit)
_put_pose = _ADAPT["put_pose"]
_before_choice = _ADAPT["before_choice"]
_after_choice = _ADAPT["after_choice"]
_new_counts = _ADAPT["new_counts"]
_adapted_choice = _ADAPT["choose"]
_quaternion_yaw = nb.njit(cache=True)(quaternion_yaw)
_planar_quaternion = nb.njit(cache=True)(planar_quaternion)

#: Controller modes.
EVORBC, STANDARD = 0, 1


class Traces(NamedTuple):
    """What a recorded episode writes, cycle by cycle (all 1-sized when ``on`` is False).

    Attributes:
        on: record the episodes.
        pose: ``(E, n_cycles + 1, 3)`` pose ``(x m, y m, heading rad)`` at each cycle's
            start, and at the end in the row after the last cycle run.
        choice: ``(E, n_cycles)`` the primitive run (-1 for a standard controller,
            :data:`NO_PRIMITIVE` for a stop).
        outputs: ``(E, n_cycles, n_outputs)`` the network's outputs.
    """

    on: bool
    pose: np.ndarray
    choice: np.ndarray
    outputs: np.ndarray


class WorldDraws(NamedTuple):
    """Each episode's perturbed world (docs/design.md section 21), or none when ``on`` is False.

    Attributes:
        on: apply the draws; otherwise the arrays may be 1-sized and are not read.
        params: ``(E, 7)`` wheel speed gain, latency (cycles), reading noise sd, dropout
            probability, then a damaged wheel's kind (0: intact), wheel and level
            (:meth:`sim_bridge.damage.DamageDraw.wheel_arrays`).
        keys: ``(E,)`` int64 key of each episode's noise.
    """

    on: bool
    params: np.ndarray
    keys: np.ndarray


class Adapting(NamedTuple):
    """An EvoRBC controller's onboard adaptation (docs/design/adaptation.md).

    Built by :func:`offline_evolution.maze_task.adapting.adapting`; the arrays are the
    :class:`~evorbc_ros.adaptation.online.OnlineAdaptation`'s of the same repertoire.

    Attributes:
        conf, iconf: :func:`evorbc_ros.adaptation.online.settings_arrays`.
        features, recorded, expected: ``(n, 3)`` the outcome model's.
        weight: ``(3,)`` 1 / each outcome dimension's extent (1/m, 1/m, 1/rad).
        noise: the model's noise variance over the prior's.
        capacity: the ring's ``K``.
        average: the most observations a slot averages.
        dt: s, the control period: cycle ``t``'s pose is stamped ``round(t dt 1e9)`` ns,
            as the bridge stamps its odometry.
    """

    conf: np.ndarray
    iconf: np.ndarray
    features: np.ndarray
    recorded: np.ndarray
    expected: np.ndarray
    weight: np.ndarray
    noise: float
    capacity: int
    average: int
    dt: float


@nb.njit(cache=True)
def _perturb_readings(inputs, n_rangefinders, noise_sd, dropout, key, cycle):
    """Rangefinder readings (in [0, 1], 0 = nothing in range) with noise and dropouts."""
    for k in range(n_rangefinders):
        if dropout > 0.0 and _hash_uniform(key, cycle, k, 0) < dropout:
            inputs[k] = 0.0  # no echo: reads as nothing in range
        elif noise_sd > 0.0 and inputs[k] > 0.0:
            u1 = _hash_uniform(key, cycle, k, 1)
            u2 = _hash_uniform(key, cycle, k, 2)
            normal = math.sqrt(-2.0 * math.log(1.0 - u1)) * math.cos(2.0 * math.pi * u2)
            inputs[k] = min(max(inputs[k] + noise_sd * normal, 0.0), 1.0)


@nb.njit(cache=True)
def _same_state(buffers, n):
    """Whether a recurrent network's two buffers hold the same bits in slots ``0..n-1``.

    Then the next step, from the same inputs, writes the same values again. The sign of
    a zero counts (it can reach an output through ``identity``); NaN never equals itself.
    """
    for k in range(n):
        a = buffers[0, k]
        b = buffers[1, k]
        if a != b or math.copysign(1.0, a) != math.copysign(1.0, b):
            return False
    return True


@nb.njit(cache=True)
def _lookup(x, y, origin, cell, table):
    """Compiled :meth:`evorbc_ros.mapping.PrimitiveLookup.nearest`."""
    nx, ny = table.shape
    i = clamped_cell((x - origin[0]) / cell[0], nx)
    j = clamped_cell((y - origin[1]) / cell[1], ny)
    return table[i, j]


@nb.njit(cache=True)
def _candidates(m, x, y, world):
    """Wall rows near ``(x, y)`` in maze ``m`` of the :class:`MazePack` ``world``."""
    base = world.cell_base[m]
    nx = world.grid_shape[m, 0]
    ny = world.grid_shape[m, 1]
    return grid_candidates(
        x,
        y,
        world.grid_origin[m, 0],
        world.grid_origin[m, 1],
        world.grid_cell,
        nx,
        ny,
        world.cell_offsets[base : base + nx * ny + 1],
        world.cell_ids,
        world.all_ids[world.all_start[m] : world.all_start[m + 1]],
    )


# The helpers of each cycle are inlined into the parallel loop: as calls, the kernel ran
# 25 % fewer cycles/s (bench/bench_ab_hot_paths.py, 4ws_episodes).


@nb.njit(cache=True, inline="always")
def _world_draw(draws, e):
    """``(gain, latency cycles, noise sd, dropout, key, damaged)`` of episode ``e``.

    Nominal (and intact) when off.
    """
    if draws.on:
        p = draws.params
        return p[e, 0], int(p[e, 1]), p[e, 2], p[e, 3], draws.keys[e], p[e, 4] != 0.0
    return 1.0, 0, 0.0, 0.0, np.int64(0), False


@nb.njit(cache=True, inline="always")
def _sense(t, x, y, h, m, world, sensors, trail, inputs, noise_sd, dropout, key):
    """Fill ``inputs`` with cycle ``t``'s readings at pose ``(x, y, h)`` in maze ``m``.

    ``trail`` is the motion input's ring (``(W + 1, 2)`` positions in m): this cycle's
    position goes in, the one ``W`` cycles earlier (the episode's first before that) is
    compared with it. Returns the wall rows near the robot, which the step reuses.
    """
    window = sensors.motion_cycles  # 0: no motion input
    rx, ry = x, y
    if window > 0:
        trail[t % (window + 1), 0] = x
        trail[t % (window + 1), 1] = y
        ref = max(t - window, 0) % (window + 1)
        rx, ry = trail[ref, 0], trail[ref, 1]
    cand = _candidates(m, x, y, world)
    tx = world.targets[m, 0]
    ty = world.targets[m, 1]
    read_sensors(x, y, h, tx, ty, rx, ry, sensors, world.boxes, cand, inputs)
    if noise_sd > 0.0 or dropout > 0.0:
        _perturb_readings(inputs, sensors.ray_angles.shape[0], noise_sd, dropout, key, t)
    return cand


@nb.njit(cache=True, inline="always")
def _think(g, t, inputs, values, buffers, recurrent, out, net):
    """Network ``g``'s outputs for ``inputs`` into ``out`` (a recurrent one steps its state)."""
    if recurrent:
        activate_recurrent(g, inputs, buffers, t % 2, out, net)
    else:
        activate(g, inputs, values, out, net)


@nb.njit(cache=True, inline="always")
def _decide(out, controller, lim, command):
    """Turn the network's outputs into ``command`` (in place); return the choice.

    EvoRBC: the mapping's point and the nearest primitive's command; standard NEAT: the
    outputs as genes, through the robot's gene matrix. Outputs that are not finite (or a
    point that is not) run no primitive: a stop (:data:`NO_PRIMITIVE`). Returns the
    primitive's index, -1 for a standard controller, or :data:`NO_PRIMITIVE`.
    """
    width = command.shape[0]
    choice = -1
    finite = True
    for k in range(out.shape[0]):
        finite = finite and math.isfinite(out[k])
    if controller.mode == EVORBC and finite:
        px, py = map_point(controller.map_kind, controller.map_params, out[0], out[1])
        finite = math.isfinite(px) and math.isfinite(py)
        if finite:
            choice = _lookup(
                px, py, controller.lookup_origin, controller.lookup_cell, controller.lookup_table
            )
            for c in range(width):
                command[c] = controller.primitive_commands[choice, c]
    elif finite:
        gene_matrix = controller.gene_matrix
        for c in range(width):
            acc = 0.0
            for k in range(out.shape[0]):
                gene = 2.0 * min(max(out[k], 0.0), 1.0) - 1.0
                acc += gene * gene_matrix[k, c]
            command[c] = acc * controller.command_scale[c]
    if finite and controller.speed_wheel_radius > 0.0:
        command[0] = speed_through_wheels(command[0], controller.speed_wheel_radius)
    if not finite:
        halt(command, lim)  # no primitive: stop
        return NO_PRIMITIVE
    return choice


@nb.njit(cache=True)
def _adapt(t, x, y, h, out, controller, command, choice, adapt, ints, floats, model):
    """The adapting controller's cycle ``t``: the grid's ``choice`` -> the primitive to run.

    As :meth:`evorbc_ros.arbitration.Controller.step` with adaptation on, fed the pose
    ``(x m, y m, h rad)`` at the cycle's start as the arbitrator node gets it from the
    bridge's odometry (stamp, quaternion and back): the motion since the last choice goes
    to the primitive chosen then, then the grid's choice is matched against the corrected
    outcomes (at the centre of its grid cell) and ``command`` rewritten if another runs.
    ``model``: the outcome model's arrays (:meth:`OutcomeModel.arrays` order) and noise.
    """
    z, w = _planar_quaternion(h)
    _put_pose(ints, floats, round(t * adapt.dt * 1e9), x, y, _quaternion_yaw(0.0, 0.0, z, w))
    (features, recorded, expected, kzx, slots, residual, inverse, alpha, correction,
     corrected, counts, noise) = model  # fmt: skip
    _before_choice(ints, floats, adapt.conf, adapt.iconf, features, recorded, expected,
                   kzx, slots, residual, inverse, alpha, correction, corrected, counts,
                   noise)  # fmt: skip
    if choice != NO_PRIMITIVE:
        px, py = map_point(controller.map_kind, controller.map_params, out[0], out[1])
        nx, ny = controller.lookup_table.shape
        o, c = controller.lookup_origin, controller.lookup_cell
        # The cell's centre as evorbc_ros.mapping.PrimitiveLookup.cell_centre computes it.
        cx = o[0] + (clamped_cell((px - o[0]) / c[0], nx) + 0.5) * c[0]
        cy = o[1] + (clamped_cell((py - o[1]) / c[1], ny) + 0.5) * c[1]
        chosen = _adapted_choice(adapt.iconf, cx, cy, choice, recorded, corrected, counts,
                                 adapt.weight)  # fmt: skip
        if chosen != choice:
            choice = chosen
            for k in range(command.shape[0]):
                command[k] = controller.primitive_commands[choice, k]
            if controller.speed_wheel_radius > 0.0:
                command[0] = speed_through_wheels(command[0], controller.speed_wheel_radius)
    _after_choice(ints, floats, adapt.conf, choice, features, recorded, expected, kzx, slots,
                  residual, inverse, alpha, correction, corrected, counts, noise)  # fmt: skip
    return choice


@nb.njit(cache=True)
def _new_model(adapt):
    """An episode's adaptation state, as the onboard controller starts it.

    The settled-cycle rule's ``(ints, floats)`` (:func:`evorbc_ros.adaptation.cycles.new_state`)
    and the outcome model's arrays as :class:`~evorbc_ros.adaptation.model.OutcomeModel`
    starts them, with its noise.
    """
    ints = np.zeros(adaptation_cycles.N_INTS, dtype=np.int64)
    ints[adaptation_cycles.RUNNING] = -1
    k = adapt.capacity
    n = adapt.recorded.shape[0]
    model = (adapt.features, adapt.recorded, adapt.expected, np.zeros((k, n)),
             np.full(k, -1, dtype=np.int64), np.zeros((k, 3)), np.zeros((k, k)),
             np.zeros((k, 3)), np.zeros((3, n)), adapt.recorded.copy(),
             _new_counts(k, adapt.average), adapt.noise)  # fmt: skip
    return ints, np.zeros(adaptation_cycles.N_FLOATS), model


@nb.njit(cache=True, inline="always")
def _record(pose, choice_trace, output_trace, e, t, x, y, h, choice, out):
    """Write cycle ``t`` of episode ``e`` into the arrays of :class:`Traces`."""
    pose[e, t, 0] = x
    pose[e, t, 1] = y
    pose[e, t, 2] = h
    choice_trace[e, t] = choice
    for k in range(out.shape[0]):
        output_trace[e, t, k] = out[k]


@nb.njit(cache=True, inline="always")
def _act(
    state, e, t, command, scaled, gain, pending, latency, lim, boxes, cand, damaged, damage, key
):
    """Step robot ``e`` one cycle on ``command``, through a perturbed world if ``scaled``.

    Every branch of :func:`_decide` set the speeds afresh this cycle. A wheel speed gain
    scales the 4WS speed, and both v and omega of a differential drive (every wheel turns
    faster by the same factor). With ``latency`` cycles, the command of ``latency`` cycles
    ago is applied and this one queued in ``pending`` (a ring starting as stops).
    ``damaged``: step with the damaged wheel ``damage`` (``(3,)`` kind, wheel, level);
    otherwise the intact model runs, bit for bit as without damage sets.
    """
    if scaled:
        command[0] *= gain
        if command.shape[0] == 2:
            command[1] *= gain
    applied = command
    if latency > 0:
        slot = t % latency
        applied = pending[slot].copy()
        pending[slot, :] = command
    if damaged:
        step_model_damaged(state, e, applied, lim, boxes, cand, damage, key, t)
    else:
        step_model(state, e, applied, lim, boxes, cand)


@nb.njit(cache=True, inline="always")
def _unchanged(state, e, before):
    """Whether robot ``e``'s whole state (pose, speed, wheel angles) equals ``before``."""
    for k in range(STATE_SIZE):  # noqa: SIM110 (a loop: no generators in compiled code)
        if state[e, k] != before[k]:
            return False
    return True


@nb.njit(cache=True, parallel=True)
def run_episodes(
    genome, maze, start, n_cycles, net, world, sensors, controller, lim, traces, draws, adapt
):
    """Run every episode ``e`` (genome ``genome[e]`` in maze ``maze[e]`` from ``start[e]``).

    Each cycle: sense, think, decide, (record), act, then stop at the target or at a fixed
    point.

    Args:
        genome, maze: ``(E,)`` network and maze index of each episode.
        start: ``(E, 3)`` start poses ``(x m, y m, heading rad)``.
        n_cycles: episode length in control cycles.
        net: :class:`~offline_evolution.arbitrator.compiled.NetworkPack`.
        world: :class:`~offline_evolution.maze_task.world.MazePack`.
        sensors: :class:`~sim_bridge.sensors.CompiledLayout`.
        controller: :class:`~offline_evolution.maze_task.task.ControllerArrays`.
        lim: the robot's limits: :class:`~sim_bridge.four_ws.motion.MotionLimits` or
            :class:`~sim_bridge.diff_drive.motion.DiffLimits` (its state fits in
            ``STATE_SIZE`` columns, x, y and heading first).
        traces: :class:`Traces`, filled when ``traces.on``.
        draws: :class:`WorldDraws`, applied when ``draws.on``.
        adapt: :class:`Adapting`: an EvoRBC controller adapts, each episode from the
            prior; None: it does not. A compile-time choice (numba prunes the branches on
            ``adapt is None``), so the kernel without adaptation is the one before it.

    Returns:
        ``(reached (E,) bool, cycles (E,) int64, final_distance (E,), initial_distance (E,),
        end (E, 2))``: distances in m to the target, ``end`` the last position (x, y in m);
        ``cycles`` is the cycle count when the target was reached, else ``n_cycles``.
    """
    n_ep = genome.shape[0]
    reached = np.zeros(n_ep, dtype=np.bool_)
    cycles = np.full(n_ep, n_cycles, dtype=np.int64)
    final_distance = np.empty(n_ep)
    initial_distance = np.empty(n_ep)
    end = np.empty((n_ep, 2))
    state = np.zeros((n_ep, STATE_SIZE))
    max_slots = net.n_slots.max()
    window = sensors.motion_cycles  # 0: no motion input
    # The traces' arrays as locals: stores into a NamedTuple's array inside the parallel
    # loop were lost (numba 0.68; tests/test_motion_input.py and test_recurrent.py).
    pose, choice_trace, output_trace = traces.pose, traces.choice, traces.outputs
    # Entries of a command: the robot's (4WS 5, differential drive 2).
    if controller.mode == EVORBC:
        width = controller.primitive_commands.shape[1]
    else:
        width = controller.gene_matrix.shape[1]
    # Flags read every cycle, as locals: numba does not hoist NamedTuple loads out of the
    # parallel loop; read from the tuples, the two cost 11 % of the cycles/s (A/B on CPU
    # time, docs/performance.md "The episode kernel in steps").
    recording, drawn = traces.on, draws.on
    for e in nb.prange(n_ep):
        g = genome[e]
        m = maze[e]
        tx = world.targets[m, 0]
        ty = world.targets[m, 1]
        state[e, X] = start[e, 0]
        state[e, Y] = start[e, 1]
        state[e, HEADING] = start[e, 2]
        inputs = np.empty(sensors.n_inputs)
        values = np.empty(max_slots)
        # A recurrent network's state (activate_recurrent): 0 at the start of the episode.
        recurrent = net.recurrent[g]
        buffers = np.zeros((2, max_slots if recurrent else 1))
        out = np.empty(net.n_outputs)
        # 4WS: (speed m/s, 4 steering angles rad); a stop keeps the last angles, as the
        # executor does, which start at 0. Differential drive: (v m/s, omega rad/s).
        command = np.zeros(width)
        before = np.empty(STATE_SIZE)
        gain, latency, noise_sd, dropout, key, damaged = _world_draw(draws, e)
        damage = draws.params[0, 4:7]  # read only when damaged
        if damaged:
            damage = draws.params[e, 4:7]
        # Commands still on their way to the wheels (latency), starting as stops.
        pending = np.zeros((max(latency, 1), width))
        # The motion input's ring: position of cycle t in row t % (window + 1) (m).
        # (Rows past the episode's length are never written: a longer window reads p(0).)
        trail = np.empty((min(window, n_cycles) + 1, 2))
        still = 0  # cycles in a row whose step left the state unchanged
        if adapt is not None:  # the episode's own rule state and outcome model
            a_ints, a_floats, model = _new_model(adapt)
        initial_distance[e] = math.hypot(start[e, 0] - tx, start[e, 1] - ty)
        dist = initial_distance[e]
        for t in range(n_cycles):
            x = state[e, X]
            y = state[e, Y]
            h = state[e, HEADING]
            cand = _sense(t, x, y, h, m, world, sensors, trail, inputs, noise_sd, dropout, key)
            _think(g, t, inputs, values, buffers, recurrent, out, net)
            choice = _decide(out, controller, lim, command)
            if adapt is not None:
                choice = _adapt(t, x, y, h, out, controller, command, choice, adapt, a_ints,
                                a_floats, model)  # fmt: skip
            if recording:
                _record(pose, choice_trace, output_trace, e, t, x, y, h, choice, out)
            for k in range(STATE_SIZE):
                before[k] = state[e, k]
            _act(
                state, e, t, command, drawn, gain, pending, latency, lim, world.boxes, cand,
                damaged, damage, key,
            )  # fmt: skip
            dist = math.hypot(state[e, X] - tx, state[e, Y] - ty)
            if dist <= world.target_radius[m]:
                reached[e] = True
                cycles[e] = t + 1
                break
            if not recording and not drawn and adapt is None:
                # A fixed point: the whole state came back unchanged, so every later cycle
                # reads the same sensors, gets the same outputs from the network and makes
                # the same step. A feed-forward network is stateless; a recurrent one must
                # also have written the values it read (both buffers equal), so its next
                # step repeats this one. A motion input reads the same (0) only once the
                # whole window, and the position this cycle compared with, hold this
                # position: more than ``window`` unchanged steps in a row. The episode's
                # outcome is already known: stop here. Not while adapting: the motion
                # summed so far is given to the model at the next unsettled cycle, which
                # may change a later choice.
                same = _unchanged(state, e, before)
                still = still + 1 if same else 0
                if same and recurrent:
                    same = _same_state(buffers, net.n_slots[g])
                if same and still > window:
                    break
        final_distance[e] = dist
        end[e, 0] = state[e, X]
        end[e, 1] = state[e, Y]
        if recording:  # the pose the last cycle run reached
            last = cycles[e]
            pose[e, last, 0] = state[e, X]
            pose[e, last, 1] = state[e, Y]
            pose[e, last, 2] = state[e, HEADING]
    return reached, cycles, final_distance, initial_distance, end
