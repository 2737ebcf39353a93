"""Lines in the robot plane and the constraint lines a robot imposes on its twist (thesis §6.4, eqs. 6.13-6.20).

A line is ``lambda = (lambda_x, lambda_y, d_lambda)`` (6.18): unit direction and signed distance to the origin;
point ``(x, y)`` lies on it iff ``lambda . (y, -x, 1) = 0`` (6.19). A twist ``(vx, vy, omega)`` with
instantaneous centre ``(x_c, y_c)`` is ``omega (y_c, -x_c, 1)`` (digest §2.2), so a row ``g`` of a no-slip
equation ``g . twist = 0`` says "the ICR lies on line g". Three or more lines have rank < 3 iff they are
concurrent or parallel (6.20).

:func:`constraint_lines` eliminates every wheel's free joint rates from the slip equations (3.22): what is left
are the rows G of (6.15)-(6.17), one labelled line each (the axle of a fixed or steerable wheel, the plane of a
wheel whose spin is assigned, the rollers of a Swedish wheel, the axle or the steering arm of a castor...).
The elimination is exact for every wheel type (including castors with delta != 0, where it yields the arm line,
digest §6.2, and the double wheels); rules 1-6 of §6.3 are its special cases.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike
from scipy.linalg import block_diag

from .._shapes import as_names, as_vectors, readonly
from ..couplings import Coupling, coupled_columns
from ..errors import ShapeError, UnknownNameError
from ..kinematics.linalg import nondimensional, rank_cutoff, rref, unit_columns
from ..robot import TWIST_NAMES, Robot, check_robot, element_table
from ._fast import cancel_roundoff

#: Rows added for assigned vehicle velocities (rules 5-6 of §6.3): the X axis, the Y axis, the line at infinity.
TWIST_LINES = {"vx": (1.0, 0.0, 0.0), "vy": (0.0, 1.0, 0.0), "omega": (0.0, 0.0, 1.0)}
_TWIST_LABELS = {"vx": "X axis (vx assigned)", "vy": "Y axis (vy assigned)",
                 "omega": "line at infinity (omega assigned)"}
_ROW_NAMES = {
    "fixed": ("axle", "plane"), "steerable": ("axle", "plane"), "castor": ("axle", "plane"),
    "swedish": ("rollers", "cross-roller line"), "ball": ("rollers", "cross-roller line"),
    "orthogonal": ("rollers", "cross-roller line"),
}


def line_through(point: ArrayLike, direction: ArrayLike) -> np.ndarray:
    """Line through `point` along `direction`, eq. (6.18): ``(u_x, u_y, P x u)``.

    ``(..., 2), (..., 2) -> (..., 3)``; the direction is normalised, lengths in m.
    """
    p, u = as_vectors(point, 2, "point"), as_vectors(direction, 2, "direction")
    norm = np.linalg.norm(u, axis=-1, keepdims=True)
    if not ((norm > 0).all() and np.isfinite(norm).all() and np.isfinite(p).all()):
        raise ShapeError("line_through: expected a finite point and a finite direction that is not (0, 0)")
    u = u / norm
    return np.concatenate([u, (p[..., 0] * u[..., 1] - p[..., 1] * u[..., 0])[..., None]], axis=-1)


def line_residual(line: ArrayLike, point: ArrayLike) -> np.ndarray:
    """``lambda . (y, -x, 1)`` of eq. (6.19): zero iff `point` lies on `line`. ``(..., 3), (..., 2) -> (...)`` [m]."""
    lam, p = as_vectors(line, 3, "line"), as_vectors(point, 2, "point")
    return lam[..., 0] * p[..., 1] - lam[..., 1] * p[..., 0] + lam[..., 2]


def normalize_lines(lines: ArrayLike) -> np.ndarray:
    """Scale rows so that ``(lambda_x, lambda_y)`` is a unit vector (6.18), or ``d = 1`` for the line at infinity.

    ``(..., 3) -> (..., 3)``; a zero row stays zero.
    """
    lam = as_vectors(lines, 3, "lines")
    n = np.hypot(lam[..., 0], lam[..., 1])
    scale = np.where(n > 1e-12 * np.maximum(np.abs(lam[..., 2]), 1.0), n, np.abs(lam[..., 2]))
    return lam / np.where(scale > 0, scale, 1.0)[..., None]


def common_point(lines: ArrayLike) -> np.ndarray:
    """Homogeneous point ``(x, y, w)`` closest to lying on every line (exact when they are concurrent, 6.20).

    ``(..., n, 3) -> (..., 3)``; ``w = 0`` means a point at infinity (parallel lines, direction ``(x, y)``).
    It is the last right singular vector ``v`` of the line matrix mapped by ``(x, y, w) = (-v_2, v_1, v_3)``.
    """
    lam = np.asarray(lines, dtype=float)
    if lam.shape[-2] < 3:
        lam = np.concatenate([lam, np.zeros((*lam.shape[:-2], 3 - lam.shape[-2], 3))], axis=-2)
    v = np.linalg.svd(lam)[2][..., -1, :]
    return np.stack([-v[..., 1], v[..., 0], v[..., 2]], axis=-1)


@dataclass(frozen=True, eq=False)
class ConstraintLines:
    """Compiled constraint lines of a robot for one set of assigned velocities (eqs. 6.15-6.17).

    ``labels[i]`` names line i ("axle of f1", "plane of o3", "X axis (vx assigned)"...); ``wheels[i]`` its wheel
    ("" for a vehicle velocity, "a + b" for a line through a coupling). ``internal`` lists wheels whose unassigned
    joint rates are not fixed by the twist (e.g. a double wheel with none of its joints assigned): a model with
    them is always undetermined.
    """

    robot: Robot
    assigned: tuple[str, ...]
    labels: tuple[str, ...]
    wheels: tuple[str, ...]
    internal: tuple[str, ...]
    coefficients: np.ndarray  # (n_lines, 2 n_elements): combination of the element rows
    constant: np.ndarray  # (n_lines, 3): rows added for vehicle velocities
    coupled: bool = False  # the rate couplings held (constraint_lines(coupled=True) on a robot that has some)

    def lines(self, beta: ArrayLike | None = None) -> np.ndarray:
        """The lines at steering configuration `beta`: ``(..., n_steer) -> (..., n_lines, 3)`` (6.18), normalised."""
        rows = element_rows(self.robot, beta)
        lam = np.einsum("lk,...kc->...lc", self.coefficients, rows)
        terms = np.einsum("lk,...kc->...lc", np.abs(self.coefficients), np.abs(rows))
        return normalize_lines(cancel_roundoff(lam, terms, axis=-1) + self.constant)

    @property
    def steered(self) -> tuple[bool, ...]:
        """Whether each line moves with the steering configuration (it belongs to a wheel that steers)."""
        steer = set(self.robot.steer_names)
        return tuple(not steer.isdisjoint(w.split(" + ")) for w in self.wheels)

    @property
    def wheel_names(self) -> frozenset[str]:
        """The wheels whose slip rows enter some line."""
        return frozenset(n for w in self.wheels if w for n in w.split(" + "))


def constraint_lines(robot: Robot, assigned: tuple[str, ...] = (), *, coupled: bool = False) -> ConstraintLines:
    """The lines G of (6.15)-(6.17) for `assigned` velocities (names from ``robot.velocity_names``).

    With nothing assigned these are the motion constraints K_r* of (5.2)-(5.9): the ICR lies on every line.
    A model with the assigned velocities is singular iff the lines are concurrent or parallel (rank < 3, 6.17),
    or some wheel in ``internal`` has undetermined rates.

    `coupled`: the robot's rate couplings (``wmrkit.couplings``) hold: an assigned joint of a differential assigns
    its channel (the weighted sum of its joints' rates) and leaves the rates across it free; a gear train turns
    its joints together. The free rates of the coupled wheels are then eliminated together, so a line may combine
    the rows of several wheels (the actuated model of a robot driven through a differential).
    """
    check_robot(robot)
    assigned = as_names(assigned, "assigned", "velocity names", UnknownNameError)
    for name in assigned:
        robot.velocity_index(name)
    coupled = coupled and any(c.rates for c in robot.couplings)
    return _compile(robot, tuple(sorted(set(assigned), key=robot.velocity_names.index)), coupled)


@functools.lru_cache(maxsize=512)
def _compile(robot: Robot, assigned: tuple[str, ...], coupled: bool = False) -> ConstraintLines:
    # decided on the robot in its largest length (the rate blocks' null spaces are the same, the thresholds
    # relative): a double castor scaled by 39 kept a combination that cancels identically as a line of round-off
    unit = nondimensional(robot)
    rng = np.random.default_rng(0)
    probe = element_rows(unit, rng.uniform(-np.pi, np.pi, (3, len(robot.steer_names))))  # (3, 2E, 3)
    coefficients, labels, wheels, internal = [], [], [], []
    n_rows = probe.shape[-2]
    starts = np.cumsum([0] + [2 * len(w.elements()) for w in robot.wheels])
    for block, couplings in _blocks(robot, coupled):
        members = [unit.wheels[i] for i in block]
        rows = np.concatenate([np.arange(starts[i], starts[i + 1]) for i in block])
        w_block = block_diag(*[_rate_block(w) for w in members])  # (rows, n_rates) constant
        names = tuple(n for w in members for n in w.rate_names)
        selected = tuple(j for j, n in enumerate(names) if n in assigned)
        if couplings:
            sub = w_block @ unit_columns(coupled_columns(couplings, names, selected)[2])
        else:
            sub = w_block[:, [j for j in range(len(names)) if j not in selected]]
        u, s, _ = np.linalg.svd(sub) if sub.size else (np.eye(len(rows)), np.zeros(0), None)
        rank = int(np.sum(s > rank_cutoff(s)))
        if rank < sub.shape[1]:
            internal.append(" + ".join(w.name for w in members))
        for n in _clean(u[:, rank:].T):
            full = np.zeros(n_rows)
            full[rows] = n
            if np.abs(np.einsum("k,bkc->bc", full, probe)).max() < 1e-12:
                continue  # a combination that cancels identically (e.g. the shared axle of a double castor)
            parts = {i: full[starts[i]:starts[i + 1]] for i in block}
            on = [i for i in block if np.abs(parts[i]).max() > 1e-12]
            coefficients.append(full)
            wheels.append(" + ".join(robot.wheels[i].name for i in on))
            labels.append(f"{_label(robot.wheels[on[0]], parts[on[0]])} of {wheels[-1]}" if len(on) == 1 else
                          f"line of {wheels[-1]} (through the {' and '.join(c.kind for c in couplings)})")
    constant = [np.zeros(3)] * len(coefficients)
    for name in assigned:
        if name in TWIST_NAMES:
            coefficients.append(np.zeros(n_rows))
            constant.append(np.array(TWIST_LINES[name]))
            labels.append(_TWIST_LABELS[name])
            wheels.append("")
    return ConstraintLines(
        robot, assigned, tuple(labels), tuple(wheels), tuple(internal),
        readonly(np.array(coefficients).reshape(-1, n_rows)), readonly(np.array(constant).reshape(-1, 3)), coupled,
    )


def _blocks(robot: Robot, coupled: bool) -> list[tuple[tuple[int, ...], tuple[Coupling, ...]]]:
    """The wheels whose free rates are eliminated together, with the rate couplings that tie them: every wheel on
    its own, or (`coupled`) the wheels joined by rate couplings as one block."""
    group = list(range(len(robot.wheels)))  # union-find over wheel indices
    index = {w.name: i for i, w in enumerate(robot.wheels)}
    ties = [c for c in robot.couplings if c.rates] if coupled else []

    def root(i: int) -> int:
        while group[i] != i:
            i = group[i]
        return i

    for c in ties:
        first, *others = (index[j.partition(".")[0]] for j in c.joints)
        for o in others:
            group[root(o)] = root(first)
    out: dict[int, list[int]] = {}
    for i in range(len(robot.wheels)):
        out.setdefault(root(i), []).append(i)
    return [(tuple(b), tuple(c for c in ties if index[c.joints[0].partition(".")[0]] in b)) for b in out.values()]


def _rate_block(w) -> np.ndarray:
    """Joint-rate columns of a wheel's slip rows (3.10): constant, ``(2 n_elements, n_rates)``."""
    blocks = []
    for e in w.elements():
        dg, g = e.delta + e.gamma, e.gamma
        generic = np.array([[-e.d * np.cos(dg), e.r * np.sin(g), 0.0], [e.d * np.sin(dg), e.r * np.cos(g), e.r_r]])
        blocks.append(generic @ np.asarray(e.rate_map, dtype=float))
    return np.concatenate(blocks, axis=0)


def _clean(n: np.ndarray) -> np.ndarray:
    """A left-null basis in reduced row-echelon form: unit rows where it spans them (exact thesis lines)."""
    if n.shape[0] == 0:
        return n
    out = rref(n, rtol=1e-10)[0][: n.shape[0]]
    out[np.abs(out) < 1e-12] = 0.0
    return out


def _label(w, n: np.ndarray) -> str:
    names = _ROW_NAMES.get(w.type)
    nz = np.flatnonzero(np.abs(n) > 1e-12)
    if names is not None:
        if len(nz) == 1:
            return names[nz[0]]
        if w.type == "castor":
            return "steering arm"  # F_phi + tan(delta) F_beta (digest §6.2)
        return "line"
    if len(nz) == 1:
        return f"{('axle', 'plane')[nz[0] % 2]} {nz[0] // 2 + 1}"
    return "line"


def element_rows(robot: Robot, beta: ArrayLike | None = None) -> np.ndarray:
    """Twist columns of every contact element's two slip rows (3.10), in the roller frame.

    ``(..., n_steer) -> (..., 2 n_elements, 3)``: per element ``(c, s, l sin(theta - alpha) - d cos(delta+gamma))``
    and ``(-s, c, l cos(theta - alpha) + d sin(delta+gamma))`` with ``theta = beta + delta + gamma`` (3.8); these
    are the lines E/F_beta/F_s and F/F_phi of (6.1)-(6.4).
    """
    p = line_parameters(robot)
    if beta is None:
        return rows_at(p, p.beta_described)
    beta = as_vectors(beta, len(robot.steer_names), "beta")
    wheel_beta = np.broadcast_to(p.beta_described, (*beta.shape[:-1], len(p.beta_described))).copy()
    wheel_beta[..., p.steer_wheels] = beta
    return rows_at(p, wheel_beta)


def rows_at(p: LineParameters, wheel_beta: np.ndarray) -> np.ndarray:
    """:func:`element_rows` from the angle β of every wheel ``(..., n_wheels)`` -> ``(..., 2 n_elements, 3)``."""
    theta = wheel_beta[..., p.element_wheel] + p.theta_offset
    c, s = np.cos(theta), np.sin(theta)
    out = np.empty((*theta.shape[:-1], theta.shape[-1], 2, 3))
    out[..., 0, 0], out[..., 0, 1] = c, s
    out[..., 0, 2] = p.l_s_alpha_neg * c + p.l_c_alpha * s - p.d_c
    out[..., 1, 0], out[..., 1, 1] = -s, c
    out[..., 1, 2] = p.l_c_alpha * c + p.l_s_alpha * s + p.d_s
    return out.reshape(*theta.shape[:-1], 2 * theta.shape[-1], 3)


@dataclass(frozen=True, eq=False)
class LineParameters:
    """Per-element constants of the constraint lines (6.1)-(6.4), derived from the robot's element table."""

    beta_described: np.ndarray  # (N,) described beta of every wheel
    steer_wheels: np.ndarray  # (n_steer,) wheel indices of the steering wheels
    element_wheel: np.ndarray  # (E,) wheel index of each contact element
    theta_offset: np.ndarray  # (E,) beta_offset + delta + gamma
    l_c_alpha: np.ndarray  # l cos(alpha)
    l_s_alpha: np.ndarray  # l sin(alpha)
    l_s_alpha_neg: np.ndarray  # -l sin(alpha)
    d_c: np.ndarray  # d cos(delta + gamma)
    d_s: np.ndarray  # d sin(delta + gamma)


@functools.lru_cache(maxsize=512)
def line_parameters(robot: Robot) -> LineParameters:
    """The constants of :func:`element_rows` for `robot` (cached per robot)."""
    t = element_table(robot)
    dg = t.delta + t.gamma
    return LineParameters(
        beta_described=t.beta_described, steer_wheels=t.steer_wheels, element_wheel=t.element_wheel,
        theta_offset=t.beta_offset + dg, l_c_alpha=t.l * np.cos(t.alpha), l_s_alpha=t.l * np.sin(t.alpha),
        l_s_alpha_neg=-t.l * np.sin(t.alpha), d_c=t.d * np.cos(dg), d_s=t.d * np.sin(dg),
    )

