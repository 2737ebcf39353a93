"""Velocity Kalman filters FK1 and FK2 (thesis §7.5.2, (7.68)-(7.77)) for any robot, and Kalman odometry.

State: the body twist ``x = (vx, vy, omega)``, a random walk (7.68) with process variance ``Q = k13^2 I`` per
sample of the log's nominal period T, and ``n Q`` over a step of ``n = max(1, round(dt / T))`` periods (a wmrkit
extension for gaps, ``docs/errata.md``: the thesis samples uniformly; T is :attr:`KalmanNoise.period` when given,
else :func:`nominal_period`).
Measurements: the no-slip rows (3.22) that hold only the twist and sensed rates, ``A_p x = -A_a qdot_a`` (the rows
(7.69)/(7.70): a wheel's rolling row is a wheel-speed reading, a lateral row a pseudo-measurement with the steering
angle inside ``C``), with noise ``R = diag(sigma^2)`` per row. Rows with an
unknown wheel rate (the steered wheel's free spin) are left out; a ``gear``'s unsensed joint is known from its
sensed ones (``A_a`` maps the sensed rates through the odometry model's ``fill``, as odometry and ``fk`` use it),
and a gear none of whose joints is sensed is one unknown, its turn ``u`` (:func:`wmrkit.couplings.gear_free`, as
WLS holds it): its rows are kept and ``u`` is eliminated, ``C`` and ``A_a`` projected (in the noise-weighted rows)
onto the complement of the gear's columns, so the two rolling rows of an unsensed solid axle give one measurement.

- **FK2** (7.70): every such row. The thesis merges the two identical lateral rows of the forklift's drive wheels
  into one of standard deviation ``k16``; kept apart, each has ``sqrt(2) k16``.
- **FK1** (7.69): FK2 without the lateral rows of fixed wheels.

The recursion is (7.71)-(7.74) with the standard covariance update; (7.75) as printed adds Q a second time
(``docs/errata.md``), available as ``thesis_double_q=True``. Computed in information form (:mod:`._kalman_kernel`).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike

from .._shapes import real_number
from ..couplings import gear_free
from ..errors import ShapeError, WmrkitError
from ..limits import MAX_QUERY_RATE
from ..odometry.covariance import check_covariance
from ..odometry.integrators import HEADING_FRACTION, Method, check_method
from ..odometry.logs import JointLog
from ..odometry.model import ConfigurationMaps, OdometryModel, cached_maps, odometry_model, wrap_angle
from ..odometry.pipeline import check_chunk, start_pose
from ..odometry.trajectories import Trajectory
from ..robot import Robot

FILTERS = ("fk1", "fk2")
#: Intervals of a log's start whose median is its nominal sample period (:func:`nominal_period`)
PERIOD_INTERVALS = 1000
#: Widest spread of the filter's standard deviations (process and rows), and their range: the information form
#: adds inverse variances, so beyond a spread of 1e6 (1e12 in variance) the smaller ones are lost to round-off; only
#: their ratios matter (scaling all of them scales the covariance and leaves the gain), and the range keeps their
#: squares normal numbers.
MAX_SPREAD, NOISE_RANGE = 1e6, (1e-150, 1e150)


#: The nominal sample periods T [s] a filter accepts (:func:`check_period`): 1 ns (a log's finest time unit) to a day.
PERIOD_RANGE = (1e-9, 86400.0)


def check_period(period: object, name: str = "period") -> float:
    """`period` [s], the nominal sample period T of ``Q``, as a float: a real number (SI seconds; a unit string is the
    CLI's and the description's, which read it) in :data:`PERIOD_RANGE`, else :class:`ShapeError` naming `name`."""
    lo, hi = PERIOD_RANGE
    if not (real_number(period) and lo <= period <= hi):  # type: ignore[operator]
        raise ShapeError(f"{name}: the nominal sample period must be a finite number of seconds in [{lo:g}, {hi:g}], "
                         f"got {period!r}")
    return float(period)  # type: ignore[arg-type]


@dataclass(frozen=True, slots=True)
class KalmanNoise:
    """Noise of the velocity filter: ``process`` (k13) [m/s per nominal sample period, rad/s for omega],
    ``lateral`` and ``longitudinal`` standard deviations [m/s] of every wheel's rows, per wheel in ``wheels``
    ``((name, lateral, longitudinal), ...)``; ``period``: the nominal sample period T [s] of ``process`` (None: the
    log's, :func:`nominal_period`)."""

    process: float = 1.0
    lateral: float = 1.0
    longitudinal: float = 1.0
    wheels: tuple[tuple[str, float, float], ...] = ()
    period: float | None = None

    def __post_init__(self) -> None:
        if self.period is not None:
            check_period(self.period, "Kalman noise period")
        if isinstance(self.wheels, str) or not all(isinstance(w, tuple | list) and len(w) == 3 and isinstance(w[0], str)
                                                   for w in self.wheels):
            raise ShapeError(f"Kalman noise wheels: expected ((wheel name, lateral, longitudinal), ...), got "
                             f"{self.wheels!r:.60}")  # a string raised "not enough values to unpack"
        named = (("process", self.process), ("lateral", self.lateral), ("longitudinal", self.longitudinal),
                 *((f"{w} ({d})", x) for w, a, b in self.wheels for d, x in (("lateral", a), ("longitudinal", b))))
        lo, hi = NOISE_RANGE
        for name, v in named:
            if not (real_number(v) and lo <= v <= hi):  # text raised numpy's TypeError
                raise ShapeError(f"Kalman noise {name}: must be a finite number in [{lo:g}, {hi:g}], got {v!r}")
        (small, a), (large, b) = min(named, key=lambda nv: nv[1]), max(named, key=lambda nv: nv[1])
        if b > MAX_SPREAD * a:
            raise ShapeError(f"Kalman noise {small} ({a:g}) and {large} ({b:g}) differ by more than a factor "
                             f"{MAX_SPREAD:g}: the filter would lose the smaller to round-off (only ratios matter)")

    def of_wheel(self, name: str) -> tuple[float, float]:
        """``(lateral, longitudinal)`` standard deviations of wheel `name`."""
        for n, a, b in self.wheels:
            if n == name:
                return a, b
        return self.lateral, self.longitudinal


def fk1_noise(k14: float, k15: float, k13: float = 1.0) -> KalmanNoise:
    """FK1 of the thesis's forklift (7.77): drive-wheel speeds ``k14``, steer lateral constraint ``k15``."""
    return KalmanNoise(k13, k15, k14, (("right_drive", k15, k14), ("left_drive", k15, k14)))


def fk2_noise(k16: float, k17: float, k18: float, k13: float = 1.0) -> KalmanNoise:
    """FK2 of the thesis's forklift (7.77): merged drive lateral row ``k16`` (each row ``sqrt(2) k16``), drive
    speeds ``k17``, steer lateral constraint ``k18``."""
    s = math.sqrt(2.0) * k16 if real_number(k16) else k16  # else KalmanNoise refuses it
    return KalmanNoise(k13, k18, k18, (("right_drive", s, k17), ("left_drive", s, k17)))


@dataclass(frozen=True, eq=False)  # eq=False: array fields
class KalmanModel:
    """The filter's matrices for one robot and sensor set: ``rows`` kept of the slip matrix, their ``sigma``;
    ``odometry``: the sensed model (joints, steering); ``thesis_double_q``: (7.75) as printed."""

    odometry: OdometryModel
    rows: np.ndarray
    sigma: np.ndarray
    process: float
    thesis_double_q: bool = False
    #: (n_velocities, p): the turns of the gears with no known joint (None: no such gear in the kept rows)
    gears: np.ndarray | None = None
    #: the nominal sample period T [s] of ``process`` (:attr:`KalmanNoise.period`; None: the log's)
    period: float | None = None
    # matrices per steering configuration met so far; not an init field, so dataclasses.replace starts a new one
    _cache: dict = field(init=False, default_factory=dict, compare=False, repr=False)
    # the worst-conditioned configuration met so far: {"condition": kappa, "config": (s,) angles}
    _worst: dict = field(init=False, default_factory=dict, compare=False, repr=False)

    def matrices(self, beta_full: np.ndarray) -> tuple[np.ndarray, ...]:
        """``(H, M, C, A_a)`` per configuration ``(U, n_steer) -> (U, 3, 3), (U, 3, n_a), (U, m, 3), (U, m, n_a)``,
        ``H`` and ``M`` per unit of process variance (``R`` divided by ``Q``, see :func:`_run`)."""
        om = self.odometry
        a = om.robot.constraint_matrix(beta_full)[..., self.rows, :]
        c, aa = a[..., :3], a[..., known_columns(om)] @ om.fill  # a gear's unsensed joints: from the sensed rates
        if self.gears is not None:  # a gear with no known joint: its turn eliminated from the rows
            c, aa = self._eliminate(a @ self.gears, c, aa)
        ct_r = np.swapaxes(c, -1, -2) / self.relative_variances
        return ct_r @ c, -(ct_r @ aa), np.ascontiguousarray(c), np.ascontiguousarray(aa)

    def _eliminate(self, f: np.ndarray, c: np.ndarray, aa: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """`c`, `aa` ``(U, m, .)`` with the unknown turns of `f` ``(U, m, p)`` eliminated: ``S = W P W^-1``, ``W =
        diag(sigma)``, ``P`` the projector onto the complement of ``W^-1 f``; ``(S C)^T R^-1 (S C) = C^T (R^-1 - R^-1 f
        (f^T R^-1 f)^+ f^T R^-1) C``, the information the rows hold of the twist whatever the turns."""
        fw = f / self.sigma[:, None]
        p = np.eye(len(self.sigma)) - fw @ np.linalg.pinv(fw)
        s = self.sigma[:, None] * p / self.sigma
        return s @ c, s @ aa

    @property
    def relative_variances(self) -> np.ndarray:
        """The rows' variances over the process variance ``sigma^2 / k13^2``: all the filter's twists depend on."""
        return (self.sigma / np.sqrt(self.process)) ** 2

    def configuration_maps(self, configs: ArrayLike | None = None) -> ConfigurationMaps:
        """``(H, M, C, A_a, [C, A_a])`` (:meth:`matrices`) for every steering configuration met so far (angles of the
        sensed steering joints [rad]), extended by the distinct rows of `configs` ``(U, s)``; kept for the next
        calls (:func:`wmrkit.odometry.model.cached_maps`). A robot without sensed steering has one configuration,
        of no angles."""
        om = self.odometry
        n_s, n_a, m = len(om.steer_joints), len(om.rate_joints), len(self.rows)
        configs = np.empty((0 if n_s else 1, n_s)) if configs is None else np.asarray(configs, dtype=float)
        configs = configs.reshape(len(configs), n_s)

        def compute(new: np.ndarray) -> tuple[np.ndarray, tuple[np.ndarray, ...]]:
            full = np.broadcast_to(om.robot.beta, (len(new), len(om.robot.steer_names))).copy()
            full[:, om.steer_index] = new
            h, mm, c, aa = self.matrices(full)
            slip = np.linalg.qr(np.concatenate([c, aa], axis=-1), mode="r")  # |[C, A_a] z| = |T z|, fewer rows
            self._note_conditioning(c, new)
            return np.ones(len(new), dtype=bool), (h, mm, c, aa, slip)

        shapes = ((3, 3), (3, n_a), (m, 3), (m, n_a), (min(m, 3 + n_a), 3 + n_a))
        return cached_maps(self._cache, configs, shapes, compute)[0]

    def _note_conditioning(self, c: np.ndarray, configs: np.ndarray) -> None:
        """Keep the worst condition number of the kept rows ``C`` ``(U, m, 3)`` (weighted by their noise, omega's
        column times the robot's size: dimensionless) over the configurations `configs` ``(U, s)``."""
        from ..analysis.isotropy import condition_number
        from ..analysis.singularity import robot_size

        if not len(configs):
            return
        weighted = c / self.sigma[:, None]
        weighted[..., 2] *= robot_size(self.odometry.robot)
        kappa = condition_number(weighted)
        k = int(np.argmax(kappa))
        if kappa[k] > self._worst.get("condition", 0.0):
            self._worst.update(condition=float(kappa[k]), config=tuple(float(a) for a in configs[k]))

    @property
    def worst_conditioning(self) -> tuple[float, tuple[float, ...]] | None:
        """The largest condition number with which the kept rows fixed the twist at a steering configuration met so
        far, and that configuration (sensed steering angles, thesis beta [rad]); None before any. Where it is large
        (:data:`ILL_CONDITIONED`) the measurements barely fix a direction of the twist and the filter carries its
        prediction there: FK1 near a forklift heading of +-90 deg, where its kept rows lose the sideways speed."""
        return (self._worst["condition"], self._worst["config"]) if self._worst else None


#: Condition number above which a filter's kept rows are said not to fix the twist (``wmrkit odometry`` warns):
#: 6 times that of the forklift's FK1 rows driving straight (16; its FK2 rows: 6.5), reached within about 1 deg of a
#: heading of +-90 deg there.
ILL_CONDITIONED = 100.0


def kalman_model(robot: Robot, kind: str = "fk2", noise: KalmanNoise | None = None,
                 sensed: Sequence[str] | None = None, *, thesis_double_q: bool = False) -> KalmanModel:
    """FK1 or FK2 (module docstring) of `robot` with its sensed joints (default ``robot.sensed``)."""
    if kind not in FILTERS:
        raise WmrkitError(f"filter must be one of {', '.join(FILTERS)}, got '{kind}'")
    if noise is not None and not isinstance(noise, KalmanNoise):  # a mapping raised "no attribute 'wheels'"
        raise ShapeError(f"noise: expected KalmanNoise or None (KalmanNoise(process, lateral, longitudinal), "
                         f"fk1_noise, fk2_noise), got {type(noise).__name__} {noise!r:.60}")
    noise = noise or KalmanNoise()
    for name, _, _ in noise.wheels:
        robot.wheel(name)
    base = odometry_model(robot, sensed)
    rng = np.random.default_rng(0)
    probe = np.vstack([robot.beta, robot.beta + rng.uniform(-1, 1, (3, len(robot.beta)))])
    a = robot.constraint_matrix(probe)
    gears = _free_gears(robot, known_columns(base))
    held = np.flatnonzero(np.abs(gears).sum(axis=1)) if gears is not None else np.empty(0, dtype=int)
    unsensed = np.setdiff1d(np.arange(3, a.shape[-1]), np.concatenate([known_columns(base), held]))
    rows, sigma, row = [], [], 0
    for w in robot.wheels:
        lat, lon = noise.of_wheel(w.name)
        for _ in w.elements():
            for axis, s in ((0, lat), (1, lon)):
                r = row + axis
                if r not in base.rows or np.any(np.abs(a[:, r, unsensed]) > 0):
                    continue
                if kind == "fk1" and axis == 0 and w.type == "fixed":
                    continue
                rows.append(r)
                sigma.append(s)
            row += 2
    rows_a = np.array(rows, dtype=int)
    if gears is not None and not np.any(a[:, rows_a] @ gears):
        gears = None  # no kept row turns with the gear: nothing to eliminate
    model = KalmanModel(base, rows_a, np.array(sigma), float(noise.process) ** 2, thesis_double_q, gears, noise.period)
    if np.linalg.matrix_rank(model.matrices(probe[:1])[2][0]) < 3:  # the random walk would carry those directions
        dropped = " (fk1 leaves out the lateral rows of fixed wheels, (7.69): use fk2)" if kind == "fk1" else ""
        raise WmrkitError(f"{kind}: the sensed rows of robot '{robot.name}' do not determine its twist{dropped}")
    return model


def _free_gears(robot: Robot, known: np.ndarray) -> np.ndarray | None:
    """The turns ``(n_velocities, p)`` of the gears none of whose joints `known` holds (velocity columns), one
    column each with its ratios (:func:`wmrkit.couplings.gear_free`); None without such a gear."""
    names = robot.velocity_names
    free, free_names = gear_free(robot.couplings, names, tuple(int(k) for k in known))
    geared = [i for i, n in enumerate(free_names) if n not in names]  # a gear's column is named by its channel
    return free[:, geared] if geared else None


def known_columns(model: OdometryModel) -> np.ndarray:
    """The velocity columns of the joint rates `model` knows: the sensed ones, then those a gear turns with them
    (``model.fill`` maps the sensed rates onto them)."""
    return model.cols[model.assigned]


@dataclass(frozen=True, eq=False)  # eq=False: array fields
class KalmanRun:
    """Filter output over a log: ``twist`` ``(N, 3)`` per interval, ``increments`` ``(N, 3)``, the final
    covariance ``covariance`` ``(3, 3)`` of the twist, ``slip`` ``(N,)`` [m], the nominal sample ``period`` [s] used
    (give it, with the last twist and the covariance, to the call filtering the log's next piece)."""

    twist: np.ndarray
    increments: np.ndarray
    covariance: np.ndarray
    slip: np.ndarray
    period: float


def nominal_period(time: ArrayLike) -> float:
    """The nominal sample period [s] of a log sampled at `time` ``(N,)`` (increasing, N >= 2): the median of its
    first :data:`PERIOD_INTERVALS` intervals, which a few gaps or a jittered clock do not move, and which only the
    log's start sets (the same whatever the pieces a stream cuts it into)."""
    return float(np.median(np.diff(np.asarray(time, dtype=float)[:PERIOD_INTERVALS + 1])))


def kalman_filter(model: KalmanModel, log: JointLog, *, x0: ArrayLike | None = None,
                  p0: ArrayLike | None = None, period: float | None = None) -> KalmanRun:
    """Run the filter over the intervals of `log` (positions: cumulative spin angles, steering angles).

    `x0` defaults to the least-squares twist of the first interval, `p0` to Q (the spec's choice; the thesis
    gives neither). Rates are the increments over each interval divided by its duration. `period`: the nominal
    sample period T [s] of Q (a number of seconds, :func:`check_period`), default the model's noise's
    (:attr:`KalmanNoise.period`), else :func:`nominal_period` of `log` (module docstring).
    """
    check_log(_selected(model, log))
    return _filter(model, log, x0, p0, period)


def _filter(model: KalmanModel, log: JointLog, x0: ArrayLike | None, p0: ArrayLike | None,
            period: float | None) -> KalmanRun:
    """:func:`kalman_filter` on a log already checked (:func:`check_log`)."""
    t = np.asarray(log.time, dtype=float)
    increments = np.empty((max(len(t) - 1, 0), 3))
    period = _period(model, period, t)
    slip, filt = _run(model, log, x0, p0, increments, np.empty((0, 3)), np.zeros(7), "exact", period)
    p = filt[[3, 4, 5, 4, 6, 7, 5, 7, 8]].reshape(3, 3)
    return KalmanRun(increments / np.diff(t)[:, None], increments, p, slip, period)


def _period(model: KalmanModel, period: float | None, time: np.ndarray) -> float:
    """`period` [s] checked, else `model`'s (its noise's), else the nominal one of a log sampled at `time`
    (:func:`nominal_period`)."""
    if period is None:
        period = model.period
    if period is None:
        return nominal_period(time) if len(time) >= 2 else 1.0  # one sample: refused by _run
    return check_period(period)


def _run(model: KalmanModel, log: JointLog, x0: ArrayLike | None, p0: ArrayLike | None, increments: np.ndarray,
         poses: np.ndarray, pose: np.ndarray, method: Method, period: float) -> tuple[np.ndarray, np.ndarray]:
    """One compiled pass (:func:`._kalman_kernel.kalman_chunk`) over the intervals of `log`: increments and poses
    into the given arrays (each skipped when ``(0, 3)``), from ``pose (7,)`` (pose, then path sums), with Q per
    nominal `period` [s]; the slip ``(N,)`` and the final filter state ``(9,)`` (x, upper entries of P)."""
    from . import _kalman_kernel

    om = model.odometry
    chunk = _selected(model, log)
    p = np.asarray(chunk.positions, dtype=float)
    t = np.asarray(chunk.time, dtype=float)
    if len(t) < 2:
        raise WmrkitError("the log needs at least two samples")
    rate_cols, steer_cols = om.columns
    first = p[0, steer_cols] + 0.5 * wrap_angle(p[1, steer_cols] - p[0, steer_cols])  # as the kernel computes
    maps = model.configuration_maps(first[None])
    if x0 is None:
        c, aa = (a[maps.find(first[None])[0]] for a in maps.arrays[2:4])
        rate0 = (p[1, rate_cols] - p[0, rate_cols]) / (t[1] - t[0])
        x0 = np.linalg.lstsq(c / model.sigma[:, None], -(aa @ rate0) / model.sigma, rcond=None)[0]
    # The kernel runs on the covariance over the process variance (Q = I, R / k13^2): the twists depend on those
    # ratios alone, and a covariance of k13^2 = 1e200 would overflow in the 3x3 inverses (cubes of its entries).
    p_start = np.eye(3) if p0 is None else check_covariance(p0, "p0", definite=True) / model.process
    x0 = np.asarray(x0, dtype=float)
    if x0.shape != (3,) or not (np.abs(x0) <= MAX_QUERY_RATE).all():
        raise ShapeError(f"x0: expected a twist (vx, vy, omega), finite and each at most {MAX_QUERY_RATE:g}, got "
                         f"{x0.tolist()}")
    filt = np.concatenate([x0, p_start[[0, 0, 0, 1, 1, 2], [0, 1, 2, 1, 2, 2]]])
    slip = np.empty(len(t) - 1)
    missing = np.empty((len(t) - 1, len(steer_cols)))
    start = 0
    while True:
        start, count = _kalman_kernel.kalman_chunk(p[1:], p[0], t[1:], t[0], rate_cols, steer_cols, start, maps.keys,
                                                   maps.ids, maps.arrays[0], maps.arrays[1], maps.arrays[4],
                                                   1.0, period, model.thesis_double_q,
                                                   filt, pose, HEADING_FRACTION[method], method == "exact",
                                                   increments, poses, slip, missing)
        if count == 0:
            filt[3:] *= model.process
            return slip, filt
        maps = model.configuration_maps(np.unique(missing[:count], axis=0))


def kalman_odometry(model: KalmanModel, log: JointLog, *, method: Method = "exact",
                    pose0: ArrayLike = (0.0, 0.0, 0.0), x0: ArrayLike | None = None,
                    p0: ArrayLike | None = None, period: float | None = None) -> Trajectory:
    """Poses from the filtered twists (one per sample, the first `pose0`), composed with `method` in the same
    pass as the filter; `x0`, `p0`, `period` as in :func:`kalman_filter`."""
    check_method(method)
    pose0 = start_pose(pose0)
    check_log(_selected(model, log))
    n = len(log)
    poses = np.empty((n, 3))
    poses[0] = pose0
    slip = np.empty(n)
    slip[0] = 0.0
    slip[1:] = _run(model, log, x0, p0, np.empty((0, 3)), poses[1:], np.concatenate([pose0, np.zeros(4)]), method,
                    _period(model, period, np.asarray(log.time, dtype=float)))[0]
    return Trajectory(np.asarray(log.time, dtype=float), poses, slip)


def check_log(log: JointLog, previous: JointLog | None = None, name: str = "the filter") -> None:
    """Refuse what the filters cannot use, as the odometry pipeline refuses it (:func:`~wmrkit.odometry.pipeline.
    check_chunk`, a compiled pass unless a value is bad): an external heading (``heading`` or gyro column: not
    used), values that are not finite numbers, time that does not increase (from `previous`, the chunk before);
    :class:`~wmrkit.odometry.logs.LogError` naming the sample. `name`: the filter's, for the messages."""
    if log.heading_world is not None:
        raise WmrkitError(f"{name} filters the wheels' twist; an external heading (heading or gyro column) is not used "
                          "by it: drop that option or use --method wls")
    check_chunk(log, previous)


def _selected(model: KalmanModel, log: JointLog) -> JointLog:
    """`log` with the columns of the filter's joints."""
    joints = model.odometry.joints
    return log if log.joints == joints else log.select(joints)


def noise_from_options(process: float, lateral: float, longitudinal: float,
                       wheels: Mapping[str, tuple[float, float]] | None = None,
                       period: float | None = None) -> KalmanNoise:
    """A :class:`KalmanNoise` from plain numbers (the CLI's options)."""
    return KalmanNoise(process, lateral, longitudinal, tuple((k, float(a), float(b))
                                                            for k, (a, b) in (wheels or {}).items()), period)
