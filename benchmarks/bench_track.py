"""The continuous control loop (``wmrkit track`` without ``--period``): the cost of one evaluation, and whole runs.

- one evaluation's wheel commands, ``_Sim.commands`` (the IK and the steering choice with the loop's checked
  arguments, :func:`~wmrkit.kinematics.loop_ik.checked_rates` and :func:`~wmrkit.control.steering.checked_steering`)
  against the general path measured in the same run, ``wheel_commands`` + ``choose_steering`` on the same twist and
  steering (what the loop called before), for the car (its front wheels at their stops) and a swerve-4;
- the least-squares twist (4.11) of the car's rear spins, held at its stops (``_Sim.least_squares_twist``), against
  ``forward_kinematics`` on the same rates;
- whole runs with the defaults (the car on the circle and the figure-eight, a diff drive and its castor on the circle,
  swerve-4 on the square, thesis-steer-castor's castors): wall time against the reference's duration;
- the cost per output sample (every 0.05 s) of the forklift and the diff drive under the P law, pure pursuit and
  Stanley (``examples/track_forklift.py``'s loop): CPU time, best of 3. No peer simulates these loops; the figures
  of the same runs before the path search was compiled and the loop's IK and reference moved to plain floats
  (commit 42ea6d6, this machine, same measure) are printed beside them (:data:`BEFORE_US`).
"""

from __future__ import annotations

import math
import time

import numpy as np

from wmrkit import catalog
from wmrkit.control import builtin_reference, track
from wmrkit.control.loop import Plant, _Sim
from wmrkit.control.steering import choose_steering
from wmrkit.kinematics.wheel_ik import forward_kinematics, wheel_commands

from ._harness import Result, best_time

#: CPU µs per output sample of :func:`_per_sample`'s runs at commit 42ea6d6 (before the compiled path search and the
#: plain-float IK, reference and checks of the continuous loop), best of 6 on the 2-core development machine at load
#: 2.5-3 (measured interleaved with this code's runs; at load 5 both were 1.3-2x slower, the old more).
BEFORE_US = {("forklift", "circle", "p"): 299, ("forklift", "figure-eight", "p"): 297,
             ("diff-drive", "circle", "p"): 1028, ("diff-drive", "figure-eight", "pure-pursuit"): 629,
             ("diff-drive", "figure-eight", "stanley"): 1083, ("forklift", "figure-eight", "pure-pursuit"): 447,
             ("forklift", "figure-eight", "stanley"): 392}


def _evaluations(name: str, n: int) -> Result:
    robot = catalog.load(name)
    sim = _Sim(robot, Plant())
    twist, beta = np.array([0.5, 0.0, 1.0]), np.array(robot.beta, dtype=float)  # the car: beyond its stops

    def lean():
        for _ in range(n):
            sim.commands(twist, beta)

    def general():
        for _ in range(n):
            c = wheel_commands(robot, twist, beta)
            choose_steering(np.asarray(c.beta) - math.pi / 2 + sim.delta, np.asarray(c.spin)[sim.wheel_of_steer],
                            beta - math.pi / 2 + sim.delta, policy="closest", ranges=sim.ranges,
                            hold_margin=sim.hold_margin)

    return Result(f"{name}: one evaluation's wheel commands", n, best_time(lean),
                  "wheel_commands + choose_steering", best_time(general))


def _least_squares(n: int) -> Result:
    robot = catalog.load("ackermann")
    sim = _Sim(robot, Plant())
    beta = np.array(robot.beta, dtype=float) + 0.1
    cmd = sim.commands(np.array([0.5, 0.0, 1.0]), beta)
    rates = {j: float(cmd.rates[robot.rate_names.index(j)]) for j in sim.drive}

    def lean():
        for _ in range(n):
            sim.least_squares_twist(cmd, beta, {})

    def general():
        for _ in range(n):
            forward_kinematics(robot, rates, beta)

    return Result("ackermann: least-squares twist of the held car", n, best_time(lean), "forward_kinematics",
                  best_time(general))


def _per_sample(robot: str, reference: str, controller: str) -> Result:
    """CPU time of one continuous run with the defaults, per output sample, beside its figure before."""
    import warnings

    bot, ref = catalog.load(robot), builtin_reference(reference)
    track(bot, ref, controller=controller, duration=2.0)  # loads the compiled path search
    best, samples = math.inf, 0
    for _ in range(3):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # a follower's arrival: not what is timed
            t0 = time.process_time()
            samples = len(track(bot, ref, controller=controller).t)
            best = min(best, time.process_time() - t0)
    us = 1e6 * best / samples
    before = BEFORE_US.get((robot, reference, controller))
    note = f"{us:.0f} us/sample" + ("" if before is None else f"; 42ea6d6: {before} us/sample, {before / us:.1f}x")
    return Result(f"track {robot} {reference} {controller}: CPU per sample", samples, best,
                  "no peer simulates this loop", None, target=note)


def run(quick: bool) -> list[Result]:
    """Per-evaluation costs against the general path, and whole continuous runs against real time."""
    n = 200 if quick else 2000
    out = [_evaluations("ackermann", n), _evaluations("swerve-4", n), _least_squares(n)]
    runs = [("ackermann", "circle"), ("diff-drive", "circle"), ("swerve-4", "square")]
    if not quick:
        runs += [("ackermann", "figure-eight"), ("thesis-steer-castor", "circle")]
    for robot, name in runs:
        reference = builtin_reference(name)
        t0 = time.perf_counter()
        result = track(catalog.load(robot), reference)
        wall = time.perf_counter() - t0
        duration = float(result.t[-1])
        # the ratio is how many times faster than real time; no target is stated for it
        out.append(Result(f"track {robot} {name} (continuous, defaults)", len(result.t), wall, "real time", duration))
    cases = list(BEFORE_US)[:3:2] if quick else list(BEFORE_US)
    return out + [_per_sample(*case) for case in cases]


if __name__ == "__main__":
    for r in run(quick=True):
        print(r.line())
