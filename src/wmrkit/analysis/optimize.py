"""Finding isotropic or best-conditioned configurations and geometries (thesis §5.4-5.5 criteria).

"Isotropy must be achieved" (§5.4): with steered wheels it is a planning criterion (stay near isotropic
configurations, :func:`best_configurations`); without, a design criterion on the geometry
(:func:`optimize_geometry`). Objectives: the condition number at the natural length (5.28), or the global
isotropy of Kim et al. 05 (mean of 1/kappa over the steering space, §5.4 and digest §3.3).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike
from scipy.optimize import minimize

from .._shapes import as_names, as_real, as_reals
from ..errors import ShapeError, UnknownNameError, WmrkitError
from ..limits import check_seed
from ..robot import Robot, check_robot
from . import _fast
from ._sym import eigvalsh2_entries
from .isotropy import _kappa, _natural_length, golden_section, kappa_function, natural_length, twist_model
from .lines import constraint_lines, line_parameters
from .singularity import check_positive_length, robot_size


@dataclass(frozen=True)
class Conditioning:
    """A steering configuration ``beta`` ``(n_steer,)`` [rad], its length D [m] and condition number (5.28).

    ``heading`` is the same configuration as the users' angles (rolling directions, 0 = straight ahead), by the
    robot's own conversion :meth:`~wmrkit.robot.Robot.heading_of_beta`; ``beta`` is the thesis's.
    """

    beta: tuple[float, ...]
    length: float
    condition_number: float
    heading: tuple[float, ...]


def best_configurations(robot: Robot, *, joints: tuple[str, ...] | None = None, length: float | None = None,
                        variables: tuple[str, ...] | None = None, resolution: int = 72,
                        max_samples: int = 20000, count: int = 8) -> tuple[Conditioning, ...]:
    """Local minima of the condition number over the steering configuration, best first (§5.5 criteria).

    kappa is :func:`~wmrkit.analysis.isotropy.twist_condition_number` for `joints`, at `length` or at each
    configuration's natural length. A grid (`resolution` per turn, at most `max_samples` points) finds the
    basins; the best `count` are refined to machine precision (Nelder-Mead, at most 200 evaluations per variable
    and start). When even 4 points per axis would exceed `max_samples` (many steering variables), a seeded
    random sample of `max_samples` configurations replaces the grid and its best `count` points start the
    refinement: memory and time stay bounded (the sample may miss narrow basins). `variables` default to the
    steering wheels that change kappa (those with an axle constraint or among the joints). Only configurations
    where kappa is finite are returned: none when the joints determine the twist nowhere (fewer joints than m).
    """
    check_robot(robot)
    _check_counts(resolution=resolution, max_samples=max_samples, count=count)
    if length is not None:  # NaN, 0, -1 and inf were taken and returned as the configurations' length; '1' as 1 m
        length = check_positive_length(length)
    model = twist_model(robot, joints)
    steer = robot.steer_names
    if variables is None:
        used = set(constraint_lines(robot).wheels) | {n.split(".")[0] for n in model.joints}
        variables = tuple(n for n in steer if n in used)
    variables = as_names(variables, "variables", "steering wheel names", UnknownNameError)
    for v in variables:
        if v not in steer:
            raise UnknownNameError(f"robot '{robot.name}' has no steering wheel '{v}' (steering: {', '.join(steer)})")
    idx = [steer.index(v) for v in variables]

    described = robot.beta

    def full(x: np.ndarray) -> np.ndarray:
        b = np.broadcast_to(described, (*np.shape(x)[:-1], len(steer))).copy()
        b[..., idx] = x
        return b

    size = robot_size(robot)

    def score(x: np.ndarray) -> float:
        b = full(np.asarray(x, dtype=float))
        return _natural_length(model, b, size)[1] if length is None else float(_kappa(model, b, length))

    if not idx:
        d, k = natural_length(robot, joints=model.joints) if length is None else (length, score(np.zeros(0)))
        return (Conditioning(tuple(robot.beta.tolist()), d, k, tuple(robot.heading.tolist())),)
    per_axis = min(resolution, _grid_points(max_samples, len(idx)))
    if len(idx) == 1:
        per_axis = resolution
    step = 2 * np.pi / max(per_axis, 4)
    if per_axis >= 4:
        axis = np.linspace(-np.pi, np.pi, per_axis, endpoint=False)
        mesh = np.stack(np.meshgrid(*([axis] * len(idx)), indexing="ij"), axis=-1)  # (n, ..., n, v)
        values = _grid_kappa(model, full(mesh), length)
        finite = np.where(np.isfinite(values), values, np.inf)
        is_min = np.ones(values.shape, bool)
        for ax in range(len(idx)):
            is_min &= (finite <= np.roll(finite, 1, ax)) & (finite <= np.roll(finite, -1, ax))
        starts = np.argwhere(is_min & np.isfinite(values))
        x0s = axis[starts[np.argsort(finite[tuple(starts.T)])][:count]]
    else:  # too many variables for a grid (4 per axis > max_samples; numpy has 32 axes at most): a seeded sample
        sample = np.random.default_rng(0).uniform(-np.pi, np.pi, (max_samples, len(idx)))
        values = _grid_kappa(model, full(sample), length)
        order = np.argsort(np.where(np.isfinite(values), values, np.inf))
        x0s = sample[order[np.isfinite(values[order])][:count]]
    found: list[tuple[np.ndarray, float]] = []
    for x0 in x0s:
        if len(idx) == 1:
            x = np.array([golden_section(lambda t: score(np.array([t])), x0[0] - step, x0[0] + step)])
        else:
            x = minimize(score, x0, method="Nelder-Mead", options={"xatol": 1e-10, "fatol": 1e-14}).x
        x = np.mod(x + np.pi, 2 * np.pi) - np.pi
        if not any(np.all(np.abs(np.angle(np.exp(1j * (x - y)))) < 1e-6) for y, _ in found):
            found.append((x, score(x)))
    out = []
    for x, k in sorted(found, key=lambda t: t[1]):
        if not np.isfinite(k):  # the twist is undetermined there (the grid's fast kernel gave a huge finite value)
            continue
        b = full(x)
        d = _natural_length(model, b, size)[0] if length is None else length
        out.append(Conditioning(tuple(float(v) for v in b), float(d), float(k),
                                tuple(robot.heading_of_beta(b).tolist())))
    return tuple(out)


def _grid_points(max_samples: int, n: int) -> int:
    """The largest k with k ** n <= max_samples (exact integer arithmetic; float roots round either way)."""
    k = max(1, round(max_samples ** (1 / n)))
    while k ** n > max_samples:
        k -= 1
    while (k + 1) ** n <= max_samples:
        k += 1
    return k


def isotropic_configurations(robot: Robot, *, joints: tuple[str, ...] | None = None,
                             variables: tuple[str, ...] | None = None, resolution: int = 72,
                             max_samples: int = 20000, tol: float = 1e-6) -> tuple[Conditioning, ...]:
    """Configurations where the model is isotropic, kappa = 1 at its natural length (5.29); may be empty.

    The search of :func:`best_configurations` (16 starts; grid or seeded sample of at most `max_samples`).
    """
    check_robot(robot)
    tol = as_real(tol, "tol")
    if not (tol >= 0 and np.isfinite(tol)):  # NaN included: it kept nothing, read as 'not isotropic'
        raise WmrkitError(f"tol: expected a tolerance >= 0 on the condition number, got {tol}")
    best = best_configurations(robot, joints=joints, variables=variables, resolution=resolution,
                               max_samples=max_samples, count=16)
    return tuple(c for c in best if c.condition_number < 1 + tol)


def _grid_kappa(model, beta: np.ndarray, length: float | None) -> np.ndarray:
    """kappa over a grid ``(..., n_steer) -> (...)``: at `length`, or minimised over D per configuration."""
    if length is not None:
        return _kappa(model, beta, length)
    size = robot_size(model.robot)
    if model.mobility == 2:  # closed form per configuration: D = |b| / |a|
        flat = beta.reshape(-1, beta.shape[-1])
        p, cl = line_parameters(model.robot), constraint_lines(model.robot)
        out = np.empty(len(flat))
        for s in range(0, len(flat), _fast.CHUNK):
            rows = _fast.element_rows_cm(p, flat[s:s + _fast.CHUNK])
            lines = _fast.normalize_cm(_fast.combine_lines(cl, rows))
            rates = _fast.combine(model.coefficients, rows)
            a, b, ok = _fast.columns_m2(rates, lines)
            na, nb = np.linalg.norm(a, axis=0), np.linalg.norm(b, axis=0)
            b = b / np.where((na > 0) & (nb > 0), nb / np.where(na > 0, na, 1.0), size)
            small, large = eigvalsh2_entries(np.einsum("jn,jn->n", a, a), np.einsum("jn,jn->n", a, b),
                                             np.einsum("jn,jn->n", b, b))
            out[s:s + _fast.CHUNK] = np.where(ok, _fast.ratio(small, large), np.nan)
        return out.reshape(beta.shape[:-1])
    if model.mobility != 3:  # kappa does not depend on D
        return _kappa(model, beta, size)
    lengths = size * np.logspace(-2, 2, 33)
    flat = beta.reshape(-1, beta.shape[-1])
    out = np.empty(len(flat))
    for s in range(0, len(flat), _fast.CHUNK):  # _kappa's chunks, the rows computed once for all the lengths
        kappa = kappa_function(model, flat[s:s + _fast.CHUNK])
        out[s:s + _fast.CHUNK] = np.min(np.stack([kappa(d) for d in lengths]), axis=0)
    return out.reshape(beta.shape[:-1])


#: Most random steering configurations the ``"global"`` objective of :func:`optimize_geometry` averages over.
MAX_GLOBAL_SAMPLES = 100_000


@dataclass(frozen=True, eq=False)
class GeometryOptimum:
    """Result of :func:`optimize_geometry`: parameters ``x``, the robot, its length D [m] and objective value."""

    x: np.ndarray
    robot: Robot
    length: float
    condition_number: float


def optimize_geometry(family: Callable[[np.ndarray], Robot], x0: ArrayLike, *,
                      bounds: Sequence[tuple[float, float]] | None = None, joints: tuple[str, ...] | None = None,
                      objective: Literal["described", "global"] = "described", samples: int = 256,
                      starts: int = 4, seed: int = 0) -> GeometryOptimum:
    """Parameters of a robot family with the best conditioning (design criterion of §5.4).

    `family` maps a parameter vector to a :class:`~wmrkit.Robot` (raise a WmrkitError for invalid ones).
    ``objective="described"``: kappa at the described configuration and natural length. ``"global"``
    (Kim et al. 05): ``1 / mean(1 / kappa)`` over `samples` random steering configurations at the best common
    length (`samples` at most :data:`MAX_GLOBAL_SAMPLES`). Nelder-Mead from `x0` and ``starts - 1`` random points
    within `bounds` (one finite ``(low, high)`` per parameter).
    """
    # the Python API reads no units: x0='1' was read as 1, None and NaN optimised nothing and returned x = nan
    x0 = np.atleast_1d(as_reals(x0, "x0"))
    if x0.ndim != 1 or not x0.size or not np.all(np.isfinite(x0)):
        raise ShapeError(f"x0: expected a vector of finite numbers (the family's parameters), got {x0.tolist()}")
    if bounds is not None:  # a number raised 'iteration over a 0-d array'
        bounds = as_reals(bounds, "bounds")
        if bounds.shape != (len(x0), 2) or not np.all(np.isfinite(bounds)) or np.any(bounds[:, 0] > bounds[:, 1]):
            raise ShapeError(f"bounds: expected one finite (low, high) per parameter, shape ({len(x0)}, 2), got "
                             f"{bounds.tolist()}")
        bounds = [tuple(b) for b in bounds.tolist()]
    _check_counts(samples=samples, starts=starts)  # starts=1e9 raised "'float' object cannot be interpreted as an ..."
    if samples > MAX_GLOBAL_SAMPLES:  # 10**9 drew 8 GB of configurations per steering wheel
        raise WmrkitError(f"samples must be at most {MAX_GLOBAL_SAMPLES}, got {samples}")
    check_seed(seed, WmrkitError)  # '1' raised numpy's TypeError
    rng = np.random.default_rng(seed)

    def evaluate(x: np.ndarray) -> tuple[float, float]:
        try:
            robot = family(np.asarray(x, dtype=float))
        except WmrkitError:
            return 1e12, np.nan  # outside the family: a finite penalty keeps Nelder-Mead's arithmetic clean
        if objective == "described":
            d, k = natural_length(robot, joints=joints)
            return (k if np.isfinite(k) else 1e12), d
        kappa = kappa_function(twist_model(robot, joints),
                               rng_fixed.uniform(-np.pi, np.pi, (samples, len(robot.steer_names))))
        inv = lambda d: -float(np.mean(1 / np.nan_to_num(kappa(d), nan=np.inf)))  # noqa: E731
        size = robot_size(robot)
        d = float(np.exp(golden_section(lambda t: inv(np.exp(t)), np.log(size / 100), np.log(size * 100),
                                        tol=1e-6)))
        mean_inv = -inv(d)
        return (1 / mean_inv if mean_inv > 0 else 1e12), d

    if objective not in ("described", "global"):
        raise UnknownNameError(f"objective must be 'described' or 'global', got {objective!r}")
    rng_fixed = np.random.default_rng(seed + 1)
    xatol = 1e-9 if objective == "described" else 1e-6  # the global objective is a sample mean: no finer
    points = [x0]
    for _ in range(starts - 1):
        points.append(rng.uniform(*np.array(bounds, dtype=float).T) if bounds is not None
                      else x0 * (1 + 0.2 * rng.normal(size=x0.shape)))
    best = None
    for p in points:
        res = minimize(lambda x: evaluate(x)[0], p, method="Nelder-Mead", bounds=bounds,
                       options={"xatol": xatol, "fatol": xatol * 1e-3, "maxiter": 300 * len(x0)})
        if best is None or res.fun < best.fun:
            best = res
    value, d = evaluate(best.x)
    return GeometryOptimum(best.x, family(best.x), float(d), float(value))


def _check_counts(**counts: object) -> None:
    """:class:`WmrkitError` naming the first of `counts` that is not an integer >= 1 (text, booleans, floats)."""
    for what, value in counts.items():
        if isinstance(value, bool) or not isinstance(value, int | np.integer) or value < 1:
            raise WmrkitError(f"{what} must be an integer >= 1, got {value!r}")
