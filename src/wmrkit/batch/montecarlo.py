"""Monte Carlo odometry: sensor errors sampled N times over one log, against the analytic covariance of paper 003.

The log (a file, or a built-in path driven by :func:`wmrkit.odometry.synthetic.simulate`) is taken as the truth.
Each Monte Carlo run perturbs its joint increments as a sensor would and integrates them as
:func:`wmrkit.odometry.pipeline.odometry` does (:func:`~wmrkit.odometry.pipeline.final_poses`, one compiled pass a
run):

- random-walk noise on every sensed joint rate's increment (wheel spins, rollers), variance ``per_rad |dq|`` (the
  model of :class:`~wmrkit.odometry.covariance.JointNoise`);
- quantisation: those readings floored to a `resolution` grid with a random phase per joint and run.
  Sensed steering angles of steered wheels are the configuration, exact here as in the analytic propagation
  (they used to take the random walk too, and a swerve square's Monte Carlo spread was 12 times the analytic
  one). A castor's angle is both a joint rate and the configuration: its random walk also moves the
  configuration, which the first-order propagation leaves out (``wmrkit batch montecarlo`` warns; its spread
  can be 100 times the analytic one);
- slip: each spin joint turns ``1 + s`` times its rolling angle over the whole run, ``s ~ N(0, slip_std)``.

The analytic counterpart is the first-order propagation ``P_k = F P F^T + G Q G^T`` (003 (14)-(17),
:func:`~wmrkit.odometry.covariance.propagate_covariance`) with ``JointNoise(per_rad, resolution^2 / 6)``. The
random walk matches it (tested); quantisation errors do not accumulate (consecutive increments' errors cancel),
so the per-sample term is conservative; systematic slip is not in 003's model at all. Runs are split into
blocks of independent random streams (``SeedSequence(seed).spawn``), one task each: the result does not depend
on the engine or the number of workers.
"""

from __future__ import annotations

import math
import os
from collections.abc import Callable
from dataclasses import dataclass
from numbers import Real

import numpy as np

from .._shapes import readonly
from ..limits import check_seed
from ..odometry.logs import JointLog
from ..odometry.model import OdometryModel, odometry_model
from ..robot import Robot, check_robot
from .engine import BatchError, Engine, engine


def _square() -> object:
    from ..odometry.synthetic import square_path

    return square_path(2.0, speed=0.5, turn_rate=0.5)


def _loop() -> object:
    from ..odometry.synthetic import TwistProfile

    return TwistProfile.from_segments([(4.0, 0.5, 0.0, 0.0), (2 * math.pi / 0.4, 0.4, 0.0, 0.4), (4.0, 0.5, 0.0, 0.0)])


def _arc() -> object:
    from ..odometry.synthetic import TwistProfile

    return TwistProfile.from_segments([(10.0, 0.5, 0.0, 0.15)])


#: Built-in paths: a 2 m square (turns in place), a straight-circle-straight loop, a 10 s arc.
PATHS: dict[str, Callable[[], object]] = {"square": _square, "loop": _loop, "arc": _arc}


@dataclass(frozen=True, eq=False)  # eq=False: array fields
class MonteCarloResult:
    """``poses`` ``(N, 3)`` final poses of the runs; ``nominal`` ``(3,)`` the noise-free final pose;
    ``covariance`` ``(3, 3)`` their empirical covariance and ``analytic`` ``(3, 3)`` the propagated one
    (x, y [m], theta [rad]); the sampled errors (``per_rad`` [rad^2/rad], ``resolution`` [rad], ``slip_std``)."""

    robot: str
    runs: int
    samples: int
    poses: np.ndarray
    nominal: np.ndarray
    covariance: np.ndarray
    analytic: np.ndarray
    per_rad: float
    resolution: float
    slip_std: float

    @property
    def mean(self) -> np.ndarray:
        """Mean final pose ``(3,)``."""
        return self.poses.mean(axis=0)

    def to_dict(self) -> dict:
        """JSON-ready mapping (no per-run poses)."""
        std = lambda c: [math.sqrt(max(c[i, i], 0.0)) for i in range(3)]  # noqa: E731
        return {"robot": self.robot, "runs": self.runs, "samples": self.samples, "nominal": self.nominal.tolist(),
                "mean": self.mean.tolist(), "covariance": self.covariance.tolist(),
                "analytic": self.analytic.tolist(), "std": std(self.covariance), "analytic_std": std(self.analytic),
                "per_rad": self.per_rad, "resolution": self.resolution, "slip_std": self.slip_std}


@dataclass(frozen=True, eq=False)
class _Block:
    robot: Robot
    log: JointLog
    runs: int
    seed: np.random.SeedSequence
    per_rad: float
    resolution: float
    slip_std: float
    method: str


#: Numbers of perturbed joint positions generated at once, runs x samples x joints (2 MiB: they stay in cache).
BATCH_VALUES = 1 << 18


def run_block(block: _Block) -> np.ndarray:
    """Final poses ``(runs, 3)`` of one block of perturbed runs (module docstring), generated about
    :data:`BATCH_VALUES` numbers at a time and integrated by :func:`~wmrkit.odometry.pipeline.final_poses`."""
    from ..odometry.pipeline import final_poses

    model = odometry_model(block.robot)
    log = block.log.select(model.joints)
    rng = np.random.default_rng(block.seed)
    spin = np.array([j.endswith(".spin") for j in log.joints])
    rate = np.flatnonzero(np.isin(log.joints, model.rate_joints))  # steering angles are the configuration: exact
    travel = log.positions - log.positions[0]
    walk = np.sqrt(block.per_rad * np.abs(np.diff(log.positions[:, rate], axis=0)))
    per = max(1, BATCH_VALUES // log.positions.size)
    poses = []
    for start in range(0, block.runs, per):
        runs = min(per, block.runs - start)
        if block.slip_std > 0:  # each spin turns 1 + s times its rolling angle over the run
            q = travel * np.where(spin, 1.0 + block.slip_std * rng.standard_normal((runs, 1, len(spin))), 1.0)
        else:
            q = np.repeat(travel[None], runs, axis=0)
        if block.per_rad > 0:
            q[:, 1:, rate] += np.cumsum(rng.standard_normal((runs, *walk.shape)) * walk, axis=1)
        q += log.positions[0]
        if block.resolution > 0:
            grid = np.floor(q[..., rate] / block.resolution + rng.random((runs, 1, len(rate)))) * block.resolution
            q[..., rate] = grid
        poses.append(final_poses(model, log, q, method=block.method))
    return np.concatenate(poses)


def path_log(robot: Robot, name: str, rate: float = 20.0) -> JointLog:
    """The noise-free log of `robot` driving the built-in path `name` (:data:`PATHS`) at `rate` [Hz]."""
    check_robot(robot, BatchError)
    from ..odometry.synthetic import simulate

    if name not in PATHS:
        raise BatchError(f"unknown path '{name}' (paths: {', '.join(PATHS)})")
    return simulate(robot, PATHS[name](), rate).log


#: Most runs of one Monte Carlo study.
MAX_RUNS = 10**6
#: Most numbers in the log, samples x (joints + 3): each run holds a few arrays of its size (a log of 3e6 samples of
#: two joints took 850 MB for two runs).
MAX_LOG_VALUES = 1 << 23
#: Most work of a study per worker, in numbers integrated: runs x (samples x (joints + 3) + a run's fixed cost
#: (:data:`RUN_COST`, :data:`STEERED_RUN_COST`, :data:`CONFIGURATION_RUN_COST`) + samples x
#: :data:`CONFIGURATION_COST` where a perturbed joint is also the configuration). Integration runs at 15-35 ns a
#: number on one core (diff-drive to swerve-4, squares), so at most about 30-70 s a worker.
MAX_WORK = 2e9
#: A run's fixed cost in numbers integrated (about 20 us: the random draws' set-up, the checks, the kernel's call).
RUN_COST = 1000
#: A steered robot's run's fixed cost (about 100 us: its configuration maps are looked up each run; 1e6 runs of
#: a 3-sample log of swerve-4, counted at :data:`RUN_COST`, took about 100 s).
STEERED_RUN_COST = 5000
#: A run's fixed cost where a perturbed joint is the configuration (1.5-2.6 ms: each run's new configurations are
#: added to the maps the model keeps; counted at :data:`RUN_COST`, 284,616 runs of a 3-sample log of
#: thesis-omni-castor were allowed, about 10 min).
CONFIGURATION_RUN_COST = 100_000
#: A sample's extra cost in numbers integrated when its configuration is perturbed (a castor's angle, a double
#: wheel's steering: both a sensed rate and the configuration): every run meets new configurations, whose maps are
#: computed (about 4-25 us a sample, thesis-omni-castor the slowest).
CONFIGURATION_COST = 2000


def study_cost(model: OdometryModel, log: JointLog, runs: int) -> float:
    """The work of `runs` runs of `log` (:data:`MAX_WORK`'s units)."""
    moving = set(model.steer_joints) & set(model.rate_joints)
    per_sample = len(log.joints) + 3 + (CONFIGURATION_COST if moving else 0)
    per_run = CONFIGURATION_RUN_COST if moving else RUN_COST if model.constant else STEERED_RUN_COST
    return runs * (len(log) * per_sample + per_run)


def _whole(n: object) -> bool:
    return isinstance(n, int | np.integer) and not isinstance(n, bool)


def check_study(runs: int, per_rad: float, resolution: float, slip_std: float,
                names: tuple[str, str, str, str] = ("runs", "per_rad", "resolution", "slip_std")) -> None:
    """Refuse (:class:`BatchError` naming the argument by `names`: the CLI's options) a number of `runs` outside
    ``[2, MAX_RUNS]`` and noise levels that are not numbers in range; one message said all three ranges, naming
    none ("noise must be in ..., got nan, 0, 0")."""
    if not _whole(runs) or not 2 <= runs <= MAX_RUNS:
        raise BatchError(f"{names[0]}: a Monte Carlo study needs at least 2 runs and at most {MAX_RUNS}, got {runs!r}")
    ranges = ((per_rad, 1.0, "noise must be in [0, 1] (per rad)"), (resolution, math.pi, "resolution must be in "
              "[0, pi] rad"), (slip_std, 1.0, "expected a slip in [0, 1] (the standard deviation of a slip ratio)"))
    for name, (value, top, expected) in zip(names[1:], ranges, strict=True):
        if isinstance(value, bool) or not isinstance(value, Real):  # text: the range check raised TypeError
            raise BatchError(f"{name}: expected a number (rad^2/rad, rad, a ratio; the Python API reads no units), "
                             f"got {value!r}")
        if not 0 <= value <= top:
            raise BatchError(f"{name}: {expected}, got {value:g}")


def monte_carlo(robot: Robot, log: JointLog, runs: int, *, per_rad: float = 1e-4, resolution: float = 0.0,
                slip_std: float = 0.0, method: str = "exact", seed: int = 0, block: int = 256,
                runner: Engine | None = None, progress: bool = False) -> MonteCarloResult:
    """`runs` perturbed copies of `log` integrated on `runner` (module docstring), blocks of `block` runs."""
    check_robot(robot, BatchError)
    from ..odometry.covariance import JointNoise
    from ..odometry.pipeline import odometry

    check_study(runs, per_rad, resolution, slip_std)
    if not _whole(block) or block < 1:  # 0 raised range()'s ValueError, a negative one 'need at least one array'
        raise BatchError(f"block: expected a whole number of runs >= 1, got {block!r}")
    check_seed(seed, BatchError)
    if len(log) < 2:  # no motion to perturb (every run failed in the kernel, naming neither log nor option)
        raise BatchError(f"{log.source}: {len(log)} sample{'s' * (len(log) != 1)}: a Monte Carlo study needs a log of "
                         "at least 2 samples")
    if log.heading_world is not None:  # the runs would integrate without it, the nominal pose with it
        raise BatchError(f"{log.source}: an external heading (heading_world) is not sampled by the Monte Carlo "
                         "runs, which perturb the joints only; give the log without it")
    values = len(log) * (len(log.joints) + 3)
    if values > MAX_LOG_VALUES:
        raise BatchError(f"log: {len(log)} samples of {len(log.joints)} joints: a Monte Carlo log holds at most "
                         f"{MAX_LOG_VALUES} numbers, samples x (joints + 3) (docs/limits.md); decimate or cut it")
    model = odometry_model(robot)
    workers = 1 if runner is None else runner.workers
    if runner is not None and runner.mode == "local":  # the embedded cluster's workers share this machine's CPUs
        workers = min(workers, os.cpu_count() or 1)
    if study_cost(model, log, runs) > MAX_WORK * workers:
        most = int(MAX_WORK * workers // study_cost(model, log, 1))
        raise BatchError(f"runs: at most {most} runs of this log ({len(log)} samples of {len(log.joints)} joints) "
                         f"on {workers} worker{'s' * (workers > 1)}, got {runs}: a study does about a minute of work "
                         f"per worker, and an embedded cluster counts at most one a CPU (docs/limits.md); more "
                         f"workers (--workers up to the CPUs, --scheduler) take more runs")
    nominal = odometry(model, log, method=method, noise=JointNoise(per_rad, resolution**2 / 6))
    sizes = [min(block, runs - s) for s in range(0, runs, block)]
    seeds = np.random.SeedSequence(seed).spawn(len(sizes))
    blocks = [_Block(robot, log, n, s, per_rad, resolution, slip_std, method)
              for n, s in zip(sizes, seeds, strict=True)]
    own = runner is None
    runner = engine(workers=0) if runner is None else runner
    try:
        poses = np.concatenate(runner.map(run_block, blocks, progress=progress, desc="monte carlo"))
    finally:
        if own:
            runner.close()
    return MonteCarloResult(robot.name, runs, len(log), readonly(poses), readonly(nominal.poses[-1].copy()),
                            readonly(np.cov(poses, rowvar=False)), readonly(nominal.covariance[-1].copy()),
                            per_rad, resolution, slip_std)


def ellipse(covariance: np.ndarray, center: np.ndarray, *, level: float = 0.95, points: int = 100) -> np.ndarray:
    """Points ``(points, 2)`` of the `level` confidence ellipse of the (x, y) block of `covariance`."""
    scale = math.sqrt(-2.0 * math.log(1.0 - level))  # chi-square quantile with 2 degrees of freedom
    w, v = np.linalg.eigh(np.asarray(covariance)[:2, :2])
    t = np.linspace(0.0, 2 * math.pi, points)
    circle = np.stack([np.cos(t), np.sin(t)])
    return (np.asarray(center)[:2, None] + scale * (v * np.sqrt(np.maximum(w, 0.0))) @ circle).T


#: Most runs drawn as points (the ellipses use every run): 10^6 points took 51 s to draw (PNG), 75 s and 149 MB
#: (SVG), with matplotlib's warning that the legend's placement is slow.
MAX_POINTS_DRAWN = 5000


def plot_monte_carlo(result: MonteCarloResult, path: str) -> None:
    """Final positions of the runs (at most :data:`MAX_POINTS_DRAWN`, every k-th) with the empirical and the
    analytic 95 % ellipses (over every run) on one plot."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(5.5, 5))
    shown = result.poses[::-(-result.runs // MAX_POINTS_DRAWN)]
    ax.scatter(shown[:, 0], shown[:, 1], s=4, alpha=0.35, color="0.4",
               label=f"{result.runs} runs" if len(shown) == result.runs else f"{len(shown)} of {result.runs} runs")
    e, a = ellipse(result.covariance, result.mean), ellipse(result.analytic, result.nominal)
    ax.plot(e[:, 0], e[:, 1], color="C0", lw=2, label="empirical 95 %")
    ax.plot(a[:, 0], a[:, 1], color="C3", lw=2, ls="--", label="analytic 95 % (003 propagation)")
    ax.plot(*result.nominal[:2], "k+", ms=12, label="noise-free")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_title(f"{result.robot}: final pose, Monte Carlo vs analytic")
    ax.legend(fontsize=8, loc="upper right")
    fig.tight_layout()
    try:
        fig.savefig(path)
    finally:  # a failed write leaves no open figure behind
        plt.close(fig)
