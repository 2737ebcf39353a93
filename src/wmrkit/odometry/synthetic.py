"""Synthetic sensor logs: drive a robot along a known path and record what its encoders would read.

The path is a piecewise-constant body twist (:class:`TwistProfile`). The true pose is its exact integral
(constant-twist SE(2) steps on a fine grid that contains every segment boundary), and the joint positions come
from the robot's own no-slip equations (3.22) solved with the twist assigned (4.11). Steerable (and double)
wheels point along the velocity of their steering joint (their lateral constraint, 3.11); while that velocity is
zero they turn linearly in time to the next heading (steering while stopped). Castor angles follow their own
kinematics, ``beta_dot`` from (3.12), integrated with ``solve_ivp``. Then the sensors: optional slip windows
(a wheel turns ``1 + ratio`` times what rolling needs), random-walk noise on spins (variance ``per_rad * |dq|``,
the :class:`~.covariance.JointNoise` model), Gaussian noise on steering readings, and encoder quantisation.
The run's :class:`~.logs.JointLog` holds the thesis's β; steering encoders read headings (0 = straight ahead), as
in any log file, and :func:`~.logs.write_log` writes the log with headings.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from .._shapes import as_names, as_real, as_reals, finite_number
from ..errors import WmrkitError
from ..kinematics.linalg import solve_assigned
from ..limits import MAX_COORDINATE, MAX_SPEED, check_seed
from ..robot import Robot
from ..wheels import Wheel, heading_in_range, slip_row_entries
from .encoders import AbsoluteEncoder, Encoder, IncrementalEncoder
from .integrators import integrate_increments
from .logs import JointLog
from .steering import convert_steering


@dataclass(frozen=True, eq=False)  # eq=False: array fields
class TwistProfile:
    """Piecewise-constant body twist: segment ``durations`` ``(S,)`` [s] and ``twists`` ``(S, 3)``
    ``(vx [m/s], vy [m/s], omega [rad/s])`` of the robot frame, from time 0."""

    durations: np.ndarray
    twists: np.ndarray

    def __post_init__(self) -> None:
        d, tw = as_reals(self.durations, "profile: durations"), as_reals(self.twists, "profile: twists")
        object.__setattr__(self, "durations", d)  # lists given in Python: duration raised "'list' has no 'sum'"
        object.__setattr__(self, "twists", tw)
        if d.ndim != 1 or tw.shape != (len(d), 3):
            raise WmrkitError(f"profile: expected durations (S,) and twists (S, 3), got {d.shape} and {tw.shape}")
        if not len(d):
            raise WmrkitError("profile: expected at least one segment, got none")
        if not (d > 0).all() or not np.isfinite(d).all():
            raise WmrkitError("every segment needs a finite duration > 0 s")
        if not (np.abs(tw) <= MAX_SPEED).all():  # NaN included
            k = int(np.argmax(~(np.abs(tw) <= MAX_SPEED).all(axis=1)))
            raise WmrkitError(f"profile: segment {k}: twist {tw[k].tolist()}: expected finite speeds within "
                              f"{MAX_SPEED:g} m/s and turn rates within {MAX_SPEED:g} rad/s")

    @classmethod
    def from_segments(cls, segments: Sequence[tuple[float, float, float, float]]) -> TwistProfile:
        """From ``(duration, vx, vy, omega)`` rows (one row alone is one segment)."""
        a = as_reals(segments, "profile: segments")
        a = a.reshape(-1, 4) if a.ndim == 1 and a.size in (0, 4) else a
        if a.ndim != 2 or a.shape[1] != 4:  # a row of 3 or 5 values was numpy's reshape error, 8 values two rows
            raise WmrkitError(f"profile: expected (duration, vx, vy, omega) rows, got shape {a.shape}")
        return cls(a[:, 0], a[:, 1:])

    @property
    def boundaries(self) -> np.ndarray:
        """Segment start times and the end time ``(S + 1,)`` [s]."""
        return np.concatenate([[0.0], np.cumsum(self.durations)])

    @property
    def duration(self) -> float:
        """Total duration [s]."""
        return float(self.durations.sum())

    def at(self, t: ArrayLike) -> np.ndarray:
        """Twist at times `t` ``(...) -> (..., 3)``; a segment holds on ``[start, end)``, the last also at its end."""
        i = np.searchsorted(self.boundaries, np.asarray(t, dtype=float), side="right") - 1
        return self.twists[np.clip(i, 0, len(self.durations) - 1)]

    def about(self, point_robot: ArrayLike) -> TwistProfile:
        """The same motion given as the twist of `point_robot` ``(x, y)`` [m]: the robot-origin twists.

        ``v_origin = v_point + omega x (origin - point)`` (rigid body; thesis (3.1)).
        """
        px, py = (float(v) for v in point_robot)
        tw = self.twists.copy()
        tw[:, 0] += tw[:, 2] * py
        tw[:, 1] -= tw[:, 2] * px
        return TwistProfile(self.durations, tw)


def square_path(side: float, *, speed: float = 0.5, turn_rate: float = 0.5, clockwise: bool = False,
                pause: float = 0.0) -> TwistProfile:
    """A closed square: four times (straight `side` [m] at `speed`, turn 90 deg in place at `turn_rate`), with an
    optional stop of `pause` [s] between segments (time for steered wheels to turn). Counter-clockwise unless
    `clockwise` (the two runs of the classic square-path benchmark)."""
    for name, value in (("side", side), ("speed", speed), ("turn_rate", turn_rate)):
        if isinstance(value, bool) or not (finite_number(value) and value > 0):
            raise WmrkitError(f"square_path: {name} must be a finite number > 0, got {value!r}")
    if isinstance(pause, bool) or not (finite_number(pause) and pause >= 0):
        raise WmrkitError(f"square_path: pause must be a finite number >= 0 s, got {pause!r}")
    w = -turn_rate if clockwise else turn_rate
    seg = [(side / speed, speed, 0.0, 0.0), (math.pi / 2 / turn_rate, 0.0, 0.0, w)]
    if pause > 0:
        seg = [seg[0], (pause, 0.0, 0.0, 0.0), seg[1], (pause, 0.0, 0.0, 0.0)]
    return TwistProfile.from_segments(seg * 4)


@dataclass(frozen=True, slots=True)
class Slip:
    """Wheel slip: joint `joint` turns ``1 + ratio`` times what rolling needs during ``[start, stop)`` [s]."""

    joint: str
    start: float
    stop: float
    ratio: float

    def __post_init__(self) -> None:  # the Python API reads no units: start='1' raised a bare TypeError in simulate
        if not isinstance(self.joint, str):
            raise WmrkitError(f"slip: joint: expected a joint's name such as 'left.spin', got {self.joint!r}")
        for name in ("start", "stop", "ratio"):
            object.__setattr__(self, name, as_real(getattr(self, name), f"slip: {name}"))


@dataclass(frozen=True, eq=False)  # eq=False: array fields
class SyntheticRun:
    """A simulated run: ``log`` (what the sensors report, angles; steering as β like every :class:`JointLog`),
    ``truth`` ``(N, 3)`` true poses at the sample times, ``true_positions`` ``(N, n)`` exact joint positions (β),
    ``counts``: raw encoder readings by joint (as the counters show them, wrapped; steering encoders read
    headings) for the joints that have an encoder."""

    log: JointLog
    truth: np.ndarray
    true_positions: np.ndarray
    counts: Mapping[str, np.ndarray]


#: Most samples of a synthetic log (each is a row of every joint array, fine-stepped `oversample` times).
MAX_SAMPLES = 10**7
#: Most fine steps (sample periods times `oversample`): each holds a few rows of every joint, about 1 kB.
MAX_FINE_STEPS = 10**8
#: Most numbers in the fine arrays of a run (2^27, 1 GiB): a fine step holds the solution and residual maps of its
#: configuration and its increments, at most :func:`fine_step_values` numbers (1.1e6 samples of the diff-drive took
#: 3.1 GB and 30 s, 1e7 samples would have taken 27 GB).
MAX_FINE_VALUES = 1 << 27


def fine_step_values(robot: Robot) -> int:
    """An upper bound of the numbers one fine step of `robot` holds in :func:`simulate` (:data:`MAX_FINE_VALUES`)."""
    return (len(robot.steer_names) + 4) * (len(robot.velocity_names) + 2 * len(robot.wheels))


def simulate(robot: Robot, profile: TwistProfile, rate: float, *, pose0: ArrayLike = (0.0, 0.0, 0.0),
             sensed: Sequence[str] | None = None, encoders: Mapping[str, Encoder] | None = None,
             spin_noise_per_rad: float = 0.0, steer_noise: float = 0.0, slips: Sequence[Slip] = (),
             oversample: int = 8, seed: int = 0) -> SyntheticRun:
    """Drive `robot` along `profile` and record its sensed joints at `rate` [Hz] (module docstring); when the
    profile's duration is not a whole number of sample periods, the robot rests until the next sample.

    `sensed` defaults to ``robot.sensed``. `encoders` quantise the named joints (spins: floor of the count,
    steering: nearest reading). `spin_noise_per_rad` [rad^2/rad], `steer_noise` [rad] (standard deviation).
    `oversample`: fine steps per sample interval for the joint kinematics. Deterministic for a given `seed`.
    """
    if not isinstance(profile, TwistProfile):  # a list of segments raised AttributeError
        raise WmrkitError(f"profile: expected a TwistProfile (TwistProfile.from_segments, square_path), got "
                          f"{type(profile).__name__}")
    sensed = robot.sensed if sensed is None else as_names(sensed, "sensed", "joint names", WmrkitError)
    if encoders is not None and not isinstance(encoders, Mapping):  # a list raised "has no attribute 'items'"
        raise WmrkitError(f"encoders: expected a mapping {{joint: encoder}}, got {type(encoders).__name__}")
    if isinstance(slips, str) or not isinstance(slips, Sequence) or not all(isinstance(s, Slip) for s in slips):
        raise WmrkitError(f"slips: expected a sequence of Slip(joint, start, stop, ratio), got {slips!r:.60}")
    _check_arguments(robot, sensed, pose0, spin_noise_per_rad, steer_noise, slips, oversample, seed)
    if isinstance(rate, bool) or not finite_number(rate):
        raise WmrkitError(f"rate: expected a finite number [Hz], got {rate!r}")
    if not (1e-6 <= rate and profile.duration * rate <= MAX_SAMPLES):
        raise WmrkitError(f"rate {rate:g} Hz over the profile's {profile.duration:g} s: need a rate >= 1e-06 Hz and "
                          f"at most {MAX_SAMPLES} sample periods")
    if profile.duration * rate * oversample > MAX_FINE_STEPS:  # the fine arrays: 15 TiB at oversample = 1e9
        raise WmrkitError(f"oversample {oversample} at {rate:g} Hz over {profile.duration:g} s: at most "
                          f"{MAX_FINE_STEPS:.0e} fine steps (sample periods times oversample)")
    values = fine_step_values(robot) * oversample * profile.duration
    if rate * values > MAX_FINE_VALUES:
        raise WmrkitError(f"rate {rate:g} Hz over the profile's {profile.duration:g} s: robot '{robot.name}' holds up "
                          f"to {fine_step_values(robot)} numbers a fine step ({oversample} a sample), a run at most "
                          f"{MAX_FINE_VALUES} (1 GiB): a rate of at most {MAX_FINE_VALUES / values:.4g} Hz")
    n = math.ceil(profile.duration * rate - 1e-9) + 1  # the whole profile: a log never stops short of its end
    t_samples = np.arange(n) / rate
    if t_samples[-1] > profile.duration:  # the robot rests from the profile's end to the last sample
        profile = TwistProfile(np.append(profile.durations, t_samples[-1] - profile.duration),
                               np.vstack([profile.twists, np.zeros(3)]))
    # every sample time itself a fine node (a linspace's 8k / 40 s fell below k / 5 s, and the sample read the node
    # after it, one fine step late), each sample period cut into `oversample` steps
    steps = t_samples[:-1, None] + np.diff(t_samples)[:, None] * (np.arange(oversample) / oversample)
    fine = np.union1d(np.append(steps.reshape(-1), t_samples[-1]),
                      profile.boundaries[profile.boundaries <= t_samples[-1]])
    sample_idx = np.searchsorted(fine, t_samples)
    dt = np.diff(fine)
    twist = profile.at(0.5 * (fine[:-1] + fine[1:]))  # (M, 3)
    beta_nodes, beta_mid = _steering(robot, profile, fine, twist, sensed)  # (M + 1, n_steer), (M, n_steer)
    _check_steer_range(robot, beta_nodes, fine, twist)
    configs, index = np.unique(beta_mid, axis=0, return_inverse=True)  # one solve per distinct configuration
    # Assigned: the twist, and the steering rates of the steered wheels that have one among the velocities (a double
    # wheel's sub-wheels roll to turn it, (3.24)): their angles are the geometry's, not a least-squares choice.
    names = robot.velocity_names
    steered = [k for k, name in enumerate(robot.steer_names)
               if robot.wheel(name).type in ("steerable", "double") and f"{name}.steer" in names]
    assigned = [0, 1, 2, *(names.index(f"{robot.steer_names[k]}.steer") for k in steered)]
    q_unit, res_unit = solve_assigned(robot.constraint_matrix(configs)[:, None], assigned, np.eye(len(assigned)))
    index = index.reshape(-1)
    motion = np.hstack([twist * dt[:, None], np.diff(beta_nodes[:, steered], axis=0)])
    q = np.einsum("nik,ni->nk", q_unit[index], motion)
    res = np.einsum("nir,ni->nr", res_unit[index], motion)
    bad = np.max(np.abs(res), axis=-1) > 1e-9 * max(1.0, float(np.max(np.abs(twist * dt[:, None]))))
    if bad.any():
        k = int(np.flatnonzero(bad)[0])
        raise WmrkitError(f"profile: at t = {fine[k]:.6g} s the twist {twist[k].tolist()} is not possible for "
                          f"robot '{robot.name}' without slip (its fixed wheels forbid it)")
    rates = q[:, 3:]
    truth = np.vstack([np.asarray(pose0, float)[None], integrate_increments(pose0, twist * dt[:, None], "exact")])
    rng = np.random.default_rng(seed)
    true_pos, meas_pos = {}, {}
    for joint in sensed:
        wheel, _, kind = joint.partition(".")
        if kind == "steer" and robot.wheel(wheel).kind.steers:
            b = beta_nodes[:, robot.steer_names.index(wheel)][sample_idx]
            true_pos[joint] = b
            meas_pos[joint] = b + (rng.normal(0.0, steer_noise, n) if steer_noise > 0 else 0.0)
            continue
        inc = rates[:, names.index(joint) - 3]
        true_pos[joint] = np.concatenate([[0.0], np.cumsum(inc)])[sample_idx]
        for s in slips:
            if s.joint == joint:
                mid = 0.5 * (fine[:-1] + fine[1:])
                inc = np.where((mid >= s.start) & (mid < s.stop), inc * (1.0 + s.ratio), inc)
        if spin_noise_per_rad > 0:
            inc = inc + rng.normal(size=inc.shape) * np.sqrt(spin_noise_per_rad * np.abs(inc))
        meas_pos[joint] = np.concatenate([[0.0], np.cumsum(inc)])[sample_idx]
    counts = {}
    for joint, enc in (encoders or {}).items():
        if joint not in meas_pos:
            raise WmrkitError(f"encoders: '{joint}' is not a sensed joint ({', '.join(sensed)})")
        if isinstance(enc, IncrementalEncoder):
            raw = enc.quantize(meas_pos[joint])
            meas_pos[joint] = raw * enc.radians_per_count
            counts[joint] = enc.wrap(raw)
        elif isinstance(enc, AbsoluteEncoder):  # reads the heading: converted at the door, as a log reader does
            heading = convert_steering(robot, (joint,), meas_pos[joint][:, None], to="heading")[:, 0]
            counts[joint] = enc.quantize(heading)
            meas_pos[joint] = convert_steering(robot, (joint,), enc.angle(counts[joint])[:, None], to="beta")[:, 0]
    log = JointLog(t_samples, sensed, np.column_stack([meas_pos[j] for j in sensed]), source="<synthetic>")
    return SyntheticRun(log, truth[sample_idx], np.column_stack([true_pos[j] for j in sensed]), counts)


def _check_arguments(robot: Robot, sensed: tuple[str, ...], pose0: ArrayLike, spin_noise_per_rad: float,
                     steer_noise: float, slips: Sequence[Slip], oversample: int, seed: int) -> None:
    """Refuse, by name, the arguments of :func:`simulate` that would give NaN poses, a silently noiseless run
    (a negative noise) or a numpy exception (a negative seed, a joint that does not exist)."""
    if not sensed:
        raise WmrkitError(f"sensed: robot '{robot.name}' senses no joint, so a log of it would be empty (list the "
                          "encoders in its wheels' 'sensed' field)")
    for joint in sensed:
        wheel, _, kind = joint.partition(".")
        if joint not in robot.rate_names and not (kind == "steer" and robot.wheel(wheel).kind.steers):
            raise WmrkitError(f"sensed: robot '{robot.name}' has no joint '{joint}' that can be sensed "
                              f"(joints: {', '.join(robot.rate_names)})")
    pose = as_reals(pose0, "pose0")  # text raised numpy's 'could not convert string to float'
    if pose.shape != (3,) or not (np.abs(pose) <= MAX_COORDINATE).all():
        raise WmrkitError(f"pose0: expected (x, y, theta), finite and within {MAX_COORDINATE:g}, got {pose.tolist()}")
    for name, value in (("spin_noise_per_rad", spin_noise_per_rad), ("steer_noise", steer_noise)):
        if isinstance(value, bool) or not (finite_number(value) and value >= 0):
            raise WmrkitError(f"{name}: a noise must be a finite number >= 0, got {value!r}")
    if isinstance(oversample, bool) or not isinstance(oversample, int | np.integer) or oversample < 1:
        raise WmrkitError(f"oversample: expected an integer >= 1 (fine steps per sample), got {oversample!r}")
    check_seed(seed, WmrkitError)
    for i, s in enumerate(slips):
        if s.joint not in sensed or s.joint.endswith(".steer"):
            raise WmrkitError(f"slips[{i}]: '{s.joint}' is not a sensed spin joint ({', '.join(sensed)})")
        if not (-math.inf < s.start < s.stop < math.inf and math.isfinite(s.ratio)):
            raise WmrkitError(f"slips[{i}]: expected finite times start < stop and a finite ratio, got start "
                              f"{s.start}, stop {s.stop}, ratio {s.ratio}")


def _steering(robot: Robot, profile: TwistProfile, fine: np.ndarray, twist: np.ndarray,
              sensed: Sequence[str]) -> tuple[np.ndarray, np.ndarray]:
    """Steering angles at the fine nodes ``(M + 1, n_steer)`` and over the fine intervals ``(M, n_steer)``:
    geometric for steerable/double wheels (the interval's own angle while moving, so a steering change at a node
    does not leak into the interval before it), an ODE for castors (only those with a sensed joint: an unsensed
    castor's angle changes no other wheel's rates), midpoints of the nodes otherwise."""
    out = np.empty((len(fine), len(robot.steer_names)))
    mid = np.empty((len(fine) - 1, len(robot.steer_names)))
    for k, name in enumerate(robot.steer_names):
        wheel = robot.wheel(name)
        if wheel.type in ("castor", "double_castor"):
            mine = any(j.partition(".")[0] == name for j in sensed)
            out[:, k] = _castor_angles(wheel, profile, fine) if mine else wheel.beta
            mid[:, k] = 0.5 * (out[:-1, k] + out[1:, k])
            continue
        x, y = wheel.position
        vx, vy = twist[:, 0] - twist[:, 2] * y, twist[:, 1] + twist[:, 2] * x  # steering joint velocity
        moving = np.hypot(vx, vy) > 1e-12
        b = np.arctan2(vx, -vy)  # axle (cos b, sin b) normal to v, positive spin along v (3.11)
        b = wheel.beta + (b - wheel.beta + np.pi / 2) % np.pi - np.pi / 2  # within 90 deg of the described angle
        out[:, k] = _nodes_from_intervals(np.where(moving, b, np.nan), fine, wheel.beta)
        mid[:, k] = np.where(moving, b, 0.5 * (out[:-1, k] + out[1:, k]))
    return out, mid


def _check_steer_range(robot: Robot, beta_nodes: np.ndarray, fine: np.ndarray, twist: np.ndarray) -> None:
    """Refuse a profile that steers a steerable or double wheel beyond its described ``steer_range`` (the log
    readers refuse such a heading, :func:`.steering.check_steer_range`): the robot cannot drive it."""
    heading = robot.heading_of_beta(beta_nodes)  # (M + 1, n_steer)
    for k, name in enumerate(robot.steer_names):
        wheel = robot.wheel(name)
        if wheel.steer_range is None or wheel.type not in ("steerable", "double"):
            continue
        lo, hi = wheel.steer_range
        bad = np.flatnonzero(~heading_in_range(heading[:, k], lo, hi, tol=1e-9))
        if bad.size:
            i = int(bad[0])
            value = (heading[i, k] + np.pi) % (2 * np.pi) - np.pi
            raise WmrkitError(f"profile: at t = {fine[i]:.6g} s wheel '{name}' would steer to heading "
                              f"{np.degrees(value):.6g} deg, outside its steer_range [{np.degrees(lo):.6g}, "
                              f"{np.degrees(hi):.6g}] deg (twist {twist[min(i, len(twist) - 1)].tolist()}): "
                              f"robot '{robot.name}' cannot drive this profile")


def _nodes_from_intervals(b: np.ndarray, fine: np.ndarray, default: float) -> np.ndarray:
    """Node values: the angle of the interval after (or before) each node; linear in time across stops."""
    nodes = np.concatenate([b, b[-1:]])
    before = np.concatenate([b[:1], b])
    nodes = np.where(np.isnan(nodes), before, nodes)
    ok = ~np.isnan(nodes)
    if not ok.any():
        return np.full(len(fine), default)
    return np.interp(fine, fine[ok], nodes[ok])


def _slip_rows_at(wheel: Wheel) -> Callable[[float], np.ndarray]:
    """``b -> wheel_slip_rows(wheel, b)`` (3.6), (3.11)-(3.13), bit for bit, for one angle ``b`` [rad]: the same
    entries (:func:`~wmrkit.wheels.slip_row_entries`) and products, without wheel_slip_rows's checks, element
    expansion and broadcasting on every call (the castor ODE's right side calls it some 30 times a sample; they
    took two thirds of ``simulate`` of a robot with castors)."""
    parts = [(np.array(e[:2] + e[3:8], dtype=float), e.beta_offset, np.asarray(e.rate_map, dtype=float))
             for e in wheel.elements()]

    def rows(b: float) -> np.ndarray:
        blocks = []
        for (l, alpha, d, delta, gamma, r, r_r), offset, rate_map in parts:
            g = np.array(slip_row_entries(b + offset, l, alpha, d, delta, gamma, r, r_r))
            blocks.append(np.concatenate([g[:, :3], g[:, 3:] @ rate_map], -1))
        return np.concatenate(blocks)

    return rows


def _castor_angles(wheel: Wheel, profile: TwistProfile, fine: np.ndarray) -> np.ndarray:
    from scipy.integrate import solve_ivp

    slip_rows = _slip_rows_at(wheel)
    beta = np.empty(len(fine))
    beta[0] = wheel.beta
    bounds = profile.boundaries
    for s in range(len(profile.durations)):
        mask = (fine >= bounds[s]) & (fine <= bounds[s + 1])
        idx = np.flatnonzero(mask)
        if len(idx) < 2:
            continue
        tw = profile.twists[s]

        def rhs(_t, b, tw=tw):
            rows = slip_rows(b[0])  # (2E, 3 + n_rates): steer rate is the first rate column
            rates = np.linalg.lstsq(rows[:, 3:], -rows[:, :3] @ tw, rcond=None)[0]
            return [rates[0]]

        sol = solve_ivp(rhs, (fine[idx[0]], fine[idx[-1]]), [beta[idx[0]]], t_eval=fine[idx], rtol=1e-10, atol=1e-12)
        beta[idx] = sol.y[0]
    return beta
