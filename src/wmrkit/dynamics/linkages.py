"""Steering linkages held by the dynamics: each ``linkage`` coupling is a holonomic constraint between steering
angles, ``beta_j = f(beta_i)`` for every wheel j it links to its leader i (``docs/dynamics.md``, Couplings).

A description gives no linkage geometry, so the dynamics hold the ideal one of its ``law``
(:func:`wmrkit.couplings.linkage_law`: the law it states, else ``ackermann`` with fixed wheels, ``parallel`` over
every steerable wheel of a robot without one, else none: the linkage is not held, :func:`unheld`), the formula
and table of :mod:`wmrkit.kinematics.linkage_law` (which the kinematics check too).

In reduced coordinates the basis depends on the leader's angle, ``nu = T(beta) p``, and the follower's
acceleration has the velocity-product term ``f''(beta_i) beta_i'^2`` (:func:`reduced`).

Heading set-points are checked against the law (:func:`heading_breach`), and against the ratios of a ``gear``
between steering joints (:func:`gear_breach`), which the dynamics hold too.

Table (``pack[17]``, ``(L, 10)``, one row per follower): follower column, leader column, the leader's column in the
basis, law (0 parallel, 1 axle), ``x_i``, ``x_j``, ``y_i - y_j``, ``beta_i - psi_i``, the rest angles ``beta_i0``,
``beta_j0``.
"""

from __future__ import annotations

import math

import numpy as np

from ..couplings import linkage_law
from ..errors import WmrkitError
from ..kinematics.linkage_law import LINKAGE_TOL, law
from ..kinematics.linkage_law import leader_of as _leader_of

#: A heading set-point [rad] (a torque file's, :func:`wmrkit.dynamics.programs.read_torques`) farther than this from
#: its linkage's law, given the other set-points of the linkage, fights it: headings written to six significant
#: digits pass, the servos then settle within that of both.
SETPOINT_TOL = 1e-5


class LinkageWarning(UserWarning):
    """A ``linkage`` coupling the dynamics do not hold (:func:`unheld`), warned by
    :meth:`~wmrkit.dynamics.model.DynamicModel.of`: each of its steering angles follows its own servo."""


def unheld(robot) -> list[str]:
    """The warnings of the linkages of `robot` the dynamics do not hold (no law stated and none to default to:
    :func:`wmrkit.couplings.linkage_law`): each steering angle follows its own servo (:class:`LinkageWarning`)."""
    return [f"{c.channel_name} is not held by the dynamics: the robot has no fixed wheel and the linkage does not link "
            "every steerable wheel, so its law is not known and each steering angle follows its own servo; state it "
            "in the coupling's law field (law: parallel if the linked wheels turn together; "
            "docs/description-format.md)"
            for c in robot.couplings if c.kind == "linkage" and linkage_law(c, robot.wheels) is None]


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


def setpoint_breach(model, beta: np.ndarray, commanded: set[int],
                    tol: float = SETPOINT_TOL) -> tuple[int, int | None, float] | None:
    """The first set-point that breaks a held linkage of `model`: steering angles `beta` ``(n_steer,)`` whose
    indices `commanded` have a servo; ``(follower, reference, angle)``: the index off the law by more than `tol`
    [rad], the commanded one of its linkage it is measured from (None: on the axle line, it keeps its rest angle
    whatever the others do) and the angle the law gives it. The reference is the leader if commanded, else the first
    commanded follower (its leader's angle found from it, :func:`_leader_of`). None when they agree."""
    for j, ref, f in _set_by_law(model, beta, commanded):
        if abs(math.remainder(beta[j] - f, 2 * math.pi)) > tol:
            return j, ref, f
    return None


def heading_breach(model, headings: np.ndarray, commanded: set[int]) -> tuple[int, int | None, float, str] | None:
    """:func:`setpoint_breach` of heading set-points `headings` ``(n_steer,)`` [rad] as users read it, then
    :func:`gear_breach`: ``(follower, reference, heading the law (the gear) gives the follower [rad], the
    coupling's name)``; None when they agree."""
    breach = setpoint_breach(model, model.robot.beta_of_heading(headings), commanded)
    if breach is None:
        return gear_breach(model, headings, commanded)
    j, ref, f = breach
    steer = f"{model.robot.steer_names[j]}.steer"
    name = next(c.channel_name for c in model.robot.couplings if c.kind == "linkage" and steer in c.joints)
    return j, ref, _heading(model, j, f), name


def gear_breach(model, headings: np.ndarray, commanded: set[int],
                tol: float = SETPOINT_TOL) -> tuple[int, int, float, str] | None:
    """The first heading set-point of `headings` ``(n_steer,)`` [rad] (the indices `commanded` servoed) that breaks
    a ``gear`` the dynamics hold between steering joints: the gear turns them in its ratios from the described
    headings, ``h_j - h_j0 = k_j u``, so ``(follower, reference, heading the gear gives it, the gear's name)``, the
    reference the gear's first commanded joint; None when they agree (within `tol` [rad])."""
    base, cols = model.pack[16], list(model.steer_columns)
    if not base.shape[1]:
        return None
    rest, gears = model.robot.heading, {}
    for k in sorted(commanded):  # each commanded steering joint in a gear: its gear's column and its ratio
        p = np.flatnonzero(base[cols[k]])
        if len(p) == 1:
            gears.setdefault(int(p[0]), []).append(k)
    for p, joints in gears.items():
        ref = joints[0]
        u = (headings[ref] - rest[ref]) / base[cols[ref], p]
        for j in joints[1:]:
            want = rest[j] + base[cols[j], p] * u
            if abs(headings[j] - want) > tol:
                steer = f"{model.robot.steer_names[j]}.steer"
                name = next(c.channel_name for c in model.robot.couplings if c.kind == "gear" and steer in c.joints)
                return j, ref, float(want), name
    return None


def _set_by_law(model, beta: np.ndarray, commanded: set[int]) -> list[tuple[int, int | None, float]]:
    """``(follower, reference, angle)`` for each commanded follower of a held linkage (:func:`setpoint_breach`):
    the angle its linkage's law gives it from its reference's set-point in `beta`."""
    table, cols, out = model.pack[17], list(model.steer_columns), []
    for lead in dict.fromkeys(int(r[1]) for r in table):
        rows = [r for r in table if int(r[1]) == lead and cols.index(int(r[0])) in commanded]
        ref = cols.index(lead)
        if ref in commanded:
            b = beta[ref]
        else:
            first = next((r for r in rows if r[3] == 0.0 or r[5] != 0.0), None)
            ref = None if first is None else cols.index(int(first[0]))
            b = beta[cols.index(lead)] if first is None else _leader_of(first, beta[ref])
        out += [(cols.index(int(r[0])), ref, law(r, b)[0]) for r in rows if cols.index(int(r[0])) != ref]
    return out


#: Most knots :func:`setpoint_knots` makes of a torque file's rows (as many as the rows of a 1 GiB table).
MAX_SETPOINT_KNOTS = 10_000_000


def setpoint_knots(model, t: np.ndarray, beta: np.ndarray, commanded: set[int],
                   tol: float = SETPOINT_TOL) -> tuple[np.ndarray, np.ndarray]:
    """Knots ``(t, beta)`` whose linear interpolation keeps the set-points of each held linkage on its law between
    rows: times `t` ``(K,)`` [s], steering set-points `beta` ``(K, n_steer)`` [rad] on the law at each row
    (:func:`setpoint_breach`), the indices `commanded` servoed. Between two rows the reference of each linkage moves
    linearly and the law sets its commanded followers from it (:func:`_on_law`): knots are inserted, evenly in
    time, until the followers' interpolation is within `tol` / 2 of the law at the middle of every interval (the
    law is smooth: a short chord's largest error is at its middle); the other columns keep their rows'
    interpolation. Without a commanded follower the rows are returned as they are; :class:`WmrkitError` beyond
    :data:`MAX_SETPOINT_KNOTS` knots."""
    if len(t) < 2 or not _set_by_law(model, beta[0], commanded):
        return t, beta
    times, rows = [t[:1]], [_on_law(model, beta[0], commanded)[None]]
    for k in range(len(t) - 1):
        pieces = 1
        while True:
            s = np.linspace(0.0, 1.0, 2 * pieces + 1)  # the knots and the middles of their intervals
            on = np.array([_on_law(model, (1 - a) * beta[k] + a * beta[k + 1], commanded) for a in s])
            off = np.abs(on[1:-1:2] - (on[:-2:2] + on[2::2]) / 2).max()
            if off <= tol / 2:
                break
            pieces = max(2 * pieces, math.ceil(pieces * math.sqrt(2 * off / tol)))
            if pieces + sum(len(x) for x in times) > MAX_SETPOINT_KNOTS:
                raise WmrkitError(f"heading set-points: more than {MAX_SETPOINT_KNOTS:.0e} knots would keep a held "
                                  "linkage's followers on its law between the rows; give rows closer together")
        times.append(np.append(t[k] + (t[k + 1] - t[k]) * s[2:-1:2], t[k + 1]))
        rows.append(on[2::2])
    return np.concatenate(times), np.concatenate(rows)


def _on_law(model, beta: np.ndarray, commanded: set[int]) -> np.ndarray:
    """`beta` with each commanded follower of a held linkage at the angle its law gives it (:func:`_set_by_law`),
    the turn nearest its value in `beta`."""
    beta = np.array(beta, dtype=float)
    for j, _, f in _set_by_law(model, beta, commanded):
        beta[j] += math.remainder(f - beta[j], 2 * math.pi)
    return beta


def _heading(model, k: int, beta: float) -> float:
    return float(model.robot.heading_of_beta(np.where(np.arange(len(model.steer_columns)) == k, beta,
                                                      model.robot.beta))[k])
