"""The path followers at any scale: the same robot and reference scaled by k (every length of the robot, the
reference's positions and speeds; its times kept) give the same run scaled by k. Before, their lengths were absolute
metres: at k = 1e-3 pure pursuit's lookahead was floored at 1 m (``MIN_LOOKAHEAD``) and the car ended 6.4 mm from
the end of its 4 mm-radius circle, with no warning (``ARRIVAL_TOL`` = 0.1 m was longer than the whole run);
Stanley's stopping length was floored there too and its ``eps`` was 1e-3 m/s (the car ended 9.0 mm from its circle's
end, 26 mm from its figure-eight's). Now they are relative: to the follower's own length ``L``, or to the reference's
top speed. The default control point of a robot whose origin is on its fixed axle (the diff drive's: Stanley's
wheelbase) was at least 0.1 m ahead; now at its largest wheel distance, scaled with it."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from strategies import scaled
from wmrkit import catalog
from wmrkit.cli.control import min_turning_radius
from wmrkit.control.points import control_point
from wmrkit.control.references import builtin_reference, default_size
from wmrkit.control.track import track
from wmrkit.control.trackers import ArrivalWarning, default_lookahead, default_wheelbase, min_length, stanley, top_speed

SCALES = (1e-3, 1.0, 1e3)


def _run(robot_name: str, ref_name: str, controller: str, k: float) -> tuple[float, float, int]:
    """End distance / k, RMS cross-track / k and the number of ArrivalWarnings of the default run at scale `k`."""
    robot = catalog.load(robot_name)
    size = default_size(ref_name, min_turning_radius(robot))
    ref = builtin_reference(ref_name, speed=0.5 * k, size=size * k)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", ArrivalWarning)
        run = track(scaled(robot, k), ref, controller=controller)
    end = float(np.hypot(*(run.tracked[-1, :2] - ref.pose[-1, :2])))
    warned = sum(issubclass(w.category, ArrivalWarning) for w in caught)
    return end / k, run.summary()["rms_cross_track"] / k, warned


@pytest.mark.parametrize("controller", ["pure-pursuit", "stanley"])
@pytest.mark.parametrize("ref_name", ["circle", "figure-eight"])
@pytest.mark.parametrize("robot_name", ["ackermann", "diff-drive"])
def test_a_scaled_robot_and_reference_give_the_same_run_scaled(robot_name, ref_name, controller):
    """End distance and RMS cross-track error / k agree across k = 1e-3, 1, 1e3 within 1e-4 of the follower's
    length ``L`` (the runs are integrated to a relative 1e-5: their ends, within the aim radius 1e-3 L of the end,
    differ by that noise), and the same arrival answer (none warns). ``L`` at 1:1: the lookahead (pure pursuit), or
    the stopping length (Stanley): the wheelbase, at least 2 s at the reference's top speed."""
    robot = catalog.load(robot_name)
    ref = builtin_reference(ref_name, size=default_size(ref_name, min_turning_radius(robot)))
    length = default_lookahead(control_point(robot), top_speed(ref))
    runs = [_run(robot_name, ref_name, controller, k) for k in SCALES]
    ends, rms, warned = (np.array(column) for column in zip(*runs, strict=True))
    assert warned.tolist() == [0, 0, 0]
    assert (ends < 1e-3 * length).all(), ends
    np.testing.assert_allclose(ends, ends[1], rtol=0, atol=1e-4 * length)
    np.testing.assert_allclose(rms, rms[1], rtol=1e-4, atol=1e-4 * length)


def test_the_default_lookahead_is_the_wheelbase_or_two_seconds_at_the_top_speed():
    """Pure pursuit's default lookahead: the car's 2.7 m wheelbase at any speed (2 s at 50 m/s would cut its turns),
    the diff drive's 2 s at the reference's top speed (1 m at the built-ins' 0.5 m/s; the figure-eight's top speed
    is sqrt(2) / 1.2 of its nominal, where its x and y speeds peak together at t = 0), scaling with the speed."""
    car, diff = control_point(catalog.load("ackermann")), control_point(catalog.load("diff-drive"))
    assert default_lookahead(car, 0.5) == pytest.approx(2.7) and default_lookahead(diff, 0.5) == 1.0
    eight = builtin_reference("figure-eight")
    assert top_speed(eight) == pytest.approx(0.5 * 2**0.5 / 1.2, rel=1e-12)
    assert default_lookahead(diff, 5e-4) == pytest.approx(1e-3) == min_length(5e-4)
    assert default_lookahead(car, 50.0) == pytest.approx(2.7) and default_lookahead(diff, 50.0) == 100.0


@pytest.mark.parametrize("k", SCALES)
def test_the_default_control_point_scales_with_the_robot(k):
    """The diff drive's default point (its origin on its axle): 0.25 m ahead at 1:1, 0.25 k at scale k (was 0.1 m at
    1e-3, the floor, 400 times its wheel distance)."""
    robot = catalog.load("diff-drive")
    reach = max(w.l for w in robot.wheels)
    np.testing.assert_allclose(control_point(scaled(robot, k)).point, [reach * k, 0.0], rtol=1e-12, atol=0)


@pytest.mark.parametrize("robot_name", ["mecanum-4", "omni-3", "swerve-4"])
def test_an_omnidirectional_robot_under_stanley_gives_the_same_run_scaled(robot_name):
    """Stanley on a robot whose control point is its axle point (no fixed wheels): its wheelbase is the robot's size
    (its largest wheel distance), scaled with it. Before, it was a fixed 0.5 m: at k = 1e-3 the mecanum-4 looked
    1,300 of its sizes ahead and ended 2.89 mm (2.89 m scaled back) from its circle's end, with no warning. At every
    k it now arrives within the aim radius 1e-3 ``L`` (``L`` its stopping length), without a warning, its RMS
    cross-track / k within 1e-4 ``L`` of the 1:1 run's. (Its end distances / k, 0.02 to 0.23 mm, spread by the
    integrator's relative 1e-5: at 1e-8 those at k = 1e-3 and 1 agree, 6.8 and 7.9 um.)"""
    robot = catalog.load(robot_name)
    cp = control_point(robot)
    reach = max(w.l for w in robot.wheels)
    assert default_wheelbase(cp) == pytest.approx(reach, rel=1e-12)
    assert default_wheelbase(control_point(scaled(robot, 1e-3))) == pytest.approx(1e-3 * reach, rel=1e-12)
    ref = builtin_reference("circle", size=default_size("circle", min_turning_radius(robot)))
    length = stanley(cp, ref).length
    runs = [_run(robot_name, "circle", "stanley", k) for k in SCALES]
    ends, rms, warned = (np.array(column) for column in zip(*runs, strict=True))
    assert warned.tolist() == [0, 0, 0], ends
    assert (ends < 1e-3 * length).all(), ends
    np.testing.assert_allclose(rms, rms[1], rtol=1e-4, atol=1e-4 * length)
