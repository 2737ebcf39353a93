"""Dynamics simulation speed (issue "slip", thesis §7.2): the forklift with Pacejka tyres at a 1 kHz step.

Target: at least 500x faster than real time. The first line times the semi-implicit fixed-step simulator on the
thesis's "rectangle" program (drive-wheel rate servos, steering servo, appendix 7.A1 tyres on all three wheels);
its "peer" is the simulated time itself, so the printed ratio is the real-time factor. The second line runs the
same model with scipy's adaptive LSODA (rtol 1e-6) as the peer, on a shorter stretch; another runs the same
simulation in 20 ms pieces through the public ``Stepper`` (what a 50 Hz controller does). Times are the best of 3,
after a first call that compiles the kernels (or loads them from numba's cache).
"""

from __future__ import annotations

import time

from wmrkit import catalog
from wmrkit.dynamics.model import DynamicModel
from wmrkit.dynamics.programs import path_program
from wmrkit.dynamics.simulate import Stepper, simulate

from ._harness import Result, best_time


def _cpu_time(fn) -> float:
    t0 = time.process_time()
    fn()
    return time.process_time() - t0


def run(quick: bool) -> list[Result]:
    """Time the forklift simulation; ``quick`` simulates 5 s instead of the whole 22.4 s rectangle."""
    model = DynamicModel.of(catalog.load("forklift"), "pacejka")
    inputs, duration = path_program(model, "rectangle", speed=2.0)
    duration = 5.0 if quick else duration
    simulate(model, inputs, 0.1)  # compile or load the kernels
    ours = best_time(lambda: simulate(model, inputs, duration, step=1e-3, record_step=0.01), repeat=3)
    factor = duration / ours
    verdict = "MET" if factor >= 500 else "NOT MET"
    lines = [Result("forklift pacejka 1 kHz semi-implicit (steps)", round(duration * 1000), ours,
                    "real time", duration, f">= 500x real time: {verdict}")]
    cpu = min(_cpu_time(lambda: simulate(model, inputs, duration, step=1e-3, record_step=0.01)) for _ in range(3))
    lines.append(Result("same, CPU time of this process (steps)", round(duration * 1000), cpu, "real time", duration,
                        "CPU-time ratio: what an idle core gives"))
    lines.append(Result("same in 20 ms pieces: Stepper.advance (steps)", round(duration * 1000),
                        best_time(lambda: _pieces(model, inputs, duration), repeat=3), "real time", duration,
                        "a 50 Hz controller's calls, no records"))
    short = 2.0
    simulate(model, inputs, 0.05, method="adaptive")
    fixed = best_time(lambda: simulate(model, inputs, short, step=1e-3, record_step=0.01), repeat=3)
    adaptive = best_time(lambda: simulate(model, inputs, short, method="adaptive", record_step=0.01), repeat=1)
    lines.append(Result("forklift 2 s: fixed 1 kHz vs scipy LSODA (steps)", 2000, fixed, "scipy LSODA", adaptive))
    return lines


def _pieces(model, inputs, duration: float) -> None:
    stepper = Stepper(model, step=1e-3)
    for _ in range(round(duration / 0.02)):
        stepper.advance(inputs, 0.02)


if __name__ == "__main__":
    for result in run(quick=False):
        print(result.line())
