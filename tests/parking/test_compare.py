"""The thesis's planner against Reeds-Shepp (rsplan, an optional peer) on the same slots."""

from __future__ import annotations

import math

import pytest
from parking_cases import CAR_91, CAR_92, SLOT_91, SLOT_92

pytest.importorskip("rsplan")
pytest.importorskip("shapely")

from wmrkit.parking.compare import compare


@pytest.mark.parametrize(("car", "slot"), [(CAR_91, SLOT_91), (CAR_92, SLOT_92)], ids=["9.1", "9.2"])
def test_same_start_same_goal_and_the_exact_check_decides(car, slot):
    ours, rs = compare(car, slot, repeat=3)
    assert ours.success and ours.colliding == 0
    # Reeds-Shepp is optimal in length for the minimum radius, obstacles ignored: never longer, and it cuts
    # through the parked cars in these tight slots (the exact check counts the poses)
    assert rs.found and rs.length <= ours.length + 1e-6
    assert not rs.success and rs.colliding > 0
    assert ours.cusps >= 1 and rs.cusps >= 0
    assert math.isfinite(rs.time_ms) and math.isfinite(ours.time_ms)


@pytest.mark.parametrize(("car", "slot"), [(CAR_91, SLOT_91), (CAR_92, SLOT_92)], ids=["9.1", "9.2"])
def test_reeds_shepp_joins_the_plans_ends_at_the_cars_radius(car, slot):
    """The comparison's Reeds-Shepp path is rsplan's between the thesis plan's ends (the end of the detection pass,
    the final pose) at the car's minimum radius h1 / tan(phi_max) (9.27), typed here from the car's table: its
    length is that path's, its poses start and end there and turn no tighter than that radius, nor does the
    thesis's path; the test above (RS never longer) would pass a radius too small."""
    import numpy as np
    import rsplan.planner

    from wmrkit.parking.planner import plan_parking

    rho = car.h1 / math.tan(car.phi_max)
    plan = plan_parking(car, slot)
    moving = [s for s in plan.segments if s.phase >= 2]
    assert max(abs(s.curvature) for s in moving) <= 1 / rho + 1e-12
    _, rs = compare(car, slot, repeat=1)
    start, goal = moving[0].start, plan.final_pose
    path = rsplan.planner.path(tuple(start), tuple(goal), rho, 0.0, 0.005)
    assert rs.length == pytest.approx(path.total_length, rel=1e-12)
    poses = np.array([w.pose_2d_tuple for w in path.waypoints()])
    np.testing.assert_allclose(poses[[0, -1]], [start, goal], atol=1e-9)
    step = np.hypot(*np.diff(poses[:, :2], axis=0).T)
    turn = np.abs(np.diff(np.unwrap(poses[:, 2])))
    assert (turn[step > 1e-6] / step[step > 1e-6]).max() == pytest.approx(1 / rho, rel=1e-4)  # tight slot: at it


def test_the_check_passes_reeds_shepp_on_the_open_road():
    """Not biased: a Reeds-Shepp lane change on the road, away from the slot, has no colliding pose."""
    import numpy as np
    import rsplan.planner

    from wmrkit.parking.verify import check_poses

    path = rsplan.planner.path((-6.0, 2.0, 0.0), (-2.0, 3.0, 0.0), CAR_91.rho_min, 0.0, 0.005)
    poses = np.array([w.pose_2d_tuple for w in path.waypoints()])
    report = check_poses(CAR_91, SLOT_91, poses)
    assert report.collision_free and report.min_clearance > 0.5


@pytest.mark.parametrize(("option", "value", "message"), [
    ("step", 0.0, "step: must be a finite length > 0 m"), ("step", -1.0, "step: must be a finite length > 0 m"),
    ("step", math.nan, "step: must be a finite length > 0 m"), ("repeat", 0, "repeat: must be an integer >= 1"),
    ("step", 1e-7, "the exact check would test 3.13e\\+07 poses")])
def test_compare_refuses_its_options_by_name(option, value, message):
    """step = 0 raised OverflowError, -1 IndexError, NaN ValueError (from rsplan), 1e-7 m made 3e7 Reeds-Shepp
    poses (gigabytes) before the check refused them; repeat = 0 gave NaN times."""
    from wmrkit.errors import WmrkitError

    with pytest.raises(WmrkitError, match=f"^{message}"):
        compare(CAR_91, SLOT_91, **{option: value})
