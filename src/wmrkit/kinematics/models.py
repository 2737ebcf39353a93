"""No-slip kinematic models of a robot (thesis ch. 4): mobility, assignable sets, direct/inverse/mixed models.

A model assigns (chooses freely) ``m`` of the velocities ``q_dot = (vx, vy, omega, wheel rates)`` and gives the
others: ``q_solved = matrix @ q_assigned``. Assigning wheel rates gives the *direct* model, twist components the
*inverse* model, a mixture a *mixed* model (§4.2). Everything is batched over steering configurations
``beta`` ``(..., n_steer)`` (``None``: the described configuration, batch shape ``()``); assignability depends
on the configuration, and a set assignable at generic angles can fail at a singular one. A ``gear`` coupling's
joints turn together (``q_j = ratio_j * u``): its rows ``q_i / ratio_i = q_j / ratio_j`` join the constraint matrix
(:func:`constraints`), so the mobility, the sets and the models are those of the motions the mechanism allows.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, Literal

import numpy as np
from numpy.typing import ArrayLike

from .._shapes import as_names, as_vectors, matvec, readonly
from ..errors import ShapeError, SingularError, WmrkitError
from ..limits import MAX_QUERY_RATE
from ..robot import TWIST_NAMES, Robot, check_robot
from .linalg import centred, coupled_constraints, matrix_rank, nondimensional, nullity, velocity_scale
from .nullspace import null_space_assignable, null_space_basis, null_space_solution, rref_solution
from .ranks import ranks_assignable, ranks_solution
from .search import SetList, exact_budget, null_space_cost, null_space_prefilter, search_sets

Method = Literal["ranks", "nullspace", "rref"]

#: Random configurations tried by :func:`generically_assignable_sets` (a fixed seed: results are reproducible).
GENERIC_SAMPLES = 3


@dataclass(frozen=True, eq=False)  # eq=False: array fields
class KinematicModel:
    """A no-slip kinematic model at a batch of configurations, eqs. (4.5)/(4.6)/(4.11).

    ``matrix``: ``(..., n_solved, n_assigned)`` read-only, ``q_solved = matrix @ q_assigned``;
    ``beta``: ``(..., n_steer)`` read-only. Units: m/s, rad/s.
    """

    robot_name: str
    velocity_names: tuple[str, ...]  # all of q_dot, in the robot's order
    assigned: tuple[str, ...]
    solved: tuple[str, ...]  # the others, in the robot's order
    beta: np.ndarray
    matrix: np.ndarray
    method: str

    @property
    def kind(self) -> str:
        """``'direct'`` (wheel rates assigned), ``'inverse'`` (twist components assigned), ``'mixed'``, or
        ``'none'`` when nothing is assigned (m = 0: the robot cannot move)."""
        twist = [n in TWIST_NAMES for n in self.assigned]
        if not twist:
            return "none"
        return "inverse" if all(twist) else "direct" if not any(twist) else "mixed"

    def solve(self, q_assigned: ArrayLike) -> np.ndarray:
        """The solved velocities for assigned ones: ``(..., n_assigned) -> (..., n_solved)``. The assigned values
        must be finite and within ``MAX_QUERY_RATE`` (m/s, rad/s): NaN and 1e308 gave NaN and overflowing rates."""
        q = bounded(as_vectors(q_assigned, len(self.assigned), "q_assigned"), self.assigned, "q_assigned")
        return matvec(self.matrix, q, "q_assigned")

    def velocities(self, q_assigned: ArrayLike) -> np.ndarray:
        """The whole velocity vector ``q_dot`` (robot order): ``(..., n_assigned) -> (..., k)``; ``A q_dot = 0``."""
        q = as_vectors(q_assigned, len(self.assigned), "q_assigned")
        solved = self.solve(q)
        out = np.empty((*solved.shape[:-1], len(self.velocity_names)))
        out[..., [self.velocity_names.index(n) for n in self.solved]] = solved
        out[..., [self.velocity_names.index(n) for n in self.assigned]] = q
        return out

    def as_dict(self) -> dict[str, Any]:
        """JSON-ready description: names, kind, configuration and matrix (nested lists)."""
        return {
            "robot": self.robot_name, "kind": self.kind, "method": self.method,
            "assigned": list(self.assigned), "solved": list(self.solved),
            "beta": self.beta.tolist(), "matrix": self.matrix.tolist(),
        }


def configuration(robot: Robot, beta: ArrayLike | None, heading: ArrayLike | None = None) -> np.ndarray:
    """The thesis's β ``(..., n_steer)`` from `beta` or `heading` (users' angles), or the described one when None."""
    beta = robot.steering(beta, heading)
    return robot.beta if beta is None else beta


def own_turn(robot: Robot) -> float:
    """The angle [rad] of the robot's own axes random configurations are drawn in: the first wheel's described
    ``beta`` (its axle, or a castor's steering frame), which turns with the robot frame, so a rigid change of frame
    draws the same configurations of the wheels (the robot's x axis would draw other ones in a turned frame); within
    half a turn of 0 (a beta described near the angle limit of 1e6 turns leaves room to draw about it)."""
    return math.remainder(robot.wheels[0].beta, 2 * math.pi) if robot.wheels else 0.0


def random_steering(robot: Robot, n: int, rng: np.random.Generator) -> np.ndarray:
    """`n` random configurations ``(n, n_steer)``: steering angles uniform about the robot's own axes
    (:func:`own_turn`). The generic rank over them is the largest met (the least m): a rank only drops on a special
    set of configurations, and numerically near it."""
    return own_turn(robot) + rng.uniform(-np.pi, np.pi, (n, len(robot.steer_names)))


def describe_configuration(robot: Robot, beta: np.ndarray, index: tuple[int, ...] = ()) -> str:
    """``"beta (w3=0.4 rad)"``, with ``[i, j]`` for an element of a batch; ``"the fixed geometry"`` if no steering."""
    if not robot.steer_names:
        return "the fixed geometry"
    values = robot.heading_of_beta(beta[index] if beta.ndim > 1 else beta)
    angles = ", ".join(f"{n}={math.degrees(v):.6g} deg"
                       for n, v in zip(robot.steer_names, values.tolist(), strict=True))
    where = f"configuration {list(index)} " if index else ""
    return f"{where}heading ({angles})"


def constraints(robot: Robot, beta: np.ndarray, gears: bool = True) -> np.ndarray:
    """The matrix every model here derives from: the nondimensional (:mod:`.linalg`) no-slip matrix (3.22) at `beta`,
    with a row per direction a ``gear`` coupling holds (:func:`~.linalg.coupled_constraints`) unless not `gears`."""
    unit = nondimensional(robot)
    return coupled_constraints(unit, beta) if gears else unit.constraint_matrix(beta)


def mobility(robot: Robot, beta: ArrayLike | None = None, *, heading: ArrayLike | None = None,
             gears: bool = True) -> np.ndarray:
    """Degree of mobility ``m = k - rank A`` (4.3): ``(..., n_steer) -> (...)`` int (β or `heading`). ``A`` holds the
    robot's ``gear`` couplings (a row per direction a gear forbids), as the models here do; ``gears=False``: the
    wheels' alone, the thesis's m (equal without a gear)."""
    check_robot(robot)
    a = constraints(robot, configuration(robot, beta, heading), gears)
    return nullity(robot, a)


def bounded(q: np.ndarray, names: Sequence[str], argument: str, limit: float = MAX_QUERY_RATE) -> np.ndarray:
    """`q` ``(..., len(names))`` itself, or :class:`ShapeError` naming `argument` and the velocity of the first value
    that is not a finite number within `limit` (default ``MAX_QUERY_RATE``, m/s, rad/s; ``math.inf``: any finite
    number): the models' products gave NaN or overflowed."""
    bad = ~np.isfinite(q) | (np.abs(q) > limit)
    if bad.any():
        where = tuple(int(x) for x in np.argwhere(bad)[0])
        within = f" within {limit:g} (rad/s or m/s)" if math.isfinite(limit) else ""
        raise ShapeError(f"{argument}: {names[where[-1]]}: expected finite numbers{within}, got {float(q[where])}")
    return q


def velocity_indices(robot: Robot, names: Sequence[str]) -> np.ndarray:
    """Columns of ``A`` (3.22) of the velocities `names` ``(n,)``; unknown or repeated names raise."""
    names = as_names(names, "assigned velocities", error=WmrkitError)
    if len(set(names)) != len(names):
        raise WmrkitError(f"assigned velocities: repeated name in {tuple(names)}")
    return np.array([robot.velocity_index(n) for n in names], dtype=int).reshape(len(names))


def _ranks(robot: Robot, a: np.ndarray) -> dict[str, np.ndarray]:
    """The keywords of :func:`~.ranks.ranks_assignable` that tie its sets to `robot`'s mobility (:func:`mobility`)
    for its nondimensional matrix `a`: the centroid's matrix and the rank m is read from."""
    whole = centred(robot, a)
    return {"whole": whole, "rank_a": matrix_rank(whole)}


def _assignable(robot: Robot, a: np.ndarray, subsets: np.ndarray, method: Method) -> np.ndarray:
    if method == "ranks":
        return ranks_assignable(a, subsets, **_ranks(robot, a))
    if method == "nullspace":
        return null_space_assignable(a, subsets)
    if method == "rref":
        return np.stack([rref_solution(a, s)[1] for s in subsets]).reshape(len(subsets), *a.shape[:-2])
    raise WmrkitError(f"method must be 'ranks', 'nullspace' or 'rref', got {method!r}")


def is_assignable(
    robot: Robot, names: Sequence[str], beta: ArrayLike | None = None, *, method: Method = "ranks",
    heading: ArrayLike | None = None,
) -> np.ndarray:
    """Whether the velocities `names` can be assigned, (4.5)/(4.6)/(4.10): ``(..., n_steer) -> (...)`` bool;
    steering `beta` (thesis) or `heading` (0 = rolling forward)."""
    a = constraints(robot, configuration(robot, beta, heading))
    return _assignable(robot, a, velocity_indices(robot, names)[None, :], method)[0]


def _sets_at(robot: Robot, a: np.ndarray, method: Method) -> tuple[tuple[str, ...], ...]:
    ranks = _ranks(robot, a)
    m = np.unique(a.shape[-1] - ranks["rank_a"])  # nullity(robot, a), from the rank the sets are tied to
    if len(m) != 1:  # the mobility changes within the batch: no set fits every configuration
        return SetList()

    def test(s: np.ndarray) -> np.ndarray:
        ok = ranks_assignable(a, s, **ranks) if method == "ranks" else _assignable(robot, a, s, method)
        return ok.reshape(len(s), -1).all(axis=1)

    sets, complete, note = search_sets(  # bounded, pruned by the null-space test (.search)
        range(a.shape[-1]), int(m[0]), test,
        prefilter=null_space_prefilter(a, int(m[0])), max_exact=exact_budget(a.shape, 2),
        walk_cost=null_space_cost(a.shape, int(m[0])), what="assignable sets")
    names = robot.velocity_names
    return SetList([tuple(names[i] for i in s) for s in sets], complete, note)


def assignable_sets(
    robot: Robot, beta: ArrayLike | None = None, *, method: Method = "ranks", heading: ArrayLike | None = None,
) -> tuple[tuple[str, ...], ...]:
    """Every set of m velocities that can be assigned at every configuration of `beta` (thesis) or `heading`
    (0 = rolling forward) (4.8: C(k, m) tests).

    Sets are tuples of velocity names in the robot's order, listed lexicographically.
    """
    check_robot(robot)
    return _sets_at(robot, constraints(robot, configuration(robot, beta, heading)), method)


def generic_configurations(robot: Robot) -> np.ndarray:
    """A few random steering configurations (fixed seed): ``(GENERIC_SAMPLES, n_steer)`` [rad]."""
    rng = np.random.default_rng(20040101)
    return rng.uniform(-np.pi, np.pi, size=(GENERIC_SAMPLES, len(robot.steer_names)))


def generic_mobility(robot: Robot) -> int:
    """The mobility at generic (random) steering angles: the smallest m over :func:`generic_configurations`."""
    return int(np.min(mobility(robot, generic_configurations(robot))))


def generically_assignable_sets(robot: Robot) -> tuple[tuple[str, ...], ...]:
    """The sets assignable at generic steering angles (almost every configuration); some fail at singular ones.

    A set is generically assignable when it is assignable at one of a few random configurations of generic
    mobility: assignability is the non-vanishing of an analytic function of beta, true almost everywhere or
    nowhere.
    """
    samples = generic_configurations(robot)
    a = constraints(robot, samples)
    m = generic_mobility(robot)
    ranks = _ranks(robot, a)
    generic = a.shape[-1] - ranks["rank_a"] == m  # nullity: one at least, m is the smallest of the samples'
    sets, complete, note = search_sets(  # bounded, pruned by the null-space test at one generic sample at least
        range(a.shape[-1]), m, lambda s: (ranks_assignable(a, s, **ranks) & generic).any(axis=1),
        prefilter=null_space_prefilter(a[generic], m, every=False), max_exact=exact_budget(a.shape, 2),
        walk_cost=null_space_cost(a[generic].shape, m), what="generically assignable sets")
    names = robot.velocity_names
    return SetList([tuple(names[i] for i in s) for s in sets], complete, note)


def _refuse(robot: Robot, names: Sequence[str], beta: np.ndarray, ok: np.ndarray) -> SingularError:
    bad = tuple(int(i) for i in np.argwhere(~ok)[0]) if ok.ndim else ()
    beta_bad = beta[bad] if beta.ndim > 1 else beta
    m_here, m_generic = int(mobility(robot, beta_bad)), generic_mobility(robot)
    label = f"({', '.join(names)})" if names else "() (no velocity)"
    if len(names) != m_here:
        why = f"a model assigns exactly m = {m_here} velocities here, got {len(names)}"
        why += f" (m = {m_generic} at generic angles)" if m_generic != m_here else ""
    elif tuple(names) in generically_assignable_sets(robot):
        why = "assignable at generic steering angles but not at this singular configuration"
    else:
        why = "not assignable at generic steering angles either"
    here = ["(" + ", ".join(s) + ")" for s in assignable_sets(robot, beta_bad)]
    hint = f"; assignable here: {' '.join(here[:8])}{' ...' if len(here) > 8 else ''}" if here else ""
    where = describe_configuration(robot, beta, bad)
    return SingularError(f"robot '{robot.name}': velocities {label} cannot be assigned at {where}: {why}{hint}")


def kinematic_model(
    robot: Robot, assigned: Sequence[str], beta: ArrayLike | None = None, *, method: Method = "ranks",
    heading: ArrayLike | None = None,
) -> KinematicModel:
    """The kinematic model with the velocities `assigned` chosen freely (4.5, 4.6 or 4.11 by `method`).

    ``beta``: ``(..., n_steer)`` or None; the model's matrix is ``(..., n_solved, n_assigned)``. Raises
    :class:`~wmrkit.errors.SingularError` naming the set and the first configuration where it is not
    assignable, and whether it is assignable at generic angles. Steering as the thesis's `beta` or as `heading`.
    """
    check_robot(robot)
    beta = configuration(robot, beta, heading)
    idx = velocity_indices(robot, assigned)
    a = constraints(robot, beta)
    if method == "ranks":
        ok, matrix = ranks_assignable(a, idx[None, :], **_ranks(robot, a))[0], ranks_solution(a, idx)
    elif method in ("nullspace", "rref"):
        matrix, ok = (null_space_solution if method == "nullspace" else rref_solution)(a, idx)
    else:
        raise WmrkitError(f"method must be 'ranks', 'nullspace' or 'rref', got {method!r}")
    if not np.all(ok):
        raise _refuse(robot, tuple(assigned), beta, np.asarray(ok))
    names = robot.velocity_names
    solved = tuple(n for n in names if n not in assigned)
    return KinematicModel(robot.name, names, tuple(assigned), solved, readonly(np.array(beta)),
                          readonly(np.ascontiguousarray(_dimensional(robot, matrix, idx))), method)


def _dimensional(robot: Robot, matrix: np.ndarray, assigned: np.ndarray) -> np.ndarray:
    """A model matrix of :func:`~.linalg.nondimensional` back in `robot`'s velocities (``q' = scale * q``)."""
    scale = velocity_scale(robot)
    solved = np.setdiff1d(np.arange(len(scale)), assigned)
    return matrix * scale[assigned] / scale[solved][:, None]


def _first_assignable(robot: Robot, a: np.ndarray, candidates: Sequence[str],
                      m: int) -> tuple[tuple[str, ...] | None, str]:
    """The first assignable set of `m` of `candidates` (None if none was found) and, when the bounded search
    stopped before its end, its note (else ``""``)."""
    names = robot.velocity_names
    columns = [names.index(n) for n in candidates]
    ranks = _ranks(robot, a)
    found, complete, note = search_sets(
        columns, m, lambda s: ranks_assignable(a, s, **ranks).reshape(len(s), -1).all(axis=1),
        prefilter=null_space_prefilter(a, m), limit=1, max_exact=exact_budget(a.shape, 2),
        walk_cost=null_space_cost(a.shape, m))
    return (tuple(names[i] for i in found[0]) if found else None), "" if complete else note


def _none_assignable(robot: Robot, what: str, beta: np.ndarray, note: str) -> SingularError:
    """No set of `what` can be assigned at `beta`, or, when the search stopped early (`note`), none was found."""
    where = describe_configuration(robot, beta)
    if not note:
        return SingularError(f"robot '{robot.name}': no {what} can be assigned at {where}")
    return SingularError(f"robot '{robot.name}': no {what} was found assignable at {where} before the {note}; name "
                         "the velocities to assign")


def direct_model(
    robot: Robot, rates: Sequence[str] | None = None, beta: ArrayLike | None = None, *,
    heading: ArrayLike | None = None,
) -> KinematicModel:
    """Direct model (§4.2): the twist and the other rates from m assigned wheel rates.

    ``rates=None`` takes the first assignable set of the robot's *sensed* rates, or failing that of all its
    wheel rates (roller rates excluded: they cannot be measured, §3.3.3).
    """
    check_robot(robot)
    beta = configuration(robot, beta, heading)
    if rates is not None:
        return kinematic_model(robot, rates, beta)
    a = constraints(robot, beta)
    m = int(np.max(nullity(robot, a)))
    usable = [n for n in robot.rate_names if not n.endswith(".roller")]
    sensed = [n for n in usable if n in robot.sensed]
    choice, note = _first_assignable(robot, a, sensed, m)
    if choice is None:
        choice, other = _first_assignable(robot, a, usable, m)
        note = other or note
    if choice is None:
        raise _none_assignable(robot, f"set of {m} wheel rates", beta, note)
    return kinematic_model(robot, choice, beta)


def _free_steering(robot: Robot, a: np.ndarray, dof: int) -> tuple[str, ...]:
    """The double wheels' steering rates (``robot.free_steering``) that no twist determines on the motions `a`
    ``(..., R, k)`` allows (`dof` of them), in order: each one kept while its row of the null space adds to the rank
    of the twist's rows and those kept. A ``gear`` turning several is one input (its first joint); a wheel whose
    spins a gear holds apart from turning on the spot steers with the twist, and with every joint locked (dof 0)
    none is free."""
    if not dof:
        return ()
    basis = null_space_basis(a, dof)
    rows, rank, free = basis[..., :3, :], matrix_rank(basis[..., :3, :]), []
    for name in robot.free_steering:
        more = np.concatenate([rows, basis[..., [robot.velocity_index(name)], :]], axis=-2)
        if np.any(matrix_rank(more) > rank):
            rows, rank, free = more, matrix_rank(more), [*free, name]
    return tuple(free)


def generic_inputs(robot: Robot, samples: int = 8) -> tuple[tuple[str, ...], int]:
    """The default inverse model's steering inputs (:func:`_free_steering`) and the mobility m with the gears, at
    generic steering (the least m over `samples` :func:`random_steering` configurations, and the inputs on those
    that meet it): the inputs of the closed forms and of the generated code."""
    a = constraints(robot, random_steering(robot, samples, np.random.default_rng(7)))
    m = nullity(robot, a)
    dof = int(m.min())
    return _free_steering(robot, a[m == dof], dof), dof


def inverse_model(
    robot: Robot, twist_names: Sequence[str] | None = None, beta: ArrayLike | None = None, *,
    heading: ArrayLike | None = None,
) -> KinematicModel:
    """Inverse model (§4.2): the wheel rates (and remaining twist components) from m assigned twist components.

    ``twist_names=None`` takes the first assignable subset of ``(vx, vy, omega)`` of size m, with the steering
    rates of double wheels that no twist determines (``robot.free_steering``, but those the gears tie to the twist
    or to another) assigned too.
    """
    check_robot(robot)
    beta = configuration(robot, beta, heading)
    if twist_names is not None:
        return kinematic_model(robot, twist_names, beta)
    a = constraints(robot, beta)
    dof = int(np.max(nullity(robot, a)))
    free = _free_steering(robot, a, dof)  # double wheels' steering rates that no twist determines
    m = dof - len(free)  # assigned, unless the gears lock everything (dof 0: the empty model, as the direct one's)
    if free:
        fixed = [robot.velocity_index(n) for n in free]
        combinations = itertools.combinations(TWIST_NAMES, m) if 0 < m <= 3 else ()  # gears can leave m <= 0
        ranks = _ranks(robot, a)
        choice = next((c + free for c in combinations if ranks_assignable(
            a, [[robot.velocity_index(n) for n in c] + fixed], **ranks).all()), None)
        note = ""
    else:
        choice, note = _first_assignable(robot, a, TWIST_NAMES, m)
    if choice is None:
        also = f" with {', '.join(free)}" if free else ""
        count = f"{m} of" if m > 0 else "set of"  # the gears may leave no twist beside the free steering rates
        error = _none_assignable(robot, f"{count} (vx, vy, omega){also}", beta, note)
        if dof and np.all(np.abs(null_space_basis(a, dof)[..., :3, :]) < 1e-9):  # the twist rows of N(A) are 0
            its = "its degree of freedom moves" if dof == 1 else f"its {dof} degrees of freedom move"
            error = SingularError(f"{error}: the body cannot move ({its} the joints with the body at rest; the "
                                  "direct model assigns them)")
        raise error
    return kinematic_model(robot, choice, beta)
