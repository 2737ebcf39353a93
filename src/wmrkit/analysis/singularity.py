"""Singularity of kinematic models (thesis ch. 6): the rank test (6.12), the line test (6.17)-(6.20), singular sets.

A model that computes the other velocities from a set of *assigned* velocities ``q_a`` exists at a
configuration iff the non-assigned columns ``A_na`` of the slip matrix (3.22) have full column rank:
``rank A_na = k - |q_a|`` (with ``|q_a| = m`` this is (6.12), ``rank A_na = rank A``; with fewer it also catches
the "undefined" case of §6.3, with more it is the rank loss of the least-squares model (6.11)). Geometrically
(§6.4, :mod:`wmrkit.analysis.lines`) the model is singular iff its constraint lines G are all concurrent or all
parallel, ``rank G < 3``. Both tests are implemented and agree (tests/analysis/test_singularity.py).

The singular set over the steering space is found exactly where it can be: every line is linear in
``(cos beta_i, sin beta_i)`` of its wheel, so each 3x3 minor of G is a trigonometric polynomial of degree <= 3
in any one steering angle; its roots are those of a degree-6 polynomial (companion matrix). One free angle gives
the exact singular angles; with more, the last angle is solved exactly on a grid of the others.
"""

from __future__ import annotations

import itertools
import numbers
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike
from scipy.optimize import minimize

from .._shapes import as_names, as_real
from ..couplings import coupled_columns
from ..errors import UnknownNameError, WmrkitError
from ..kinematics.linalg import centred, matrix_rank, nondimensional, robot_size, unit_columns
from ..kinematics.models import configuration
from ..robot import Robot, check_robot
from . import _fast
from .lines import constraint_lines, element_rows, line_parameters

#: Relative tolerance of the line test: ``sigma_min / sigma_max`` of the normalised lines below it is singular.
SINGULAR_RTOL = 1e-8


def is_singular_rank(robot: Robot, beta: ArrayLike | None, assigned: tuple[str, ...], *,
                     heading: ArrayLike | None = None, coupled: bool = False) -> np.ndarray:
    """Rank test (6.12): ``rank A_na < k - |assigned|``. ``(..., n_steer) -> (...)`` bool.

    `assigned` are names from ``robot.velocity_names`` (twist components and wheel joint rates). Steering: `beta`
    (thesis, None: as described) or `heading` (0 = rolling forward). `coupled`: the robot's rate couplings hold
    (:func:`wmrkit.couplings.coupled_columns`): ``A_na`` is the slip matrix in the free variables, the twist
    components not assigned and the free rate combinations ``T_rest``.
    """
    check_robot(robot)
    cols = [robot.velocity_index(n) for n in assigned]
    a = nondimensional(robot).constraint_matrix(beta, heading=heading)  # kinematics.linalg's tolerances
    if not {0, 1, 2} & set(cols):  # the whole twist free: that of the centroid, the same in every frame
        a = centred(robot, a)
    if coupled:
        rates = robot.rate_names
        rest = unit_columns(coupled_columns(robot.couplings, rates, tuple(rates.index(n) for n in assigned
                                                                          if n in rates))[2])
        twist = [j for j in range(3) if j not in cols]
        free = np.concatenate([a[..., twist], a[..., 3:] @ rest], axis=-1)
        return matrix_rank(free) < free.shape[-1]
    free = [j for j in range(a.shape[-1]) if j not in cols]
    return matrix_rank(a[..., free]) < len(free)


def is_singular(robot: Robot, beta: ArrayLike | None, assigned: tuple[str, ...], *,
                rtol: float = SINGULAR_RTOL, heading: ArrayLike | None = None, coupled: bool = False) -> np.ndarray:
    """Line test (6.17)-(6.20): the constraint lines G are concurrent or parallel. ``(..., n_steer) -> (...)`` bool.

    Also True when a wheel has joint rates the assigned set leaves undetermined (e.g. a double wheel with none of
    its joints assigned). Equals :func:`is_singular_rank` away from numerical ties. Uses an SVD per configuration
    (accurate to machine precision); :func:`singularity_distance` is the fast measure for maps. Steering: `beta`
    (thesis, None: as described) or `heading` (0 = rolling forward). `coupled`: through the robot's rate couplings
    (:func:`wmrkit.analysis.lines.constraint_lines`).
    """
    check_robot(robot)
    rtol = as_real(rtol, "rtol")  # '1' raised numpy's UFuncTypeError; NaN answered False everywhere
    if not 0 <= rtol < np.inf:
        raise WmrkitError(f"rtol: expected a finite relative tolerance >= 0, got {rtol}")
    cl = constraint_lines(robot, assigned, coupled=coupled)
    beta = configuration(robot, beta, heading)
    if cl.internal or len(cl.labels) < 3:
        return np.ones(beta.shape[:-1], bool)
    g = centred(robot, cl.lines(beta), metres=True)  # the same in every robot frame (kinematics.linalg)
    norm = np.linalg.norm(g, axis=-1, keepdims=True)  # a line through a coupling can vanish at some configurations
    sv = np.linalg.svd(g / np.where(norm > 0, norm, 1.0), compute_uv=False)
    return sv[..., 2] <= rtol * sv[..., 0]


def singularity_distance(robot: Robot, beta: ArrayLike | None, assigned: tuple[str, ...], *,
                         length: float | None = None, heading: ArrayLike | None = None,
                         coupled: bool = False) -> np.ndarray:
    """Distance to singularity: ``sigma_min / sigma_max`` of the lines G (6.17), rows scaled to unit norm.

    ``(..., n_steer) -> (...)`` in [0, 1]; 0 exactly at singular configurations. The ``d_lambda`` column is
    divided by `length` [m] (default: the robot's size, :func:`robot_size`) so the measure has no units.
    Steering: `beta` (thesis, None: as described) or `heading` (0 = rolling forward). `coupled`: through the
    robot's rate couplings.
    """
    check_robot(robot)
    cl = constraint_lines(robot, assigned, coupled=coupled)
    beta = configuration(robot, beta, heading)
    if cl.internal or len(cl.labels) < 3:
        return np.zeros(beta.shape[:-1])
    flat = beta.reshape(int(np.prod(beta.shape[:-1])), beta.shape[-1])
    out = np.empty(len(flat))
    if length is not None:
        length = check_positive_length(length)
    p, length = line_parameters(robot), float(robot_size(robot) if length is None else length)
    for s in range(0, len(flat), _fast.CHUNK):
        rows = _fast.element_rows_cm(p, flat[s:s + _fast.CHUNK])
        out[s:s + _fast.CHUNK] = _fast.distance_cm(_fast.combine_lines(cl, rows), length)
    return out.reshape(beta.shape[:-1])


def check_positive_length(length: float) -> float:
    """`length` as a float; :class:`WmrkitError` unless the characteristic length `length` [m] is a finite number
    > 0 (it divides the omega column), a :class:`~wmrkit.errors.ShapeError` for text and booleans (the Python API
    reads no units: '1' raised a bare TypeError). Internal searches (natural lengths, their figures) reach beyond
    the lengths a user may give, which the user's doors bound with :func:`wmrkit.limits.check_length`
    (``analyze``, ``--length``)."""
    length = as_real(length, "length")
    if not 0 < length < np.inf:  # NaN included
        raise WmrkitError(f"length: must be a finite number > 0 m, got {length}")
    return length


@dataclass(frozen=True, eq=False)
class SingularSet:
    """Where a model with `assigned` velocities is singular over the steering variables `variables`.

    ``always``: singular at every configuration; otherwise ``configurations`` ``(n, len(variables))`` [rad] lists
    singular configurations (the other steering angles at their described values): all of them when
    ``exact`` (zero or one variable), points on the singular curves/surfaces sampled on a grid otherwise, and the
    described configuration when it is singular (a sample misses a set of high codimension).
    ``reasons`` explains an ``always``. ``coordinated``: only configurations with all steered axles through one
    ICR were searched (:func:`wmrkit.analysis.coordinated.coordinated_singular_set`); ``reasons`` then describes
    the singular ICRs. ``coupled``: the robot's rate couplings held (an assigned joint of a differential assigns
    its channel), as for the actuated model.
    """

    assigned: tuple[str, ...]
    variables: tuple[str, ...]
    always: bool
    configurations: np.ndarray
    exact: bool
    reasons: tuple[str, ...] = ()
    coordinated: bool = False
    coupled: bool = False

    @property
    def never(self) -> bool:
        """No singular configuration found (certain when ``exact``)."""
        return not self.always and len(self.configurations) == 0


def singular_set(robot: Robot, assigned: tuple[str, ...], *, variables: tuple[str, ...] | None = None,
                 resolution: int = 180, max_samples: int = 20000, coupled: bool = False) -> SingularSet:
    """The singular configurations of the model with `assigned` velocities (§6.3-6.5).

    `variables`: steering wheels to vary (default: those whose lines enter G, since the others do not matter);
    the rest stay at their described angles. With more than one variable, all but the last are sampled on a
    grid of `resolution` points per turn (fewer if the grid would exceed `max_samples` points) and the last is
    solved exactly. `coupled`: through the robot's rate couplings (the actuated model of a robot with a
    differential: :func:`wmrkit.analysis.lines.constraint_lines`).
    """
    check_robot(robot)
    for key, value in (("resolution", resolution), ("max_samples", max_samples)):
        if isinstance(value, bool) or not isinstance(value, numbers.Integral) or value < 1:  # none: 'always'
            raise WmrkitError(f"singular_set: {key} must be a whole number >= 1, got {value!r}")
    cl = constraint_lines(robot, assigned, coupled=coupled)
    steer = robot.steer_names
    if variables is None:
        variables = tuple(n for n in steer if n in cl.wheel_names)
    variables = as_names(variables, "variables", "steering wheel names", UnknownNameError)
    for v in variables:
        if v not in steer:
            raise UnknownNameError(f"robot '{robot.name}' has no steering wheel '{v}' (steering: {', '.join(steer)})")
    idx = [steer.index(v) for v in variables]
    base = robot.beta
    empty = np.zeros((0, len(variables)))
    if cl.internal:
        why = tuple(f"the joint rates of {w} are not determined by the assigned velocities" for w in cl.internal)
        return SingularSet(cl.assigned, variables, True, empty, True, why, coupled=cl.coupled)
    if len(cl.labels) < 3:
        why = (f"only {len(cl.labels)} constraint line(s): fewer assigned velocities than the mobility",)
        return SingularSet(cl.assigned, variables, True, empty, True, why, coupled=cl.coupled)
    if not variables:
        sing = bool(is_singular(robot, base, cl.assigned, coupled=cl.coupled))
        why = ("the lines " + ", ".join(cl.labels) + " are concurrent or parallel",) if sing else ()
        return SingularSet(cl.assigned, variables, sing, empty, True, why, coupled=cl.coupled)
    per_axis = resolution if len(idx) <= 2 else min(resolution, int(max_samples ** (1 / (len(idx) - 1))))
    grid = np.linspace(-np.pi, np.pi, per_axis, endpoint=False)
    if per_axis < 4:  # too many variables for a grid (numpy has 32 axes at most): a seeded random sample
        outer = np.random.default_rng(0).uniform(-np.pi, np.pi, (max_samples, len(idx) - 1))
    else:
        mesh = np.meshgrid(*([grid] * (len(idx) - 1)), indexing="ij")
        outer = np.stack([g.ravel() for g in mesh], axis=-1) if mesh else np.zeros((1, 0))
    configs = np.broadcast_to(base, (len(outer), len(steer))).copy()
    configs[:, idx[:-1]] = outer
    roots, always = _roots_last(cl, configs, idx[-1])
    if always.all():
        return SingularSet(cl.assigned, variables, True, empty, len(idx) == 1,
                           ("the lines " + ", ".join(cl.labels) + " are always concurrent or parallel",),
                           coupled=cl.coupled)
    found = [np.zeros((0, len(idx)))]
    for i, rs in enumerate(roots):
        values = grid if always[i] else rs  # a whole line of the last angle is singular: sample it
        c = np.repeat(configs[i][None], len(values), axis=0)
        c[:, idx[-1]] = values
        found.append(c[:, idx])
    if 4 <= per_axis and len(idx) >= 2 and sum(map(len, found)) == 0:  # isolated points (codimension 2) escape
        # the curve sampling (searched on a grid: not with a random sample)
        found.append(_isolated(cl, base, idx, per_axis))
    found_arr = np.concatenate(found)
    described = base[idx]  # a sample misses a set of high codimension (castors at rest all pointing one way)
    if (len(idx) >= 2 and not np.any(np.all(np.abs(found_arr - described) < 1e-9, axis=1))
            and is_singular(robot, base, cl.assigned, coupled=cl.coupled)):
        found_arr = np.concatenate([found_arr, described[None]])
    if len(found_arr):
        found_arr = found_arr[np.lexsort(found_arr.T[::-1])]
    return SingularSet(cl.assigned, variables, False, found_arr, len(idx) == 1, coupled=cl.coupled)


def _isolated(cl, base: np.ndarray, idx: list[int], per_axis: int, count: int = 8) -> np.ndarray:
    """Local minima of the singularity distance on a grid, refined by Nelder-Mead; those that reach zero."""
    axis = np.linspace(-np.pi, np.pi, per_axis, endpoint=False)
    mesh = np.stack(np.meshgrid(*([axis] * len(idx)), indexing="ij"), axis=-1)
    beta = np.broadcast_to(base, (*mesh.shape[:-1], len(base))).copy()
    beta[..., idx] = mesh
    dist = singularity_distance(cl.robot, beta, cl.assigned, coupled=cl.coupled)
    is_min = dist < 0.2
    for ax in range(len(idx)):
        is_min &= (dist <= np.roll(dist, 1, ax)) & (dist <= np.roll(dist, -1, ax))
    starts = np.argwhere(is_min)
    starts = starts[np.argsort(dist[tuple(starts.T)])][:count]

    def f(x):
        b = base.copy()
        b[idx] = x
        return float(singularity_distance(cl.robot, b, cl.assigned, coupled=cl.coupled))

    out: list[np.ndarray] = []
    for s in starts:
        res = minimize(f, axis[s], method="Nelder-Mead", options={"xatol": 1e-12, "fatol": 1e-15, "maxiter": 800})
        x = np.mod(res.x + np.pi, 2 * np.pi) - np.pi
        if res.fun < 1e-9 and not any(np.abs(np.angle(np.exp(1j * (x - y)))).max() < 1e-6 for y in out):
            out.append(x)
    return np.array(out).reshape(-1, len(idx))


def _roots_last(cl, configs: np.ndarray, j: int) -> tuple[list[np.ndarray], np.ndarray]:
    """Exact singular values of steering angle `j` for each row of `configs` ``(B, n_steer)``."""
    n_fit = 7  # a trigonometric polynomial of degree 3 is fixed by 7 samples
    t = 2 * np.pi * np.arange(n_fit) / n_fit
    samples = np.repeat(configs[:, None, :], n_fit, axis=1)
    samples[..., j] = t
    raw = np.einsum("lk,...kc->...lc", cl.coefficients, element_rows(cl.robot, samples)) + cl.constant
    triples = _triples(cl, raw.shape[-2])
    with np.errstate(divide="ignore", under="ignore"):  # LAPACK's LU flags a subnormal pivot (an angle of 1e-311
        minors = np.linalg.det(raw[..., triples, :])  # rad); the minor is then +-0, as it should be. (B, 7, M)
    basis = np.stack([np.ones(n_fit)] + [f(k * t) for k in (1, 2, 3) for f in (np.cos, np.sin)], axis=1)
    coef = np.linalg.solve(basis, minors)  # (B, 7, M): a0, a1, b1, a2, b2, a3, b3
    scale = np.maximum(np.abs(raw).max(axis=(1, 2, 3)), 1e-300) ** 3
    size = np.abs(coef).max(axis=1)  # (B, M)
    always = ~(size > 1e-10 * scale[:, None]).any(axis=1)
    c = coef[np.arange(len(coef)), :, np.argmax(size, axis=1)]  # (B, 7)
    a, b = c[:, 1::2], c[:, 2::2]
    poly = np.concatenate([((a - 1j * b) / 2)[:, ::-1], c[:, :1], (a + 1j * b) / 2], axis=1)  # z^6 ... z^0
    roots: list[np.ndarray] = [np.zeros(0, complex)] * len(poly)  # rows that vanish identically have no roots
    for i, z in zip(np.flatnonzero(~always), _poly_roots(poly[~always]), strict=True):
        roots[i] = z
    row = np.concatenate([np.full(len(z), i) for i, z in enumerate(roots)] + [np.zeros(0, int)]).astype(int)
    z = np.concatenate([*roots, np.zeros(0, complex)])
    on_circle = (np.abs(np.abs(z) - 1) < 1e-4) & ~always[row]
    row, x = row[on_circle], _newton(c[row[on_circle]], np.angle(z[on_circle]))
    beta = configs[row].copy()
    beta[:, j] = x
    ok = _rank_deficient(cl, beta)
    row, x = row[ok], np.mod(x[ok] + np.pi, 2 * np.pi) - np.pi
    out = []
    for i in range(len(configs)):
        keep = np.sort(x[row == i])
        if len(keep) > 1:
            gap = np.diff(np.concatenate([keep, keep[:1] + 2 * np.pi]))
            keep = keep[gap > 1e-7]
        out.append(keep)
    return out, always


def _triples(cl, n_lines: int) -> np.ndarray:
    """Row triples whose minors are used: all of them, or the 20 largest at random configurations."""
    triples = np.array(list(itertools.combinations(range(n_lines), 3)))
    if len(triples) <= 20:
        return triples
    beta = np.random.default_rng(1).uniform(-np.pi, np.pi, (8, len(cl.robot.steer_names)))
    g = cl.lines(beta)
    size = np.abs(np.linalg.det(g[:, triples, :])).max(axis=0)
    return triples[np.argsort(size)[::-1][:20]]


def _poly_roots(poly: np.ndarray) -> list[np.ndarray]:
    """Roots of each row's polynomial (highest power first), leading and trailing near-zeros trimmed; batched."""
    mag = np.abs(poly)
    big = mag > 1e-12 * np.maximum(mag.max(axis=1, keepdims=True), 1e-300)
    first = np.argmax(big, axis=1)
    last = poly.shape[1] - 1 - np.argmax(big[:, ::-1], axis=1)
    out: list[np.ndarray] = [np.zeros(0, complex)] * len(poly)
    for lo, hi in set(zip(first.tolist(), last.tolist(), strict=True)):
        rows = np.flatnonzero((first == lo) & (last == hi) & big.any(axis=1))
        deg = hi - lo
        if deg <= 0:
            continue
        p = poly[rows, lo:hi + 1]
        comp = np.zeros((len(rows), deg, deg), complex)
        comp[:, 0, :] = -p[:, 1:] / p[:, :1]
        comp[:, np.arange(1, deg), np.arange(deg - 1)] = 1.0
        for r, z in zip(rows, np.linalg.eigvals(comp), strict=True):
            out[r] = z
    return out


def _newton(c: np.ndarray, x: np.ndarray) -> np.ndarray:
    """Two Newton steps on ``a0 + sum a_k cos(k x) + b_k sin(k x)`` (coefficient rows `c` ``(n, 7)``) from `x`."""
    k = np.arange(1, 4)
    a, b = c[:, 1::2], c[:, 2::2]
    tiny = 1e-9 * np.abs(c).max(axis=1, initial=0.0)
    for _ in range(2):
        kx = x[:, None] * k
        f = c[:, 0] + np.sum(np.cos(kx) * a + np.sin(kx) * b, axis=1)
        df = np.sum(k * (np.cos(kx) * b - np.sin(kx) * a), axis=1)
        step = np.where(np.abs(df) > tiny, f / np.where(df == 0, 1.0, df), 0.0)
        x = x - np.clip(step, -1e-3, 1e-3)
    return x


def _rank_deficient(cl, beta: np.ndarray) -> np.ndarray:
    """Where the lines really have rank < 3 (all minors vanish): ``(n, n_steer) -> (n,)`` bool."""
    g = centred(cl.robot, cl.lines(beta), metres=True)
    s = np.linalg.svd(g, compute_uv=False)
    return s[:, -1] < 1e-6 * s[:, 0]
