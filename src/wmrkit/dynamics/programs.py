"""Inputs for the simulator: torque files and built-in programs (straight, turn, the paths of thesis §7.5.4).

A torque file is a CSV with a header ``time,<wheel>.<joint>,...``: times [s] strictly increasing from at most 0,
torques [N m] on actuated joints (``spin``, ``spin1``/``spin2``, ``steer``), linear between rows, the last row held;
a ``<wheel>.heading`` column [rad] is a steering-servo reference instead (the users' heading, 0 = straight ahead;
actuated steering only: a castor steers passively). A column may write its unit in brackets, as the other CSV files
of wmrkit do (:data:`TORQUE_FILE_UNITS`: ``time [s]``, ``<wheel>.spin [N m]``, ``<wheel>.heading [deg]``); the
set-points of one held linkage on its law at each row
(:func:`~wmrkit.dynamics.linkages.heading_breach`) and, between rows, the linkage's other columns set by its law
from its reference column's interpolation (:class:`~wmrkit.dynamics.inputs.Inputs`).

A built-in program (:func:`path_program`) is a schedule of body twists; each actuated wheel follows the no-slip
rate of its twist (wheel IK, §8.4) through a saturated rate servo and each actuated steering the IK heading
through a PD servo. The pose is not fed back: the robot slips and drifts as the tyres dictate, which is what a
slip study needs (the thesis's experiments 7.5.4: rectangle, corkscrew, D, figure eight, triple loop).
"""

from __future__ import annotations

import csv
import math
import os
from collections.abc import Sequence

import numpy as np
from numpy.typing import ArrayLike

from .._numbers import number_problem
from .._shapes import as_reals, readonly, real_number
from ..errors import ShapeError, WmrkitError
from ..limits import MAX_SIZE, MAX_SPEED, MAX_TORQUE, check_table_size
from ..units import BARE_ANGLE_LIMIT, UNITS, split_unit
from .inputs import Inputs, joint_column, knots
from .linkages import SETPOINT_TOL, first_breach, first_ik_breach, gear_breach, heading_breach, linkage_breach
from .model import DynamicModel

#: Natural frequency [rad/s] of the programs' servos (the default `bandwidth`): a fixed step longer than its
#: inverse cannot resolve them (``wmrkit simulate --path``).
BANDWIDTH = 30.0
#: Side slip [m/s] of a fixed wheel above which :func:`twist_program` calls a twist infeasible.
SLIP_TOL = 1e-6
#: Built-in programs: name -> segments (duration [s], forward speed factor, curvature [1/m] at speed 1).
PATHS: dict[str, tuple[tuple[float, float, float], ...]] = {
    "straight": ((1.0, 0.0, 0.0), (1.0, 1.0, 0.0)),
    "turn": ((1.0, 0.0, 0.0), (1.0, 1.0, 0.0), (1.0, 1.0, 1 / 3)),
    "rectangle": ((1.0, 0.0, 0.0), *((4.0, 1.0, 0.0), (2.356, 1.0, 1 / 3), (2.0, 1.0, 0.0), (2.356, 1.0, 1 / 3)) * 2),
    "corkscrew": ((1.0, 0.0, 0.0), (3.0, 1.0, 0.0), *((3.142, 1.0, 1 / 3), (1.5, 1.0, 0.0)) * 3),
    "d": ((1.0, 0.0, 0.0), (5.0, 1.0, 0.0), (2.356, 1.0, 1 / 3), (4.712, 1.0, 1 / 3), (2.356, 1.0, 1 / 3)),
    "figure-eight": ((1.0, 0.0, 0.0), (9.425, 1.0, 1 / 3), (9.425, 1.0, -1 / 3)),
    "triple-loop": ((1.0, 0.0, 0.0), (28.274, 1.0, 1 / 3)),
}


def path_program(model: DynamicModel, name: str, *, speed: float = 2.0, radius_scale: float = 1.0,
                 bandwidth: float = BANDWIDTH) -> tuple[Inputs, float]:
    """Inputs of the built-in program `name` (:data:`PATHS`) at `speed` [m/s]; returns ``(inputs, duration)``.

    Each segment holds a forward speed and a curvature (radius ``3 m x radius_scale`` in the turns); the first
    second ramps the speed up from 0. The durations are for ``speed = 2`` with ``radius_scale = 1`` (a 90 deg turn
    at radius 3 m takes 2.356 s) and scale with ``radius_scale / (speed / 2)``.
    """
    if name not in PATHS:
        raise WmrkitError(f"unknown program '{name}' (programs: {', '.join(PATHS)})")
    if not (real_number(speed) and 0 < speed <= MAX_SPEED):  # text raised "'<' not supported"
        got = f"{speed:g} m/s" if real_number(speed) else repr(speed)
        raise ShapeError(f"speed: expected a program speed in (0, {MAX_SPEED:g}] m/s, got {got}")
    if not (real_number(radius_scale) and 0 < radius_scale <= MAX_SIZE):
        raise ShapeError(f"radius_scale: expected a number in (0, {MAX_SIZE:g}], got {radius_scale!r}")
    scale = radius_scale * 2.0 / speed
    times, twists, t = [0.0], [(0.0, 0.0, 0.0)], 0.0
    for k, (duration, v, curvature) in enumerate(PATHS[name]):
        dt = duration if k == 0 else duration * scale
        twist = (speed * (1.0 if k == 0 else v), 0.0, speed * curvature / radius_scale)
        times += [t + min(0.2, dt / 4), t + dt] if k else [t + dt]
        twists += [twist, twist] if k else [twist]
        t += dt
    if not math.isfinite(t):  # its knots at inf s: twist_program refused them under the name 'time'
        raise ShapeError(f"speed: {speed:g} m/s: program '{name}' would never end (its segments last "
                          f"{radius_scale:g} x 2 m/s / speed times their durations at 2 m/s)")
    feasible = feasible_twists(model, np.array(twists))  # the slip left (a skid steer's turns) is the robot's
    return twist_program(model, np.array(times), feasible, bandwidth=bandwidth, allow_slip=True), t


def feasible_twists(model: DynamicModel, twists: ArrayLike) -> np.ndarray:
    """`twists` ``(K, 3)`` with ``vy`` replaced by the value that least-squares zeroes the fixed wheels' side slip.

    A robot with fixed wheels away from its origin (the forklift at its fork tips) must move sideways at the
    origin when it turns; programs give ``(v, 0, omega)`` and this makes them feasible (unchanged without fixed
    wheels: ``vy = 0``).
    """
    from ..kinematics.wheel_ik import wheel_commands

    twists = np.array(twists, dtype=float).reshape(-1, 3)
    at0 = wheel_commands(model.robot, twists * [1, 0, 1]).slip
    at1 = wheel_commands(model.robot, twists * [1, 0, 1] + [0, 1, 0]).slip
    slope = at1 - at0  # the side slip is affine in vy
    denom = np.sum(slope * slope, axis=-1)
    twists[:, 1] = np.where(denom > 0, -np.sum(slope * at0, axis=-1) / np.where(denom > 0, denom, 1), 0.0)
    return twists


def twist_program(model: DynamicModel, time: ArrayLike, twists: ArrayLike, *, bandwidth: float = BANDWIDTH,
                  allow_slip: bool = False) -> Inputs:
    """Servo inputs that make the actuated joints follow the no-slip joint motion of body `twists` ``(K, 3)``.

    A twist that has no no-slip motion (a fixed wheel would slip sideways by more than ``SLIP_TOL``: ``(v, 0,
    omega)`` for the forklift, whose origin is at the fork tips, or any turn of a skid steer) raises
    :class:`WmrkitError` naming the knot and the wheel; :func:`feasible_twists` gives the closest feasible twists,
    and ``allow_slip=True`` commands the wheels' rolling components and lets the tyres slip (skid steering). So is a
    twist that a ``gear`` coupling forbids (its joints out of its ratios: a solid axle turning); with ``allow_slip``
    each joint's servo follows its own rate and they fight through the gear, which holds; and one whose steering a
    ``linkage`` cannot set (:mod:`.linkages`; ``allow_slip``: the steering servos fight through it).
    Twists are finite, their speeds within ``limits.MAX_SPEED`` [m/s] and their turn rates within as many rad/s.

    Rate servos on actuated wheel joints (gain ``bandwidth x`` the wheel's reflected inertia, at least the grip
    torque per 0.1 rad/s, saturated at the grip ``mu Fz r`` with mu = 1); the joints of a ``differential`` coupling
    share one servo on their carrier rate, their torques in the coupling's ratios (an open differential: the speed
    difference is the tyres'); critically damped PD servos on actuated steering (natural frequency `bandwidth`
    [rad/s] on the inertia each one moves, :func:`steering_gains`), saturated (smoothly) where the tyres can hold
    the steering torque no more: ``mu Fz`` (mu = 1) at the contacts' distance from the steering axis (a double
    wheel's ``b``, a castor's ``d``; none for a steerable wheel, whose contact is on its axis). Without that limit
    a double wheel asked to steer 90 deg from rest got 9600 N m and lifted the robot off its wheels in a
    millisecond. A robot without an actuated joint is refused.
    """
    from ..kinematics.wheel_ik import wheel_commands

    t = knots(time)
    _check_bandwidth(bandwidth)
    twists = np.array(as_reals(twists, "twists"), dtype=float)  # a copy: the inputs keep it (read-only); no text
    if twists.size != 3 * len(t):
        raise ShapeError(f"twists: expected one (vx, vy, omega) per time, ({len(t)}, 3), got shape {twists.shape}")
    twists = twists.reshape(len(t), 3)
    bad = ~(np.abs(twists) <= MAX_SPEED).all(axis=1)  # NaN included
    if bad.any():
        k = int(np.argmax(bad))
        raise ShapeError(f"twist {tuple(float(v) for v in twists[k])} at t = {t[k]:g} s: expected finite speeds "
                          f"within {MAX_SPEED:g} m/s and a turn rate within {MAX_SPEED:g} rad/s")
    robot, n = model.robot, model.n
    if not robot.actuated:
        raise WmrkitError(f"robot '{robot.name}' has no actuated joint: no servo would drive it (it would not "
                          "move); list the motors in its wheels' 'actuated' field")
    cmd = wheel_commands(robot, twists, slip_tol=SLIP_TOL)
    rolls = np.all(np.abs(cmd.slip) <= SLIP_TOL, axis=-1)  # not cmd.feasible: a heading outside the steer_range
    if not allow_slip and not rolls.all():  # is held at the range's end by its servo
        k = int(np.argmin(rolls))
        w = int(np.argmax(np.abs(cmd.slip[k])))
        raise WmrkitError(f"twist {tuple(float(v) for v in twists[k])} at t = {t[k]:g} s has no no-slip motion for "
                          f"'{robot.name}': fixed wheel '{robot.wheel_names[w]}' would slip sideways at "
                          f"{abs(cmd.slip[k, w]):.3g} m/s; use feasible_twists(model, twists) for the closest "
                          "feasible motion, or allow_slip=True to let the tyres slip (skid steering)")
    geared = cmd.in_gear  # each departure's contact speed within SLIP_TOL too (gear_check)
    if not allow_slip and not geared.all():
        k, g = (int(i) for i in np.argwhere(~geared)[0])
        c = robot.couplings[g]
        raise WmrkitError(f"twist {tuple(float(v) for v in twists[k])} at t = {t[k]:g} s has no no-slip motion for "
                          f"'{robot.name}': it would turn {c.joints_words()} out of its ratios "
                          f"({', '.join(f'{r:g}' for r in c.ratios)}), which the gear holds together; use "
                          "allow_slip=True to let its servos fight and the tyres slip")
    headings = np.zeros((len(t), len(model.steer_columns)))
    steer_wheels = [w for w in robot.wheels if w.kind.steers]
    for k, w in enumerate(steer_wheels):
        h = cmd.heading[:, robot.wheel_names.index(w.name)]
        headings[:, k] = np.where(np.isfinite(h), h, w.heading)
    fight = _check_linkages(model, t, twists, headings, allow_slip)
    rates = np.zeros((len(t), n))
    rates[:, 3:3 + cmd.rates.shape[-1]] = np.nan_to_num(cmd.rates)
    gain, limit = np.zeros(n), np.full(n, np.inf)
    loads = model.normal_loads()
    m_total = model.body.mass + sum(w.mass for w in robot.wheels)
    driven = [c for c in range(3, n) if model.is_actuated(c) and ".steer" not in model.names[c]]
    for c in driven:
        w = robot.wheel(model.names[c].split(".")[0])
        reflected = w.spin_inertia + m_total * w.r ** 2 / max(len(driven), 1)
        contact = _contacts_of(model, w.name)
        limit[c] = max(loads[contact].max(), 1.0) * w.r
        gain[c] = max(bandwidth * reflected, limit[c] / 0.1)  # full grip torque at 0.1 rad/s of error at most
    group, ratio = model.pack[13], model.pack[14]
    for k in set(group[driven].tolist()) - {-1}:  # one motor through a differential: torques in the ratios
        members = [c for c in driven if group[c] == k]
        r = ratio[members] / ratio[members].mean()
        gain[members], limit[members] = r * gain[members].mean(), r * (limit[members] / r).min()
    servoed = [c for c in model.steer_columns if model.is_actuated(c)]
    kp, kd = steering_gains(model, servoed, held=driven, bandwidth=bandwidth)
    steer_limit = np.full(len(steer_wheels), np.inf)
    for k, (w, c) in enumerate(zip(steer_wheels, model.steer_columns, strict=True)):
        lever = math.hypot(w.d, w.b)  # the contacts' distance from the steering axis
        if c in servoed and lever > 0:
            contact = _contacts_of(model, w.name)
            steer_limit[k] = max(loads[contact].sum(), 1.0) * lever
    return Inputs(*(readonly(a) for a in (t, np.zeros((len(t), n)), rates, gain, limit, headings, kp, kd,
                                          steer_limit, twists, t.copy())), fight_linkages=fight)


def _check_linkages(model: DynamicModel, t: np.ndarray, twists: np.ndarray, headings: np.ndarray,
                    allow_slip: bool) -> bool:
    """Refuse (unless `allow_slip`) the first knot whose IK `headings` ``(K, n_steer)`` break a ``linkage`` the
    dynamics hold (:mod:`.linkages`: a synchro chain asked to turn its wheels apart), or the ratios of a ``gear``
    between servoed steering joints (:func:`~.linkages.gear_breach`: two units geared 1:2 asked to crab), naming
    it; whether one does (with `allow_slip`: the servos fight through it, ``Inputs.fight_linkages``). Every knot at
    once (:func:`~.linkages.first_ik_breach`), the message from the first one that breaks one."""
    if not len(model.pack[17]) and not model.pack[16].shape[1]:
        return False
    servoed = {k for k, c in enumerate(model.steer_columns) if model.is_actuated(c)}
    k = first_ik_breach(model, headings, servoed)  # every knot at once
    if k is None or allow_slip:
        return k is not None
    geared = gear_breach(model, headings[k], servoed)
    if geared:
        j, ref, want, gear = geared
        steered = model.robot.steer_names
        raise WmrkitError(f"twist {tuple(float(v) for v in twists[k])} at t = {t[k]:g} s has no no-slip motion "
                          f"for '{model.robot.name}': its wheels' steering breaks the ratios of {gear.words()} "
                          f"(it sets {steered[j]} at heading {want:.6g} rad with {steered[ref]}'s at "
                          f"{headings[k, ref]:.6g} rad, the wheel IK {headings[k, j]:.6g} rad), which the "
                          "dynamics hold; use allow_slip=True to let its servos fight and the tyres slip")
    breach = linkage_breach(model, model.robot.beta_of_heading(headings[k]))
    raise WmrkitError(f"twist {tuple(float(v) for v in twists[k])} at t = {t[k]:g} s has no no-slip motion "
                      f"for '{model.robot.name}': its wheels' steering breaks a linkage ({breach}), which "
                      "the dynamics hold; use allow_slip=True to let its servos fight and the tyres slip")


def _check_bandwidth(bandwidth: float) -> None:
    if not (real_number(bandwidth) and bandwidth > 0):  # text raised math's TypeError
        raise ShapeError(f"bandwidth: expected a natural frequency > 0 rad/s, got {bandwidth}")


def _contacts_of(model: DynamicModel, wheel: str) -> list[int]:
    """Indices in ``model.contacts`` of `wheel`'s contact points (``wheel`` or ``wheel.1``, ``wheel.2``)."""
    return [e for e, name in enumerate(model.contacts) if name.split(".")[0] == wheel]


def steering_gains(model: DynamicModel, servoed: Sequence[int], *, held: Sequence[int] = (),
                   bandwidth: float = BANDWIDTH) -> tuple[np.ndarray, np.ndarray]:
    """Gains ``(kp, kd)`` ``(n_steer,)`` of critically damped PD steering servos of natural frequency `bandwidth`
    [rad/s] on the steering columns `servoed` (0 elsewhere): ``kp = J w^2``, ``kd = 2 J w`` with ``J`` the
    inertia each servo moves (:meth:`DynamicModel.steering_inertia`) while the servoed joints and the columns
    `held` (wheel-rate servos) keep still. A double wheel whose spins are servoed turns the whole body about its
    pivot: its own ``inertia.steer`` would leave that servo some 100 times too soft (damping ratio near 0.1).

    The servoed steering joints of one ``linkage`` (or one ``gear``: castors', double wheels' steering) act as one
    servo on it: their gains, each in proportion to its own wheel's inertia, sum through the law's slopes (the
    gear's ratios) to ``J w^2`` and ``2 J w``, ``J`` the linkage's (gear's) reflected inertia with the other joints
    held (two servos of a synchro drive's four wheels, each tuned on its own wheel, gave ``w / sqrt 2`` and damping
    ratio 0.71: a 4.3 % overshoot; two double wheels' steering geared 1:2, ``0.905 w`` and 0.90).
    """
    kp, kd = np.zeros(len(model.steer_columns)), np.zeros(len(model.steer_columns))
    if not set(servoed) <= set(model.steer_columns):
        raise ShapeError(f"servoed: expected steering columns of model.names {list(model.steer_columns)}, got "
                          f"{list(servoed)}")
    _check_bandwidth(bandwidth)
    if not servoed:
        return kp, kd
    inertia = np.array(model.steering_inertia([*servoed, *held]))
    columns = list(model.steer_columns)
    t = model._basis(model.robot.beta)[0]  # the motions the couplings allow: nu = T p
    for p in range(t.shape[1]):  # each motion: a held linkage (its leader's), a gear, or one joint
        together = [j for j in servoed if t[j, p] != 0]  # (a follower of slope 0 stays, here)
        if len(together) < 2:  # one servo: tuned on the linkage or gear above (the others do not hold it)
            continue
        slope = t[together, p]  # each joint's rate per unit rate of the leader
        ks = [columns.index(j) for j in together]
        moved = model.steering_inertia([j for j in [*servoed, *held] if j not in together])[ks[0]] * slope[0] ** 2
        inertia[ks] *= moved / float(slope ** 2 @ inertia[ks])  # sum slope^2 kp = moved w^2
    on = np.isin(model.steer_columns, servoed)
    kp[on] = inertia[on] * bandwidth ** 2
    kd[on] = 2 * inertia[on] * bandwidth
    return kp, kd


def _check_radians(source: str, column: str, headings: np.ndarray) -> None:
    """A heading column [rad] stays within a turn, as a bare angle anywhere else (``units.parse_quantity``)."""
    beyond = np.flatnonzero(np.abs(headings) > BARE_ANGLE_LIMIT)
    if beyond.size:
        h = headings[beyond[0]]
        raise WmrkitError(f"{source}:{beyond[0] + 2}: column '{column}': a heading is read in radians, and {h:g} rad "
                          f"is more than a turn; degrees? {h:g} deg = {math.radians(h):.6g} rad")


def _check_torques(source: str, column: str, torques: np.ndarray) -> None:
    """A torque column [N m] stays within :data:`~wmrkit.limits.MAX_TORQUE`."""
    beyond = np.flatnonzero(np.abs(torques) > MAX_TORQUE)
    if beyond.size:
        raise WmrkitError(f"{source}:{beyond[0] + 2}: column '{column}': {torques[beyond[0]]:.8g} N m is beyond the "
                          f"largest torque wmrkit applies, {MAX_TORQUE:g} N m (docs/limits.md)")


def _check_setpoints(source: str, model: DynamicModel, href: np.ndarray, commanded: list[int]) -> None:
    """Refuse the first row whose heading set-points `href` ``(K, n_steer)`` break a linkage or a steering gear the
    dynamics hold (:func:`~wmrkit.dynamics.linkages.first_breach`, every row at once; its
    :func:`~wmrkit.dynamics.linkages.heading_breach`): their servos would fight it, naming the two columns."""
    if not len(model.pack[17]) and not model.pack[16].shape[1]:
        return
    steered, k = model.robot.steer_names, first_breach(model, href, set(commanded))
    breach = None if k is None else heading_breach(model, href[k], set(commanded))
    if breach is not None:
        j, ref, want, c = breach
        by = "whatever the others do" if ref is None else (f"with column '{steered[ref]}.heading' at "
                                                        f"{href[k, ref]:.6g} rad")
        kind = c.kind
        raise WmrkitError(f"{source}:{k + 2}: column '{steered[j]}.heading': {href[k, j]:.6g} rad breaks {c.words()}, "
                          f"which sets {steered[j]} at heading {want:.6g} rad {by}: the steering servos would fight "
                          f"the {kind} the dynamics hold; give headings on its "
                          f"{'law' if kind == 'linkage' else 'ratios'} (within {SETPOINT_TOL:g} rad) or one heading "
                          f"column per {kind} (docs/dynamics.md)")


#: The units a torque file's header may write in brackets, per column, with their factor to SI ('time [s]' was
#: refused as "expected a header 'time,<wheel>.<joint>,...'").
TORQUE_FILE_UNITS = {"time": {"s": 1.0}, "heading": {"rad": 1.0, "deg": UNITS["angle"]["deg"]},
                     "torque": {"N m": 1.0, "Nm": 1.0, "N*m": 1.0}}


def _header_unit(source: str, column: str) -> tuple[str, float]:
    """A torque file's `column` without its bracketed unit (:func:`~wmrkit.units.split_unit`), and that unit's factor
    to SI (1 without one); a unit the column does not take (``time [ms]``, a ``--out`` file's ``spin [rad]``) is
    refused naming both."""
    parts = split_unit(column)
    if parts is None:
        return column, 1.0
    name, unit = parts
    kind = "time" if name == "time" else "heading" if name.endswith(".heading") else "torque"
    units = TORQUE_FILE_UNITS[kind]
    if unit not in units:
        what = {"time": "the time", "heading": "a heading", "torque": "a torque (any column but time and headings)"}
        raise WmrkitError(f"{source}:1: column '{column}': {what[kind]} is read in "
                          f"{' or '.join(f'[{u}]' for u in units)} in a torque file")
    return name, units[unit]


def read_torques(model: DynamicModel, path: str | os.PathLike[str]) -> Inputs:
    """:class:`Inputs` from a torque CSV (module docstring); errors name the file, the line and the column."""
    source = str(path)
    check_table_size(path, WmrkitError, "torque file")
    try:
        with open(path, newline="", encoding="utf-8-sig") as fh:  # a byte-order mark is not part of 'time'
            rows = list(csv.reader(fh))
    except (OSError, UnicodeDecodeError) as err:
        raise WmrkitError(f"{source}: cannot read the file ({err.__class__.__name__})") from None
    named = [_header_unit(source, h.strip()) for h in (rows[0] if rows else ())]
    header, scale = [h for h, _ in named], [k for _, k in named]
    if not header or header[0] != "time" or len(rows) < 2:
        raise WmrkitError(f"{source}:1: expected a header 'time,<wheel>.<joint>,...' and at least one row")
    twice = next((h for i, h in enumerate(header) if h in header[:i]), None)
    if twice is not None:
        raise WmrkitError(f"{source}:1: column '{twice}' given twice")
    values = np.zeros((len(rows) - 1, len(header)))
    for i, row in enumerate(rows[1:], start=2):
        if len(row) != len(header):
            raise WmrkitError(f"{source}:{i}: {len(row)} values for {len(header)} columns")
        for j, cell in enumerate(row):
            problem = number_problem(cell)
            if problem is not None:
                raise WmrkitError(f"{source}:{i}: column '{header[j]}': {problem}")
            values[i - 2, j] = float(cell) * scale[j]
    if np.any(np.diff(values[:, 0]) <= 0):
        raise WmrkitError(f"{source}: times must be strictly increasing")
    if values[0, 0] > 0:  # held before the first row, the first torques would act from t = 0
        raise WmrkitError(f"{source}:2: the first row is at t = {values[0, 0]:g} s; the torques start at t = 0 (add a "
                          "row at time 0, or subtract the first time)")
    torques, headings = {}, {}
    for j, name in enumerate(header[1:], start=1):
        wheel, _, joint = name.partition(".")
        if joint == "heading":
            _check_radians(source, name, values[:, j])
        else:
            _check_torques(source, name, values[:, j])
        try:
            if joint == "heading":
                steered = model.robot.steer_names
                if wheel not in steered:
                    raise WmrkitError(f"robot '{model.robot.name}' has no steered wheel '{wheel}' (a heading column "
                                      f"is a steering reference; steered wheels: {', '.join(steered) or 'none'})")
                column = model.steer_columns[steered.index(wheel)]
                if not model.is_actuated(column):
                    raise WmrkitError(f"the steering of wheel '{wheel}' is not actuated (it steers passively, as the "
                                      f"tyres turn it): no servo can follow a heading (actuated: "
                                      f"{', '.join(model.robot.actuated) or 'none'})")
                headings[column] = values[:, j]
            else:
                torques[name] = values[:, j]
                joint_column(model, name)
        except (WmrkitError, ValueError) as err:
            raise WmrkitError(f"{source}:1: column '{name}': {err}") from None
    t = values[:, 0]
    if not headings:
        return Inputs.torques_only(model, t, torques)
    href = np.tile(model.robot.heading, (len(values), 1))
    for k, c in enumerate(model.steer_columns):
        if c in headings:
            href[:, k] = headings[c]
    _check_setpoints(source, model, href, [k for k, c in enumerate(model.steer_columns) if c in headings])
    inputs = Inputs.torques_only(model, t, torques)  # between rows, the linkages' followers on their laws (Inputs)
    kp, kd = steering_gains(model, list(headings))
    return Inputs(inputs.time, inputs.torques, inputs.rate_reference, inputs.rate_gain, inputs.torque_limit,
                  readonly(href), readonly(kp), readonly(kd))
