"""Executing a plan (§9.3.3): a timed reference with stops and steering switches, driven by the car's kinematics.

Each segment gets a trapezoidal speed profile from ``v_max`` and ``a_max`` (the thesis's simulator: "one
trapezoid per stretch", a stop at every change of direction or steering); at each stop the steering turns to the
next segment's angle at ``steer_rate`` with the car at rest. The reference is followed either open loop through
the robot's own kinematic model (per-wheel inverse kinematics §8.4 gives the steering angles and wheel rates,
forward kinematics (4.11) turns the actuated wheel rates back into the twist, the exact SE(2) step integrates
it), or closed loop through :func:`wmrkit.control.track` (``controller=...``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from .._shapes import finite_number, readonly
from ..errors import WmrkitError
from ..kinematics.wheel_ik import forward_kinematics, wheel_commands
from ..odometry.integrators import integrate_exact, integrate_increments
from ..robot import Robot
from .geometry import Vehicle
from .path import Segment
from .planner import ParkingPlan

if TYPE_CHECKING:
    from ..control.feasibility import Feasibility

#: Wheel radius of the vehicle built from the planner's parameters (the thesis gives none), in car lengths
#: ``a1 + b1``: 0.3 m for example 1's 2 m car.
WHEEL_RADIUS = 0.15
#: Default top speed [car lengths/s] and acceleration [car lengths/s^2] of the execution, the length ``a1 + b1``
#: along which the car drives: 0.5 m/s and 0.5 m/s^2 for example 1's 2 m car, 0.225 for example 2's 0.9 m one.
#: In car lengths, so that a car and its plan scaled together are driven in the same time, and the same steering
#: rate [rad/s], period `dt` [s] and gain [1/s] give the same answers, scaled: in m/s a 2 mm copy of example 1
#: drove its 9 mm path in 7 samples and hit the front car, Table 8.1 "NO". (Not in :func:`.planner.size`: example
#: 2's 3.5 m width would drive it at 0.875 m/s, and the closed loop then hit the rear car.)
V_MAX, A_MAX = 0.25, 0.25
#: Samples of the open loop's kinematics solved at once (its batched inverse and forward kinematics take about
#: 2 KB a sample: a 9.8 km plan, 394,511 samples, took 870 MB at once, 280 MB in chunks).
CHUNK = 10_000
#: Most samples of an executed plan (about 400 bytes each while it is driven: 200 MB; a 57 km plan, 2.3e6
#: samples, took over 3.2 GB and ended in a MemoryError traceback under a 4 GB limit).
MAX_SAMPLES = 500_000


@dataclass(frozen=True, eq=False)
class Execution:
    """A driven plan (frozen, arrays read-only; eq=False: array fields). ``n`` samples:

    ``t`` ``(n,)`` [s]; ``reference`` ``(n, 3)`` P_f's planned pose at ``t``; ``pose`` ``(n, 3)`` P_f's driven pose;
    ``steering`` ``(n,)`` [rad] the equivalent front steering heading commanded (0 straight, CCW positive);
    ``wheel_headings`` ``(n, n_steer)`` [rad] every steerable wheel's heading from the robot's inverse kinematics;
    ``segment`` ``(n,)`` index of the segment (stops belong to the next one); ``mode`` "open-loop" or the
    controller's name; ``deviation`` ``(n,)`` [m] distance of P_f from its reference.
    """

    robot: Robot
    mode: str
    t: np.ndarray
    reference: np.ndarray
    pose: np.ndarray
    steering: np.ndarray
    wheel_headings: np.ndarray
    segment: np.ndarray
    deviation: np.ndarray

    @property
    def duration(self) -> float:
        """Time to drive the whole plan [s]."""
        return float(self.t[-1] - self.t[0])


def vehicle_robot(vehicle: Vehicle, r: float | None = None) -> Robot:
    """The car of Fig. 9.19 as a wmrkit robot: two fixed rear wheels at ``+-d1/2`` (one when ``d1 = 0``) and the
    equivalent steering wheel at ``h1`` ahead; origin P_f, REP-103 frame; rear spins and steering actuated. Wheel
    radius `r` [m], by default :data:`WHEEL_RADIUS` car lengths."""
    r = WHEEL_RADIUS * vehicle.length if r is None else r
    wheels = [{"name": "steer", "type": "steerable", "position": [vehicle.h1, 0.0], "beta": math.pi / 2, "r": r,
               "actuated": ["steer"], "sensed": ["spin", "steer"]}]
    half = vehicle.track / 2
    rear = [("rear_left", half), ("rear_right", -half)] if half > 0 else [("rear", 0.0)]
    wheels += [{"name": n, "type": "fixed", "position": [0.0, y], "beta": math.pi / 2, "r": r,
                "actuated": ["spin"], "sensed": ["spin"]} for n, y in rear]
    return Robot.from_dict({"name": "parking-car", "wheels": wheels})


def trapezoid(length: float, v_max: float, a_max: float, t: np.ndarray) -> np.ndarray:
    """Distance travelled at times `t` [s] on a trapezoidal (or triangular) speed profile over `length` [m]."""
    t_acc = v_max / a_max
    if a_max * t_acc * t_acc >= length:  # triangular: never reaches v_max
        t_acc, v_max = math.sqrt(length / a_max), math.sqrt(length * a_max)
    t_flat = (length - v_max * t_acc) / v_max
    total = 2 * t_acc + t_flat
    t = np.clip(t, 0.0, total)
    up = 0.5 * a_max * np.minimum(t, t_acc) ** 2
    flat = v_max * np.clip(t - t_acc, 0.0, t_flat)
    down_t = np.clip(t - t_acc - t_flat, 0.0, t_acc)
    down = v_max * down_t - 0.5 * a_max * down_t**2
    return np.clip(up + flat + down, 0.0, length)


def trapezoid_duration(length: float, v_max: float, a_max: float) -> float:
    """Duration [s] of :func:`trapezoid` over `length`."""
    if length <= 0:
        return 0.0
    t_acc = v_max / a_max
    if a_max * t_acc * t_acc >= length:
        return 2 * math.sqrt(length / a_max)
    return 2 * t_acc + (length - v_max * t_acc) / v_max


def timed_reference(segments: tuple[Segment, ...] | list[Segment], *, v_max: float = 0.5, a_max: float = 0.5,
                    steer_rate: float = 0.5, dt: float = 0.05) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """``(t, pose, distance, segment)``: P_f's planned pose sampled every `dt` [s], stops included.

    ``distance`` ``(n,)`` [m] is the distance along the current segment; ``segment`` ``(n,)`` its index. Speeds
    [m/s], accelerations [m/s^2], steering rate [rad/s] are positive.
    """
    for name, value in (("v_max", v_max), ("a_max", a_max), ("steer_rate", steer_rate), ("dt", dt)):
        # a_max = inf raised "dt: expected finite numbers, got nan"; dt = inf gave one sample a segment; True was 1
        if isinstance(value, bool) or not (finite_number(value) and value > 0):
            raise WmrkitError(f"{name}: must be a finite number > 0, got {value!r}")
    durations = [abs(seg.steering - steer) / steer_rate + trapezoid_duration(seg.length, v_max, a_max)
                 for seg, steer in zip(segments, [0.0, *(s.steering for s in segments)], strict=False)]
    if sum(max(1, math.ceil(d / dt)) for d in durations) + 1 > MAX_SAMPLES:
        raise WmrkitError(f"the plan takes {sum(durations):.4g} s to drive: executing it samples at most "
                          f"{MAX_SAMPLES} poses ({MAX_SAMPLES * dt:.0f} s at {dt:g} s, docs/limits.md)")
    ts, poses, dists, segs = [], [], [], []
    t0, steer = 0.0, 0.0
    for k, seg in enumerate(segments):
        wait = abs(seg.steering - steer) / steer_rate
        duration = wait + trapezoid_duration(seg.length, v_max, a_max)
        n = max(1, math.ceil(duration / dt))
        local = np.linspace(0.0, duration, n + 1)[(1 if k else 0):]
        s = trapezoid(seg.length, v_max, a_max, local - wait) if seg.length > 0 else np.zeros_like(local)
        ts.append(t0 + local)
        poses.append(integrate_exact(np.array(seg.start), np.array(seg.twist), s))
        dists.append(s)
        segs.append(np.full(len(local), k))
        t0, steer = t0 + duration, seg.steering
    return np.concatenate(ts), np.concatenate(poses), np.concatenate(dists), np.concatenate(segs)


def speed_limits(plan: ParkingPlan, v_max: float | None = None, a_max: float | None = None) -> tuple[float, float]:
    """``(v_max [m/s], a_max [m/s^2])``: the ones given, else :data:`V_MAX` and :data:`A_MAX` car lengths."""
    unit = plan.vehicle.length
    return (V_MAX * unit if v_max is None else v_max, A_MAX * unit if a_max is None else a_max)


def execute_plan(plan: ParkingPlan, robot: Robot | None = None, *, v_max: float | None = None,
                 a_max: float | None = None, steer_rate: float = 0.5, dt: float = 0.05, controller: str | None = None,
                 gain: float = 1.0) -> Execution:
    """Drive `plan` with `robot` (default :func:`vehicle_robot`; a car-like robot with its origin anywhere).

    Speed `v_max` [m/s] and acceleration `a_max` [m/s^2] default to :func:`speed_limits` (in car lengths); the
    steering rate [rad/s], period `dt` [s] and `gain` [1/s] have no length, so a scaled car gets scaled answers.

    Open loop (``controller=None``): inverse kinematics of the robot for the planned twist, forward kinematics
    from the actuated wheel rates, exact integration. Closed loop: ``controller`` ``"p"`` or ``"pi"``, the
    thesis's position laws (8.2)-(8.3) of :func:`wmrkit.control.track` with pole `gain` [1/s], steering the
    midpoint of the steering axle along its planned path (the geometric trackers of ``wmrkit.control`` drive
    forward only and cannot follow the cusps of a parking path).
    """
    if not plan.feasible:
        raise WmrkitError(f"the plan is not feasible ({plan.reason}): nothing to execute")
    robot = vehicle_robot(plan.vehicle) if robot is None else robot
    _check_steering(plan, robot)  # refuses robots that are not car-like, or cannot steer the plan
    offset = _rear_axle_midpoint(robot)
    v_max, a_max = speed_limits(plan, v_max, a_max)
    t, ref, dist, seg = timed_reference(plan.segments, v_max=v_max, a_max=a_max, steer_rate=steer_rate, dt=dt)
    kappa = np.array([s.curvature for s in plan.segments])[seg]
    direction = np.array([s.direction for s in plan.segments])[seg]
    steering = np.array([s.steering for s in plan.segments])[seg]
    if controller not in (None, "p", "pi"):
        raise WmrkitError(f"controller '{controller}': a parking path reverses; use 'p' or 'pi' (thesis 8.2-8.3) "
                          "or none (open loop)")
    if controller is None:
        pose, headings = _open_loop(robot, offset, ref[0], t, dist, seg, kappa, direction)
        mode = "open-loop"
    else:
        pose, headings = _closed_loop(robot, offset, t, ref, controller, gain)
        mode = controller
    deviation = np.hypot(pose[:, 0] - ref[:, 0], pose[:, 1] - ref[:, 1])
    return Execution(robot, mode, readonly(t), readonly(ref), readonly(pose), readonly(steering),
                     readonly(headings), readonly(seg), readonly(deviation))


def _check_steering(plan: ParkingPlan, robot: Robot) -> None:
    """Refuse a `robot` that is not car-like (:func:`.problem.car_axles`), or whose wheels' ``steer_range`` does not
    reach the plan's tightest turn (open loop they were turned beyond it, closed loop the car left the path)."""
    from .problem import car_axles, curvature_limit

    h1 = car_axles(robot)[0]
    kappa = max((abs(s.curvature) for s in plan.segments), default=0.0)
    limit = curvature_limit(robot)
    if kappa > limit * (1 + 1e-9):
        raise WmrkitError(f"the plan steers to {math.degrees(math.atan(h1 * kappa)):.4g} deg; robot '{robot.name}' "
                          f"steers at most {math.floor(math.degrees(math.atan(h1 * limit)) * 100) / 100:.2f} deg "
                          f"within its wheels' steer_range (radius {1 / kappa:.4g} m planned, {1 / limit:.4g} m "
                          "reachable): plan with that phi_max")


def _rear_axle_midpoint(robot: Robot) -> np.ndarray:
    fixed = [w for w in robot.wheels if w.type == "fixed"]
    return np.mean([[w.l * math.cos(w.alpha), w.l * math.sin(w.alpha)] for w in fixed], axis=0)


def _origin_twist(twist_pf: np.ndarray, offset: np.ndarray) -> np.ndarray:
    """Body twist of the robot origin from that of P_f at `offset` (rigid body: v_o = v_P - omega x r_P)."""
    out = twist_pf.copy()
    out[..., 0] += twist_pf[..., 2] * offset[1]
    out[..., 1] -= twist_pf[..., 2] * offset[0]
    return out


def _pf_pose(pose_origin: np.ndarray, offset: np.ndarray) -> np.ndarray:
    c, s = np.cos(pose_origin[:, 2]), np.sin(pose_origin[:, 2])
    return np.column_stack([pose_origin[:, 0] + c * offset[0] - s * offset[1],
                            pose_origin[:, 1] + s * offset[0] + c * offset[1], pose_origin[:, 2]])


def _origin_pose(pose_pf: np.ndarray, offset: np.ndarray) -> np.ndarray:
    c, s = math.cos(pose_pf[2]), math.sin(pose_pf[2])
    return np.array([pose_pf[0] - c * offset[0] + s * offset[1], pose_pf[1] - s * offset[0] - c * offset[1],
                     pose_pf[2]])


def _open_loop(robot, offset, pose0, t, dist, seg, kappa, direction):
    step = np.diff(dist, prepend=dist[0])
    # a segment's first sample follows the previous segment's end, its start: the car has driven dist from there
    # (more than 0 when the steering wait is shorter than dt; setting it to 0 lost 0.6 mm a stop at dt = 0.05 s)
    new = np.r_[False, seg[1:] != seg[:-1]]
    step[new] = dist[new]
    dt = np.diff(t, prepend=t[0])
    speed = np.divide(step, dt, out=np.zeros_like(step), where=dt > 0)
    twist_pf = np.column_stack([direction * speed, np.zeros_like(speed), direction * speed * kappa])
    unit = np.column_stack([direction, np.zeros_like(speed), direction * kappa])  # steering set at rest too
    names = [f"{w.name}.spin" for w in robot.wheels if "spin" in w.actuated]
    idx = [robot.rate_names.index(n) for n in names]
    twist = np.empty_like(twist_pf)
    beta = np.empty((len(t), len(robot.steer_names)))
    for part in (slice(k, k + CHUNK) for k in range(0, len(t), CHUNK)):  # bounded memory: ~2 KB a sample at once
        commands = wheel_commands(robot, _origin_twist(unit[part], offset))
        moving = wheel_commands(robot, _origin_twist(twist_pf[part], offset), commands.beta)
        rates = {n: moving.rates[:, i] for n, i in zip(names, idx, strict=True)}
        twist[part] = forward_kinematics(robot, rates, commands.beta)[0]
        beta[part] = commands.beta
    origin0 = _origin_pose(pose0, offset)
    increments = twist * dt[:, None]
    origin = np.vstack([origin0, integrate_increments(origin0, increments[1:])])
    return _pf_pose(origin, offset), np.asarray(robot.heading_of_beta(beta))


def _closed_loop(robot, offset, t, ref, controller, gain):
    """Track the steering axle's midpoint (a point off the fixed axle, as §8.6 controls) with wmrkit.control."""
    from ..control.track import MAX_CONTINUOUS_SAMPLES, track

    output_dt = float(t[1] - t[0])
    if t[-1] / output_dt > MAX_CONTINUOUS_SAMPLES:  # track's own refusal named its options (--duration, ...)
        raise WmrkitError(f"controller '{controller}': the plan takes {t[-1]:.0f} s to drive; the closed loop "
                          f"simulates at most {MAX_CONTINUOUS_SAMPLES * output_dt:.0f} s: execute it open loop "
                          "(no controller), or plan a shorter pass (dx2)")
    reference, front = _steering_axle_reference(robot, offset, t, ref)
    run = track(robot, reference, controller=controller, gain=gain, point=tuple(front),
                initial_pose=_origin_pose(ref[0], offset), output_dt=output_dt)
    pose = np.stack([np.interp(t, run.t, run.pose[:, j]) for j in range(3)], axis=-1)
    heading = np.stack([np.interp(t, run.t, run.heading[:, j]) for j in range(run.heading.shape[1])], axis=-1)
    return _pf_pose(pose, offset), heading


def _steering_axle_reference(robot: Robot, offset: np.ndarray, t: np.ndarray, ref: np.ndarray):
    """``(reference, point)``: the timed path of the steering axle's midpoint, `point` ``(2,)`` [m, robot frame],
    when P_f (at `offset` from the robot origin) follows `ref` ``(n, 3)`` at `t` (what the closed loop tracks)."""
    from ..control.references import reference_from_samples

    front = np.mean([[w.l * math.cos(w.alpha), w.l * math.sin(w.alpha)] for w in robot.wheels
                     if w.type == "steerable"], axis=0)
    point = front - offset  # in P_f's frame (the robot frame translated to P_f)
    c, s = np.cos(ref[:, 2]), np.sin(ref[:, 2])
    target = np.column_stack([ref[:, 0] + c * point[0] - s * point[1], ref[:, 1] + s * point[0] + c * point[1],
                              ref[:, 2]])
    return reference_from_samples("parking plan", t, target), front


def plan_feasibility(plan: ParkingPlan, robot: Robot | None = None, *, v_max: float | None = None,
                     a_max: float | None = None, steer_rate: float = 0.5, dt: float = 0.05) -> Feasibility:
    """Table 8.1's verdict (§8.5, kinematic framework) on `plan` timed as :func:`execute_plan` drives it (its
    ``v_max``, ``a_max``, ``steer_rate``, ``dt``), for `robot` (default :func:`vehicle_robot`) tracked at its
    steering axle's midpoint, as the closed loop tracks it: the same verdict as that run's ``feasibility``."""
    from ..control.feasibility import feasibility

    if not plan.feasible:
        raise WmrkitError(f"the plan is not feasible ({plan.reason}): nothing to judge")
    robot = vehicle_robot(plan.vehicle) if robot is None else robot
    v_max, a_max = speed_limits(plan, v_max, a_max)
    t, ref, _, _ = timed_reference(plan.segments, v_max=v_max, a_max=a_max, steer_rate=steer_rate, dt=dt)
    reference, front = _steering_axle_reference(robot, _rear_axle_midpoint(robot), t, ref)
    return feasibility(robot, reference, point=(float(front[0]), float(front[1])))
