"""One call that tracks a reference with any robot: :func:`track` -> :class:`TrackingRun` (what ``wmrkit track``
prints, and what a planner, e.g. the parking application, calls to execute a plan)."""

from __future__ import annotations

import math
from dataclasses import replace
from typing import TYPE_CHECKING, Literal

import numpy as np
from numpy.typing import ArrayLike

from .._shapes import as_real, as_vectors, readonly
from ..kinematics.wheel_ik import wheel_commands
from ..limits import MAX_COORDINATE, MAX_SPEED
from ..robot import Robot
from ..wheels import heading_from_beta
from .actuators import LowLevelLoops
from .feasibility import BLOCK, Feasibility, feasibility
from .follower_run import Limit, check_arrival, follower_bound, span
from .laws import PositionLaw, check_gate, check_sampling, fastest_pole
from .loop import MAX_SAMPLED_EVALUATIONS, Plant, check_stiffness, longest_sampled_run, simulate
from .points import (
    ControlError,
    ControlPoint,
    StoppedRun,
    check_delay,
    control_point,
    point_pose,
    robot_reach,
)
from .references import Reference
from .trackers import (
    PathFollower,
    PathIndex,
    default_wheelbase,
    max_curvature,
    pure_pursuit,
    stanley,
    top_speed,
)
from .tracking_run import SLIP_TOL, TrackingRun

if TYPE_CHECKING:
    from ..slip.kalman import KalmanNoise
    from ..slip.weights import SlipWeights

__all__ = ["CONTROLLERS", "SLIP_TOL", "TrackingRun", "from_first_sample", "initial_pose_on", "track"]

#: Controllers: the thesis's laws (8.1)-(8.3) and the two geometric trackers users use.
CONTROLLERS = ("p", "pi", "point", "pure-pursuit", "stanley")


def initial_pose_on(cp: ControlPoint, reference: Reference) -> np.ndarray:
    """The pose whose controlled point sits on the reference's start, rolling along it (zero initial error)."""
    x, y, th = reference.pose[0]
    theta = th - cp.forward if cp.reduced else th
    c, s = math.cos(theta), math.sin(theta)
    px, py = cp.point
    return np.array([x - c * px + s * py, y - s * px - c * py, theta])


def track(robot: Robot, reference: Reference, *, controller: str = "p", gain: float = 1.0,
          integral_gain: float | None = None, gate: float | None = None, initial_pose: ArrayLike | None = None,
          period: float | None = None, delay: int = 0, duration: float | None = None,
          point: ArrayLike | None = None, loops: LowLevelLoops | None = None, policy: str = "closest",
          skew_free: bool = False, lookahead: float | None = None, stanley_gain: float = 1.0,
          output_dt: float = 0.05, dynamics: bool = False, tyre: str | None = None,
          feedback: str = "pose", slip_model: str = "none", weights: SlipWeights | None = None,
          noise: KalmanNoise | None = None, ramp: bool = False, progress: bool = False) -> TrackingRun:
    """Track `reference` with `robot` (thesis ch. 8): closed loop, continuous (``period`` None) or discrete.

    The run's time 0 is the reference's first sample (:func:`from_first_sample`: TUM files carry Unix times).
    `duration` [s]: default the reference's; a geometric tracker's default run ends once its point has passed the
    path's end, within :func:`.trackers.follower_duration`, its extra time cut to what the loop's limits allow
    (:func:`.follower_run.follower_bound`; warning :class:`.trackers.ArrivalWarning` when it ends more than
    its ``arrival_tol`` from the end, naming the limit that cut it); a given `duration` is run whole.

    `controller`: ``"p"`` (8.2), ``"pi"`` (8.3), ``"point"`` (8.1), ``"pure-pursuit"``, ``"stanley"``. `gain`: the pole
    ``a`` [1/s] of every coordinate; `integral_gain` ``b`` [1/s^2] of ``"pi"`` (default ``a^2/4``, critically damped);
    `gate` [m]: feedforward gate (8.53). `initial_pose` ``(3,)`` default: the tracked point on the reference
    (:func:`initial_pose_on`; the geometric trackers' own point). `delay` in samples (discrete only). `point` ``(2,)``
    [m]: controlled point of a reduced-mobility robot (:func:`control_point`). `loops`: low-level actuator loops;
    `policy`: steering root (:mod:`.steering`). `skew_free`: second-order discretisation of the held twist.
    Geometric trackers: `lookahead` [m] (pure pursuit; default :func:`.trackers.default_lookahead`, the wheelbase of
    a robot with steered wheels, at least 2 s at the reference's top speed), `stanley_gain` [1/s]. `dynamics`: the
    plant is the chapter-7 dynamic model with tyres (`tyre`: traction model name, default as described), driven by
    servos each period (:func:`.dynamic_plant.simulate_dynamics`; period default 0.02 s); with it,
    `feedback="odometry"` measures the pose by odometry from the sensed joints (``TrackingRun.estimate``) instead of
    exactly, ``"wls"`` by WLS odometry with friction coefficients `weights`, ``"fk2"`` by the Kalman filter FK2 with
    `noise`; `slip_model` ``"mqe"`` or ``"mcd"``: the wheel commands come from the inverse slip model instead of the
    no-slip IK (thesis future work 4, :func:`.slip_loop.simulate_slip_control`); `ramp`: there, each period's
    commands are reached linearly over the period instead of held (first-order hold). `progress`: a tqdm bar over
    the periods of such a loop.
    """
    if controller not in CONTROLLERS:
        raise ControlError(f"unknown controller '{controller}' (controllers: {', '.join(CONTROLLERS)})")
    # the Python API reads no units: text ("1" read as 1 s, or a bare TypeError) and booleans are refused
    gain, stanley_gain, output_dt = (as_real(v, what) for what, v in
                                     (("gain", gain), ("stanley_gain", stanley_gain), ("output_dt", output_dt)))
    integral_gain, gate, period, duration, lookahead = (
        None if v is None else as_real(v, what) for what, v in (
            ("integral_gain", integral_gain), ("gate", gate), ("period", period), ("duration", duration),
            ("lookahead", lookahead)))
    if not (math.isfinite(gain) and gain >= 0):
        raise ControlError(f"gain: expected a pole a >= 0 (1/s), got {gain}")
    check_delay(delay)
    if period is None and delay and not dynamics:
        raise ControlError("delay: a measurement delay in samples needs a sample period (--period)")
    cp = control_point(robot, point)
    if reference.t[0] != 0.0:  # absolute (TUM: Unix) times: the run's clock starts at the first sample
        reference = from_first_sample(reference)
    geometric = controller in ("pure-pursuit", "stanley")
    given_duration = duration is not None
    sampled = 0.02 if dynamics and period is None else period
    slipping = slip_model != "none" or feedback not in ("pose", "odometry") or ramp
    cut = None
    if given_duration:
        duration = float(duration)
    elif geometric:  # a longer run, within the loop's limits
        limits = _limits(robot, Plant(loops, policy), sampled, dynamics, slipping, output_dt)
        duration, cut = follower_bound(reference.duration, limits)
    else:
        duration = reference.duration
    _check_timing(duration, sampled, output_dt)
    if sampled is not None and delay > 0 and delay * sampled >= duration:
        raise ControlError(f"delay: {delay} samples of {sampled:g} s reach past the run ({duration:g} s): the loop "
                           "would never see a measurement (open loop)")
    pose0 = initial_pose_on(cp, reference) if initial_pose is None else as_vectors(initial_pose, 3, "initial_pose")
    if not (np.abs(pose0) <= MAX_COORDINATE).all() or pose0.ndim != 1:  # NaN included
        raise ControlError(f"initial_pose: expected one pose (x, y, theta), finite and within {MAX_COORDINATE:g}, "
                           f"got {pose0.tolist()}")
    if controller in ("p", "pi", "point"):
        b = gain * gain / 4 if integral_gain is None else integral_gain
        if controller == "pi" and integral_gain is None and not math.isfinite(b):  # beyond a ~ 1.3e154 1/s
            raise ControlError(f"gain: {gain:g} 1/s: the PI law's integral gain a^2 / 4 overflows")
        law = PositionLaw.uniform(controller, gain, b if controller == "pi" else 0.0, gate)  # type: ignore[arg-type]
        if sampled is not None:
            check_sampling(law, sampled, delay=delay, stacklevel=3)
        check_gate(law, reference.velocity, stacklevel=3)
        # the law in scalar arithmetic (law_controller's numbers): a few us a call, for every loop (issue 11)
        from .dynamic_plant import fast_law_controller

        ctrl, tracked_point = fast_law_controller(cp, law, reference), cp.point
        pole, what = fastest_pole(law), f"gain (--gain) {gain:g} 1/s"
    elif controller == "pure-pursuit":
        ctrl, tracked_point = pure_pursuit(cp, reference, lookahead, max_curvature(robot)), cp.axle_point
        pole, what = 0.0, ""
    else:
        length = default_wheelbase(cp)
        ctrl = stanley(cp, reference, stanley_gain, length, min(1.2, math.atan(length * max_curvature(robot))))
        tracked_point = cp.axle_point + length * np.array([math.cos(cp.forward), math.sin(cp.forward)])
        pole, what = stanley_gain, f"stanley gain (--stanley-gain) {stanley_gain:g} 1/s"  # e' = -k e near the path
    stops = isinstance(ctrl, PathFollower) and not given_duration
    until = ctrl.stop_rule(None if sampled is None else delay) if stops else None
    if initial_pose is None and geometric:  # the tracker's own point starts on the reference, not the law's
        pose0 = initial_pose_on(_full_point(cp, tracked_point), reference)
    if dynamics:
        from .dynamic_plant import simulate_dynamics

        if loops is not None or skew_free:
            raise ControlError("dynamics: the wheels are driven by the dynamic model's servos; no low-level loops "
                               "or skew-free option with it")
        from ..dynamics.runs import DivergedError, UnstableStepError
        from ..dynamics.simulate import LiftOffError

        period = 0.02 if period is None else period
        _check_dynamic_work(duration, period, slipping)
        call = f"wmrkit.control.{'simulate_slip_control' if slipping else 'simulate_dynamics'}"  # has a step
        try:
            if slipping:
                from .slip_loop import simulate_slip_control

                out = simulate_slip_control(robot, ctrl, pose0, duration, period=period, delay=delay, tyre=tyre,
                                            slip_model=slip_model, feedback=feedback, weights=weights, noise=noise,
                                            ramp=ramp, step=DYNAMICS_STEP, progress=progress, policy=policy,
                                            until=until)
            else:
                out = simulate_dynamics(robot, ctrl, pose0, duration, period=period, delay=delay, tyre=tyre,
                                        feedback=feedback, step=DYNAMICS_STEP, policy=policy, until=until)
        except LiftOffError as err:
            raise _stopped(StoppedRun(
                f"{err.what}; the servos follow each period's command with up to the grip's torque, so a step in the "
                "command (a corner of the reference, a start off it) can tip the robot: give a smoother reference, a "
                "lower speed or gain, or start on the reference", err.t), robot, reference, tracked_point,
                "dynamic") from None
        except DivergedError as err:  # the state's: its advice named a step, which is no option of track's
            raise _stopped(StoppedRun(
                f"{err.what}; lower the speed or the gain; track integrates at {DYNAMICS_STEP:g} s, which no option "
                f"changes (in Python, {call}(..., step=...) runs the loop at a shorter one)", err.t), robot, reference,
                tracked_point, "dynamic") from None
        except StoppedRun as err:
            raise _stopped(err, robot, reference, tracked_point, "dynamic") from None
        except UnstableStepError as err:  # its step is no option of track's
            raise err.advised(f"track integrates at {DYNAMICS_STEP:g} s, which no option changes; in Python, "
                              f"{call}(..., step={err.fine:.3g}) runs the loop at the step that "
                              + ("went on" if err.conclusive else "would tell")) from None
    elif feedback != "pose" or slip_model != "none" or ramp:
        what = (f"feedback='{feedback}'" if feedback != "pose" else f"slip_model='{slip_model}'"
                if slip_model != "none" else "ramp=True")
        raise ControlError(f"{what} needs the dynamic plant (dynamics=True): it acts on the dynamics with tyres")
    else:
        if period is None:
            _check_continuous_work(cp, reference, pose0, duration, output_dt,
                                   gain if controller in ("p", "pi", "point") else None)
            if top_speed(reference) > 0:  # a follower stops at the path's end (at rest, errors may stay exactly 0)
                check_stiffness(pole, min(duration, reference.duration) if stops else duration, duration, what)
        try:
            out = simulate(robot, ctrl, pose0, duration, period=period, delay=delay, plant=Plant(loops, policy),
                           output_dt=output_dt, skew_free=skew_free, breaks=reference.breaks,
                           rtol=1e-5 if geometric else 1e-8, until=until,
                           atol=GEOMETRIC_ATOL_TIME * _speed_scale(robot, reference) if geometric else 1e-10)
        except StoppedRun as err:
            raise _stopped(err, robot, reference, tracked_point, "kinematic") from None
    t, pose = out["t"], out["pose"]
    if not (np.all(np.isfinite(pose)) and np.all(np.abs(pose[:, :2]) <= MAX_COORDINATE)):
        k = int(np.argmax(~(np.isfinite(pose).all(axis=1) & (np.abs(pose[:, :2]) <= MAX_COORDINATE).all(axis=1))))
        raise _stopped(StoppedRun(f"the closed loop diverged at t = {t[k]:.6g} s (the pose leaves "
                                  f"{MAX_COORDINATE:g} m): lower the gain, or shorten the period", float(t[k])),
                       robot, reference, tracked_point, "dynamic" if dynamics else "kinematic")
    if isinstance(ctrl, PathFollower) and not given_duration:
        check_arrival(ctrl, t, pose, cut, None if sampled is None else delay)
    tcp = _full_point(cp, tracked_point)
    tracked = point_pose(tcp, pose)
    ref = reference.sample(t)
    error = np.hypot(tracked[:, 0] - ref[:, 0], tracked[:, 1] - ref[:, 1])
    cross = PathIndex(reference).cross_track(tracked[:, :2])
    commands = wheel_commands(robot, out["twist"], out["target"])
    if "rates" in out:  # the commanded rates of the actuated wheels (the slip model's when it gave them)
        from .slip_loop import with_commanded_rates

        commands = with_commanded_rates(robot, commands, out["info"]["assigned"], out["rates"])
    steer_delta = np.array([robot.wheel(n).delta for n in robot.steer_names])
    heading = heading_from_beta(out["beta"], steer_delta)
    return TrackingRun(robot, controller, readonly(t), readonly(pose), readonly(ref), readonly(tracked),
                       readonly(error), readonly(cross), readonly(out["twist"]), readonly(np.asarray(heading)),
                       commands, period, delay, readonly(out["estimate"]) if "estimate" in out and
                       feedback != "pose" else None, slip_model, feedback,
                       readonly(~out["in_range"]) if "in_range" in out else None,
                       _feasibility(robot, reference, tracked_point, "dynamic" if dynamics else "kinematic",
                                    # a follower slows to its own stop at the path's end, not the reference's
                                    min(t[-1], reference.duration) if geometric else t[-1]),
                       readonly(np.asarray(heading_from_beta(out["target"], steer_delta))),
                       readonly(out["moved"]) if "moved" in out else None)


def _limits(robot: Robot, plant: Plant, sampled: float | None, dynamics: bool, slipping: bool,
            output_dt: float) -> list[Limit]:
    """The longest runs the loop allows [s] (the refusals of :func:`_check_timing`, :func:`.loop.simulate`,
    :func:`_check_continuous_work`, :func:`_check_dynamic_work`), each with how to lift it."""
    step = output_dt if sampled is None else sampled
    out = [Limit(span(MAX_SAMPLES, step), f"the limit of {MAX_SAMPLES:.0e} samples of {step:g} s",
                 "give a longer period (--period)")]
    if dynamics:
        from ..dynamics.simulate import MAX_STEPS

        out.append(Limit(span(MAX_STEPS, DYNAMICS_STEP), f"the dynamics' limit of {MAX_STEPS:.0e} integration steps",
                         "give a shorter reference"))
        if slipping:
            out.append(Limit(span(MAX_SLIP_PERIODS, step), f"the limit of {MAX_SLIP_PERIODS} periods with the slip "
                             "model", "give a longer period (--period)"))
    elif sampled is None:
        out.append(Limit(span(MAX_CONTINUOUS_SAMPLES, output_dt), "the continuous loop's limit of "
                         f"{MAX_CONTINUOUS_SAMPLES * output_dt:g} s", "give a sample period (--period)"))
    else:
        out.append(Limit(longest_sampled_run(robot, plant, sampled), f"the sampled loop's limit of "
                         f"{MAX_SAMPLED_EVALUATIONS} evaluations", "give a longer period (--period)"))
    return out


def _stopped(err: StoppedRun, robot: Robot, reference: Reference, point: np.ndarray,
             framework: Literal["kinematic", "dynamic"]) -> StoppedRun:
    """`err`, naming the last jump of `reference` at or before the run stopped that Table 8.1 says the robot
    tracked at `point` cannot follow (the likely cause: a step of the commands), if there is one."""
    verdict = _feasibility(robot, reference, point, framework, err.t)
    found = [v for v in verdict.violations if v.signal != "turn"] if verdict else []  # jumps, not a TightTurn
    if not found:
        return err
    last = found[-1].t
    jumps = [v for v in found if v.t == last]
    end = " (the reference's end, where it stops)" if last == reference.t[-1] else ""
    return StoppedRun(f"{err}; before it, at t = {last:.4g} s{end}, Table 8.1 (column '{verdict.requirement.column}' "
                      f"for the tracked point, {framework} framework) found a jump the robot cannot follow: "
                      f"{' and '.join(v.kind for v in jumps)}: {jumps[0].remedy}", err.t)


def _feasibility(robot: Robot, reference: Reference, point: np.ndarray,
                 framework: Literal["kinematic", "dynamic"], end: float) -> Feasibility | None:
    """Table 8.1's verdict on `reference` for `robot` tracked at `point` ``(2,)`` [m, robot frame], its violations
    up to `end` [s]; None for a degenerate robot (no column of the table) other than a skid steer."""
    from .feasibility import requirement

    try:  # a skid steer is judged as the differential drive it drives as, as feasibility does
        requirement(robot, framework, point=(float(point[0]), float(point[1])))
    except ControlError:
        return None
    # the run's part, and a margin to judge its end: a 10 s run (4.2 s) of an 8.8e6-sample circle judged it all in 3.9 s
    stop = int(np.searchsorted(reference.t, end, side="right")) + 2 * BLOCK
    last = float(reference.t[-1])
    if stop < len(reference.t):
        reference = replace(reference, t=reference.t[:stop], pose=reference.pose[:stop],
                            velocity=reference.velocity[:stop], acceleration=reference.acceleration[:stop])
    elif end > last and framework == "dynamic":  # past its end the reference holds its last pose at rest
        # the speed steps to 0 there: the wheel rates jump, which the dynamic framework forbids in every column; the
        # kinematic one lets them jump, and no wheel must re-orient for a stop that nothing follows (types 3 and 5
        # need p_ref C1 for the wheels' headings, which (8.10) gives from p_ref's velocity: undefined at rest)
        reference = held_at_rest(reference, 2 * BLOCK)
    found = feasibility(robot, reference, framework, point=(float(point[0]), float(point[1])))
    stopped = float(reference.t[-2 * BLOCK]) if end > last and framework == "dynamic" else math.nan  # first at rest
    found_all = (replace(v, t=last) if v.t == stopped else v for v in found.violations)  # the stop: at the end
    return Feasibility(found.requirement, tuple(v for v in found_all if v.t <= end))


def held_at_rest(reference: Reference, samples: int) -> Reference:
    """`reference` and `samples` more samples, at its sample spacing, at rest at its last pose: what the loop
    follows past its end (:meth:`Reference.at`), its speed stepping to 0 after the last sample (Table 8.1 judges
    that step as any other)."""
    t = reference.t[-1] + (reference.t[-1] - reference.t[-2]) * np.arange(1, samples + 1)
    rest = np.zeros((samples, 3))
    return replace(reference, t=np.r_[reference.t, t], pose=np.vstack([reference.pose, rest + reference.pose[-1]]),
                   velocity=np.vstack([reference.velocity, rest]),
                   acceleration=np.vstack([reference.acceleration, rest]))


#: Most samples of a run (control periods, or output samples of a continuous loop): each costs a control law
#: evaluation in Python.
MAX_SAMPLES = 10**6


def _check_timing(duration: float, period: float | None, output_dt: float) -> None:
    if not (math.isfinite(duration) and duration > 0):
        raise ControlError(f"duration: expected a positive number of seconds, got {duration}")
    if period is not None and not (math.isfinite(period) and 0 < period <= duration):
        raise ControlError(f"period: expected a sample period in (0, duration = {duration:g} s], got {period:g} s")
    if not (math.isfinite(output_dt) and output_dt > 0):
        raise ControlError(f"output_dt: expected a positive number of seconds, got {output_dt:g}")
    step = output_dt if period is None else period
    if duration / step > MAX_SAMPLES:
        raise ControlError(f"duration {duration:g} s at {'a period' if period else 'an output step'} of {step:g} s: "
                           f"more than {MAX_SAMPLES} samples; give a shorter duration (--duration)"
                           f"{' or a longer period (--period)' if period else ''}")


#: Most output samples of a continuous kinematic loop (2000 s at the 0.05 s output step): each costs about 1.7 ms
#: (its share of the ODE's evaluations, and the record), so a 1 km circle at 0.5 m/s (12,566 s) took 6 min.
MAX_CONTINUOUS_SAMPLES = 40_000


def _check_continuous_work(cp: ControlPoint, reference: Reference, pose0: np.ndarray, duration: float,
                           output_dt: float, gain: float | None) -> None:
    """Refuse up front a continuous kinematic loop that would run for minutes, or command an impossible speed: too
    long a run, or (under a law) a start so far from the reference that the law commands beyond ``MAX_SPEED``.
    With fixed wheels the heading then turns at ``speed / |point|``, and the explicit integrator crawls until its
    evaluation budget ends (``--from 1e9 1e9 3``: 50 s before 'too stiff'); without, the run would report motion
    at that speed (or, beyond 1e6 m/s, a loop 'diverged at t = 0')."""
    if duration / output_dt > MAX_CONTINUOUS_SAMPLES:
        raise ControlError(f"duration {duration:g} s (--duration, or the reference's length at its --speed and "
                           f"--size): a continuous loop simulates at most {MAX_CONTINUOUS_SAMPLES * output_dt:g} s "
                           f"({MAX_CONTINUOUS_SAMPLES} output samples of {output_dt:g} s, about 1 min of computing); "
                           "give a shorter --duration, or a sample period (--period)")
    if gain is None:
        return
    distance = float(np.hypot(*(point_pose(cp, pose0)[:2] - reference.pose[0, :2])))
    speed = gain * distance + float(np.hypot(*reference.velocity[0, :2]))
    if speed > MAX_SPEED:
        reach = max(0.0, MAX_SPEED - float(np.hypot(*reference.velocity[0, :2]))) / gain
        why = (f"the continuous loop would be too stiff to integrate (the heading turns at that speed over "
               f"{float(np.hypot(*cp.point)):.3g} m)" if cp.reduced else "no wheeled robot moves so fast")
        raise ControlError(f"initial pose (--from): the controlled point starts {distance:.4g} m from the reference, "
                           f"and the law commands {speed:.4g} m/s at t = 0, beyond {MAX_SPEED:g} m/s: {why}; start "
                           f"closer to the reference (within {reach:.4g} m at this gain), lower the gain, or give a "
                           "sample period (--period)")


#: Integration step of the loops through the dynamics [s] (their default).
DYNAMICS_STEP = 1e-3
#: The geometric trackers' absolute integration tolerance [m] as a time [s] at the reference's top speed (1e-7 m at
#: 0.5 m/s): relative, as their lengths are (:mod:`.trackers`), so a scaled run is the same run scaled.
GEOMETRIC_ATOL_TIME = 2e-7
def _speed_scale(robot: Robot, reference: Reference) -> float:
    """The speed [m/s] setting a geometric tracker's integration tolerance: the reference's top speed, or for a
    reference at rest (0: the tolerance 0, the integrator's first step at t = NaN, a traceback) the robot's size
    per second."""
    return top_speed(reference) or robot_reach(robot)


#: Most control periods of a loop with slip-model commands or slip-aware feedback: each solves the nonlinear slip
#: model (1 to 2.3 ms a period for the skid steer and the forklift: at most about 2 min).
MAX_SLIP_PERIODS = 50_000


def _check_dynamic_work(duration: float, period: float, slipping: bool) -> None:
    from ..dynamics.simulate import MAX_STEPS

    if duration / DYNAMICS_STEP > MAX_STEPS:
        raise ControlError(f"duration {duration:g} s through the dynamics: more than {MAX_STEPS:.0e} integration "
                           f"steps of {DYNAMICS_STEP:g} s")
    if slipping and duration / period > MAX_SLIP_PERIODS:
        raise ControlError(f"duration {duration:g} s at a period of {period:g} s: more than {MAX_SLIP_PERIODS} control "
                           "periods with slip-model commands or feedback (each solves the slip model)")


def from_first_sample(reference: Reference) -> Reference:
    """`reference` with its times (and breaks) counted from its first sample [s]: what :func:`track` follows (the
    loop starts at t = 0; a reference starting later was held at its first pose, one already over at its last)."""
    t0 = float(reference.t[0])
    return replace(reference, t=readonly(reference.t - t0), breaks=tuple(b - t0 for b in reference.breaks))


def _full_point(cp: ControlPoint, p: np.ndarray) -> ControlPoint:
    return replace(cp, point=readonly(np.asarray(p, dtype=float).copy()))
