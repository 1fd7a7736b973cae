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

import numba as nb
import numpy as np

from evorbc_ros import mapping as onboard_mapping
from offline_evolution.arbitrator.compiled import activate, activate_recurrent
from sim_bridge.four_ws_motion import HEADING, STATE_SIZE, X, Y, speed_through_wheels
from sim_bridge.geometry import grid_candidates
from sim_bridge.kinematics import halt, step_model
from sim_bridge.sensors import read_sensors

map_point = nb.njit(cache=True)(onboard_mapping.map_point)
clamped_cell = nb.njit(cache=True)(onboard_mapping.clamped_cell)
NO_PRIMITIVE = onboard_mapping.NO_PRIMITIVE

#: Controller modes.
EVORBC, STANDARD = 0, 1


@nb.njit(cache=True)
def _hash_uniform(key, cycle, index, salt):
    """A uniform number in [0, 1) from ``(key, cycle, index, salt)`` (splitmix64's mixer)."""
    z = np.uint64(key) + np.uint64(cycle * 1024 + index * 4 + salt + 1) * np.uint64(
        0x9E3779B97F4A7C15
    )
    z = (z ^ (z >> np.uint64(30))) * np.uint64(0xBF58476D1CE4E5B9)
    z = (z ^ (z >> np.uint64(27))) * np.uint64(0x94D049BB133111EB)
    z = z ^ (z >> np.uint64(31))
    return float(z >> np.uint64(11)) * (1.0 / 9007199254740992.0)


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


@nb.njit(cache=True, parallel=True)
def run_episodes(
    genome,
    maze,
    start,
    n_cycles,
    net,
    world,
    sensors,
    controller,
    lim,
    record,
    trace_pose,
    trace_choice,
    trace_outputs,
    perturbed,
    world_params,
    noise_keys,
):
    """Run every episode ``e`` (genome ``genome[e]`` in maze ``maze[e]`` from ``start[e]``).

    Args:
        genome, maze: ``(E,)`` network and maze index of each episode.
        start: ``(E, 3)`` start poses ``(x m, y m, heading rad)``.
        n_cycles: episode length in control cycles.
        net: :class:`~offline_evolution.arbitrator.compiled.NetworkPack`.
        world: :class:`~offline_evolution.maze_task.world.MazePack`.
        sensors: :class:`~sim_bridge.sensors.CompiledLayout`.
        controller: :class:`~offline_evolution.maze_task.task.ControllerArrays`.
        lim: the robot's limits: :class:`~sim_bridge.four_ws_motion.MotionLimits` or
            :class:`~sim_bridge.diff_drive_motion.DiffLimits` (its state fits in
            ``STATE_SIZE`` columns, x, y and heading first).
        record: fill ``trace_pose (E, n_cycles + 1, 3)``, ``trace_choice (E, n_cycles)`` and
            ``trace_outputs (E, n_cycles, n_outputs)``; otherwise they may be 1-sized.
        perturbed: apply ``world_params (E, 4)`` (wheel speed gain, latency in cycles,
            reading noise sd, dropout probability) and ``noise_keys (E,)``; otherwise they
            may be 1-sized and are not read.

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
    n_outputs = net.n_outputs
    net_recurrent, net_slots = net.recurrent, net.n_slots
    # Fields the loop reads every cycle, as locals: numba does not hoist NamedTuple loads.
    boxes, targets, target_radius = world.boxes, world.targets, world.target_radius
    mode, map_kind, map_params = controller.mode, controller.map_kind, controller.map_params
    lookup_origin, lookup_cell = controller.lookup_origin, controller.lookup_cell
    lookup_table, primitive_commands = controller.lookup_table, controller.primitive_commands
    gene_matrix, command_scale = controller.gene_matrix, controller.command_scale
    wheel_radius = controller.speed_wheel_radius
    n_rangefinders = sensors.ray_angles.shape[0]
    window = sensors.motion_cycles  # 0: no motion input
    # Entries of a command: the robot's (4WS 5, differential drive 2).
    width = primitive_commands.shape[1] if mode == EVORBC else gene_matrix.shape[1]
    for e in nb.prange(n_ep):
        g = genome[e]
        m = maze[e]
        tx = targets[m, 0]
        ty = targets[m, 1]
        state[e, X] = start[e, 0]
        state[e, Y] = start[e, 1]
        state[e, HEADING] = start[e, 2]
        inputs = np.empty(sensors.n_inputs)
        values = np.empty(max_slots)
        # A recurrent network's state (activate_recurrent): 0 at the start of the episode.
        recurrent = net_recurrent[g]
        buffers = np.zeros((2, max_slots if recurrent else 1))
        out = np.empty(n_outputs)
        # 4WS: (speed m/s, 4 steering angles rad); a stop keeps the last angles, as the
        # executor does, which start at 0. Differential drive: (v m/s, omega rad/s).
        command = np.zeros(width)
        before = np.empty(STATE_SIZE)
        gain, latency, noise_sd, dropout, key = 1.0, 0, 0.0, 0.0, 0
        if perturbed:
            gain = world_params[e, 0]
            latency = int(world_params[e, 1])
            noise_sd = world_params[e, 2]
            dropout = world_params[e, 3]
            key = noise_keys[e]
        # Commands still on their way to the wheels (latency): a ring of the last ones,
        # starting as stops with the steering straight.
        pending = np.zeros((max(latency, 1), width))
        # The motion input's ring: position of cycle t in row t % (window + 1) (m).
        # (Rows past the episode's length are never written: a longer window reads p(0).)
        trail = np.empty((min(window, n_cycles) + 1, 2))
        still = 0  # cycles in a row whose step left the state unchanged
        initial_distance[e] = math.hypot(start[e, 0] - tx, start[e, 1] - ty)
        dist = initial_distance[e]
        for t in range(n_cycles):
            x = state[e, X]
            y = state[e, Y]
            h = state[e, HEADING]
            rx, ry = x, y
            if window > 0:
                trail[t % (window + 1), 0] = x
                trail[t % (window + 1), 1] = y
                ref = max(t - window, 0) % (window + 1)
                rx, ry = trail[ref, 0], trail[ref, 1]
            cand = _candidates(m, x, y, world)
            read_sensors(x, y, h, tx, ty, rx, ry, sensors, boxes, cand, inputs)
            if noise_sd > 0.0 or dropout > 0.0:
                _perturb_readings(inputs, n_rangefinders, noise_sd, dropout, key, t)
            if recurrent:
                activate_recurrent(g, inputs, buffers, t % 2, out, net)
            else:
                activate(g, inputs, values, out, net)
            choice = -1
            finite = True
            for k in range(n_outputs):
                finite = finite and math.isfinite(out[k])
            if mode == EVORBC and finite:
                px, py = map_point(map_kind, map_params, out[0], out[1])
                finite = math.isfinite(px) and math.isfinite(py)
                if finite:
                    choice = _lookup(px, py, lookup_origin, lookup_cell, lookup_table)
                    for c in range(width):
                        command[c] = primitive_commands[choice, c]
            elif finite:
                for c in range(width):
                    acc = 0.0
                    for k in range(n_outputs):
                        gene = 2.0 * min(max(out[k], 0.0), 1.0) - 1.0
                        acc += gene * gene_matrix[k, c]
                    command[c] = acc * command_scale[c]
            if finite and wheel_radius > 0.0:
                command[0] = speed_through_wheels(command[0], wheel_radius)
            if not finite:
                choice = NO_PRIMITIVE
                halt(command, lim)  # no primitive: stop
            if record:
                trace_pose[e, t, 0] = x
                trace_pose[e, t, 1] = y
                trace_pose[e, t, 2] = h
                trace_choice[e, t] = choice
                for k in range(n_outputs):
                    trace_outputs[e, t, k] = out[k]
            for k in range(STATE_SIZE):
                before[k] = state[e, k]
            if perturbed:
                # Every branch above set the speeds afresh this cycle. A wheel speed gain
                # scales the 4WS speed, and both v and omega of a differential drive
                # (every wheel turns faster by the same factor).
                command[0] *= gain
                if width == 2:
                    command[1] *= gain
            if latency > 0:
                # Apply the command of ``latency`` cycles ago and queue this one.
                slot = t % latency
                applied = pending[slot].copy()
                pending[slot, :] = command
                step_model(state, e, applied, lim, boxes, cand)
            else:
                step_model(state, e, command, lim, boxes, cand)
            dist = math.hypot(state[e, X] - tx, state[e, Y] - ty)
            if dist <= target_radius[m]:
                reached[e] = True
                cycles[e] = t + 1
                break
            if not record and not perturbed:
                # A fixed point: the whole state (pose, speed, wheel angles) came back
                # unchanged, so every later cycle reads the same sensors, gets the same
                # outputs from the network and makes the same step. A feed-forward network
                # is stateless; a recurrent one must also have written the values it read
                # (both buffers equal), so its next step repeats this one. A motion input
                # reads the same (0) only once the whole window, and the position this
                # cycle compared with, hold this position: more than ``window`` unchanged
                # steps in a row. The episode's outcome is already known: stop here.
                same = True
                for k in range(STATE_SIZE):
                    if state[e, k] != before[k]:
                        same = False
                        break
                still = still + 1 if same else 0
                if same and recurrent:
                    same = _same_state(buffers, net_slots[g])
                if same and still > window:
                    break
        final_distance[e] = dist
        end[e, 0] = state[e, X]
        end[e, 1] = state[e, Y]
        if record:
            last = cycles[e]
            trace_pose[e, last, 0] = state[e, X]
            trace_pose[e, last, 1] = state[e, Y]
            trace_pose[e, last, 2] = state[e, HEADING]
    return reached, cycles, final_distance, initial_distance, end
