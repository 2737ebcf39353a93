"""The geometric path followers drive at the path's speed where they are on it, slow to stop at its end, and a
default run lasts until they arrive (or a bounded extra time, with a warning)."""

from __future__ import annotations

import json
import math
import warnings

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from wmrkit import catalog
from wmrkit.cli.control import min_turning_radius
from wmrkit.cli.main import main
from wmrkit.control.references import builtin_reference, default_size, reference_from_samples
from wmrkit.control.track import track
from wmrkit.control.trackers import ArrivalWarning, PathIndex, follower_duration

#: Within this of the path's end [m]: the tolerance of a follower of length 1 m (``ARRIVAL_FRACTION``), the shortest
#: default length here (a longer one tolerates more: this is the stricter test).
END_TOL = 0.1


def _end_distance(run, ref) -> float:
    return float(np.hypot(*(run.tracked[-1, :2] - ref.pose[-1, :2])))


@pytest.mark.parametrize("controller", ["pure-pursuit", "stanley"])
@pytest.mark.parametrize("name", ["diff-drive", "forklift", "ackermann"])
def test_a_late_follower_drives_on_to_the_path_s_end(controller, name):
    """A follower drove at the reference's speed at the run's time and stopped with it: from 2 m behind the 10 m
    line it stopped 2 m short of the end (it drove 10 m in the reference's 20 s). Now it drives the path's speed
    where it is on it, and the run lasts until it arrives: at the end within ``END_TOL``, inside the bound."""
    robot, ref = catalog.load(name), builtin_reference("line")  # 10 m along +x at 0.5 m/s
    start = track(robot, ref, controller=controller, duration=0.1).pose[0] - np.array([2.0, 0.0, 0.0])
    run = track(robot, ref, controller=controller, initial_pose=start)
    assert run.tracked[0, 0] == pytest.approx(-2.0)
    assert _end_distance(run, ref) < END_TOL
    # 12 m at 0.5 m/s, and at most twice the time over the last stopping length (<= 2.7 m): 24 s to 29.4 s
    assert 24.0 < run.t[-1] < 24.0 + 2.7 / 0.5 + 0.5 <= follower_duration(ref.duration)


@pytest.mark.parametrize("controller", ["pure-pursuit", "stanley"])
@pytest.mark.parametrize("name", ["ackermann", "bicycle", "forklift", "diff-drive", "agv-drive-unit",
                                  "thesis-tricycle"])
def test_followers_end_at_the_path_s_end_of_smooth_references(controller, name):
    """The trackers table's robots at `wmrkit track`'s defaults, on the references Table 8.1 lets them follow
    (smooth: no tangent jump): the tracked point ends within ``END_TOL`` of the path's end, on the path
    (its projection at the path's full length), without a warning."""
    robot = catalog.load(name)
    for ref_name in ("line", "circle", "arc-line"):
        ref = builtin_reference(ref_name, size=default_size(ref_name, min_turning_radius(robot)))
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always", ArrivalWarning)
            run = track(robot, ref, controller=controller)
        assert not [w for w in caught if issubclass(w.category, ArrivalWarning)], ref_name
        path = PathIndex(ref)
        assert path.project(run.tracked[-1, :2], run.t[-1])[0] == pytest.approx(path.s[-1]), ref_name
        assert _end_distance(run, ref) < END_TOL, ref_name


def test_a_run_that_cannot_arrive_says_so(capsys):
    """A follower that had not reached the path's end when the run ended said nothing (the car's corner: 0.58 m
    from the end under pure pursuit, 0.15 m late on the path and 0.56 m beside it). Now a default run that ends away
    from the end warns: still on its way after the bounded extra time (30 m behind the 10 m line: 15 m driven in
    the 30 s bound), or past the end beside it (the car 1 m before the line's end and 0.5 m beside it: reaching the
    end needs a turn of radius 1.25 m, inside its 4 m turning radius)."""
    assert main(["track", "diff-drive", "--reference", "line", "--controller", "pure-pursuit", "--from", "-30", "0",
                 "0", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["t"][-1] == pytest.approx(follower_duration(20.0)) == 30.0
    said = [w for w in out["warnings"] if "did not reach the path's end" in w]
    assert len(said) == 1 and "ended 25 m from it" in said[0] and "the run ended at 30 s" in said[0], said
    assert "beyond the 0.1 m tolerance (0.1 of its length 1 m)" in said[0]  # 2 s at the line's 0.5 m/s
    assert main(["track", "ackermann", "--reference", "line", "--controller", "pure-pursuit", "--from", "9", "0.5",
                 "0"]) == 0
    err = capsys.readouterr().err
    assert "wmrkit: warning: the path follower did not reach the path's end" in err
    assert "it passed the path's end beside it" in err
    # a given duration is the user's: run whole, no word on arrival
    assert main(["track", "diff-drive", "--reference", "line", "--controller", "stanley", "--duration", "5"]) == 0
    assert "path's end" not in capsys.readouterr().err


def test_a_follower_drives_the_path_s_speed_where_it_is():
    """The speed comes from the path at the robot's projection, not from the reference's clock: a reference
    accelerating from rest (x = t^2 / 4, speed t / 2 = sqrt(x)) gives speed sqrt(s) at arc length s, at least a
    tenth of its top speed (a start from rest would never leave it)."""
    t = np.linspace(0.0, 8.0, 801)
    ref = reference_from_samples("ramp", t, np.column_stack([t * t / 4, 0 * t, 0 * t]))
    path = PathIndex(ref)
    top = float(np.hypot(*ref.velocity[:, :2].T).max())
    assert top == pytest.approx(4.0, rel=1e-2)
    for s in (1.0, 4.0, 9.0, 15.0):
        assert path.speed(s) == pytest.approx(math.sqrt(s), rel=1e-3)
    assert path.speed(0.0) == pytest.approx(0.1 * top)
    run = track(catalog.load("diff-drive"), ref, controller="pure-pursuit")
    assert _end_distance(run, ref) < END_TOL


def test_stanley_s_front_point_converges_as_hoffmann_s_law_says():
    """Stanley (Hoffmann et al. 2007) steers delta = psi_e + atan(k e / v) with v the FRONT axle's speed: its
    cross-track error then obeys e' = -v sin(atan(k e / v)), whatever the heading. The front point drove at
    v / cos(delta), v the reference's speed, the rear axle's: it converged faster than the law (and drove ahead of
    the reference). Now the front point drives at the path's speed, the speed in the law."""
    robot, ref = catalog.load("diff-drive"), builtin_reference("line", duration=60.0)  # 30 m at 0.5 m/s
    start = track(robot, ref, controller="stanley", duration=0.1).pose[0] + np.array([0.0, 0.5, 0.0])
    run = track(robot, ref, controller="stanley", initial_pose=start, duration=6.0)
    assert run.tracked[0, 1] == pytest.approx(0.5)
    law = solve_ivp(lambda _, e: -0.5 * np.sin(np.arctan(e / (0.5 + 1e-3))), (0.0, 6.0), [0.5], t_eval=run.t,
                    rtol=1e-10, atol=1e-12)
    np.testing.assert_allclose(run.tracked[:, 1], law.y[0], atol=2e-4)
    speed = np.hypot(*np.diff(run.tracked[:, :2], axis=0).T) / np.diff(run.t)
    np.testing.assert_allclose(speed, 0.5, atol=2e-3)  # the front point at the path's speed
