"""Steering linkages held by the dynamics: each ``linkage`` coupling is a holonomic constraint between steering
angles, ``beta_j = f(beta_i)`` for every wheel j it links to its leader i (``docs/dynamics.md``, Couplings).

A description gives no linkage geometry, so the dynamics hold the ideal one of its ``law``
(:func:`wmrkit.couplings.linkage_law`: the law it states, else ``ackermann`` with fixed wheels, ``parallel`` over
every steerable wheel of a robot without one, else none: the linkage is not held, :func:`unheld`), the formula
and table of :mod:`wmrkit.kinematics.linkage_law` (which the kinematics check too).

In reduced coordinates the basis depends on the leader's angle, ``nu = T(beta) p``, and the follower's
acceleration has the velocity-product term ``f''(beta_i) beta_i'^2`` (:func:`reduced`).

Heading set-points are checked against the law (:func:`heading_breach`), and against the ratios of a ``gear``
between steering joints (:func:`gear_breach`), which the dynamics hold too; a table of them every row at once
(:func:`first_breach`).

Table (``pack[17]``, ``(L, 10)``, one row per follower): follower column, leader column, the leader's column in the
basis, law (0 parallel, 1 axle), ``x_i``, ``x_j``, ``y_i - y_j``, ``beta_i - psi_i``, the rest angles ``beta_i0``,
``beta_j0``.
"""

from __future__ import annotations

import math

import numpy as np

from ..couplings import Coupling, linkage_law
from ..errors import WmrkitError
from ..kinematics.linkage_law import LINKAGE_TOL, law
from ..wheels import wrap_angle
from . import _setpoints

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
    return [f"{c.words()} is not held by the dynamics: the robot has no fixed wheel and the linkage does not link "
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
    """Why steering angles `beta` ``(n_steer,)`` (and velocities `nu`) break a linkage of `model`, naming it
    (:meth:`~wmrkit.couplings.Coupling.words`), its wheels as it does, and the heading (or steering rate) it gives the
    follower with its leader's; None when they hold every linkage."""
    table, cols, wheels = model.pack[17], list(model.steer_columns), model.robot.steer_names
    for row in table:
        j, i = cols.index(int(row[0])), cols.index(int(row[1]))
        f, slope, _ = law(row, beta[i])
        name = next(c.words() for c in model.robot.couplings
                    if c.kind == "linkage" and f"{model.names[int(row[0])]}" in c.joints)
        if abs(math.remainder(beta[j] - f, 2 * math.pi)) > LINKAGE_TOL:
            return (f"{name} sets {wheels[j]} at heading {_heading(model, j, f):.6g} rad with {wheels[i]} at "
                    f"{_heading(model, i, beta[i]):.6g} rad, not {_heading(model, j, beta[j]):.6g} rad")
        if nu is not None and abs(nu[int(row[0])] - slope * nu[int(row[1])]) > LINKAGE_TOL * (
                1 + abs(nu[int(row[1])])):
            return (f"{name} turns {wheels[j]}'s steering at {slope * nu[int(row[1])]:.6g} rad/s with {wheels[i]}'s "
                    f"at {nu[int(row[1])]:.6g} rad/s, not {nu[int(row[0])]:.6g} rad/s")
    return None


def setpoint_breach(model, beta: np.ndarray, commanded: set[int],
                    tol: float = SETPOINT_TOL) -> tuple[int, int | None, float] | None:
    """The first set-point that breaks a held linkage of `model`: steering angles `beta` ``(n_steer,)`` whose
    indices `commanded` have a servo; ``(follower, reference, angle)``: the index off the law by more than `tol`
    [rad], the commanded one of its linkage it is measured from (None: on the axle line, it keeps its rest angle
    whatever the others do) and the angle the law gives it. The reference is the leader if commanded, else the first
    commanded follower (its leader's angle found from it, :func:`~wmrkit.kinematics.linkage_law.leader_of`).
    None when they agree."""
    plan = _law_plan(model, commanded)
    at, off = _law_offs(model, plan, np.asarray(beta, dtype=float)[None])
    off = np.flatnonzero(off[0] > tol)
    if not len(off):
        return None
    j, _, src, _ = plan[off[0]].tolist()
    return j, src if src in commanded else None, float(at[0, off[0]])


def heading_breach(model, headings: np.ndarray, commanded: set[int]) -> tuple[int, int | None, float, Coupling] | None:
    """:func:`setpoint_breach` of heading set-points `headings` ``(n_steer,)`` [rad] as users read it, then
    :func:`gear_breach`: ``(follower, reference, heading the law (the gear) gives the follower [rad], the
    coupling)``; None when they agree."""
    breach = setpoint_breach(model, model.robot.beta_of_heading(headings), commanded)
    if breach is None:
        return gear_breach(model, headings, commanded)
    j, ref, f = breach
    steer = f"{model.robot.steer_names[j]}.steer"
    linkage = next(c for c in model.robot.couplings if c.kind == "linkage" and steer in c.joints)
    return j, ref, _heading(model, j, f), linkage


def first_breach(model, headings: np.ndarray, commanded: set[int]) -> int | None:
    """The first row of heading set-points `headings` ``(K, n_steer)`` [rad] (the indices `commanded` servoed) that
    :func:`heading_breach` refuses, every row judged at once (compiled for a large table); None when none is."""
    headings = np.asarray(headings, dtype=float).reshape(len(headings), -1)
    bad = np.zeros(len(headings), dtype=bool)
    plan = _law_plan(model, commanded)
    if len(plan):
        bad |= (_law_offs(model, plan, model.robot.beta_of_heading(headings))[1] > SETPOINT_TOL).any(axis=1)
    for j, _, want in _geared(model, headings, commanded):
        bad |= _gear_off(headings[:, j], want) > SETPOINT_TOL
    return int(np.argmax(bad)) if bad.any() else None


def first_ik_breach(model, headings: np.ndarray, servoed: set[int]) -> int | None:
    """The first row of wheel-IK headings `headings` ``(K, n_steer)`` [rad] that breaks a held linkage (every
    follower off its leader's law by more than ``LINKAGE_TOL``: :func:`linkage_breach`) or the ratios of a ``gear``
    between the steering joints `servoed` (:func:`gear_breach`), every row judged at once (compiled for a large
    table); None when none does. A twist program's check (:func:`~.programs.twist_program`)."""
    headings = np.asarray(headings, dtype=float).reshape(len(headings), -1)
    bad = np.zeros(len(headings), dtype=bool)
    plan = _law_plan(model, set(range(headings.shape[1])))  # every follower from its leader, as linkage_breach
    if len(plan):
        bad |= (_law_offs(model, plan, model.robot.beta_of_heading(headings))[1] > LINKAGE_TOL).any(axis=1)
    for j, _, want in _geared(model, headings, servoed):
        bad |= _gear_off(headings[:, j], want) > SETPOINT_TOL
    return int(np.argmax(bad)) if bad.any() else None


def gear_breach(model, headings: np.ndarray, commanded: set[int],
                tol: float = SETPOINT_TOL) -> tuple[int, int, float, Coupling] | None:
    """The first heading set-point of `headings` ``(n_steer,)`` [rad] (the indices `commanded` servoed) that breaks
    a ``gear`` the dynamics hold between steering joints (:func:`_geared`): ``(follower, reference, heading the gear
    gives it, the gear)``; None when they agree (within `tol` [rad])."""
    for j, ref, want in _geared(model, headings, commanded):
        if _gear_off(headings[j], want) > tol:
            steer = f"{model.robot.steer_names[j]}.steer"
            gear = next(c for c in model.robot.couplings if c.kind == "gear" and steer in c.joints)
            return j, ref, float(want), gear
    return None


def _gear_off(heading: np.ndarray, want: np.ndarray) -> np.ndarray:
    """How far [rad] a follower's `heading` is from the one its gear gives it, `want`, the short way round (a
    heading is an orientation: 179 deg and -181 deg are one). ``(...), (...) -> (...)``."""
    return np.abs(wrap_angle(np.asarray(heading) - want))


def _gears(model, commanded: set[int]) -> list[tuple[list[int], np.ndarray]]:
    """``(joints, ratios)`` of each ``gear`` the dynamics hold between commanded steering joints: their indices
    (ascending; the first, the gear's reference) and their ratios ``k_j`` (the gear turns them ``h_j - h_j0 = k_j u``
    from the described headings)."""
    base, cols = model.pack[16], list(model.steer_columns)
    if not base.shape[1]:
        return []
    gears: dict[int, list[int]] = {}
    for k in sorted(commanded):  # each commanded steering joint in a gear: its gear's column
        p = np.flatnonzero(base[cols[k]])
        if len(p) == 1:
            gears.setdefault(int(p[0]), []).append(k)
    return [(joints, np.array([base[cols[j], p] for j in joints])) for p, joints in gears.items()]


def _geared(model, headings: np.ndarray, commanded: set[int]) -> list[tuple[int, int, np.ndarray]]:
    """``(follower, reference, heading)`` for each commanded steering joint of a ``gear`` the dynamics hold but its
    first commanded one, the reference (:func:`_gears`): the heading [rad] the gear gives the follower from the
    reference's in `headings` ``(..., n_steer)`` (one per row)."""
    rest, out = model.robot.heading, []
    for joints, ratios in _gears(model, commanded):
        ref = joints[0]
        u = (headings[..., ref] - rest[ref]) / ratios[0]
        out += [(j, ref, rest[j] + k * u) for j, k in zip(joints[1:], ratios[1:], strict=True)]
    return out


def _law_offs(model, plan: np.ndarray, beta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(at, off)`` ``(K, F)``: the angle the law gives each follower of `plan` (:func:`_law_plan`) from each row
    of the steering set-points `beta` ``(K, n_steer)``, and how far its set-point is from it [rad]."""
    beta = np.ascontiguousarray(beta, dtype=float)
    at, off = np.empty((len(beta), len(plan))), np.empty((len(beta), len(plan)))
    if len(plan):
        _loops(at.size).law_offs(np.ascontiguousarray(model.pack[17], dtype=float), plan, beta, at, off)
    return at, off


def _law_plan(model, commanded: set[int]) -> np.ndarray:
    """``(F, 4)`` int, a row per commanded follower of a held linkage: its index, its row of the table, the index
    whose set-point gives its leader's angle (the leader if commanded, else the first commanded follower the leader's
    angle is found from, else the leader: a follower on the axle line keeps its rest angle whatever it is) and the
    table row whose inverse finds it (:func:`~wmrkit.kinematics.linkage_law.leader_of`; -1: the leader's own)."""
    table, cols, plan = model.pack[17], list(model.steer_columns), []
    for lead in dict.fromkeys(int(r[1]) for r in table):
        rows = [k for k, r in enumerate(table) if int(r[1]) == lead and cols.index(int(r[0])) in commanded]
        src, inv = cols.index(lead), -1
        if src not in commanded:
            inv = next((k for k in rows if table[k, 3] == 0.0 or table[k, 5] != 0.0), -1)
            src = src if inv < 0 else cols.index(int(table[inv, 0]))
        plan += [(cols.index(int(table[k, 0])), k, src, inv) for k in rows if cols.index(int(table[k, 0])) != src]
    return np.array(plan, dtype=np.int64).reshape(-1, 4)


#: Most knots :func:`setpoint_knots` inserts between the rows of a set-point table (a 0.5 rad row step of a small
#: car's steering inserts 139): its loops put at most ``5 (rows - 1) + 12 knots + 1`` set-points on the law
#: (tests/dynamics/test_linkage_setpoints.py): about two seconds for a million rows and these knots, which with the
#: torques interpolated at them take some 100 MB per ten columns.
MAX_SETPOINT_KNOTS = 1_000_000


class SetpointKnotsError(WmrkitError):
    """More than :data:`MAX_SETPOINT_KNOTS` knots :func:`setpoint_knots` would insert (a door names its source)."""


def setpoint_knots(model, t: np.ndarray, beta: np.ndarray, commanded: set[int],
                   tol: float = SETPOINT_TOL) -> tuple[np.ndarray, np.ndarray]:
    """Knots ``(t, beta)`` whose linear interpolation keeps the set-points of each held linkage on its law between
    rows: times `t` ``(K,)`` [s], steering set-points `beta` ``(K, n_steer)`` [rad] on the law at each row
    (:func:`setpoint_breach`), the indices `commanded` servoed; each follower's rows taken on the turn its law
    reaches from its first row and every other column's steps taken the short way (:func:`continued`: a heading
    written wrapped turns the short way).
    Between two rows the reference of each linkage moves linearly and the law sets its commanded followers from it
    (:func:`._setpoints.angle`): each step is cut into even pieces in time, their number raised (at least doubled,
    every step at once) until the followers' interpolation is within `tol` / 2 of the law at the middle of every
    piece (the law is smooth: a short chord's largest error is at its middle); the other columns keep their rows'
    interpolation. Without a commanded follower the rows are returned continued; :class:`SetpointKnotsError`
    where more than :data:`MAX_SETPOINT_KNOTS` knots would be inserted (before they are computed)."""
    plan = _law_plan(model, commanded)
    beta = continued(model, beta, commanded)
    if len(t) < 2 or not len(plan):
        return t, beta
    args = (np.ascontiguousarray(model.pack[17], dtype=float), plan)
    t = np.ascontiguousarray(t, dtype=float)
    pieces, rows = np.ones(len(t) - 1, dtype=np.int64), np.arange(len(t) - 1)
    while len(rows):
        off = np.empty(len(rows))
        _loops(int(np.sum(2 * pieces[rows] + 1))).chord_errors(*args, beta, rows, pieces[rows], off)
        rows, off = rows[off > tol / 2], off[off > tol / 2]
        more = np.maximum(2.0 * pieces[rows], np.ceil(pieces[rows] * np.sqrt(2 * off / tol)))
        if np.sum(pieces - 1) + np.sum(more - pieces[rows]) > MAX_SETPOINT_KNOTS:
            worst = rows[np.argmax(more)]
            raise SetpointKnotsError(
                f"heading set-points: keeping a held linkage's followers on its law between the rows would insert "
                f"more than {MAX_SETPOINT_KNOTS:.0e} knots (the step from t = {t[worst]:g} s to {t[worst + 1]:g} s "
                f"alone at least {more.max() - 1:.0f}); give the heading of one wheel per linkage (the linkage turns "
                "the others) or smaller heading steps between rows")
        pieces[rows] = more
    at, on = np.empty(1 + int(pieces.sum())), np.empty((1 + int(pieces.sum()), beta.shape[1]))
    _loops(len(at)).knots(*args, t, beta, pieces, at, on)
    return at, on


def continued(model, beta: np.ndarray, commanded: set[int]) -> np.ndarray:
    """The steering set-points `beta` ``(K, n_steer)`` [rad] moved by whole turns so that each step between rows turns
    the short way (:func:`._setpoints.continued`): a heading written wrapped, +179 deg then -179 deg, turns 2 deg, not
    358; the commanded followers of each held linkage (indices `commanded`; none: every column on its own) the way
    their law turns; the commanded joints of each steering gear the way the gear turns them, its turn stepping the
    short way (:func:`._setpoints.gear_continued`: with 1:2, the front turning 100 deg turns the rear 200 deg, not
    its own short way, -160 deg)."""
    beta = np.ascontiguousarray(beta, dtype=float)
    if len(beta) < 2:
        return beta
    plan, turned = _law_plan(model, commanded), np.empty_like(beta)
    _loops(len(beta) * max(len(plan), 1)).continued(np.ascontiguousarray(model.pack[17], dtype=float), plan, beta,
                                                    turned)
    for joints, ratios in _gears(model, commanded):
        if len(joints) > 1:  # a gear's reference alone steps the short way as any column
            rest = np.asarray(model.robot.beta, dtype=float)[joints]
            _loops(len(beta) * len(joints) * _setpoints.GEAR_TRIES).gear_continued(
                np.array(joints, dtype=np.int64), ratios, rest, SETPOINT_TOL, beta, turned)
    return turned


def _loops(work: int):
    """The loops of :func:`setpoint_knots` for `work` law evaluations: plain Python, compiled from
    :data:`~._setpoints.COMPILED_WORK`."""
    if work < _setpoints.COMPILED_WORK:
        return _setpoints
    from . import _setpoint_kernel
    return _setpoint_kernel


def _heading(model, k: int, beta: float) -> float:
    return float(model.robot.heading_of_beta(np.where(np.arange(len(model.steer_columns)) == k, beta,
                                                      model.robot.beta))[k])
