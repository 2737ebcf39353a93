"""Single-call kinematics for a controller's tick: per-wheel IK, FK and one odometry step, compiled per robot.

The batched functions (:func:`~wmrkit.kinematics.wheel_ik.wheel_commands`, :func:`~wmrkit.kinematics.wheel_ik.
forward_kinematics`, :func:`wmrkit.odometry.odometry`) are made for arrays of twists and samples; one call on one
twist pays tens of microseconds of NumPy overhead. :func:`realtime` compiles, once per robot, a numba kernel with the
robot's geometry frozen in as constants, cached on disk (numba keys it by those constants: another robot's is
another kernel), so that a later process loads it instead of compiling it again (seconds). Each call then takes
scalars and caller-owned arrays and writes its results into them: no Python objects are created per call (the ik of
a robot with a held linkage allocates two small arrays, its steering axes' speeds and the wheels it turns onto the
root their linkage sets). The
numbers are those of the batched path (same formulas: the three wheel groups of ``_ik_fast`` (§8.4), the sensed
direct model (4.11) of :func:`wmrkit.odometry.odometry_model`, the exact SE(2) step of paper 003 with the same
inlined sine and cosine). ``benchmarks/bench_realtime.py`` times them
against WPILib per call.

Steering angles at this door are headings (0 = rolling straight ahead), as everywhere a user types or reads one.
FK and the odometry step are compiled for robots whose sensed model does not depend on steering angles (differential,
skid-steer, Mecanum, omni, ...); for robots that steer they evaluate the model's matrices at the given headings per
call (correct, slower).
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from .. import _jit
from .._jit import compile_cached, drop_oversized_cache, drop_stale_cache, float64_vector
from .._shapes import as_names
from ..errors import SelectionError, WmrkitError
from ..limits import MAX_QUERY_RATE
from ..odometry import _kernels
from ..odometry._kernels import _cos_sin, _sinc
from ..robot import Robot
from ..units import MAX_ANGLE, MAX_TURNS
from . import _gear_kernel, _ik_fast, _linkage_kernel, gear_check, linkage_check, linkage_law
from ._gear_kernel import steer_breach, steer_roots
from ._linkage_kernel import _breach_at, _reference, _roots_at
from ._linkage_kernel import in_range_at as _in_range
from .gear_check import GEAR_RTOL, gear_table, steer_gears
from .linkage_law import LINKAGE_TOL
from .wheel_ik import SLIP_TOL, check_tolerances

#: Most bytes of compiled kernels cached for this file (one set per robot, about 0.2 MB: some 150 robots); beyond, the
#: cache is dropped at import (:func:`~wmrkit._jit.drop_oversized_cache`).
MAX_CACHE_BYTES = 32 << 20

drop_stale_cache([__file__], [_kernels.__file__, _jit.__file__, _linkage_kernel.__file__, linkage_check.__file__,
                              linkage_law.__file__, _gear_kernel.__file__, gear_check.__file__])
drop_oversized_cache(__file__, MAX_CACHE_BYTES)

HALF_PI = 0.5 * math.pi
OVERFLOW = ("odometry_step: the step overflows (joint positions too far from the previous ones); the pose and "
            "previous are unchanged")


@dataclass(frozen=True, eq=False)
class Realtime:
    """Compiled single-call kinematics of one robot (build with :func:`realtime`). Arrays are caller-owned.

    - ``ik(vx, vy, omega, heading, rates_out, heading_out) -> bool``: per-wheel IK of one twist. `heading`
      ``(n_steer,)`` the current headings [rad]; writes the joint rates ``(n_rates,)`` (``robot.rate_names``) and
      the new headings; returns whether the twist is feasible (no fixed wheel slips beyond 1e-9 m/s, every heading
      within its wheel's ``steer_range``, every gear coupling's rates in its ratios and a steering gear's angles
      too, every held linkage's angles on its law), as ``wheel_commands``.
    - ``fk(rates, heading, twist_out)``: the twist ``(3,)`` from the sensed joint rates ``(n_a,)`` (``rate_joints``)
      by the least squares (4.11), at headings ``(n_steer_sensed,)`` of ``steer_joints`` (ignored when constant).
    - ``odometry_step(pose, previous, positions, heading_mid)``: one exact SE(2) step; `pose` ``(3,)`` is updated
      in place from the joint positions ``(n_a,)`` (``rate_joints``; any real dtype or a list, cast to float64 at
      the door: one compiled kernel serves them all) and `previous` (updated to `positions`).
    """

    robot: Robot
    rate_joints: tuple[str, ...]
    steer_joints: tuple[str, ...]
    constant: bool
    ik: Any
    fk: Any
    odometry_step: Any


@functools.lru_cache(maxsize=16)
def realtime(robot: Robot, sensed: tuple[str, ...] | None = None, *, speed_tol: float = 1e-12,
             slip_tol: float = SLIP_TOL) -> Realtime:
    """The single-call kinematics of `robot`, compiled at their first call (seconds, once per robot: cached on disk,
    a later process loads them in about half a second; :data:`MAX_CACHE_BYTES`); `sensed` as for the odometry
    model."""
    from ..odometry.model import odometry_model

    check_tolerances(speed_tol, slip_tol)
    if sensed is not None:  # a wrong argument is refused here, not kept as the FK's refusal (a lone string was)
        sensed = as_names(sensed, "sensed", "'wheel.joint' names", SelectionError)
    p = _ik_fast.plan(robot)
    ik = _ik_kernel(p, robot, speed_tol, slip_tol)
    try:
        model = odometry_model(robot, sensed)
    except WmrkitError as err:  # the sensors do not give the motion: the IK still works, FK and odometry cannot
        refuse = _refusal(err)
        return Realtime(robot, (), (), False, ik, refuse, refuse)
    if model.constant:
        twist_map = np.ascontiguousarray(model.solution[:3], dtype=float)
        fk = _constant_fk(twist_map)
        step = _constant_step(twist_map)
    else:
        fk, step = _steering_fk_and_step(model)
    return Realtime(robot, model.rate_joints, model.steer_joints, model.constant, ik, fk, step)


def _refusal(err: Exception):
    def refuse(*_args):
        raise type(err)(str(err))

    return refuse


def _ik_kernel(p: _ik_fast.Plan, robot: Robot, speed_tol: float, slip_tol: float):
    """The IK of ``wheel_commands`` for one twist, with the plan's arrays frozen in as constants."""
    n_rates, n_steer = p.n_rates, p.n_steer
    constant = np.ascontiguousarray(p.constant_rates, dtype=float) if p.has_constant else np.zeros((3, n_rates))
    lateral = np.ascontiguousarray(p.fixed_lateral, dtype=float)
    roundoff = np.ascontiguousarray(p.fixed_roundoff, dtype=float)
    n_fixed = lateral.shape[1]
    steered_beta, sx, sy = p.steered_beta.copy(), p.steered_x.copy(), p.steered_y.copy()
    n_o = len(sx)
    spin_col, inv_r = np.full(n_o, -1), np.zeros(n_o)  # per twist-steered wheel: its spin column (-1: a double)
    spin_col[p.steered_spin_of], inv_r[p.steered_spin_of] = p.steered_spin_col, p.steered_inv_r
    e_beta, e_castor = p.element_beta.copy(), p.element_castor.copy()
    e_steer, e_spin = p.element_steer_col.copy(), p.element_spin_col.copy()
    offset, el, ealpha, ed, edelta, egamma, er, _ = (a.copy() for a in p.element_params)
    n_e = len(e_beta)
    delta = np.array([w.delta for w in robot.wheels if w.kind.steers], dtype=float)
    ranges = (p.steer_range[:, p.steer_wheels] if p.steer_range is not None
              else np.array([[-np.inf], [np.inf]]).repeat(n_steer, axis=1))
    ranged = np.isfinite(ranges).all(axis=0)  # (n_steer,): the wheels with a steer_range (heading lo, hi)
    lo, width = np.where(ranged, ranges[0], 0.0), np.where(ranged, ranges[1] - ranges[0], 0.0)
    shapes = (f"ik: heading and heading_out must be float64 arrays of shape ({n_steer},) (robot.steer_names) and "
              f"rates_out one of shape ({n_rates},) (robot.rate_names)")
    limit = MAX_QUERY_RATE
    too_big = f"ik: the twist (vx, vy, omega) must be finite, each at most {limit:g} in size"
    bad_heading = f"ik: the headings must be finite, at most {MAX_TURNS:g} turns [rad]"
    max_angle = MAX_ANGLE  # wheel_commands' bound (as_angles): beyond, the wrapped angle is round-off
    gears = gear_table(robot, robot.rate_names)  # wheel_commands' in_gear (gear_check.gears_hold), flattened
    gear_cols, gear_k, gear_lever, gear_start = gears.joint, gears.ratio, gears.lever, gears.start
    n_gears, gear_rtol = len(gears.coupling), GEAR_RTOL
    links = linkage_check._plan(robot)  # wheel_commands' in_linkage (linkage_check.linkage_holds), its judge compiled
    link_table, link_start, link_lead, link_x, link_y = links.table, links.start, links.lead, links.x, links.y
    link_lo, link_width, link_offset = links.lo, links.width, links.offset
    n_links, link_tol = len(links.lead), LINKAGE_TOL
    sg = steer_gears(robot)  # wheel_commands' in_steer_gear (gear_check.steer_breach, compiled)
    sg_joint, sg_k, sg_start, sg_rest, sg_x, sg_y = (sg.table.joint, sg.table.ratio, sg.table.start, sg.rest, sg.x,
                                                     sg.y)
    sg_rows, sg_turns, n_sgears = sg.rows, sg.turns, len(sg.table.coupling)
    coupled = n_links > 0 or n_sgears > 0  # the axes' speeds and the wheels whose root ik chose are needed

    def ik(vx, vy, w, heading, rates_out, heading_out):
        if not (float64_vector(rates_out) and float64_vector(heading_out) and heading.shape[0] == n_steer
                and heading_out.shape[0] == n_steer and rates_out.shape[0] == n_rates):
            raise ValueError(shapes)  # written past their ends otherwise
        if not (abs(vx) <= limit and abs(vy) <= limit and abs(w) <= limit):  # NaN included
            raise ValueError(too_big)
        for k in range(n_steer):
            if not abs(heading[k]) <= max_angle:  # NaN included
                raise ValueError(bad_heading)
        beta = heading_out  # the thesis's angles while computing, headings on return: nothing is allocated
        for k in range(n_steer):
            beta[k] = _wrap(heading[k] - delta[k] + HALF_PI)
        for j in range(n_rates):
            rates_out[j] = vx * constant[0, j] + vy * constant[1, j] + w * constant[2, j]
        free = np.zeros(n_steer if coupled else 0, dtype=np.bool_)  # the wheels whose root ik chose: moving
        for i in range(n_o):  # (8.9), (8.12): the steering axis's velocity u, the closer of b and b + pi
            k = steered_beta[i]
            minus_ux = sy[i] * w - vx
            uy = sx[i] * w + vy
            speed = math.sqrt(minus_ux * minus_ux + uy * uy)
            along = minus_ux * math.sin(beta[k]) + uy * math.cos(beta[k])
            sign = -1.0 if abs(along) <= 1e-12 * speed else math.copysign(1.0, along)  # a tie: rolling forward
            moving = speed > speed_tol
            if coupled:
                free[k] = moving
            if moving:
                beta[k] = math.atan2(minus_ux * sign + 0.0, uy * sign)
                h = beta[k] + (delta[k] - HALF_PI)
                if ranged[k] and not _in_range(h, lo[k], width[k]) and _in_range(h + math.pi, lo[k], width[k]):
                    beta[k] = _wrap(beta[k] + math.pi)  # the other root is within the steer_range: take it
                    sign = -sign
            if spin_col[i] >= 0:
                rates_out[spin_col[i]] = -speed * sign * inv_r[i] if moving else 0.0
        linked = True
        axis_speed = np.empty(n_steer if coupled else 0)
        turn = np.zeros(n_steer if coupled else 0, dtype=np.bool_)
        for k in range(n_steer if coupled else 0):  # the axes' speeds (linkage_check._speeds)
            axis_speed[k] = math.hypot(vx - w * link_y[k], vy + w * link_x[k])
        if n_links:  # each linkage's reference found once: its wheels on the roots it sets, then its law judged
            for g in range(n_links):
                first, last, lead = link_start[g], link_start[g + 1], link_lead[g]
                ref, b = _reference(link_table, first, last, lead, beta, axis_speed)
                if ref < 0:  # no axis moves: nothing to set or break
                    continue
                _roots_at(link_table, first, last, lead, beta, b, math.pi, free, link_lo, link_width, link_offset, turn)
                _turn_half_round(steered_beta, spin_col, turn, beta, rates_out)
                breach = _breach_at(link_table, first, last, lead, beta, axis_speed, True, slip_tol, link_tol, ref, b)
                linked = linked and breach[0] < 0
        if n_sgears:  # each gear between steering joints: its wheels on the roots it sets (judged below)
            for g in range(n_sgears):
                steer_roots(sg_joint, sg_k, sg_start[g], sg_start[g + 1], sg_rest, sg_x, sg_y, vx, vy, w, sg_rows,
                            sg_turns, beta, axis_speed, slip_tol, link_tol, free, link_lo, link_width, link_offset,
                            turn)
                _turn_half_round(steered_beta, spin_col, turn, beta, rates_out)
        for e in range(n_e):  # castor-like elements at the (new) angle: rows (3.10), (8.24), (8.25)
            theta = beta[e_beta[e]] + offset[e] + edelta[e] + egamma[e]
            c, s = math.cos(theta), math.sin(theta)
            cdg, sdg = math.cos(edelta[e] + egamma[e]), math.sin(edelta[e] + egamma[e])
            lat = vx * c + vy * s + w * (el[e] * math.sin(theta - ealpha[e]) - ed[e] * cdg)
            roll = -vx * s + vy * c + w * (el[e] * math.cos(theta - ealpha[e]) + ed[e] * sdg)
            beta_dot = -lat / (-ed[e] * cdg) if e_castor[e] else 0.0
            rates_out[e_steer[e]] = beta_dot
            rates_out[e_spin[e]] = -(roll + ed[e] * sdg * beta_dot) / (er[e] * math.cos(egamma[e]))
        feasible = linked
        for f in range(n_fixed):
            slip = vx * lateral[0, f] + vy * lateral[1, f] + w * lateral[2, f]
            if abs(slip) > slip_tol and abs(slip) > (abs(vx) * roundoff[0, f] + abs(vy) * roundoff[1, f]
                                                     + abs(w) * roundoff[2, f]):  # not round-off (wheel_commands)
                feasible = False
        for g in range(n_sgears if feasible else 0):  # a gear between steering joints sets their angles too
            if steer_breach(sg_joint, sg_k, sg_start[g], sg_start[g + 1], sg_rest, sg_x, sg_y, vx, vy, w, beta,
                            slip_tol, link_tol)[0] >= 0:
                feasible = False
        for k in range(n_steer):
            beta[k] = _wrap(beta[k] + delta[k] - HALF_PI)
            if ranged[k] and not _in_range(beta[k], lo[k], width[k]):
                feasible = False
        largest = 0.0
        for j in range(n_rates if n_gears else 0):  # robots without gears skip this (the one-call path's cost)
            largest = max(largest, abs(rates_out[j]))
        for g in range(n_gears):  # a gear turns its joints as q_j = k_j u (gear_check.gears_hold)
            kq, kk = 0.0, 0.0
            for t in range(gear_start[g], gear_start[g + 1]):
                kq += gear_k[t] * rates_out[gear_cols[t]]
                kk += gear_k[t] * gear_k[t]
            relative, absolute = True, True  # round-off of the rates, or the slip floor at the contacts
            for t in range(gear_start[g], gear_start[g + 1]):
                e = abs(rates_out[gear_cols[t]] - gear_k[t] * (kq / kk))
                relative = relative and e <= gear_rtol * largest
                absolute = absolute and e * gear_lever[t] <= slip_tol
            if not (relative or absolute):
                feasible = False
        return feasible

    return compile_cached(ik)


@compile_cached
def _turn_half_round(steered_beta, spin_col, turn, beta, rates_out):
    """Each steered wheel whose root a linkage or gear set half a turn from its own (`turn`, by ``beta`` index):
    its angle turned by pi, its spin (column `spin_col`, -1: none) negated; `turn` cleared."""
    for i in range(steered_beta.shape[0]):
        k = steered_beta[i]
        if turn[k]:
            beta[k] = _wrap(beta[k] + math.pi)
            if spin_col[i] >= 0:
                rates_out[spin_col[i]] = -rates_out[spin_col[i]]
        turn[k] = False


@compile_cached
def _wrap(a):
    """The angle `a` [rad] wrapped into (-pi, pi]."""
    two_pi = 2.0 * math.pi
    y = a - two_pi * np.round(a / two_pi)
    if y <= -math.pi:
        return y + two_pi
    if y > math.pi:
        return y - two_pi
    return y


def _constant_fk(twist_map: np.ndarray):
    n_a = twist_map.shape[1]
    shapes = f"fk: rates must have shape ({n_a},) (rate_joints) and twist_out be a float64 array of shape (3,)"
    bad = f"fk: the rates must be finite, each at most {MAX_QUERY_RATE:g} in size [rad/s]"
    limit = MAX_QUERY_RATE

    def fk(rates, heading, twist_out):
        if not (float64_vector(twist_out) and twist_out.shape[0] == 3 and rates.shape[0] == n_a):
            raise ValueError(shapes)
        for j in range(n_a):
            if not abs(rates[j]) <= limit:
                raise ValueError(bad)
        for r in range(3):
            acc = 0.0
            for j in range(n_a):
                acc += twist_map[r, j] * rates[j]
            twist_out[r] = acc

    return compile_cached(fk)


def _constant_step(twist_map: np.ndarray):
    n_a = twist_map.shape[1]
    shapes = (f"odometry_step: pose must be a float64 array of shape (3,), previous one of shape ({n_a},) "
              f"(rate_joints) and positions of shape ({n_a},)")
    bad = "odometry_step: the pose and the joint positions must be finite"
    overflow = OVERFLOW

    def step(pose, previous, positions):
        if not (float64_vector(pose) and float64_vector(previous) and pose.shape[0] == 3
                and previous.shape[0] == n_a and positions.shape[0] == n_a):
            raise ValueError(shapes)
        for j in range(n_a):
            if not (math.isfinite(positions[j]) and math.isfinite(previous[j])):
                raise ValueError(bad)
        if not (math.isfinite(pose[0]) and math.isfinite(pose[1]) and math.isfinite(pose[2])):
            raise ValueError(bad)
        if not _step(pose, previous, positions, twist_map):
            raise ValueError(overflow)

    kernel, ndarray, float64 = compile_cached(step), np.ndarray, np.dtype(float)

    def odometry_step(pose, previous, positions, heading_mid):
        """The door of the compiled `kernel`: positions cast to a float64 vector (integer counts, float32, a list)
        and `heading_mid` (constant model) not passed, so that one compiled specialisation serves every caller."""
        if positions.__class__ is not ndarray or positions.dtype is not float64:
            positions = np.asarray(positions, dtype=float)
        if pose.__class__ is not ndarray or previous.__class__ is not ndarray or positions.ndim != 1:
            raise ValueError(shapes)  # (a list or a 2-D array was numba's TypingError)
        kernel(pose, previous, positions)

    odometry_step.kernel = kernel  # type: ignore[attr-defined]
    return odometry_step


@compile_cached
def _step(pose, previous, positions, twist_map):
    """One exact SE(2) step (paper 003 (21)-(25)): body increments ``twist_map @ dq``, chord ``sinc(h)`` along the
    mid heading, with the odometry kernels' own sine and cosine (the batched path's numbers). Returns False, and
    writes nothing, when the new pose would not be finite (positions too far apart to subtract)."""
    d0 = d1 = d2 = 0.0
    for j in range(positions.shape[0]):
        dq = positions[j] - previous[j]
        d0 += twist_map[0, j] * dq
        d1 += twist_map[1, j] * dq
        d2 += twist_map[2, j] * dq
    h = 0.5 * d2
    f = _sinc(h)
    c, s = _cos_sin(pose[2] + h)
    x, y, theta = pose[0] + f * (c * d0 - s * d1), pose[1] + f * (s * d0 + c * d1), pose[2] + d2
    if not (math.isfinite(x) and math.isfinite(y) and math.isfinite(theta)):
        return False
    for j in range(positions.shape[0]):
        previous[j] = positions[j]
    pose[0], pose[1], pose[2] = x, y, theta
    return True


def _steering_fk_and_step(model):
    """Robots whose sensed model depends on steering: the model's matrices at the headings, per call."""
    robot = model.robot
    delta = np.array([robot.wheel(j.partition(".")[0]).delta for j in model.steer_joints], dtype=float)

    n_a, n_s = len(model.rate_joints), len(delta)

    def twist_map(heading, name: str) -> np.ndarray:
        heading = np.asarray(heading, dtype=float)
        if heading.shape != (n_s,) or not (np.abs(heading) <= MAX_ANGLE).all():  # NaN included
            raise ValueError(f"{name}: the headings must be a finite array of shape ({n_s},), at most {MAX_TURNS:g} "
                             "turns [rad] (steer_joints)")
        s, _ = model.matrices(heading - delta + HALF_PI)
        return np.ascontiguousarray(s[:3])

    def fk(rates, heading, twist_out):
        rates = np.asarray(rates, dtype=float)
        if rates.shape != (n_a,) or not float64_vector(twist_out) or np.shape(twist_out) != (3,):
            raise ValueError(f"fk: rates must have shape ({n_a},) (rate_joints) and twist_out be a float64 array "
                             "of shape (3,)")
        if not (np.abs(rates) <= MAX_QUERY_RATE).all():
            raise ValueError(f"fk: the rates must be finite, each at most {MAX_QUERY_RATE:g} in size [rad/s]")
        twist_out[:] = twist_map(heading, "fk") @ rates

    def step(pose, previous, positions, heading_mid):
        if not (float64_vector(pose) and float64_vector(previous) and np.shape(pose) == (3,)
                and np.shape(previous) == (n_a,) and np.shape(positions) == (n_a,)):
            raise ValueError(f"odometry_step: pose must be a float64 array of shape (3,), previous one of shape "
                             f"({n_a},) (rate_joints) and positions of shape ({n_a},)")
        if not (np.isfinite(pose).all() and np.isfinite(previous).all() and np.isfinite(positions).all()):
            raise ValueError("odometry_step: the pose and the joint positions must be finite")
        if not _step(pose, previous, np.asarray(positions, dtype=float), twist_map(heading_mid, "odometry_step")):
            raise ValueError(OVERFLOW)

    return fk, step
