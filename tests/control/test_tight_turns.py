"""A built-in reference tighter than a car can turn (control/turn_limits.py): ``wmrkit track`` and ``wmrkit
feasibility`` say so in one line. Before, ``wmrkit track ackermann --reference circle --size 1`` only said its
linkage was held at one stop, then at the other (the car backing up), and ``wmrkit feasibility`` said 'feasible:
yes' (Table 8.1 judges continuity only)."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from wmrkit import catalog
from wmrkit.cli.main import main
from wmrkit.control.turn_limits import point_turning_radius

#: The catalog car: wheelbase 2.70 m, track 1.55 m, stops at +-40 deg. Its inner wheel at its stop puts the ICR
#: 2.7 / tan(40 deg) m beside it on the rear axle's line, half a track more from the axle's midpoint (closed form).
R_MIN = 2.70 / math.tan(math.radians(40.0)) + 0.775


@pytest.mark.parametrize("point", [(0.0, 0.0), (2.809, 0.0), (1.0, 0.5)])
def test_a_point_of_the_car_turns_on_the_closed_form_radius(point):
    """On its tightest circle (either way) every point turns about an ICR R_MIN beside the rear axle's midpoint:
    the point's tightest is the nearer of the two."""
    x, y = point
    expected = min(math.hypot(x, y - R_MIN), math.hypot(x, y + R_MIN))
    assert point_turning_radius(catalog.load("ackermann"), point) == pytest.approx(expected, rel=1e-9)
    assert point_turning_radius(catalog.load("diff-drive"), point) == 0.0  # turns on the spot: no limit


def test_track_says_the_circle_is_tighter_than_the_car_turns(capsys):
    """The P law tracks a point 2.809 m ahead of the rear axle (4.882 m at least on a circle); where the 1 m circle
    runs beside it, the law asks the car to back up (the commanded speed of its rear axle negative), and a car
    backing up turns the other way at the same steering: its linkage swings to the other stop. Said once, with the
    times of the commanded reversal."""
    assert main(["track", "ackermann", "--reference", "circle", "--size", "1", "--json"]) == 0
    run = json.loads(capsys.readouterr().out)
    first = run["warnings"][0]
    tracked = math.hypot(2.809, R_MIN)
    assert first.startswith("the reference turns by ")
    assert ("on 1 m on average), tighter than the robot can drive: a wider turn: over " in first
            and "the tracked point turns by " in first and f"(on {tracked:.4g} m at its tightest, and "
            f"{math.degrees(2 * math.atan(2.809 / R_MIN)):.3g} deg more by re-steering; the robot's minimum turning "
            f"radius is {R_MIN:.4g} m" in first)
    left, right = (np.array(run["wheels"][w]["spin"]) * 0.33 for w in ("rear_left", "rear_right"))
    t, speed, omega = np.array(run["t"]), 0.5 * (left + right), (right - left) / 1.55  # the rear axle's commands
    back = t[speed < -1e-9]
    assert len(back) > 100  # seconds of it
    assert f"the law backs it up where the reference runs beside it (t = {back[0]:.4g} to {back[-1]:.4g} s" in first
    steer = np.array(run["wheels"]["front_left"]["heading"])
    both = (speed < -0.05) & (omega > 0.05)  # backing up and turning left: the steering at the right
    assert both.sum() > 20 and np.all(steer[both] < 0)
    (tight,) = [v for v in run["feasibility"]["violations"] if v["signal"] == "turn"]
    assert run["feasibility"]["continuous"] is True and run["feasibility"]["feasible"] is False
    assert tight["radius"] == pytest.approx(tracked, rel=1e-3)


def test_default_and_unlimited_robots_are_not_warned(capsys):
    """The car's default circle (6 m: 1.5 times R_MIN, rounded up) and a diff drive's 1 m circle: no such line."""
    for argv in (["track", "ackermann", "--reference", "circle", "--duration", "2"],
                 ["track", "diff-drive", "--reference", "circle", "--size", "1", "--duration", "2"]):
        assert main([*argv, "--json"]) == 0
        assert not [w for w in json.loads(capsys.readouterr().out)["warnings"] if "tighter than" in w], argv


@pytest.mark.parametrize("framework", ["kinematic", "dynamic"])
def test_feasibility_says_no_to_a_circle_tighter_than_the_car_turns(capsys, framework):
    """Table 8.1 judges the 1 m circle continuous; the judged point, the rear axle's midpoint, turns on R_MIN at
    least, and its heading with its tangent: over a lap it turns by L / R_MIN at most, a quarter of the circle's
    turn. Not feasible, exit 1, in either framework (the stops bound an angle, not its rate); the continuity verdict
    said apart."""
    argv = ["feasibility", "ackermann", "--reference", "circle", "--size", "1", "--framework", framework]
    assert main([*argv, "--json"]) == 1
    answer = json.loads(capsys.readouterr().out)
    assert answer["feasible"] is False and answer["continuous"] is True and answer["warnings"] == []
    (v,) = answer["violations"]
    assert v["signal"] == "turn" and v["kind"] == "turn tighter than the steering stops allow"
    assert {"t", "kind", "signal", "size", "remedy"} <= set(v)
    assert v["size"] == pytest.approx(1.0, rel=1e-3)  # its mean radius: the circle's
    assert v["radius"] == v["turning"] == pytest.approx(R_MIN, rel=1e-9)
    assert v["limit"] == pytest.approx(v["length"] / R_MIN, rel=1e-9)
    assert v["turn"] > 0.95 * 2 * math.pi and v["length"] == pytest.approx(v["turn"], rel=1e-3)  # most of a lap
    assert main(argv) == 1
    out = capsys.readouterr().out.splitlines()
    assert out[2:4] == ["Table 8.1 (continuity): yes; steering stops: NO", "feasible: NO (1 violation(s))"]
    assert out[4].startswith("  t =    0.000 s  turn tighter than the steering stops allow: the reference turns by ")


def _write(path, t, x, y, theta):
    np.savetxt(path, np.column_stack([t, x, y, theta]), delimiter=",", header="t,x,y,theta", comments="", fmt="%.6f")
    return str(path)


def _circle(path, radius, speed=0.5, dt=0.05):
    t = np.arange(0.0, 2 * math.pi * radius / speed, dt)
    th = speed * t / radius
    return _write(path, t, radius * np.sin(th), radius * (1 - np.cos(th)), th)


def _square(path, leg, speed=0.5, dt=0.05):
    t = np.arange(0.0, 4 * leg / speed, dt)
    k = np.minimum((speed * t // leg).astype(int), 3)
    corner, step = np.array([[0, 0], [leg, 0], [leg, leg], [0, leg]]), np.array([[1, 0], [0, 1], [-1, 0], [0, -1]])
    xy = corner[k] + step[k] * (speed * t - k * leg)[:, None]
    return _write(path, t, xy[:, 0], xy[:, 1], np.arctan2(step[k, 1], step[k, 0]))


def test_reference_files_are_judged_from_their_samples(tmp_path, capsys):
    """A file of a 1 m circle: not feasible for the car (and warned by track, at its tracked point); files of a 6 m
    circle and of a square of 8 m legs are within its reach (the square's corners are Table 8.1's tangent jumps,
    which its straight legs lie between): no tight turn. A diff drive turns on the spot: the 1 m circle is fine."""
    small, large, square = _circle(tmp_path / "c1.csv", 1.0), _circle(tmp_path / "c6.csv", 6.0), _square(
        tmp_path / "sq8.csv", 8.0)
    for path, feasible, signals in ((small, False, ["turn"]), (large, True, []), (square, False, ["chi"] * 3)):
        assert main(["feasibility", "ackermann", "--reference", path, "--json"]) == (0 if feasible else 1)
        answer = json.loads(capsys.readouterr().out)
        assert answer["feasible"] is feasible and [v["signal"] for v in answer["violations"]] == signals, path
        assert main(["track", "ackermann", "--reference", path, "--duration", "3", "--json"]) == 0
        said = [w for w in json.loads(capsys.readouterr().out)["warnings"] if "tighter than the robot" in w]
        assert len(said) == (0 if feasible or signals != ["turn"] else 1), path
    assert main(["feasibility", "diff-drive", "--reference", small, "--json"]) == 0
    capsys.readouterr()


def _car_path(point, dt=0.02, speed=1.0, duration=60.0):
    """Positions of `point` (robot frame) of the catalog car driving forward with its steering swinging from stop
    to stop (the rear axle's curvature (1 / R_MIN) sin(s / 1.5 m)), integrated in closed steps: within its reach."""
    s = np.arange(0.0, duration * speed, dt * speed)
    kappa = np.sin(s / 1.5) / R_MIN
    theta = np.concatenate([[0.0], np.cumsum(0.5 * (kappa[1:] + kappa[:-1]) * np.diff(s))])
    mid = 0.5 * (theta[1:] + theta[:-1])
    x = np.concatenate([[0.0], np.cumsum(np.cos(mid) * np.diff(s))])
    y = np.concatenate([[0.0], np.cumsum(np.sin(mid) * np.diff(s))])
    px, py = point
    return s / speed, x + px * np.cos(theta) - py * np.sin(theta), y + px * np.sin(theta) + py * np.cos(theta), theta


@pytest.mark.parametrize("point", [(0.0, 0.0), (2.809, 0.0), (1.0, 0.5)])
def test_a_path_the_car_drives_at_its_stops_is_within_reach(tmp_path, capsys, point):
    """The path of a point of the car steering from stop to stop: no tight turn (the bound is necessary only); the
    same path turned twice as tight (its positions scaled by 0.5) is not within reach at the rear axle."""
    t, x, y, theta = _car_path(point)
    path = _write(tmp_path / "drive.csv", t, x, y, theta)
    argv = ["feasibility", "ackermann", "--reference", path, "--point", str(point[0]), str(point[1]), "--json"]
    main(argv)
    assert not [v for v in json.loads(capsys.readouterr().out)["violations"] if v["signal"] == "turn"]
    if point == (0.0, 0.0):
        main([*argv[:3], _write(tmp_path / "half.csv", t, 0.5 * x, 0.5 * y, theta), *argv[4:]])
        assert [v for v in json.loads(capsys.readouterr().out)["violations"] if v["signal"] == "turn"]


@pytest.mark.parametrize(("scale", "flagged"), [(1.0, False), (0.97, True)])
def test_a_circle_at_the_stops_is_within_reach_and_a_tighter_one_is_not(tmp_path, capsys, scale, flagged):
    """The rear axle's midpoint on a circle of R_MIN (the car at its stops; a file rounded to 1e-6 m) is within
    reach; 3 % tighter it turns 0.19 rad more than the car can over the lap (2 pi * 0.03)."""
    path = _circle(tmp_path / "c.csv", scale * R_MIN)
    assert main(["feasibility", "ackermann", "--reference", path, "--json"]) == (1 if flagged else 0)
    got = [v for v in json.loads(capsys.readouterr().out)["violations"] if v["signal"] == "turn"]
    assert len(got) == flagged


def test_a_stopped_run_names_no_tight_turn_as_its_jump():
    """A run that stops names the last Table 8.1 jump before it; a TightTurn is no jump (it read 'found a jump the
    robot cannot follow: turn tighter than the steering stops allow')."""
    from wmrkit.control.points import StoppedRun
    from wmrkit.control.references import builtin_reference
    from wmrkit.control.track import _stopped

    stop = StoppedRun("the loop diverged at t = 5 s", 5.0)
    got = _stopped(stop, catalog.load("ackermann"), builtin_reference("circle", size=1.0), np.zeros(2), "kinematic")
    assert str(got) == "the loop diverged at t = 5 s"


def test_a_path_of_zero_length_turns_nowhere():
    """A reference at rest (every sample at one point) raised an IndexError from its empty set of chords, in
    feasibility and in every track of the car."""
    from wmrkit.control.turn_limits import turn_excess

    t = np.linspace(0.0, 2.0, 5)
    assert turn_excess(catalog.load("ackermann"), t, np.tile([1.0, 2.0], (5, 1)), (0.0, 0.0)) is None
