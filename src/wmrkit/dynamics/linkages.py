"""Steering linkages held by the dynamics: each ``linkage`` coupling is a holonomic constraint between steering
angles, ``beta_j = f(beta_i)`` for every wheel j it links to its leader i (``docs/dynamics.md``, Couplings).

A description gives no linkage geometry, so the dynamics hold the ideal one the robot's wheels define:

- with fixed wheels (their axles on one line, the ``axle``), the linked wheels' axles meet on that line: the
  exact Ackermann law. In the axle's frame (x along the fixed wheels' rolling direction, y along the axle, x_i, y_i
  the steering point of wheel i, psi its heading from the fixed wheels'), ``psi_j = atan2(x_j sin psi_i, x_i cos
  psi_i + (y_i - y_j) sin psi_i)`` (mod pi), so ``f' = x_i x_j / D`` with ``D`` the squared norm of that pair;
- without a fixed wheel, the linked wheels turn together, ``beta_j - beta_j0 = beta_i - beta_i0`` (a synchro
  drive's chain: one ICR at infinity while they stay parallel).

The leader is the linkage's first wheel (with fixed wheels, the first one off the axle line). The ratios are not
used. In reduced coordinates the basis depends on the leader's angle, ``nu = T(beta) p``, and the follower's
acceleration has the velocity-product term ``f''(beta_i) beta_i'^2`` (:func:`reduced`).

Table (``pack[17]``, ``(L, 10)``, one row per follower): follower column, leader column, the leader's column in the
basis, law (0 parallel, 1 axle), ``x_i``, ``x_j``, ``y_i - y_j``, ``beta_i - psi_i``, the rest angles ``beta_i0``,
``beta_j0``.
"""

from __future__ import annotations

import math

import numpy as np

from ..errors import WmrkitError
from ..wheels import heading_from_beta

#: Width of the table's rows.
COLUMNS = 10
#: A steering angle [rad] (or a rate, relative to the leader's) farther than this from its linkage's law breaks it.
LINKAGE_TOL = 1e-9


def law(row, beta):
    """``(f, f', f'')`` of the linkage row `row` at the leader's angle `beta` [rad] (compiled as it is by
    :mod:`._kernels`): the follower's angle, continuous from its rest angle (it turns less than half round)."""
    if row[3] == 0.0:
        return row[9] + beta - row[8], 1.0, 0.0
    xi, xj, dy = row[4], row[5], row[6]
    psi, psi0 = beta - row[7], row[8] - row[7]
    s, c, s0, c0 = math.sin(psi), math.cos(psi), math.sin(psi0), math.cos(psi0)
    u, v, u0, v0 = xj * s, xi * c + dy * s, xj * s0, xi * c0 + dy * s0
    d = u * u + v * v
    slope = xi * xj / d
    curvature = -2.0 * slope * (u * xj * c + v * (dy * c - xi * s)) / d
    return row[9] + math.atan2(u * v0 - v * u0, v * v0 + u * u0), slope, curvature


def linkage_table(robot, names: tuple[str, ...]) -> np.ndarray:
    """The table of the module docstring for `robot` with velocity `names` (the model's); ``(0, 10)`` without a
    linkage. Raises :class:`WmrkitError` naming the linkage when the robot cannot hold it."""
    linkages = [c for c in robot.couplings if c.kind == "linkage"]
    rows = []
    if not linkages:
        return np.zeros((0, COLUMNS))
    axle = _axle(robot)
    for c in linkages:
        wheels = [robot.wheel(j.partition(".")[0]) for j in c.joints]
        frame = [(0.0, 0.0, w.beta) for w in wheels] if axle is None else [_in_axle(axle, w) for w in wheels]
        lead = next((k for k, (x, _, _) in enumerate(frame) if axle is None or abs(x) > 1e-9), None)
        if lead is None:
            raise WmrkitError(f"robot '{robot.name}': {c.channel_name}: every linked wheel is on the fixed wheels' "
                              "axle line, so no steering angle sets the ICR; the dynamics cannot hold it")
        xi, yi, psi_i = frame[lead]
        wi = wheels[lead]
        for k, (xj, yj, psi_j) in enumerate(frame):
            if k == lead:
                continue
            wj = wheels[k]
            row = [names.index(f"{wj.name}.steer"), names.index(f"{wi.name}.steer"), -1, 0.0 if axle is None else 1.0,
                   xi, xj, yi - yj, wi.beta - psi_i, wi.beta, wj.beta]
            if axle is not None:
                want = math.atan2(xj * math.sin(psi_i), xi * math.cos(psi_i) + (yi - yj) * math.sin(psi_i))
                off = math.remainder(want - psi_j, math.pi)  # mod pi: a wheel mounted either way round
                if abs(off) > LINKAGE_TOL:
                    heads = ", ".join(f"{w.name} {math.degrees(float(heading_from_beta(w.beta, w.delta))):.4g} deg"
                                      for w in (wi, wj))
                    raise WmrkitError(
                        f"robot '{robot.name}': {c.channel_name}: at the described headings ({heads}) the linked "
                        f"wheels' axles do not meet on the fixed wheels' axle line ({wj.name} would be at "
                        f"{math.degrees(float(heading_from_beta(wj.beta + off, wj.delta))):.4g} deg): "
                        "the dynamics hold a linkage on one ICR; describe headings that agree (docs/dynamics.md)")
            rows.append(row)
    return np.array(rows, dtype=float).reshape(-1, COLUMNS)


def _axle(robot) -> tuple[np.ndarray, float] | None:
    """``(point, heading)`` of the fixed wheels' common axle line (a point on it, their rolling direction), None
    without a fixed wheel; :class:`WmrkitError` when their axles are not one line (no ICR for a linkage)."""
    fixed = [w for w in robot.wheels if w.type == "fixed"]
    if not fixed:
        return None
    p0, h0 = _position(fixed[0]), float(heading_from_beta(fixed[0].beta, fixed[0].delta))
    n0 = np.array([math.cos(h0), math.sin(h0)])
    scale = max(1.0, *(float(np.abs(_position(w)).max()) for w in fixed))
    for w in fixed[1:]:
        h = float(heading_from_beta(w.beta, w.delta))
        if abs(math.sin(h - h0)) > 1e-9 or abs(n0 @ (_position(w) - p0)) > 1e-9 * scale:
            links = ", ".join(c.channel_name for c in robot.couplings if c.kind == "linkage")
            raise WmrkitError(f"robot '{robot.name}': {links}: the fixed wheels' axles ({fixed[0].name}, {w.name}) "
                              "are not one line, so no ICR is common to them and the linked wheels; the dynamics "
                              "cannot hold the linkage")
    return p0, h0


def _position(w) -> np.ndarray:
    return np.array([w.l * math.cos(w.alpha), w.l * math.sin(w.alpha)])


def _in_axle(axle: tuple[np.ndarray, float], w) -> tuple[float, float, float]:
    """``(x, y, psi)`` of wheel `w` in the axle's frame: along the fixed wheels' rolling direction, along the axle,
    its heading from theirs."""
    p0, h0 = axle
    r = _position(w) - p0
    return (float(r[0] * math.cos(h0) + r[1] * math.sin(h0)), float(-r[0] * math.sin(h0) + r[1] * math.cos(h0)),
            float(heading_from_beta(w.beta, w.delta)) - h0)


def coupling_basis(gears: np.ndarray, table: np.ndarray, n: int) -> np.ndarray:
    """The basis of the model (``pack[16]``): the gears' (``(n, 0)``: none, the identity) less the followers'
    columns, the followers' rows filled per state (:func:`reduced`); the table's leader columns set (in place)."""
    if not len(table):
        return gears
    base = gears if gears.shape[1] else np.eye(n)
    followers = table[:, 0].astype(int)
    keep = [k for k in range(base.shape[1]) if not base[followers, k].any()]
    base = np.ascontiguousarray(base[:, keep])
    for row in table:
        row[2] = int(np.flatnonzero(base[int(row[1])])[0])
    return base


def reduced(table: np.ndarray, base: np.ndarray, beta_of, nu: np.ndarray | None) -> tuple[np.ndarray, np.ndarray]:
    """``(T, c)``: the basis ``nu = T p`` at the steering angles `beta_of(column)` and the velocity-product
    acceleration ``c`` (``nu' = T p' + c``; zero where `nu` is None)."""
    t, c = np.array(base), np.zeros(base.shape[0])
    for row in table:
        _, slope, curvature = law(row, beta_of(int(row[1])))
        t[int(row[0]), int(row[2])] = slope
        if nu is not None:
            c[int(row[0])] = curvature * nu[int(row[1])] ** 2
    return t, c


def linkage_breach(model, beta: np.ndarray, nu: np.ndarray | None = None) -> str | None:
    """Why steering angles `beta` ``(n_steer,)`` (and velocities `nu`) break a linkage of `model`, naming it and
    the angle (or rate) it gives; None when they hold every linkage."""
    table, cols = model.pack[17], list(model.steer_columns)
    for row in table:
        j, i = cols.index(int(row[0])), cols.index(int(row[1]))
        f, slope, _ = law(row, beta[i])
        name = next(c.channel_name for c in model.robot.couplings
                    if c.kind == "linkage" and f"{model.names[int(row[0])]}" in c.joints)
        if abs(math.remainder(beta[j] - f, 2 * math.pi)) > LINKAGE_TOL:
            return (f"{name} sets {model.names[int(row[0])]} at heading {_heading(model, j, f):.6g} rad from "
                    f"{model.names[int(row[1])]}, not {_heading(model, j, beta[j]):.6g} rad")
        if nu is not None and abs(nu[int(row[0])] - slope * nu[int(row[1])]) > LINKAGE_TOL * (
                1 + abs(nu[int(row[1])])):
            return (f"{name} turns {model.names[int(row[0])]} at {slope * nu[int(row[1])]:.6g} rad/s with "
                    f"{model.names[int(row[1])]}, not {nu[int(row[0])]:.6g} rad/s")
    return None


def _heading(model, k: int, beta: float) -> float:
    return float(model.robot.heading_of_beta(np.where(np.arange(len(model.steer_columns)) == k, beta,
                                                      model.robot.beta))[k])
