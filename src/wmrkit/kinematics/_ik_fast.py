"""Per-robot arrays and vectorised kernels behind :func:`wmrkit.kinematics.wheel_ik.wheel_commands` (thesis §8.4).

A robot's wheels fall into three groups, each solved for a whole batch of twists at once:

- *constant*: fixed, Swedish, ball and orthogonal wheels. Their rates are a constant matrix times the twist
  (rolling row of (3.11); (8.27)/(8.28) for rollers) and a fixed wheel's lateral row (8.14) gives its slip.
- *steered by the twist*: steerable (centred orientable) and double wheels. The angle zeroing the lateral slip is
  (8.9), ``atan2(-u_x, u_y)`` with ``u`` the velocity of the steering axis; of it and its opposite the one closest to
  the current angle is kept (the other one when only it is within the wheel's ``steer_range``; a linked wheel the
  one its linkage sets, :func:`steer_linked`), and the spin follows from (8.12) with the matching sign.
- *at the current angle*: castors, double castors (and the sub-wheels of a double wheel once its angle is chosen):
  the element rows (3.10) at that angle give the steering rate (8.24) and the spins (8.25).
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np

from .._shapes import readonly
from ..errors import SingularError
from ..robot import Robot
from ..wheels import generic_slip_rows, geometry_problem, heading_in_range, slip_row_entries, wrap_angle
from .gear_check import SteerGears, steer_gear_turns, steer_gears, steer_roots
from .linkage_check import _Plan as _LinkPlan
from .linkage_check import _roots, linkage_turns
from .linkage_law import LINKAGE_TOL

TWO_PI = 2.0 * math.pi
CONSTANT_TYPES = ("fixed", "swedish", "ball", "orthogonal")
TWIST_STEERED_TYPES = ("steerable", "double")


#: Round-off of a fixed wheel's lateral slip per unit of ``|vx| + |vy| + l |omega|`` (its row's entries are at most
#: 1, 1 and its distance l; cos(pi/2) is 6e-17): a slip within it is 0. A 1 km robot turning at 1e6 rad/s (the
#: documented limits) left 1.2e-7 m/s on a wheel rolling exactly along its path, over slip_tol: "not feasible".
SLIP_ROUNDOFF = 8 * float(np.finfo(float).eps)


@dataclass(frozen=True, eq=False)
class Plan:
    """Read-only arrays of one robot for the batched per-wheel IK (eq=False: array fields)."""

    n_wheels: int
    n_rates: int
    n_steer: int
    has_constant: bool  # some wheel is fixed, Swedish, ball or orthogonal
    constant_rates: np.ndarray  # (3, n_rates): rates = twist @ constant_rates; zero columns for other wheels
    fixed_wheels: np.ndarray  # (n_f,) wheel indices of fixed wheels
    fixed_lateral: np.ndarray  # (3, n_f): lateral slip = twist @ fixed_lateral (3.11 row 0 / 8.14) [m/s]
    fixed_roundoff: np.ndarray  # (3, n_f): |twist| @ fixed_roundoff bounds that slip's round-off [m/s]
    steered_beta: np.ndarray  # (n_o,) index into beta of the twist-steered wheels
    steered_x: np.ndarray  # (n_o,) steering-axis position [m]
    steered_y: np.ndarray
    steered_spin_col: np.ndarray  # (n_s,) rate column of each steerable (not double) wheel's spin
    steered_spin_of: np.ndarray  # (n_s,) its position among the twist-steered wheels
    steered_inv_r: np.ndarray  # (n_s,) 1 / r [1/m]
    element_beta: np.ndarray  # (E_c,) index into beta of the elements solved at an angle
    element_params: tuple[np.ndarray, ...]  # (beta_offset, l, alpha, d, delta, gamma, r, r_r), each (E_c,)
    element_castor: np.ndarray  # (E_c,) bool: steering rate from the lateral row (8.24); False: held (double)
    element_steer_col: np.ndarray  # (E_c,) rate column of the steering joint
    element_spin_col: np.ndarray  # (E_c,) rate column of the sub-wheel's spin
    steer_wheels: np.ndarray  # (n_steer,) wheel index of every steering angle
    spin_col: np.ndarray  # (N,) rate column of the spin ('spin' or 'spin1'); -1 without one
    spin2_col: np.ndarray  # (N,) rate column of 'spin2' (double wheels), -1 elsewhere
    steer_rate_col: np.ndarray  # (N,) rate column of the steering joint rate, -1 where it is not a column
    only_steerable: bool  # every wheel steerable, in order: the spins are the rates, the angles the config
    spin_select: slice | np.ndarray | None  # how to take the spins out of the rates (see :func:`selector`)
    steer_rate_select: slice | np.ndarray | None
    wheel_names: tuple[str, ...]
    rate_names: tuple[str, ...]
    wheel_delta: np.ndarray  # (N,) each wheel's delta: heading = steer + delta - pi/2
    steer_range: np.ndarray | None  # (2, N) heading ranges (lo, hi), +-inf where none; None: no wheel has one


@functools.lru_cache(maxsize=256)
def plan(robot: Robot) -> Plan:
    """The IK arrays of `robot` (built once per robot); :class:`SingularError` for a degenerate wheel built in Python
    (a castor without offset, Swedish rollers along the axle: :func:`~wmrkit.wheels.geometry_problem`), whose
    steering or spin rate no twist determines (it gave inf and NaN rates, called feasible)."""
    for w in robot.wheels:
        problem = geometry_problem(w.type, w.geometry())
        if problem is not None:
            raise SingularError(f"robot '{robot.name}': wheel '{w.name}': {problem[0]}: {problem[1]}: no twist "
                                "determines its rates, so it has no wheel commands (8.4)")
    n = len(robot.wheels)
    steer_names = robot.steer_names
    col = {name: i for i, name in enumerate(robot.rate_names)}
    constant = np.zeros((3, len(col)))
    fixed, lateral = [], []
    steered_beta, sx, sy, spin_cols, spin_of, inv_r = [], [], [], [], [], []
    e_beta, e_params, e_castor, e_steer, e_spin = [], [], [], [], []
    spin_col, spin2_col, steer_rate_col = np.full(n, -1), np.full(n, -1), np.full(n, -1)
    for i, w in enumerate(robot.wheels):
        own = {j: col[f"{w.name}.{j}"] for j in w.kind.rates}
        spin_col[i] = own.get("spin", own.get("spin1", -1))
        spin2_col[i] = own.get("spin2", -1)
        steer_rate_col[i] = own.get("steer", -1)
        if w.type in CONSTANT_TYPES:
            e = w.elements()[0]
            rows = generic_slip_rows(w.beta + e.beta_offset, e.l, e.alpha, e.d, e.delta, e.gamma, e.r, e.r_r)
            if w.type == "fixed":  # rolling row: phi_dot = -row1[:3] . twist / r (8.12 at constant beta)
                constant[:, own["spin"]] = -rows[1, :3] / rows[1, 4]
                fixed.append(i)
                lateral.append(rows[0, :3])
            else:  # Swedish (8.27), roller (8.28) from the second row with phi_dot substituted
                spin = -rows[0, :3] / rows[0, 4]
                constant[:, own["spin"]] = spin
                constant[:, own["roller"]] = -(rows[1, :3] + rows[1, 4] * spin) / rows[1, 5]
            continue
        k = steer_names.index(w.name)
        if w.type in TWIST_STEERED_TYPES:
            if w.type == "steerable":
                spin_cols.append(own["spin"])
                spin_of.append(len(steered_beta))
                inv_r.append(1.0 / w.r)
            steered_beta.append(k)
            sx.append(w.position[0])
            sy.append(w.position[1])
        if w.type != "steerable":
            for e, sub in zip(w.elements(), ("spin1", "spin2") if len(w.elements()) == 2 else ("spin",), strict=True):
                e_beta.append(k)
                e_params.append((e.beta_offset, *e[:2], *e[3:8]))
                e_castor.append(w.type != "double")
                e_steer.append(own["steer"])
                e_spin.append(own[sub])
    params = np.array(e_params, dtype=float).reshape(-1, 8).T

    def ints(x: list[int]) -> np.ndarray:
        return readonly(np.array(x, dtype=int))

    def floats(x: list[float]) -> np.ndarray:
        return readonly(np.array(x, dtype=float))

    return Plan(
        n_wheels=n, n_rates=len(col), n_steer=len(steer_names), constant_rates=readonly(constant),
        has_constant=any(w.type in CONSTANT_TYPES for w in robot.wheels),
        fixed_wheels=ints(fixed), fixed_lateral=readonly(np.array(lateral, dtype=float).reshape(-1, 3).T.copy()),
        fixed_roundoff=readonly(SLIP_ROUNDOFF * np.array([[1.0, 1.0, robot.wheels[i].l] for i in fixed],
                                                         dtype=float).reshape(-1, 3).T.copy()),
        steered_beta=ints(steered_beta), steered_x=floats(sx), steered_y=floats(sy),
        steered_spin_col=ints(spin_cols), steered_spin_of=ints(spin_of), steered_inv_r=floats(inv_r),
        element_beta=ints(e_beta), element_params=tuple(readonly(p.copy()) for p in params),
        element_castor=readonly(np.array(e_castor, dtype=bool)), element_steer_col=ints(e_steer),
        element_spin_col=ints(e_spin),
        steer_wheels=ints([i for i, w in enumerate(robot.wheels) if w.kind.steers]),
        spin_col=readonly(spin_col), spin2_col=readonly(spin2_col), steer_rate_col=readonly(steer_rate_col),
        only_steerable=all(w.type == "steerable" for w in robot.wheels),
        spin_select=selector(spin_col), steer_rate_select=selector(steer_rate_col),
        wheel_names=robot.wheel_names, rate_names=robot.rate_names,
        wheel_delta=readonly(np.array([w.delta for w in robot.wheels], dtype=float)),
        steer_range=readonly(np.array([w.steer_range or (-np.inf, np.inf) for w in robot.wheels], dtype=float).T)
        if any(w.steer_range for w in robot.wheels) else None,
    )


def selector(cols: np.ndarray) -> slice | np.ndarray | None:
    """How to take columns `cols` (-1: none, NaN) of the rates: None if all are -1, a slice if evenly spaced
    (a view, no copy: e.g. Mecanum's spins between rollers), else the index array itself."""
    if (cols < 0).all():
        return None
    step = np.diff(cols)
    if (cols >= 0).all() and (len(cols) == 1 or (step[0] > 0 and (step == step[0]).all())):
        return slice(int(cols[0]), int(cols[-1]) + 1, int(step[0]) if len(cols) > 1 else 1)
    return readonly(cols.copy())


#: Twists per block of the steering kernel: its temporaries stay in cache and are reused (no page faults).
BLOCK = 8192


def constant_rates(p: Plan, twist: np.ndarray) -> np.ndarray:
    """``twist @ constant_rates`` as ``(C^T twist^T)^T``, one BLAS product per block of :data:`BLOCK` twists.

    ``(..., 3) -> (..., n_rates)``: a transposed view of a rate-major array (each rate contiguous). Blocks keep
    OpenBLAS on one thread (small products), which is faster on a shared machine than its threaded large product.
    """
    flat = twist.reshape(-1, 3)
    m = flat.shape[0]
    out = np.empty((p.n_rates, m))
    ct = p.constant_rates.T
    for start in range(0, m, 2 * BLOCK):
        np.matmul(ct, flat[start:start + 2 * BLOCK].T, out=out[:, start:start + 2 * BLOCK])
    return out.T.reshape(*twist.shape[:-1], p.n_rates)


def steer_to_twist(
    p: Plan, twist: np.ndarray, current: np.ndarray, speed_tol: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Angles (8.9) closest to `current`, and the steerable wheels' spins (8.12), for a batch of twists.

    ``(..., 3), (..., n_o) -> (..., n_o) angles [rad] in (-pi, pi], (..., n_s) spins [rad/s], (..., n_o) held``.
    Where the steering axis does not move (speed <= `speed_tol` [m/s]) the angle is undefined: the current angle
    (wrapped) is kept and the spin is 0. Vectorised over blocks of :data:`BLOCK` twists, one row per wheel
    (long inner loops, cache-sized temporaries); the results are transposed views of wheel-major arrays.
    """
    n_o, n_s = len(p.steered_x), len(p.steered_spin_of)
    batch = np.broadcast_shapes(twist.shape[:-1], current.shape[:-1])
    t = np.broadcast_to(twist, (*batch, 3)).reshape(-1, 3)
    m = t.shape[0]
    if current.ndim > 1:  # one current angle per twist: wheel-major too
        cur = np.ascontiguousarray(np.broadcast_to(current, (*batch, n_o)).reshape(-1, n_o).T)
    else:
        cur = current[:, None]
    cos_cur, sin_cur = np.cos(cur), np.sin(cur)
    beta, spin, held = np.empty((n_o, m)), np.empty((n_s, m)), np.empty((n_o, m), dtype=bool)
    for start in range(0, m, BLOCK):
        b = slice(start, start + BLOCK)
        c, s = (cos_cur[:, b], sin_cur[:, b]) if current.ndim > 1 else (cos_cur, sin_cur)
        _steer_block(p, t[b], c, s, speed_tol, beta[:, b], spin[:, b], held[:, b])
    if held.any():
        kept = np.broadcast_to(wrap_angle(cur), beta.shape)
        beta[held] = kept[held]
        spin[held[p.steered_spin_of]] = 0.0
    if p.steer_range is not None:
        _prefer_in_range(p, beta, spin, held)
    return (beta.T.reshape(*batch, n_o), spin.T.reshape(*batch, n_s), held.T.reshape(*batch, n_o))


def steer_linked(
    robot: Robot, p: Plan, twist: np.ndarray, current: np.ndarray, batch: tuple[int, ...], speed_tol: float,
    slip_tol: float,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`steer_to_twist`'s angles ``(..., n_o)``, spins ``(..., n_s)`` and held flags ``(..., n_o)`` of the
    twist-steered wheels at steering `current` ``(..., n_steer)``, each linked wheel it moves set on the root of (8.9)
    its linkage sets (:func:`~wmrkit.kinematics.linkage_check.linkage_turns`), then each geared one on the root its
    gear between steering joints sets (:func:`~wmrkit.kinematics.gear_check.steer_gear_turns`; `slip_tol` [m/s] the
    gear check's floor), its spin reversed."""
    steered = current if p.only_steerable else current[..., p.steered_beta]
    angles, spins, held = steer_to_twist(p, twist, steered, speed_tol)
    if not (any(c.kind == "linkage" for c in robot.couplings) or steer_gears(robot).table.coupling):
        return angles, spins, held
    config = np.broadcast_to(wrap_angle(current), (*batch, p.n_steer)).copy()
    config[..., p.steered_beta] = angles
    free = np.zeros((*held.shape[:-1], p.n_steer), dtype=bool)
    free[..., p.steered_beta] = ~held
    angles, spins = _turned(p, linkage_turns(robot, twist, config, free), angles, spins, config)
    angles, spins = _turned(p, steer_gear_turns(robot, twist, config, free, slip_tol), angles, spins, config)
    return angles, spins, held


def _turned(p: Plan, turn: np.ndarray | None, angles: np.ndarray, spins: np.ndarray,
            config: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The angles ``(..., n_o)`` and spins ``(..., n_s)`` with the wheels `turn` ``(..., n_steer)`` (None: none) turned
    half round, spins reversed; `config` ``(..., n_steer)`` updated in place."""
    if turn is None or not turn.any():
        return angles, spins
    turn = turn[..., p.steered_beta]
    angles = np.where(turn, wrap_angle(angles + np.pi), angles)
    config[..., p.steered_beta] = angles
    return angles, np.where(turn[..., p.steered_spin_of], -spins, spins)


def _prefer_in_range(p: Plan, beta: np.ndarray, spin: np.ndarray, held: np.ndarray) -> None:
    """Where the closest root's heading is outside its wheel's ``steer_range`` and the other root's is inside,
    take the other root (``beta + pi``, spin negated): the wheel can follow the twist. In place, ``(n_o, m)``."""
    wheels = p.steer_wheels[p.steered_beta]
    lo, hi = p.steer_range[:, wheels][..., None]  # (n_o, 1) each; +-inf: no range
    heading = beta + (p.wheel_delta[wheels] - 0.5 * math.pi)[:, None]
    flip = ~held & ~heading_in_range(heading, lo, hi) & heading_in_range(heading + math.pi, lo, hi)
    if flip.any():
        beta[flip] = wrap_angle(beta[flip] + math.pi)
        spin[flip[p.steered_spin_of]] *= -1.0


def wrap_one(a: float) -> float:
    """:func:`~wmrkit.wheels.wrap_angle` of one float, the same operations (``round`` halves to even, as ``rint``)."""
    y = a - TWO_PI * round(a / TWO_PI)
    return y + TWO_PI if y <= -math.pi else (y - TWO_PI if y > math.pi else y)


def in_range_one(h: float, lo: float, hi: float, tol: float = 1e-12) -> bool:
    """:func:`~wmrkit.wheels.heading_in_range` of one heading, the same operations (``%`` is ``np.mod``)."""
    if not (math.isfinite(lo) and math.isfinite(hi)):
        return True
    return (h - lo + tol) % TWO_PI - tol <= hi - lo + tol


def steering_one(p: Plan, vx: float, vy: float, w: float, current: list[float], speed_tol: float, slip_tol: float,
                 links: _LinkPlan | None = None, gears: SteerGears | None = None) -> list[float]:
    """The configuration (thesis angles, ``(n_steer,)``) :func:`steer_to_twist` and :func:`_prefer_in_range` give
    one twist at steering `current`, in plain floats with the same operations (:func:`_steer_block`'s): a few µs
    for a few wheels instead of a hundred, for a loop that needs only the angles (the continuous control loop).
    Castor-like angles are kept (wrapped), as :func:`~wmrkit.kinematics.wheel_ik.wheel_commands` keeps them; with
    the robot's held linkages `links` (:func:`wmrkit.kinematics.linkage_check._plan`) a linked wheel it moves is
    set on the root its linkage sets (:func:`wmrkit.kinematics.linkage_check._roots`), with its gears between steering
    joints `gears` (:func:`wmrkit.kinematics.gear_check.steer_gears`; `links` given too) a geared one on the root its
    gear sets (:func:`wmrkit.kinematics.gear_check.steer_roots`, `slip_tol` the gear check's floor), as
    ``wheel_commands`` sets them."""
    config = [wrap_one(c) for c in current]
    moved = []
    for i, k in enumerate(p.steered_beta.tolist()):
        minus_ux = float(p.steered_y[i]) * w - vx
        uy = float(p.steered_x[i]) * w + vy
        speed = math.sqrt(minus_ux * minus_ux + uy * uy)
        if speed <= speed_tol:  # held: the current angle, never flipped
            continue
        sign = minus_ux * math.sin(current[k]) + uy * math.cos(current[k])
        sign = -1.0 if abs(sign) <= 1e-12 * speed else math.copysign(1.0, sign)
        beta = math.atan2(minus_ux * sign + 0.0, uy * sign)
        if p.steer_range is not None:
            wheel = int(p.steer_wheels[k])
            lo, hi = float(p.steer_range[0, wheel]), float(p.steer_range[1, wheel])
            heading = beta + (float(p.wheel_delta[wheel]) - 0.5 * math.pi)
            if not in_range_one(heading, lo, hi) and in_range_one(heading + math.pi, lo, hi):
                beta = wrap_one(beta + math.pi)
        config[k] = beta
        moved.append(k)
    if links is not None and len(links.lead):
        speeds = [math.hypot(vx - w * y, vy + w * x) for x, y in zip(links.x.tolist(), links.y.tolist(), strict=True)]
        turn, free = [False] * len(config), [k in moved for k in range(len(config))]
        for g, lead in enumerate(links.lead.tolist()):
            _roots(links.table, int(links.start[g]), int(links.start[g + 1]), lead, config, speeds, free, links.lo,
                   links.width, links.offset, turn)
        for k in moved:
            if turn[k]:
                config[k] = wrap_one(config[k] + math.pi)
    if gears is not None and links is not None and gears.table.coupling:
        t, turn = gears.table, [False] * len(config)
        speeds = [math.hypot(vx - w * y, vy + w * x) for x, y in zip(gears.x.tolist(), gears.y.tolist(), strict=True)]
        free = [k in moved for k in range(len(config))]
        for g in range(len(t.coupling)):
            steer_roots(t.joint, t.ratio, int(t.start[g]), int(t.start[g + 1]), gears.rest, gears.x, gears.y, vx, vy, w,
                        gears.rows, gears.turns, config, speeds, slip_tol, LINKAGE_TOL, free, links.lo, links.width,
                        links.offset, turn)
        for k in moved:
            if turn[k]:
                config[k] = wrap_one(config[k] + math.pi)
    return config


def _steer_block(
    p: Plan, t: np.ndarray, cos_cur: np.ndarray, sin_cur: np.ndarray, speed_tol: float,
    beta: np.ndarray, spin: np.ndarray, held: np.ndarray,
) -> None:
    """One block of :func:`steer_to_twist`: twists ``(B, 3)``, outputs ``(n_o, B)`` written in place."""
    vx, vy, w = t[:, 0], t[:, 1], t[:, 2]
    minus_ux = p.steered_y[:, None] * w  # -u_x = omega y - v_x: the steering axis's velocity, x negated
    minus_ux -= vx
    uy = p.steered_x[:, None] * w
    uy += vy
    speed = minus_ux * minus_ux
    tmp = uy * uy
    speed += tmp
    np.sqrt(speed, out=speed)  # |phi_dot| r of (8.12)
    # (8.9) gives b0 = atan2(-u_x, u_y), whose spin is -speed / r; b0 + pi (spin +speed / r) is the other root.
    # sign(cos(b0 - current)) = -1 means b0 + pi is closer to the current angle: negate u, atan2 returns it.
    sign = minus_ux * sin_cur
    np.multiply(uy, cos_cur, out=tmp)
    sign += tmp
    tie = np.abs(sign) <= 1e-12 * speed  # both roots 90 deg away: the one rolling forward, as WPILib's optimize
    np.copysign(1.0, sign, out=sign)
    sign[tie] = -1.0  # the spin is -speed sign / r
    minus_ux *= sign
    minus_ux += 0.0  # -0.0 -> +0.0: atan2 then returns +pi, never -pi, for a wheel rolling straight back
    uy *= sign
    np.arctan2(minus_ux, uy, out=beta)
    if spin.shape == speed.shape:
        np.multiply(speed, sign, out=spin)
    else:
        np.multiply(speed[p.steered_spin_of], sign[p.steered_spin_of], out=spin)
    spin *= -p.steered_inv_r[:, None]
    np.less_equal(speed, speed_tol, out=held)


def castor_rates_one(p: Plan, vx: float, vy: float, w: float, beta: list[float], elements: list[int]) -> list[float]:
    """:func:`solve_elements`' steering rates (8.24) of the castor-like `elements` (indices ``< E_c``) for one
    twist at steering `beta` ``(n_steer,)``, in plain floats (the rows of :func:`~wmrkit.wheels.slip_row_entries`
    with math's sine): a few µs instead of tens, for the continuous loop's castors at every evaluation."""
    offset, *geometry = p.element_params
    out = []
    for e in elements:
        if not p.element_castor[e]:  # a double wheel: its steering held
            out.append(0.0)
            continue
        (g0, g1, g2, g3, _, _), _ = slip_row_entries(beta[int(p.element_beta[e])] + float(offset[e]),
                                                     *(float(g[e]) for g in geometry), sin=math.sin, cos=math.cos)
        out.append(-(vx * g0 + vy * g1 + w * g2) / g3)
    return out


def solve_elements(p: Plan, twist: np.ndarray, beta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Steering rates (8.24) and spins (8.25) of castor-like elements at angles `beta` (double: steering held).

    ``(..., 3), (..., n_steer) -> (..., E_c), (..., E_c)`` [rad/s]. From the element rows (3.10): row 0 gives
    ``beta_dot`` (``-d cos(delta)`` is its coefficient; a double wheel's is 0 and its rate is taken as 0, i.e. the
    unit keeps its angle relative to the body), row 1 the spin. Unbatched `beta` evaluates the rows once.
    """
    offset, *geometry = p.element_params
    g = generic_slip_rows(beta[..., p.element_beta] + offset, *geometry)  # (..., E_c, 2, 6)
    lateral = np.einsum("...k,...ek->...e", twist, g[..., 0, :3])
    rolling = np.einsum("...k,...ek->...e", twist, g[..., 1, :3])
    coef = np.where(p.element_castor, g[..., 0, 3], 1.0)
    beta_dot = np.where(p.element_castor, -lateral / coef, 0.0)
    spin = -(rolling + g[..., 1, 3] * beta_dot) / g[..., 1, 4]
    return beta_dot, spin
