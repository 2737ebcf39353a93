"""Extended kinematic solution (thesis §4.5, eqs. 4.76, 4.82-4.84): more assigned velocities than the mobility.

A centred steerable wheel's steering rate is not a column of ``A`` (3.22), but steering the wheel changes
``A(beta)``: with ``n_o`` such wheels one may assign ``m + n_o`` velocities and choose the steering angles that
make them slip-free (4.76). At a given ``beta`` the least-squares solution (4.11) of the over-assigned system
is (4.82); its residual ``A q_dot`` is the slip indicator. The steering-angle conditions (4.83) are the roots of
that residual over the steering angles, found here numerically (batched Levenberg-Marquardt from several
starts); substituting them gives the slip-free extended solution (4.84). A ``gear`` coupling is held throughout, as
``fk`` holds it (:func:`~.linalg.geared_solve`), and :func:`extended_dof` counts the mobility it leaves; assigned
rates out of a gear's ratios are used as given, with a :class:`GearWarning`. A held ``linkage`` is judged as ``ik`` and
``fk`` judge it (:mod:`.linkage_check`): each steerable wheel keeps its own angle, and ``in_linkage`` is False where
they break the linkage's law (:class:`LinkageAngleWarning`, naming it and the wheels): angles found for the assigned
velocities (:func:`solve_steering`, :func:`no_slip_extended_solution`) as ``ik`` judges its angles for a twist, given
ones (:func:`extended_solution`) as ``fk`` judges given headings.
"""

from __future__ import annotations

import warnings
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from .._shapes import as_names, as_vectors, readonly
from ..couplings import GearWarning
from ..errors import ShapeError, SingularError, UnknownNameError
from ..robot import Robot
from .gear_check import given_gear_breaches
from .linalg import geared_solve
from .linkage_check import LinkageAngleWarning, given_breaches, ik_breaches, linkage_holds
from .models import bounded, configuration, describe_configuration, generic_mobility, velocity_indices
from .wheel_ik import FK_SLIP_RTOL, SLIP_TOL

#: Most grid starts per problem of :func:`solve_steering` (its default 8 per wheel on 4 steered wheels); beyond,
#: a seeded sample of the grid. Each start costs about 7 ms when no root exists (4096: 27 s for a swerve-4).
MAX_STARTS = 4096
#: Residual norm [m/s] below which steering angles count as slip-free (times ``1 + |A|_max |q_assigned|``).
ROOT_TOL = 1e-9


@dataclass(frozen=True, eq=False)  # eq=False: array fields
class ExtendedSolution:
    """Least-squares velocities for an over-assigned set at a batch of configurations, (4.11)/(4.82).

    ``q_dot``: ``(..., k)`` in the robot's velocity order (assigned entries copied in); ``residual``:
    ``(..., 2 n_contacts)`` slip along the roller axes (3.6) [m/s]; ``beta``: ``(..., n_steer)`` [rad];
    ``in_gear``: ``(..., n_couplings)`` bool, False where the assigned rates of a ``gear``'s joints break its ratios
    (:class:`GearWarning`; True for the other couplings); ``in_linkage``: the same shape, False where ``beta`` breaks
    a held ``linkage``'s law (:class:`LinkageAngleWarning`; module docstring).
    """

    robot_name: str
    velocity_names: tuple[str, ...]
    assigned: tuple[str, ...]
    beta: np.ndarray
    q_dot: np.ndarray
    residual: np.ndarray
    in_gear: np.ndarray
    in_linkage: np.ndarray

    @property
    def slip(self) -> np.ndarray:
        """Norm of the residual ``|A q_dot|`` [m/s], ``(...)``: zero iff the wheels do not slip here. Assigned rates
        that break a gear are used as given, as ``fk`` uses them, and each wheel keeps its own steering angle: the
        wheels may roll without slip while a gear or linkage forbids the motion, so the assignment is consistent only
        where also every ``in_gear`` and every ``in_linkage``."""
        return np.linalg.norm(self.residual, axis=-1)

    @property
    def solved(self) -> tuple[str, ...]:
        """Names of the velocities not assigned, in the robot's order."""
        return tuple(n for n in self.velocity_names if n not in self.assigned)

    def values(self, names: Sequence[str]) -> np.ndarray:
        """The entries of ``q_dot`` named `names`: ``(..., len(names))``."""
        names = as_names(names, "names", "velocity names", UnknownNameError)
        unknown = [n for n in names if n not in self.velocity_names]
        if unknown:
            raise UnknownNameError(f"no velocity '{unknown[0]}' (velocities: {', '.join(self.velocity_names)})")
        return self.q_dot[..., [self.velocity_names.index(n) for n in names]]

    def as_dict(self) -> dict[str, Any]:
        """JSON-ready summary (lists and plain values)."""
        return {"assigned": list(self.assigned), "velocity_names": list(self.velocity_names),
                "beta": self.beta.tolist(), "q_dot": self.q_dot.tolist(), "slip": self.slip.tolist(),
                "in_gear": self.in_gear.tolist(), "in_linkage": self.in_linkage.tolist()}


def extended_dof(robot: Robot) -> int:
    """Velocities an extended solution may assign: ``m + n_o`` (§4.5), m with the robot's gears
    (:func:`~.models.mobility`), n_o the steering joints (centred steerable wheels), linkages not used: each steered
    wheel counts, so a synchro drive's three linked wheels count 3, not 1 (the solutions judge the angles against the
    linkage: ``in_linkage``)."""
    return generic_mobility(robot) + sum(w.type == "steerable" for w in robot.wheels)


def extended_solution(
    robot: Robot, assigned: Sequence[str], q_assigned: ArrayLike, beta: ArrayLike | None = None, *,
    heading: ArrayLike | None = None,
) -> ExtendedSolution:
    """Least-squares solution (4.11) for any assigned set at `beta`, eq. (4.82), with its slip residual.

    ``q_assigned``: ``(..., n_a)``; ``beta``: ``(..., n_steer)`` or None; they broadcast. For a set that is
    assignable (4.10) the residual is zero; with more than m assigned velocities it is zero only at the
    steering angles of :func:`solve_steering`. ``heading`` (0 = rolling forward) instead of ``beta``: the same.
    Assigned rates that break a ``gear``'s ratios: :class:`GearWarning`, ``in_gear`` False. Given angles that break a
    held ``linkage``'s law by more than ``asin(FK_SLIP_RTOL)`` (1.15 deg), as ``fk`` judges given headings: the
    linkage cannot set them, :class:`LinkageAngleWarning`, ``in_linkage`` False.
    """
    given = "the headings" if heading is not None else "the described headings" if beta is None else "the angles beta"
    return _extended_solution(robot, assigned, q_assigned, configuration(robot, beta, heading), 4, given=given)


def _extended_solution(robot: Robot, assigned: Sequence[str], q_assigned: ArrayLike, beta: np.ndarray,
                       stacklevel: int | None, *, given: str | None) -> ExtendedSolution:
    """:func:`extended_solution` at the thesis's `beta`; `stacklevel`: of the warnings on a broken gear or linkage
    (None: the caller warned); `given`: `beta` judged as ``fk`` judges given angles, the user's name for them
    (``"the headings"``, ``"the angles beta"``), else (None) as ``ik`` judges its angles for the solution's twist
    (:func:`_in_linkage`)."""
    idx, q = _assigned(robot, assigned, q_assigned)
    in_gear = _in_gear(robot, idx, q, stacklevel)
    q_dot, residual = _solve(robot, robot.constraint_matrix(beta), idx, q)
    batch = q_dot.shape[:-1]
    beta = np.array(np.broadcast_to(beta, (*batch, beta.shape[-1])))
    in_linkage = _in_linkage(robot, beta, None if given else q_dot[..., :3], stacklevel, given)
    return ExtendedSolution(robot.name, robot.velocity_names, tuple(assigned), readonly(beta),
                            readonly(q_dot), readonly(residual),
                            readonly(np.array(np.broadcast_to(in_gear, (*batch, in_gear.shape[-1])))),
                            readonly(in_linkage))


def _in_linkage(robot: Robot, beta: np.ndarray, twist: np.ndarray | None, stacklevel: int | None,
                given: str | None = None) -> np.ndarray:
    """``(..., n_couplings)`` bool: False where the steering `beta` ``(..., n_steer)`` breaks a held ``linkage``'s law
    (:mod:`.linkage_check`, the judge of ``ik`` and ``fk``): with the solution's `twist` ``(..., 3)``, as ``ik``
    judges its angles for a twist (:func:`~.linkage_check.linkage_holds`: a wheel off the law would slip sideways
    beyond the slip floor); `twist` None, as ``fk`` judges given angles (:func:`~.linkage_check.given_breaches`,
    off by more than ``asin(FK_SLIP_RTOL)``; `given`: what the user gave them as, for the warning). A
    :class:`LinkageAngleWarning` per linkage broken in the first row that breaks one, at `stacklevel` (None: no
    warning); the headings it shows are users' (0 = rolling straight ahead) whether given as headings or beta."""
    out = np.ones((*beta.shape[:-1], len(robot.couplings)), dtype=bool)
    if not any(c.kind == "linkage" for c in robot.couplings):
        return out
    if twist is not None:
        out = linkage_holds(robot, twist, beta, SLIP_TOL)
        bad = np.argwhere(~out.all(axis=-1))
        if stacklevel is not None and len(bad):
            row = tuple(bad[0])
            for b in ik_breaches(robot, twist[row], beta[row], SLIP_TOL):
                warnings.warn(f"a steering linkage cannot set these headings: {b.describe(robot)}, which the "
                              f"assigned velocities need (set by the linkage, the wheel would slip sideways at "
                              f"{b.slip:.3g} m/s)", LinkageAngleWarning, stacklevel=stacklevel)
        return out
    rows, inverse = np.unique(beta.reshape(-1, beta.shape[-1]), axis=0, return_inverse=True)
    flat, said = out.reshape(-1, len(robot.couplings)), False
    for r, row in enumerate(rows):
        off = given_breaches(robot, row, FK_SLIP_RTOL)
        for b in off:
            flat[inverse.reshape(-1) == r, b.coupling] = False
        if stacklevel is not None and off and not said:
            said = True
            for b in off:
                warnings.warn(f"{given} break a steering linkage: {b.describe(robot)}: it cannot set them, so the "
                              f"solution at them is not the robot's motion; check {given}",
                              LinkageAngleWarning, stacklevel=stacklevel)
    return out


def _in_gear(robot: Robot, idx: np.ndarray, q: np.ndarray, stacklevel: int | None) -> np.ndarray:
    """``(..., n_couplings)`` bool: False where the assigned rates `q` ``(..., n_a)`` (columns `idx`) of a ``gear``'s
    joints break its ratios, judged row by row as ``fk`` judges its rates
    (:func:`~.gear_check.given_gear_breaches`: beyond round-off and the slip floor); a :class:`GearWarning` per
    gear broken (its first row's numbers) at `stacklevel` (None: no warning)."""
    couplings = robot.couplings
    names = tuple(robot.velocity_names[i] for i in idx)
    out = np.ones((*q.shape[:-1], len(couplings)), dtype=bool)
    if not any(c.kind == "gear" and sum(j in names for j in c.joints) >= 2 for c in couplings):
        return out  # nothing to judge: no row loop
    rows, inverse = np.unique(q.reshape(-1, q.shape[-1]), axis=0, return_inverse=True)
    flat, said = out.reshape(-1, len(couplings)), set()
    for r, row in enumerate(rows):
        for b in given_gear_breaches(robot, names, row, SLIP_TOL):
            k = next(i for i, c in enumerate(couplings) if c is b.coupling)
            flat[inverse.reshape(-1) == r, k] = False
            if stacklevel is not None and k not in said:
                said.add(k)
                warnings.warn(b.warning(names, row), GearWarning, stacklevel=stacklevel)
    return out


def _solve(robot: Robot, a: np.ndarray, idx: np.ndarray, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(4.11) with the robot's ``gear`` couplings held, as ``fk`` holds them (:func:`~.linalg.geared_solve`): a gear's
    joints turn together, so the residual is the slip of motions the mechanism allows."""
    return geared_solve(a, robot.couplings, robot.velocity_names, idx, q, "q_assigned")


def _assigned(robot: Robot, assigned: Sequence[str], q_assigned: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    """Columns of the assigned velocities and their values ``(..., n_a)``, finite and within ``MAX_QUERY_RATE``
    (NaN gave a NaN slip, 1e300 an infinite one, and solve_steering returned the guess as a root)."""
    if len(assigned) == 0:
        raise ShapeError(f"assigned: expected at least one velocity name of robot '{robot.name}', got none")
    idx = velocity_indices(robot, assigned)
    return idx, bounded(as_vectors(q_assigned, len(idx), "q_assigned"), assigned, "q_assigned")


def _wrap(x: np.ndarray) -> np.ndarray:
    return (x + np.pi) % (2 * np.pi) - np.pi


def solve_steering(
    robot: Robot, assigned: Sequence[str], q_assigned: ArrayLike, beta_guess: ArrayLike | None = None,
    *, heading: ArrayLike | None = None, starts: int = 8, iterations: int = 60,
) -> np.ndarray:
    """Steering angles making an over-assigned set slip-free, the conditions (4.83) in general form.

    Finds roots of the residual of (4.11) over the angles of the centred steerable wheels (the others, and
    castor angles, stay at `beta_guess`) by Levenberg-Marquardt from `beta_guess` (the thesis needs beta to vary
    continuously, so the nearby root is wanted); where that fails, from a grid of ``starts`` angles per wheel,
    keeping the root closest to the guess (at most :data:`MAX_STARTS` starts per problem: beyond, a seeded sample
    of the grid). ``q_assigned``: ``(..., n_a)``, finite, within ``MAX_QUERY_RATE``; ``beta_guess``:
    ``(..., n_steer)`` or None (described), or the guess as the users' ``heading`` (0 = rolling forward). Returns
    the thesis's β ``(..., n_steer)`` [rad], steerable angles wrapped to [-pi, pi). Raises
    :class:`~wmrkit.errors.SingularError` where no angle makes the assignment slip-free. Assigned rates that break a
    ``gear``'s ratios are used as given (the wheels' slip only): :class:`GearWarning`, as ``fk`` warns. Each steerable
    wheel gets its own angle; angles a held ``linkage`` cannot set for the solution's twist, as ``ik`` judges them:
    :class:`LinkageAngleWarning` naming it and the wheels.
    """
    return _solve_steering(robot, assigned, q_assigned, beta_guess, heading, starts, iterations, 4)


def _solve_steering(robot: Robot, assigned: Sequence[str], q_assigned: ArrayLike, beta_guess: ArrayLike | None,
                    heading: ArrayLike | None, starts: int, iterations: int, stacklevel: int) -> np.ndarray:
    """:func:`solve_steering`, its :class:`GearWarning` at `stacklevel`."""
    if not (isinstance(starts, int | np.integer) and starts >= 1 and isinstance(iterations, int | np.integer)
            and iterations >= 0):
        raise ShapeError(f"solve_steering: expected starts >= 1 and iterations >= 0 (integers), got {starts!r} and "
                         f"{iterations!r}")
    guess = configuration(robot, beta_guess, heading)
    idx, q = _assigned(robot, assigned, q_assigned)
    _in_gear(robot, idx, q, stacklevel)
    batch = np.broadcast_shapes(q.shape[:-1], guess.shape[:-1])
    guess = np.broadcast_to(guess, (*batch, guess.shape[-1])).reshape(-1, guess.shape[-1])
    q = np.broadcast_to(q, (*batch, q.shape[-1])).reshape(-1, q.shape[-1])
    free = [i for i, n in enumerate(robot.steer_names) if robot.wheel(n).type == "steerable"]
    if not free:
        return readonly(guess.reshape(*batch, -1).copy())
    scale = 1.0 + np.abs(robot.constraint_matrix(guess)).max(axis=(-1, -2)) * np.linalg.norm(q, axis=-1)
    tol = (ROOT_TOL * scale) ** 2  # (B,) on the squared residual

    def solve(x0: np.ndarray, rows: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """LM from starts ``x0`` ``(P, len(rows), n_o)`` for the problems `rows`."""

        def residual(x: np.ndarray) -> np.ndarray:
            beta = np.broadcast_to(guess[rows], (*x.shape[:-1], guess.shape[-1])).copy()
            beta[..., free] = x
            return _solve(robot, robot.constraint_matrix(beta), idx, q[rows])[1]

        return _levenberg_marquardt(residual, x0, iterations, tol[rows])

    x, cost = solve(guess[None][..., free], np.arange(len(q)))
    x, cost = x[0], cost[0]
    failed = np.flatnonzero(cost > tol)
    if len(failed):
        grid = np.linspace(-np.pi, np.pi, starts, endpoint=False)
        if starts ** len(free) <= MAX_STARTS:
            points = np.stack(np.meshgrid(*[grid] * len(free), indexing="ij"), -1).reshape(-1, 1, len(free))
        else:  # starts^n_o grows without bound (8 starts, 6 wheels: 262,144): a seeded sample of the grid
            points = grid[np.random.default_rng(0).integers(0, starts, (MAX_STARTS, 1, len(free)))]
        chunk = max(1, 4 * MAX_STARTS // len(points))  # problems per call: bounded memory
        for part in (failed[k:k + chunk] for k in range(0, len(failed), chunk)):
            xs, costs = solve(np.broadcast_to(points, (len(points), len(part), len(free))), part)
            distance = np.where(costs <= tol[part], np.sum(_wrap(xs - guess[part][:, free]) ** 2, axis=-1), np.inf)
            best = np.argmin(distance, axis=0)
            x[part] = xs[best, np.arange(len(part))]
            cost[part] = costs[best, np.arange(len(part))]
    bad = np.flatnonzero(cost > tol)
    if len(bad):
        where = np.unravel_index(bad[0], batch) if batch else ()
        raise SingularError(
            f"robot '{robot.name}': no steering angles make ({', '.join(assigned)}) = "
            f"{np.round(q[bad[0]], 6).tolist()} slip-free near "
            f"{describe_configuration(robot, guess.reshape(*batch, -1), tuple(int(i) for i in where))} "
            f"(smallest residual {float(np.sqrt(cost[bad[0]])):.3g} m/s)")
    out = guess.copy()
    out[:, free] = _wrap(x)
    if any(c.kind == "linkage" for c in robot.couplings):  # ik's judge on the solution's twist
        _in_linkage(robot, out, _solve(robot, robot.constraint_matrix(out), idx, q)[0][:, :3], stacklevel)
    return readonly(out.reshape(*batch, -1))


def _levenberg_marquardt(f, x: np.ndarray, iterations: int, tol: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Minimise ``|f(x)|^2`` for every start at once, ``x`` ``(..., n)``, central-difference Jacobian.

    Stops after `iterations`, or once every cost is below ``1e-12 tol`` (a polished root), or below `tol` (broadcast
    against the costs ``(...)``) with no step improving any more.
    """
    h, n = 1e-6, x.shape[-1]
    r = f(x)
    cost = np.sum(r**2, axis=-1)
    lam = np.full(cost.shape, 1e-3)
    eye = np.eye(n)
    better = np.ones(cost.shape, dtype=bool)
    for _ in range(iterations):
        if np.all(cost <= 1e-12 * tol) or (np.all(cost <= tol) and not better.any()):
            break
        steps = np.stack([(f(x + h * eye[j]) - f(x - h * eye[j])) / (2 * h) for j in range(n)], axis=-1)
        jtj = np.swapaxes(steps, -1, -2) @ steps
        g = (np.swapaxes(steps, -1, -2) @ r[..., None])[..., 0]
        damped = jtj + lam[..., None, None] * (np.diagonal(jtj, axis1=-2, axis2=-1)[..., None] * eye + 1e-12 * eye)
        dx = -np.linalg.solve(damped, g[..., None])[..., 0]
        r_new = f(x + dx)
        cost_new = np.sum(r_new**2, axis=-1)
        better = cost_new < cost
        x = np.where(better[..., None], x + dx, x)
        r = np.where(better[..., None], r_new, r)
        cost = np.where(better, cost_new, cost)
        lam = np.where(better, lam / 3, lam * 4)
    return x, cost


def no_slip_extended_solution(
    robot: Robot, assigned: Sequence[str], q_assigned: ArrayLike, beta_guess: ArrayLike | None = None, *,
    heading: ArrayLike | None = None,
) -> ExtendedSolution:
    """The slip-free extended solution (4.84): (4.82) at the steering angles of :func:`solve_steering`.

    ``(..., n_a), (..., n_steer) -> ExtendedSolution`` whose ``beta`` holds the angles to steer to (the thesis's β);
    the guess as `beta_guess` or as the users' `heading`. ``in_linkage``: the angles judged as ``ik`` judges its
    angles for the solution's twist (:class:`LinkageAngleWarning` where a held linkage cannot set them).
    """
    beta = _solve_steering(robot, assigned, q_assigned, beta_guess, heading, 8, 60, 4)  # warns: gear, linkage
    return _extended_solution(robot, assigned, q_assigned, beta, None, given=None)
