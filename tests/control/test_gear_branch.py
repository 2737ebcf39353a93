"""A steering gear keeps its least-squares fit continuous along a run (control/linked_ranges.py ``settle``). Units
geared 1:2 (examples/robots/geared.json: rest headings 0) asked headings ``(d0, d1)`` fit at ``u = d0 + 2 e / 5``
with ``e = d1 - 2 d0`` taken by whole turns (closed form of ``k . d / k . k``, ``k = (1, 2)``); the fits of ``e``
and ``e - 2 pi`` miss by ``|e| / sqrt(5)`` and ``|e - 2 pi| / sqrt(5)``: alike where ``e = pi``. Before, the best
fit was taken at each call, so the kept heading jumped 4 pi / 5 there, and ``wmrkit track
examples/robots/geared.json --reference circle --size 3`` crawled at t = 3.76 s (RK45 steps of 1e-6 s) until 'too
stiff' after 2 min."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from wmrkit import Robot
from wmrkit.control import builtin_reference
from wmrkit.control.laws import PositionLaw
from wmrkit.control.loop import HOLD_MARGIN, law_controller, simulate
from wmrkit.control.points import control_point
from wmrkit.control.steering import range_keeper
from wmrkit.control.track import initial_pose_on

ROBOT = Robot.from_file(Path(__file__).parents[2] / "examples" / "robots" / "geared.json")
D0 = 0.3


def _kept(e: float, current_e: float, margin: float) -> float:
    """The front heading kept for asked ``(D0, 2 D0 + e)`` (written wrapped) with the gear at its fit of ``e =
    current_e``."""
    u = D0 + 0.4 * current_e
    headings = np.array([D0, math.remainder(2 * D0 + e, 2 * math.pi)])
    range_keeper(ROBOT)(headings, np.zeros(len(ROBOT.rate_names)), np.array([u, 2 * u]), margin)
    assert headings[1] == pytest.approx(2 * headings[0], abs=1e-12)  # on the gear
    return float(headings[0])


@pytest.mark.parametrize("margin", [HOLD_MARGIN, math.inf])
def test_a_gear_keeps_its_fit_through_the_tie_of_two_fits(margin):
    """Asked across the tie ``e = pi`` (by 0.01 rad either way), the gear on the fit of ``e = pi - 0.02`` keeps
    that fit (``D0 + 2 e / 5``, continuous); before, past the tie it took ``D0 + 2 (e - 2 pi) / 5``, 2.51 rad away."""
    for e in (math.pi - 0.01, math.pi + 0.01):
        assert _kept(e, math.pi - 0.02, margin) == pytest.approx(D0 + 0.4 * e, abs=1e-12)


def test_a_gear_without_hysteresis_takes_the_better_fit_and_with_it_keeps_its_own():
    """Past the tie by 0.3 rad the other fit misses 2 * 0.3 / sqrt(5) = 0.27 rad less: taken without a hold margin
    (the loops through the dynamics), not with one (the kinematic loop: the gear turns continuously, and leaves its
    fit only where that fit ends, at e = 5 pi / 2, the front half a turn from the heading asked). Either way the
    heading kept is a local minimum of the miss (numeric neighbours)."""
    e = math.pi + 0.3
    assert _kept(e, math.pi - 0.02, 0.0) == pytest.approx(D0 + 0.4 * (e - 2 * math.pi), abs=1e-12)
    assert _kept(e, math.pi - 0.02, HOLD_MARGIN) == pytest.approx(D0 + 0.4 * e, abs=1e-12)
    asked = np.array([D0, 2 * D0 + e])

    def miss(u: float) -> float:
        return float(np.sum((np.remainder(np.array([u, 2 * u]) - asked + math.pi, 2 * math.pi) - math.pi) ** 2))

    for u in (_kept(e, math.pi - 0.02, 0.0), _kept(e, math.pi - 0.02, HOLD_MARGIN)):
        assert miss(u) < min(miss(u - 1e-4), miss(u + 1e-4))


def test_the_continuous_loop_of_the_geared_units_passes_the_tie():
    """The geared units on the 3 m circle for 4 s under a law blind to the gear (the full pose's, which ``track``
    gave them before it controlled their reduced point, control/coupled_point.py): the asked headings cross the tie
    (e below -pi) and the commanded front heading is the closed-form fit ``d0 + 2 e / 5`` of the asked axles (from
    the wheel positions, ``v + omega z x p``, each root mod pi nearest the commanded heading) with ``e`` unwrapped
    along the run: continuous. Before: 'too stiff' at t = 3.76 s after 30 s of computing."""
    reference = builtin_reference("circle", size=3.0)
    blind = control_point(ROBOT, reduced=False)
    out = simulate(ROBOT, law_controller(blind, PositionLaw.uniform("p", 1.0), reference),
                   initial_pose_on(blind, reference), 4.0, breaks=reference.breaks)
    twist, commanded = out["twist"], np.asarray(ROBOT.heading_of_beta(out["target"]))
    asked = np.zeros(commanded.shape)
    for k, name in enumerate(ROBOT.steer_names):
        x, y = ROBOT.wheel(name).position
        axle = np.arctan2(twist[:, 1] + twist[:, 2] * x, twist[:, 0] - twist[:, 2] * y)
        asked[:, k] = axle + math.pi * np.round((commanded[:, k] - axle) / math.pi)
    e = np.unwrap(asked[:, 1] - 2 * asked[:, 0])
    assert e.min() < -math.pi  # through the tie
    fit = asked[:, 0] + 0.4 * e
    np.testing.assert_allclose(np.remainder(fit - commanded[:, 0] + math.pi, 2 * math.pi) - math.pi, 0.0, atol=1e-9)
    np.testing.assert_allclose(commanded[:, 1], 2 * commanded[:, 0], atol=1e-12)
