"""The sensed direct model over samples: joint increments from encoders to body increments, for any robot.

Between two samples the no-slip equations (3.22)-(3.23), ``A(beta) q_dot = 0``, are linear in the rates, so they
hold for the rates integrated over the interval: ``A(beta_mid) dq = 0`` with ``beta_mid`` the steering angles at
the middle of the interval (second order in the step). The sensed joint increments are *assigned* and the others
(the body increment ``(dx, dy, dtheta)``, unsensed wheel rates) are solved by least squares with the ranks
method (4.9)-(4.11) (:func:`wmrkit.kinematics.linalg.solve_assigned`), the joints of a ``gear`` coupling that are
not sensed assigned with its sensed ones (:func:`wmrkit.couplings.gear_fill`), a gear none of whose joints is sensed
one unknown, its turn (:func:`wmrkit.kinematics.linalg.geared_solve`); the residual ``A dq`` [m] is the slip
indicator of (4.11)/(4.82), zero when the sensors agree with rolling without slip. No division by a time step.

Steering angles come from the sensed ``WHEEL.steer`` joints. A steering wheel whose steer angle is not sensed and
that has no sensed joint is left out (a passive castor's rows never constrain the twist; an unsensed steered
wheel only adds a constraint the other wheels may or may not pin down). Robots without sensed steering have a
constant matrix: its solution matrix is computed once. Otherwise one solution is computed per distinct
steering configuration in the data (quantised steering encoders give few) and kept by the model
(:meth:`OdometryModel.configuration_maps`, up to :data:`CACHE_SIZE` configurations) for the next chunks and logs.
"""

from __future__ import annotations

import functools
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike

from .._shapes import as_names, readonly
from ..couplings import gear_fill
from ..errors import UnknownNameError, WmrkitError
from ..kinematics.linalg import geared_solve, geared_twist_determined
from ..robot import Robot, check_robot
from ..wheels import heading_from_beta
from .integrators import _finite

#: Steering configurations whose maps a model keeps; a chunk with more new ones (continuous steering) starts afresh.
CACHE_SIZE = 1 << 14
#: Largest ratio of two wheels' least-squares weights: the rows are scaled by them, so the squared residuals by their
#: squares; 1e6 is the 1e12 of the WLS friction coefficients (``slip.weights.MAX_RATIO``). At 1e16 the forklift's
#: drive-wheel rows fell below the rank tolerance and its odometry stood still (a pose of 4e-31 m, exit 0).
MAX_WEIGHT_RATIO = 1e6


class SensingError(WmrkitError, ValueError):
    """The sensed joints cannot give the robot's motion (too few sensors, unusable sensors, singular steering)."""


@dataclass(frozen=True, eq=False)  # eq=False: array fields
class ModelIncrements:
    """Result of :meth:`OdometryModel.increments` for N sample intervals (outputs computed on demand).

    ``rate_increments`` ``(N, n_a)``: the assigned (sensed) increments [rad]. ``solution`` ``(k, n_a)`` maps them
    to the solved velocity columns (body increment, then the kept wheel rates named ``joint_names``);
    ``residual_map`` ``(R, n_a)`` to ``A dq``, or is None when the sensors have no redundancy (the residual is
    then identically 0). For steering robots both carry a leading axis of distinct configurations ``(U, ...)``
    and ``index`` ``(N,)`` says which one each interval uses. The body increments and the slip come from one
    compiled pass over the samples (:func:`._kernels.linear_maps`; no BLAS call, no per-sample matrix gather),
    the hot path of odometry; the arrays handed out from it are read-only.
    """

    rate_increments: np.ndarray
    joint_names: tuple[str, ...]
    solution: np.ndarray
    residual_map: np.ndarray | None
    index: np.ndarray | None = None

    def __len__(self) -> int:
        return len(self.rate_increments)

    @functools.cached_property
    def _body_and_slip(self) -> tuple[np.ndarray, np.ndarray]:
        """Body increments ``(N, 3)`` and slip ``(N,)``, read-only, in one pass."""
        body, slip = self._products(self.solution[..., :3, :], self.residual_map)
        body.setflags(write=False)
        slip.setflags(write=False)
        return body, slip

    def kernel_maps(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The maps in the form the compiled kernels take, see :func:`kernel_maps`."""
        return kernel_maps(self.solution, self.residual_map, self.index)

    def _products(self, plain: np.ndarray, squared: np.ndarray | None) -> tuple[np.ndarray, np.ndarray]:
        """``plain @ dq`` ``(N, P)`` and ``|squared @ dq|`` ``(N,)`` (0 when `squared` is None) per interval."""
        from . import _kernels  # numba loads on first use

        n, n_a = self.rate_increments.shape

        def per_configuration(m: np.ndarray) -> np.ndarray:  # (U, rows, n_a)
            return m if self.index is not None else m[None]

        index = kernel_maps(self.solution, None, self.index)[2]
        out, norm = np.empty((n, plain.shape[-2])), np.zeros(n)
        _kernels.linear_maps(np.asarray(self.rate_increments, dtype=float), per_configuration(plain),
                             np.empty((1, 0, n_a)) if squared is None else per_configuration(squared), index,
                             out, norm)
        return out, norm

    def column(self, i: int) -> np.ndarray | None:
        """Solved column `i` ``(N,)`` (0, 1, 2: dx [m], dy [m], dtheta [rad]), read-only; None when identically 0."""
        if not np.any(self.solution[..., i, :]):
            return None
        return self._body_and_slip[0][:, i]

    @property
    def increments_robot(self) -> np.ndarray:
        """Body increments ``(N, 3)``: ``(dx [m], dy [m], dtheta [rad])`` over each interval."""
        return self._body_and_slip[0].copy()

    @property
    def joint_increments(self) -> np.ndarray:
        """Every kept wheel rate integrated over each interval ``(N, n)`` [rad], names in ``joint_names``."""
        return self._products(self.solution[..., 3:, :], None)[0]

    @property
    def twist_map(self) -> np.ndarray:
        """The map from ``rate_increments`` to ``increments_robot``: ``(3, n_a)`` or per interval ``(N, 3, n_a)``."""
        s = self.solution[..., :3, :]
        return s if self.index is None else s[self.index]

    @property
    def residual(self) -> np.ndarray:
        """``A dq`` per kept constraint row ``(N, R)`` [m]: the slip over each interval (4.11)."""
        if self.residual_map is None:
            return np.zeros((len(self), 0))
        return self._products(self.residual_map, None)[0]

    @property
    def slip(self) -> np.ndarray:
        """Norm of the residual per interval [m], the slip indicator of (4.11). ``(N,)``, read-only.

        Row by row, accumulating squares (a quadratic form ``dq^T Rm^T Rm dq`` would cancel: small residuals
        are the interesting ones).
        """
        return self._body_and_slip[1]


@dataclass(frozen=True, eq=False)  # eq=False: array fields
class ConfigurationMaps:
    """Matrices per steering configuration, kept by a model: ``keys`` ``(U, s)`` the configurations (angles of the
    sensed steering joints [rad]) sorted lexicographically, ``ids`` ``(U,)`` int64 the row of each in every array
    of ``arrays`` ``((U, ...), ...)``. Read-only. For :class:`OdometryModel`: the solution ``(U, k, n_a)`` and
    residual ``(U, R, n_a)`` maps (see :meth:`OdometryModel.matrices`), and the triangular factor (QR)
    ``(U, min(R, n_a), n_a)`` of the residual map, whose product with ``dq`` has the norm of the residual in fewer
    rows (an orthogonal change of rows: no cancelling quadratic form)."""

    keys: np.ndarray
    ids: np.ndarray
    arrays: tuple[np.ndarray, ...]

    def find(self, configs: np.ndarray) -> np.ndarray:
        """Row in ``arrays`` of each configuration ``(M, s) -> (M,)`` int64, -1 when unknown."""
        from . import _steering_kernels  # numba loads on first use
        out = np.empty(len(configs), dtype=np.int64)
        _steering_kernels.find_configurations(self.keys, self.ids, np.asarray(configs, dtype=float), out)
        return out


def cached_maps(cache: dict, configs: np.ndarray, shapes: tuple[tuple[int, ...], ...],
                compute: Callable[[np.ndarray], tuple[np.ndarray, tuple[np.ndarray, ...]]]
                ) -> tuple[ConfigurationMaps, np.ndarray]:
    """The maps kept in `cache` extended by those of the configurations `configs` ``(M, s)`` (distinct rows) not
    yet there, and the rows of `configs` that `compute` refuses ``(B, s)``. ``compute(new) -> (ok (M',), arrays
    of new[ok])``; `shapes`: each array's shape after the configuration axis. When the cache would grow beyond
    :data:`CACHE_SIZE` configurations it starts afresh with those of `configs`, all of them (so a caller that
    asks for every configuration it still needs finds them all)."""
    cached = cache.get("maps")
    n_s = configs.shape[1]
    new = configs if cached is None or not len(cached.keys) or not len(configs) else configs[cached.find(configs) < 0]
    if cached is None or len(cached.keys) + len(new) > CACHE_SIZE:  # afresh, with every configuration asked for
        cached = ConfigurationMaps(frozen(np.empty((0, n_s))), frozen(np.empty(0, dtype=np.int64)),
                                   tuple(frozen(np.empty((0, *sh))) for sh in shapes))
        new = configs
    if len(new) == 0:
        cache["maps"] = cached
        return cached, new
    ok, arrays = compute(new)
    keys = np.empty((len(cached.keys) + int(ok.sum()), n_s))  # in the order of the arrays' rows
    keys[cached.ids], keys[len(cached.keys):] = cached.keys, new[ok]
    order = np.lexsort(keys.T[::-1]) if n_s else np.arange(len(keys))  # column 0 first, as _steering_kernels._find
    maps = ConfigurationMaps(frozen(keys[order]), frozen(order.astype(np.int64)),
                             tuple(frozen(np.concatenate([old, a])) for old, a in zip(cached.arrays, arrays,
                                                                                       strict=True)))
    cache["maps"] = maps
    return maps, new[~ok]


@dataclass(frozen=True, eq=False)  # eq=False: array fields
class OdometryModel:
    """Sensed direct model of one robot over samples (module docstring); build it with :func:`odometry_model`.

    ``joints``: the log columns it reads, ``wheel.joint``; ``rate_joints``: those whose increments are assigned
    (spins, castor steering rates); ``steer_joints``: those giving the steering configuration ``beta``.
    """

    robot: Robot
    joints: tuple[str, ...]
    rate_joints: tuple[str, ...]
    steer_joints: tuple[str, ...]
    rows: np.ndarray  # constraint rows kept
    cols: np.ndarray  # velocity columns kept (twist first)
    assigned: np.ndarray  # positions of rate_joints among the kept columns
    steer_index: np.ndarray  # position of each steer joint in the robot's beta
    row_weights: np.ndarray  # weight of each kept row in the least squares
    solution: np.ndarray | None  # (k, n_a), constant robots only
    residual_map: np.ndarray | None  # (R, n_a), constant robots with redundant sensors only
    fill: np.ndarray  # (n_assigned, n_a): the assigned rates from the sensed ones (a gear turns its joints together)
    # maps per steering configuration met so far; not an init field, so dataclasses.replace starts a new one
    _cache: dict = field(init=False, default_factory=dict, compare=False, repr=False)

    @property
    def constant(self) -> bool:
        """True when the constraint matrix does not depend on sensed steering angles (fast path)."""
        return self.solution is not None

    @property
    def joint_names(self) -> tuple[str, ...]:
        """Names of the kept wheel rates (``ModelIncrements.joint_increments`` columns)."""
        names = self.robot.velocity_names
        return tuple(names[c] for c in self.cols[3:])

    def increments(self, rate_increments: ArrayLike, beta_mid: ArrayLike | None = None) -> ModelIncrements:
        """Body increments from sensed joint increments, eqs. (3.22), (4.11).

        ``(N, n_a), (N, n_steer_sensed) -> ModelIncrements``: `rate_increments` [rad] in the order of
        ``rate_joints``; `beta_mid` [rad], the steering angles of ``steer_joints`` at the middle of each
        interval (ignored and optional for a constant model).
        """
        dq = np.asarray(rate_increments, dtype=float)
        if dq.ndim != 2 or dq.shape[1] != len(self.rate_joints):
            raise WmrkitError(f"rate_increments: expected shape (N, {len(self.rate_joints)}), got {dq.shape}")
        _finite(dq, "rate_increments")
        if self.constant:
            return ModelIncrements(dq, self.joint_names, self.solution, self.residual_map)
        s, rm, index = self._solve_by_configuration(dq, beta_mid)
        return ModelIncrements(dq, self.joint_names, s, rm, index)

    def from_positions(self, positions: ArrayLike, *, previous: ArrayLike | None = None) -> ModelIncrements:
        """Increments between consecutive samples of joint positions. ``(N + 1, n_joints) -> N intervals``.

        Columns in the order of ``joints``: cumulative spin angles and steering angles [rad]. Steering angles
        are differenced modulo 2 pi (they change by less than pi between samples). With `previous`
        ``(n_joints,)``, the sample before ``positions[0]``, the result has one interval per row of `positions`.
        """
        p = np.asarray(positions, dtype=float)
        if p.ndim != 2 or p.shape[1] != len(self.joints):
            raise WmrkitError(f"positions: expected shape (N + 1, {len(self.joints)}), got {p.shape}")
        _finite(p, "positions")
        if previous is not None:
            _finite(np.asarray(previous, dtype=float), "previous")
        if previous is None:
            d = np.diff(p, axis=0)
        else:
            d = np.empty_like(p)
            np.subtract(p[0], previous, out=d[0])
            np.subtract(p[1:], p[:-1], out=d[1:])
            p = np.concatenate([np.asarray(previous, dtype=float)[None], p]) if self.steer_joints else p
        n_a = len(self.rate_joints)
        if not self.steer_joints:  # joints == rate_joints: no copies
            return self.increments(d)
        steer_cols = [self.joints.index(j) for j in self.steer_joints]
        d[:, steer_cols] = wrap_angle(d[:, steer_cols])
        beta_mid = p[:-1, steer_cols] + 0.5 * d[:, steer_cols]
        rate = d[:, :n_a] if self.joints[:n_a] == self.rate_joints else d[:, [self.joints.index(j) for j in
                                                                                self.rate_joints]]
        return self.increments(rate, beta_mid)

    def matrices(self, beta: ArrayLike | None = None) -> tuple[np.ndarray, np.ndarray]:
        """Solution and residual maps at steering angles `beta` of ``steer_joints``.

        ``(..., n_steer_sensed) -> (..., k, n_a), (..., R, n_a)``: ``q = S @ dq``, ``A q = Rm @ dq``.
        """
        if self.constant:
            rm = self.residual_map
            return self.solution, np.zeros((len(self.rows), self.solution.shape[1])) if rm is None else rm
        beta = np.asarray(beta, dtype=float)
        full = np.broadcast_to(self.robot.beta, (*beta.shape[:-1], len(self.robot.steer_names))).copy()
        full[..., self.steer_index] = beta
        return solution_maps(self.robot, full, self.rows, self.cols, self.sensed, self.row_weights)

    @property
    def sensed(self) -> np.ndarray:
        """Positions in ``cols`` of the sensed rates (``rate_joints``): the first of ``assigned``."""
        return self.assigned[:len(self.rate_joints)]

    @property
    def columns(self) -> tuple[np.ndarray, np.ndarray]:
        """Positions in ``joints`` of ``rate_joints`` and of ``steer_joints`` (int64)."""
        return (np.array([self.joints.index(j) for j in self.rate_joints], dtype=np.int64),
                np.array([self.joints.index(j) for j in self.steer_joints], dtype=np.int64))

    def configuration_maps(self, configs: ArrayLike | None = None) -> tuple[ConfigurationMaps, np.ndarray]:
        """The maps (solution, residual, its QR factor: :class:`ConfigurationMaps`) of every configuration met so
        far, extended by those of `configs` ``(M, s)`` (angles of ``steer_joints`` [rad], distinct rows); also
        the rows of `configs` at which the sensed joints do not determine the motion ``(B, s)`` (left out). Kept
        for the next calls (one model, many chunks and logs): each configuration's maps are computed once, by
        :meth:`matrices`."""
        n_s, n_a, k, r = len(self.steer_joints), len(self.rate_joints), len(self.cols), len(self.rows)
        configs = np.empty((0, n_s)) if configs is None else np.asarray(configs, dtype=float)
        configs = configs.reshape(len(configs), n_s)

        def compute(new: np.ndarray) -> tuple[np.ndarray, tuple[np.ndarray, ...]]:
            ok = _twist_determined(self.robot, new, self)
            s, rm = self.matrices(new[ok]) if ok.any() else (np.empty((0, k, n_a)), np.empty((0, r, n_a)))
            return ok, (s, rm, np.linalg.qr(rm, mode="r"))

        return cached_maps(self._cache, configs, ((k, n_a), (r, n_a), (min(r, n_a), n_a)), compute)

    def undetermined(self, beta: np.ndarray, bad: np.ndarray) -> SensingError:
        """The error naming the first interval whose steering angles, a row of `beta` ``(N, s)``, is among the
        configurations `bad` ``(B, s)`` at which the sensed joints do not determine the motion."""
        hit = (beta[:, None, :] == bad[None]).all(axis=2).any(axis=1)
        i = int(np.flatnonzero(hit)[0])
        delta = [self.robot.wheel(j.partition(".")[0]).delta for j in self.steer_joints]
        heading = heading_from_beta(beta[i], np.array(delta, dtype=float))
        angles = ", ".join(f"{j}={np.degrees(h):.4g} deg" for j, h in zip(self.steer_joints, heading, strict=True))
        return SensingError(f"interval {i}: the sensed joints ({', '.join(self.joints)}) do not determine the motion "
                            f"at steering headings {angles} (0 = straight ahead)")

    def _solve_by_configuration(self, dq: np.ndarray, beta_mid: ArrayLike | None) -> tuple[np.ndarray, ...]:
        if beta_mid is None:
            raise WmrkitError(f"beta_mid: robot '{self.robot.name}' steers; the steering angles are needed")
        beta = np.asarray(beta_mid, dtype=float)
        if beta.shape != (dq.shape[0], len(self.steer_joints)):
            raise WmrkitError(f"beta_mid: expected shape ({dq.shape[0]}, {len(self.steer_joints)}), got {beta.shape}")
        _finite(beta, "beta_mid")
        configs, index = configurations(beta)
        maps, bad = self.configuration_maps(configs)
        if len(bad):
            raise self.undetermined(beta, bad)
        rows = maps.find(configs)
        return maps.arrays[0][rows], maps.arrays[1][rows], index


def odometry_model(robot: Robot, sensed: Sequence[str] | None = None, *,
                   weights: Mapping[str, float] | None = None) -> OdometryModel:
    """The sensed direct model of `robot` over samples (ranks method, eqs. (4.9)-(4.11); module docstring).

    `sensed`: joints ``wheel.joint`` the log provides (default ``robot.sensed``; a sequence, not one string).
    `weights`: wheel name -> weight > 0 of its constraint rows in the least squares (default 1): how much that
    wheel's no-slip equations are trusted, the weighting idea of the thesis's WLS estimator (§7.4.4). A small
    weight on the forklift's steered wheel, whose angle is coarsely quantised, gives nearly the drive wheels'
    differential odometry while its residual still reports the disagreement. The residual is always the
    unweighted ``A dq``. Raises :class:`SensingError` when the joints cannot give the motion,
    :class:`UnknownNameError` for a name the robot lacks.
    """
    check_robot(robot, SensingError)  # a catalog name raised "'str' object has no attribute 'sensed'"
    sensed = robot.sensed if sensed is None else as_names(sensed, "sensed", "'wheel.joint' names", SensingError)
    if weights is not None and not isinstance(weights, Mapping):  # 'abc' or 1.0: dict()'s TypeError or ValueError
        raise SensingError(f"weights: expected a mapping {{wheel name: weight}}, got {type(weights).__name__} "
                           f"{weights!r:.60}")
    weights = dict(weights or {})
    for name, w in weights.items():
        robot.wheel(name)
        if not (isinstance(w, int | float | np.number) and not isinstance(w, bool) and w > 0 and np.isfinite(w)):
            raise SensingError(f"weight of wheel '{name}' must be a finite number > 0, got {w}")
    for name in sensed:
        wheel_name, _, joint = name.partition(".")
        wheel = robot.wheel(wheel_name)
        if joint not in wheel.kind.joints:
            raise UnknownNameError(f"wheel '{wheel_name}' of robot '{robot.name}' has no joint '{joint}' "
                                   f"(joints: {', '.join(wheel.kind.joints)})")
    if len(set(sensed)) != len(sensed):
        twice = sorted({s for s in sensed if sensed.count(s) > 1})
        raise SensingError(f"sensed joints listed twice: {', '.join(twice)}")
    rows, cols, row, col = [], list(range(3)), 0, 3
    rate_joints, steer_joints, steer_index, row_weights = [], [], [], []
    for wheel in robot.wheels:
        n_rows, n_rates = 2 * len(wheel.elements()), len(wheel.kind.rates)
        mine = [s for s in sensed if s.partition(".")[0] == wheel.name]
        steer = f"{wheel.name}.steer"
        if wheel.kind.steers and steer not in mine and mine:
            raise SensingError(f"wheel '{wheel.name}' steers but '{steer}' is not sensed, so {', '.join(mine)} "
                               "cannot be used; sense the steering angle or leave the wheel out")
        if wheel.kind.steers and steer in mine:
            steer_joints.append(steer)
            steer_index.append(robot.steer_names.index(wheel.name))
        if not wheel.kind.steers or mine:
            rows += range(row, row + n_rows)
            row_weights += [float(weights.get(wheel.name, 1.0))] * n_rows
            cols += range(col, col + n_rates)
            rate_joints += [s for s in mine if s.partition(".")[2] in wheel.kind.rates]
        row, col = row + n_rows, col + n_rates
    if row_weights and max(row_weights) > MAX_WEIGHT_RATIO * min(row_weights):
        raise SensingError(f"weights {min(row_weights):g} and {max(row_weights):g} of the sensed wheels differ by more "
                           f"than a factor {MAX_WEIGHT_RATIO:g}: the least squares would lose the smaller rows to "
                           "round-off (only ratios matter; a wheel without a weight has 1)")
    cols_a = np.array(cols)
    kept = tuple(robot.velocity_names[c] for c in cols)  # a gear's joint turns with its sensed ones (fill)
    positions, fill = gear_fill(robot.couplings, kept, tuple(kept.index(j) for j in rate_joints))
    joints = tuple(dict.fromkeys([*rate_joints, *steer_joints]))
    model = OdometryModel(robot, joints, tuple(rate_joints), tuple(steer_joints), np.array(rows, dtype=int), cols_a,
                          np.array(positions, dtype=int), np.array(steer_index, dtype=int),
                          frozen(np.array(row_weights)), None, None, frozen(fill))
    if steer_joints:
        return model
    if not _twist_determined(robot, robot.beta[None, :], model)[0]:
        raise SensingError(f"the sensed joints of robot '{robot.name}' ({', '.join(sensed) or 'none'}) do not "
                           "determine its motion")
    s, rm = solution_maps(robot, robot.beta, model.rows, model.cols, model.sensed, model.row_weights)
    scale = np.max(np.abs(_kept_matrix(robot, robot.beta, model.rows, model.cols)))
    redundant = np.max(np.abs(rm), initial=0.0) > 1e-12 * scale  # else A dq = 0 exactly: no spare sensor
    return OdometryModel(robot, joints, tuple(rate_joints), (), model.rows, cols_a, model.assigned,
                         model.steer_index, model.row_weights, frozen(s), frozen(rm) if redundant else None,
                         model.fill)


def kernel_maps(solution: np.ndarray, residual_map: np.ndarray | None,
                index: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Maps in the form the compiled kernels take: body maps ``(U, 3, n_a)``, residual maps ``(U, R, n_a)`` (R = 0
    when `residual_map` is None) and the configuration index ``(N,)`` int64 (empty for a constant model, whose
    `solution` ``(k, n_a)`` and `residual_map` ``(R, n_a)`` have no configuration axis)."""
    n_a = solution.shape[-1]
    lead = (lambda m: m) if index is not None else (lambda m: m[None])
    residual = np.empty((1, 0, n_a)) if residual_map is None else lead(residual_map)
    flat = np.empty(0, dtype=np.int64) if index is None else np.asarray(index).astype(np.int64, copy=False)
    return lead(solution[..., :3, :]), residual, flat


def wrap_angle(angle: ArrayLike) -> np.ndarray:
    """`angle` [rad] wrapped into ``[-pi, pi)``. ``(...) -> (...)``."""
    return (np.asarray(angle, dtype=float) + np.pi) % (2 * np.pi) - np.pi


def configurations(beta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Distinct rows of `beta` ``(N, s)`` (sorted) and the index of each row ``(N,)`` int64, in O(N) plus a sort
    of the runs: quantised steering changes between few samples, so only the first sample of each run is sorted."""
    n = len(beta)
    change = np.empty(n, dtype=bool)
    change[:1] = True
    np.any(beta[1:] != beta[:-1], axis=1, out=change[1:])
    starts = np.flatnonzero(change)
    if beta.shape[1] == 1:  # one steering angle: a 1-D sort, several times faster than rows
        values, inverse = np.unique(beta[starts, 0], return_inverse=True)
        configs = values[:, None]
    else:
        configs, inverse = np.unique(beta[starts], axis=0, return_inverse=True)
    return configs, np.repeat(inverse.reshape(-1).astype(np.int64), np.diff(np.append(starts, n)))


def _kept_matrix(robot: Robot, beta_full: np.ndarray, rows: np.ndarray, cols: np.ndarray) -> np.ndarray:
    a = robot.constraint_matrix(beta_full)
    return a[..., rows, :][..., cols]


def solution_maps(robot: Robot, beta_full: np.ndarray, rows: np.ndarray, cols: np.ndarray,
                  sensed: np.ndarray, row_weights: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(S, Rm)`` from (4.11) for each configuration: geared_solve (on the rows scaled by their weights, a gear's
    other joints held) for the unit vector of each sensed rate (`sensed`: their positions in `cols`); ``Rm = A S``,
    the unweighted residual map."""
    a = _kept_matrix(robot, beta_full, rows, cols)
    n_a = len(sensed)
    q, _ = geared_solve((a * row_weights[:, None])[..., None, :, :], robot.couplings,
                        tuple(robot.velocity_names[c] for c in cols), sensed, np.eye(n_a))  # (..., n_a, k)
    s = np.swapaxes(q, -1, -2)
    return s, a @ s


def _twist_determined(robot: Robot, beta_full: np.ndarray, model: OdometryModel) -> np.ndarray:
    """Whether the free columns fix the twist: rank(A_free) = rank(A_free without the twist) + 3. ``(U,)``."""
    if model.steer_joints:
        full = np.broadcast_to(robot.beta, (len(beta_full), len(robot.steer_names))).copy()
        full[:, model.steer_index] = beta_full
        beta_full = full
    a = _kept_matrix(robot, beta_full, model.rows, model.cols)
    names = tuple(robot.velocity_names[c] for c in model.cols)
    return geared_twist_determined(a, robot.couplings, names, tuple(model.sensed.tolist()))


def frozen(a: ArrayLike) -> np.ndarray:
    """`a` as a C-contiguous read-only array (the arrays a model holds)."""
    return readonly(np.ascontiguousarray(a))


def wheel_slip(model: OdometryModel, positions: ArrayLike) -> dict[str, float]:
    """RMS slip per wheel [m per interval] over consecutive joint positions ``(N + 1, n_joints)`` (``model.joints``):
    the residual rows (4.11) of each wheel's contacts. Names the wheels whose sensors disagree with the others; none
    when the sensors have no redundancy (they cannot disagree)."""
    res = model.from_positions(positions).residual  # (N, R) over model.rows, (N, 0) without redundancy
    if res.shape[1] == 0:
        return {}
    robot = model.robot
    owner = robot.row_wheels[model.rows]
    out = {}
    for i, w in enumerate(robot.wheels):
        cols = owner == i
        if cols.any() and len(res):
            out[w.name] = float(np.sqrt(np.mean(np.sum(res[:, cols] ** 2, axis=1))))
    return out

