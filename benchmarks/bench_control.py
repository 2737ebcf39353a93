"""Kinematic control (thesis ch. 8): the cost of one control tick against WPILib's, and simulation speed.

- one tick of the thesis's loop for a differential drive (position law (8.2) at the point ahead of the axle, the
  admissible twist, per-wheel IK ``wheel_commands``), against WPILib's ``RamseteController.calculate`` followed by
  ``DifferentialDriveKinematics.toWheelSpeeds``, called once per tick from Python in both cases;
- the same tick for a swerve-4 (full pose) against ``HolonomicDriveController.calculate`` + ``toSwerveModuleStates``;
- both again through the single-call path :func:`wmrkit.control.tick.control_tick` (scalar law, compiled IK);
- the single-call tick of the geared units (examples/robots/geared.json: steering geared 1:2, one steering degree of
  freedom, the twist solved by Newton's method compiled in the tick) against the batched path of the same law
  (``law_controller`` + ``wheel_commands``: WPILib has no controller for such a robot);
- closed-loop simulation of the forklift on the figure-eight (30 s, continuous, ideal loops), with the real
  truck's low-level loops at a 0.1 s period, and through the chapter-7 dynamics with Pacejka tyres at 1 kHz
  (control at 50 Hz): how many times faster than real time (issue target for the last: 200x).
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np

from wmrkit import Robot, catalog
from wmrkit.control import builtin_reference, control_point, forklift_real_loops, law_controller, track
from wmrkit.control.laws import PositionLaw
from wmrkit.kinematics.wheel_ik import wheel_commands

from ._harness import Result, best_time, peer


def _ticks(robot, ref, n: int) -> float:
    cp = control_point(robot)
    ctrl = law_controller(cp, PositionLaw.uniform("p", 1.0), ref)
    poses = ref.pose[:n] + 0.01
    beta = robot.beta

    def loop():
        for k in range(n):
            twist, _ = ctrl(ref.t[k], poses[k], np.zeros(3))
            wheel_commands(robot, twist, beta)

    return best_time(loop)


def _single_call(robot, ref, n: int) -> float:
    from wmrkit.control.tick import control_tick

    tick = control_tick(robot).tick
    twist, rates = np.zeros(3), np.zeros(len(robot.rate_names))
    heading = np.array(robot.heading, dtype=float)
    out = np.zeros_like(heading)
    pose = (ref.pose[:n] + 0.01).tolist()
    r, v = ref.pose[:n].tolist(), ref.velocity[:n].tolist()
    tick(*pose[0], *r[0], *v[0], heading, twist, rates, out)  # compile

    def loop():
        for k in range(n):
            tick(*pose[k], *r[k], *v[k], heading, twist, rates, out)

    return best_time(loop)


def _ramsete(n: int) -> float | None:
    ctl, kin, geo = peer("wpimath.controller"), peer("wpimath.kinematics"), peer("wpimath.geometry")
    if ctl is None:
        return None
    r, k = ctl.RamseteController(), kin.DifferentialDriveKinematics(0.4)
    pose, goal = geo.Pose2d(0.0, 0.01, geo.Rotation2d(0.01)), geo.Pose2d(0.0, 0.0, geo.Rotation2d(0.0))

    def loop():
        for _ in range(n):
            k.toWheelSpeeds(r.calculate(pose, goal, 0.5, 0.0))

    return best_time(loop)


def _holonomic(n: int) -> float | None:
    ctl, kin, geo, traj = (peer("wpimath.controller"), peer("wpimath.kinematics"), peer("wpimath.geometry"),
                           peer("wpimath.trajectory"))
    if ctl is None:
        return None
    pid = ctl.PIDController(1.0, 0.0, 0.0)
    prof = ctl.ProfiledPIDControllerRadians(1.0, 0.0, 0.0, traj.TrapezoidProfileRadians.Constraints(6.28, 3.14))
    hdc = ctl.HolonomicDriveController(pid, ctl.PIDController(1.0, 0.0, 0.0), prof)
    t2 = geo.Translation2d
    k = kin.SwerveDrive4Kinematics(t2(0.28, 0.28), t2(0.28, -0.28), t2(-0.28, 0.28), t2(-0.28, -0.28))
    pose, goal = geo.Pose2d(0.0, 0.01, geo.Rotation2d(0.01)), geo.Pose2d(0.0, 0.0, geo.Rotation2d(0.0))

    def loop():
        for _ in range(n):
            k.toSwerveModuleStates(hdc.calculate(pose, goal, 0.5, geo.Rotation2d(0.0)))

    return best_time(loop)


def run(quick: bool) -> list[Result]:
    """Per-tick costs against WPILib (ratio = WPILib time / ours) and closed-loop simulation speed."""
    ref = builtin_reference("figure-eight")
    n = min(2_000 if quick else 20_000, len(ref.t))  # one tick per reference sample
    out = [Result("diff-drive tick: law (8.2) + point twist + IK", n, _ticks(catalog.load("diff-drive"), ref, n),
                  "wpimath Ramsete + toWheelSpeeds", _ramsete(n)),
           Result("swerve-4 tick: law (8.2) + IK (closest angle)", n, _ticks(catalog.load("swerve-4"), ref, n),
                  "wpimath HolonomicDriveController + toSwerveModuleStates", _holonomic(n))]
    out += [Result("diff-drive single-call tick (control_tick)", n, _single_call(catalog.load("diff-drive"), ref, n),
                   "wpimath Ramsete + toWheelSpeeds", _ramsete(n), target="no slower than WPILib"),
            Result("swerve-4 single-call tick (control_tick)", n, _single_call(catalog.load("swerve-4"), ref, n),
                   "wpimath HolonomicDriveController + toSwerveModuleStates", _holonomic(n),
                   target="no slower than WPILib")]
    geared = Robot.from_file(Path(__file__).parents[1] / "examples" / "robots" / "geared.json")
    out.append(Result("geared-units single-call tick (Newton, compiled)", n, _single_call(geared, ref, n),
                      "wmrkit batched path of the same law", _ticks(geared, ref, min(n, 2_000)) * n / min(n, 2_000)))
    fork = catalog.load("forklift")
    for label, kwargs in (("ideal, continuous", {}),
                          ("real loops, T = 0.1 s", {"loops": forklift_real_loops(), "period": 0.1, "delay": 1})):
        duration = 10.0 if quick else 30.0
        t0 = time.perf_counter()
        track(fork, ref, gain=0.5, duration=duration, **kwargs)
        wall = time.perf_counter() - t0
        out.append(Result(f"forklift figure-eight {duration:g} s, {label}", int(duration * 1000), wall,
                          "real time", duration))  # the ratio is how many times faster than real time: no target
    return out + _dynamic_loop(fork, ref, 10.0 if quick else 30.0)


def _dynamic_loop(fork, ref, duration: float) -> list[Result]:
    """The closed loop through the ch. 7 dynamics (Pacejka tyres, 1 kHz, control at 50 Hz): the simulation
    (:func:`simulate_dynamics`, wall and CPU time, best of 3 after a warm-up that loads the compiled kernels) against
    the issue's target of 200x real time, and the whole ``track(..., dynamics=True)`` call (adds the per-sample
    errors, cross-track distances and wheel commands of the TrackingRun)."""
    from wmrkit.control.dynamic_plant import fast_law_controller, simulate_dynamics
    from wmrkit.control.track import initial_pose_on

    cp = control_point(fork)
    ctrl = fast_law_controller(cp, PositionLaw.uniform("p", 0.5), ref)
    pose0 = initial_pose_on(cp, ref)
    simulate_dynamics(fork, ctrl, pose0, 1.0, period=0.02)  # compile, or load the kernels from numba's cache
    wall = best_time(lambda: simulate_dynamics(fork, ctrl, pose0, duration, period=0.02))
    cpu = 1e9
    for _ in range(3):
        c0 = time.process_time()
        simulate_dynamics(fork, ctrl, pose0, duration, period=0.02)
        cpu = min(cpu, time.process_time() - c0)
    whole = best_time(lambda: track(fork, ref, gain=0.5, duration=duration, dynamics=True, period=0.02), repeat=1)
    label = f"forklift figure-eight {duration:g} s, dynamics + Pacejka 1 kHz, T = 0.02 s"
    verdict = "MET" if duration / wall >= 200 else "NOT MET"
    return [Result(f"{label} (simulate_dynamics)", int(duration * 1000), wall, "real time", duration,
                   target=f">= 200x real time: {verdict}"),
            Result("same, CPU time of this process", int(duration * 1000), cpu, "real time", duration,
                   target="CPU-time ratio: what an idle core gives"),
            Result("same, the whole track(..., dynamics=True) call", int(duration * 1000), whole, "real time", duration,
                   target="includes the TrackingRun's error and cross-track series")]


if __name__ == "__main__":
    for r in run(quick=True):
        print(r.line())
