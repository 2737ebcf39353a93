"""Pure pursuit arrives at the path's end wherever the geometry allows: its goal is held at the end once the end is
nearer than the lookahead (the arc through it reaches it), and its run does not stop while the end is still ahead."""

from __future__ import annotations

import math
import re
import warnings

import numpy as np
import pytest

from wmrkit import catalog
from wmrkit.cli.control import min_turning_radius
from wmrkit.control.references import builtin_reference, default_size
from wmrkit.control.track import track
from wmrkit.control.trackers import ArrivalWarning, PathIndex, max_curvature

#: How close [m] the continuous loop (rtol 1e-5) brings a robot to a point on an arc it drives exactly.
ON_ARC = 1e-3


def _end_curvature(point: np.ndarray, heading: float, end: np.ndarray) -> float:
    """The curvature [1/m] of the circle through `point`, tangent to `heading`, through `end` (closed form)."""
    d = end - point
    lateral = -math.sin(heading) * d[0] + math.cos(heading) * d[1]
    return 2.0 * lateral / float(d @ d)


@pytest.mark.parametrize("lookahead", [1.0, 2.5])
@pytest.mark.parametrize("name", ["ackermann", "bicycle", "forklift", "agv-drive-unit", "thesis-tricycle"])
def test_pure_pursuit_arrives_at_the_end_of_smooth_paths(name, lookahead):
    """Past the path's end the goal lay on the end's tangent: the robot straightened over the last lookahead while
    the path still curved, and passed the end beside it (the 3 m circle at a 2.5 m lookahead: 0.12 m; the car's
    circle at its 2.7 m wheelbase: 68 mm). Now the goal is held at the end once the end is nearer: from the pose
    where that happens, the end lies on one arc within the robot's tightest turn (checked here, closed form), the
    arc pure pursuit drives, so the tracked point ends on the end, to the integrator's accuracy."""
    robot = catalog.load(name)
    kappa_max = max_curvature(robot)
    for ref_name in ("line", "circle", "figure-eight"):
        ref = builtin_reference(ref_name, size=default_size(ref_name, min_turning_radius(robot)))
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always", ArrivalWarning)
            run = track(robot, ref, controller="pure-pursuit", lookahead=lookahead)
        assert not [w for w in caught if issubclass(w.category, ArrivalWarning)], ref_name
        path, end = PathIndex(ref), ref.pose[-1, :2]
        s = np.array([path.project(p[:2], t)[0] for p, t in zip(run.tracked, run.t, strict=True)])
        k = int(np.argmax(s + lookahead >= path.s[-1]))  # the goal reaches the end
        step = run.tracked[k + 1, :2] - run.tracked[k, :2]
        heading = math.atan2(step[1], step[0])  # the tracked point's direction of travel there
        assert abs(_end_curvature(run.tracked[k, :2], heading, end)) < kappa_max, ref_name  # the geometry allows
        assert float(np.hypot(*(run.tracked[-1, :2] - end))) < ON_ARC, ref_name


def test_pure_pursuit_does_not_stop_while_the_end_is_ahead_of_it():
    """A run stopped once the tracked point crossed the end's line, wherever the end was: the diff drive 1 cm
    before the line's end and 0.3 m beside it, on the arc of radius 0.15 m pure pursuit drives to it (closed form:
    ``d^2 / (2 y)``), crossed the line at once and stopped 0.30 m from the end. Now it stops only once the end is no
    longer ahead of it (or within its aim radius), and drives to it at the speed that stops it there (its distance
    to the end, not the path's arc length left, 0 once its projection is on the end: it crawled at 0.5 % speed)."""
    robot, ref = catalog.load("diff-drive"), builtin_reference("line")  # 10 m along +x, at 0.5 m/s
    end = ref.pose[-1, :2]
    radius = 1.0 / abs(_end_curvature(np.array([9.99, 0.3]), 0.0, end))
    assert radius == pytest.approx((0.01**2 + 0.3**2) / (2 * 0.3))  # within reach of a robot that turns in place
    run = track(robot, ref, controller="pure-pursuit", initial_pose=[9.99, 0.3, 0.0])  # the axle point: the origin
    assert float(np.hypot(*(run.tracked[-1, :2] - end))) < ON_ARC
    assert run.t[-1] < 2 * math.pi * radius / (0.1 * 0.5)  # within half a turn at the least approach speed
    path = PathIndex(ref)
    ahead = np.array([10.05, 0.3])  # past the end's line, 0.3 m beside the end
    assert path.done(ahead, path.s[-1])  # what ended the run: past the line (Stanley's rule, still)
    assert not path.done(ahead, path.s[-1], heading=-math.pi / 2)  # the end ahead (to the right, 0.05 m back)
    assert path.done(ahead, path.s[-1], heading=0.0)  # the end behind: passed beside it


def test_a_follower_that_passes_the_end_beside_it_says_why():
    """The warning said only "it passed the path's end beside it". Now, for pure pursuit, it names when the end
    went out of reach and why: a turn tighter than the robot's tightest (the car 1 m before the line's end and
    0.5 m beside it: the circle tangent to its heading through the end has radius (1 + 0.25) / (2 * 0.5) = 1.25 m,
    its own 3.99 m), or the end behind it (the diff drive starting 0.2 m past the end's line)."""
    radius = (1.0**2 + 0.5**2) / (2 * 0.5)
    car = catalog.load("ackermann")
    with pytest.warns(ArrivalWarning) as caught:
        track(car, builtin_reference("line"), controller="pure-pursuit", initial_pose=[9.0, 0.5, 0.0])
    said = str(caught[-1].message)
    assert (f"it passed the path's end beside it: from t = 0 s, {math.hypot(1.0, 0.5):.3g} m from it, the end needed "
            f"a turn of radius {radius:.3g} m, tighter than the robot's tightest ({min_turning_radius(car):.3g} m)"
            in said), said
    with pytest.warns(ArrivalWarning) as caught:
        track(catalog.load("diff-drive"), builtin_reference("line"), controller="pure-pursuit",
              initial_pose=[10.2, 0.3, 0.0])
    said = str(caught[-1].message)
    assert f"from t = 0 s, {math.hypot(0.2, 0.3):.3g} m from it, the end was behind it" in said, said


def test_stanley_that_passes_the_end_beside_it_says_why():
    """Stanley's warning gave no reason. Its tracked point is the front point ``F``, ``L`` = 2.7 m ahead of the car's
    axle point ``A``: from ``A`` = (7, 1) facing +x, ``F`` = (9.7, 1), the circle of ``A`` whose ``F`` passes
    through the end (10, 0) has radius ``R`` with ``|E - C| = |F - C|``, ``C = A - R (0, 1)`` (a right turn),
    solved here by bisection, inside the car's 3.99 m: the warning names it (from t = 0 s, ``F`` 1.04 m from the
    end)."""
    car = catalog.load("ackermann")
    a, f, end = np.array([7.0, 1.0]), np.array([9.7, 1.0]), np.array([10.0, 0.0])

    def gap(r: float) -> float:  # |E - C| - |F - C| for the centre C of a right turn of radius r
        c = a - r * np.array([0.0, 1.0])
        return float(np.hypot(*(end - c)) - np.hypot(*(f - c)))

    lo, hi = 0.5, 3.0
    assert gap(lo) * gap(hi) < 0
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if gap(lo) * gap(mid) > 0 else (lo, mid)
    with pytest.warns(ArrivalWarning) as caught:
        track(car, builtin_reference("line"), controller="stanley", initial_pose=[7.0, 1.0, 0.0])
    said = str(caught[-1].message)
    assert (f"it passed the path's end beside it: from t = 0 s, {float(np.hypot(*(end - f))):.3g} m from it, the "
            "end needed a turn of radius " in said), said
    assert abs(float(re.search(r"a turn of radius ([0-9.]+) m", said)[1]) - lo) <= 5e-3 + 1e-9  # as shown: 3 digits
    assert (f"m (of its axle point, 2.7 m behind its tracked point), tighter than Stanley's tightest "
            f"({min_turning_radius(car):.3g} m: its steering limit)" in said), said
