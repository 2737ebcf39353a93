"""References (built-in shapes, TUM/CSV files), the trackers, and the ``track`` / ``feasibility`` commands."""

from __future__ import annotations

import json
import math
import re
import warnings

import numpy as np
import pytest

from wmrkit import catalog
from wmrkit.cli.main import main
from wmrkit.control.references import (
    BUILTIN,
    CORNER_RECOVERY,
    TIGHTEST_TURN,
    TURN_MARGIN,
    ReferenceError,
    builtin_reference,
    load_reference,
)
from wmrkit.control.track import track
from wmrkit.control.trackers import ArrivalWarning, follower_duration
from wmrkit.errors import UnknownNameError


@pytest.mark.parametrize("name", list(BUILTIN))
def test_builtin_derivatives_are_the_numeric_ones(name):
    """Exact velocities and accelerations against central differences, away from the corners."""
    ref = builtin_reference(name, dt=0.001)
    ok = np.ones(len(ref.t), bool)
    for b in ref.breaks:
        ok &= np.abs(ref.t - b) > 0.005
    ok[:2] = ok[-2:] = False
    num_v = np.gradient(ref.pose, ref.t, axis=0)
    num_a = np.gradient(ref.velocity, ref.t, axis=0)
    np.testing.assert_allclose(num_v[ok], ref.velocity[ok], atol=1e-5)
    np.testing.assert_allclose(num_a[ok], ref.acceleration[ok], atol=1e-4)
    p, _v = ref.at(0.123)
    np.testing.assert_allclose(p, ref.sample(np.array([0.123]))[0], atol=1e-6)


def test_files_tum_and_csv(tmp_path):
    ref = builtin_reference("circle")
    th = ref.pose[:, 2]
    tum = tmp_path / "ref.tum"
    rows = np.column_stack([ref.t, ref.pose[:, :2], 0 * th, 0 * th, 0 * th, np.sin(th / 2), np.cos(th / 2)])
    np.savetxt(tum, rows)
    csv = tmp_path / "ref.csv"
    np.savetxt(csv, np.column_stack([ref.t, ref.pose]), delimiter=",", header="t,x,y,theta", comments="", fmt="%.17g")
    for path in (tum, csv):
        got = load_reference(path)
        np.testing.assert_allclose(got.pose, ref.pose, atol=1e-9)
        np.testing.assert_allclose(got.velocity[5:-5], ref.velocity[5:-5], atol=1e-4)
    bad = tmp_path / "bad.csv"
    bad.write_text("t,x,y,theta\n0,0,0,0\n0,1,0,0\n1,2,0,0\n")
    with pytest.raises(ReferenceError, match="times must increase"):
        load_reference(bad)
    with pytest.raises(ReferenceError, match="no such file"):
        load_reference(tmp_path / "none.csv")
    with pytest.raises(UnknownNameError, match="did you mean 'circle'"):
        builtin_reference("circel")


def test_csv_with_a_byte_order_mark_is_read(tmp_path):
    """A spreadsheet's 'CSV UTF-8' starts with a BOM: 'expected the columns t,x,y,theta, got \\ufefft,x,y,theta'."""
    path = tmp_path / "bom.csv"
    path.write_bytes(b"\xef\xbb\xbft,x,y,theta\n0,0,0,0\n1,1,0,0\n2,2,0,0\n")
    np.testing.assert_allclose(load_reference(path).pose[:, 0], [0.0, 1.0, 2.0])


def test_a_lap_too_short_or_too_long_names_speed_and_size():
    """'--speed 1e4' said 'duration/dt gives 1 samples': neither option a user gives."""
    with pytest.raises(ReferenceError, match=r"^reference 'circle' at 10000 m/s, size 3 m: 0\.001885 s \(one lap at "
                                             r"this speed and size\) sampled every 0\.01 s gives 1 samples"):
        builtin_reference("circle", speed=1e4)


def test_headings_in_degrees_are_refused_and_unwrapped_radians_kept(tmp_path):
    """'t,x,y,theta' with theta 90 was read as 90 rad and followed as 2.035 rad (exit 0)."""
    deg = tmp_path / "deg.csv"
    deg.write_text("t,x,y,theta\n0,0,0,0\n1,1,0,90\n2,2,0,0\n")
    with pytest.raises(ReferenceError, match=r"sample 2: theta 90 rad.*degrees\? 90 deg = 1.5708 rad"):
        load_reference(deg)
    t = np.linspace(0, 20, 201)  # three turns on the spot, unwrapped: beyond a turn, small steps
    spin = tmp_path / "spin.csv"
    np.savetxt(spin, np.column_stack([t, 0 * t, 0 * t, 3 * math.pi * t / 10]), delimiter=",", header="t,x,y,theta",
               comments="", fmt="%.17g")
    assert load_reference(spin).pose[-1, 2] == pytest.approx(6 * math.pi)


def test_a_reference_faster_than_any_robot_is_refused(tmp_path):
    """Times in ns read as s: 'track' said the start was too far ('start closer ... within 0 m')."""
    fast = tmp_path / "fast.csv"
    fast.write_text("t,x,y,theta\n0,0,0,0\n1e-12,1,0,0\n2e-12,2,0,0\n")
    with pytest.raises(ReferenceError, match=r"samples 1-2 move at 1e\+12 m/s, beyond 1000 m/s"):
        load_reference(fast)


def test_a_value_that_is_not_a_number_is_named_with_its_line_and_column(tmp_path):
    """'times and poses must be finite numbers' left the user to search the file for it; then 'sample 2: y nan',
    counted from the first sample, not the file's line."""
    bad = tmp_path / "bad.csv"
    bad.write_text("t,x,y,theta\n0,0,0,0\n1,1,nan,0\n2,2,0,0\n")
    with pytest.raises(ReferenceError, match=r"bad.csv:3: column 'y': value nan is not a finite number$"):
        load_reference(bad)
    bad.write_text("t,x,y,theta\n0,0,0,0\n1,1,0,0\ninf,2,0,0\n")
    with pytest.raises(ReferenceError, match=r"bad.csv:4: column 't': value inf is not a finite number$"):
        load_reference(bad)


def test_speed_and_size_are_refused_with_a_file_reference(tmp_path, capsys):
    """They were ignored: a file's samples give its speed and size."""
    path = tmp_path / "ref.csv"
    path.write_text("t,x,y,theta\n0,0,0,0\n1,1,0,0\n2,2,0,0\n")
    for command in ("feasibility", "track"):
        assert main([command, "diff-drive", "--reference", str(path), "--speed", "3"]) == 2
        assert "--speed and --size apply to a built-in reference" in capsys.readouterr().err


@pytest.mark.parametrize("controller", ["pure-pursuit", "stanley"])
@pytest.mark.parametrize("name", ["diff-drive", "forklift", "swerve-4"])
def test_geometric_trackers_converge_onto_the_path(controller, name):
    run = track(catalog.load(name), builtin_reference("line", duration=40), controller=controller,
                initial_pose=[0.0, 0.4, 0.0], duration=25.0, lookahead=1.0)
    assert run.cross_track[0] > 0.3 and run.cross_track[-1] < 0.01


@pytest.mark.parametrize("name", ["diff-drive", "mecanum-4"])
def test_pure_pursuit_turns_round_to_a_path_that_runs_behind_it(name):
    """A reference reversing along -x with heading 0 puts the goal point straight behind: kappa = 2 y_g / L^2 ~ 0
    drove the robot straight away (final error 8.3 m on a 5 m reference; cross-track growing without bound)."""
    from wmrkit.control.references import reference_from_samples

    t = np.arange(0.0, 40.001, 0.1)
    ref = reference_from_samples("reverse", t, np.column_stack([-0.5 * t, 0 * t, 0 * t]))
    run = track(catalog.load(name), ref, controller="pure-pursuit", initial_pose=[0.0, 0.2, 0.0])
    assert run.cross_track[run.t > 25].max() < 0.01
    assert run.tracked[-1, 0] < -15.0  # along the path, towards -x


def test_pure_pursuit_goal_past_the_path_end_lies_on_its_tangent():
    """The goal point was held at the path's end: a robot that reached it before the reference's time ended circled
    it on ever tighter turns (``2 / L_d``, ``L_d -> 0``): a 2 m line from 0.5 m ahead was 'too stiff to integrate'
    after 34 s, and the circle from 0.3 m off (the docs' comparison) after 2 min. Past the end it stops (the path is
    driven: it drove on along the tangent to x = 2.5 m until the reference's time ended)."""
    from wmrkit.control.points import control_point
    from wmrkit.control.trackers import pure_pursuit

    robot, ref = catalog.load("diff-drive"), builtin_reference("line", duration=4.0)  # 2 m along +x
    control = pure_pursuit(control_point(robot), ref, 1.0)
    twist, _ = control(1.0, np.array([1.99, 0.0, 0.0]), np.zeros(3))  # 1 cm before the end, heading along the path
    # slowing to stop at the end: 0.5 m/s scaled by sqrt(0.01 m left / 1 m lookahead)
    assert twist[2] == pytest.approx(0.0) and twist[0] == pytest.approx(0.5 * math.sqrt(0.01 / 1.0))
    twist, _ = control(1.0, np.array([2.01, 0.0, 0.0]), np.zeros(3))  # 1 cm past it: stopped
    assert (twist == 0).all()
    run = track(robot, ref, controller="pure-pursuit", initial_pose=[0.5, 0.0, 0.0])
    # the stop is a step of the speed inside an integration step: within 2 mm at the trackers' rtol 1e-5 (1.3 mm)
    assert np.abs(run.twist[:, 2]).max() < 1e-9 and run.pose[-1, 0] == pytest.approx(2.0, abs=2e-3)


@pytest.mark.parametrize("controller", ["pure-pursuit", "stanley"])
def test_geometric_trackers_run_on_past_the_reference_s_end_at_rest(controller, capsys):
    """Their path search looks within 5 s of the run's time: more than 5 s past the reference's end it looked in no
    sample at all ('wmrkit track diff-drive --reference line --controller stanley --duration 40': a traceback,
    ValueError: attempt to get argmin of an empty sequence). Once its point has passed the path's end (it slows to
    stop there, so past the reference's end) the robot is at rest."""
    ref = builtin_reference("line", duration=4.0)  # 2 m along +x
    run = track(catalog.load("diff-drive"), ref, controller=controller, duration=12.0)
    assert run.t[-1] == pytest.approx(12.0)  # a given duration is run whole
    arrived = run.t[np.argmax(run.tracked[:, 0] >= 2.0)]
    assert 4.0 < arrived < 12.0 - 1.0
    # at rest within the integration step over the stop (< 3 mm at its last 1 cm/s), then exactly
    rest = run.t >= arrived
    assert np.abs(run.pose[rest] - run.pose[-1]).max() < 3e-3
    rest = run.t >= arrived + 1.0
    np.testing.assert_allclose(run.pose[rest], run.pose[rest][:1].repeat(rest.sum(), axis=0), atol=1e-12)
    assert run.tracked[-1, :2] == pytest.approx([2.0, 0.0], abs=1e-3)
    assert main(["track", "diff-drive", "--reference", "line", "--controller", controller, "--duration", "40",
                 "--json"]) == 0
    # at the line's end, 10 m along +x (within 5 mm: the continuous loop's step over the reference's stop at 20 s)
    assert json.loads(capsys.readouterr().out)["summary"]["final_error"] < 5e-3


def _distance_to_polyline(xy, p):
    a, b = xy[:-1], xy[1:]
    d = b - a
    u = np.clip(np.sum((p - a) * d, axis=1) / np.maximum(np.sum(d * d, axis=1), 1e-300), 0.0, 1.0)
    return float(np.hypot(*(p - a - u[:, None] * d).T).min())


def test_the_path_search_follows_a_robot_off_the_reference_s_time():
    """The path was searched within 5 s of the run's time only: a point further ahead or behind projected on that
    window's edge (Stanley ahead on the car's square saw the path's end only from 59 s; pure pursuit behind aimed
    from the window's first sample). 8 m square at 0.5 m/s: corners at arc lengths 8, 16, 24 m (16, 32, 48 s)."""
    from wmrkit.control.trackers import PathIndex

    path = PathIndex(builtin_reference("square", size=8.0))
    for t, point, s, chi, e in ((0.0, (8.2, 3.0), 11.0, math.pi / 2, -0.2),  # 22 s ahead, on the 2nd leg
                                (20.0, (3.0, -0.1), 3.0, 0.0, -0.1),  # 14 s behind, on the 1st
                                (56.0, (0.1, -1.0), 32.0, -math.pi / 2, 0.1)):  # past the end (its last sample)
        assert path.project(np.array(point), t) == (pytest.approx(s), pytest.approx(chi), pytest.approx(e))


def test_stanley_stops_at_the_end_of_the_car_s_square():
    """Stanley's front point gains on the reference at each corner (3.76 m by the 8 m square's end): it reached the
    path's end at 56 s and drove on along its last tangent until the reference's time ended, 3.76 m past it: the
    final cross-track error was its maximum. Now it stops there: the final point is on the path's end. (A 12 m square
    since Stanley's steering is limited to the car's: turning on its 4 m radius at the corners, it still ends 0.13 m
    beside the 8 m square's last leg, which is too short to recover on.) Its front point drives at the path's speed
    (it reached the end at 93.75 s of 96 at the rear axle's), and slows to stop there: the run ends when it
    arrives, after the reference's end, within the followers' bounded extra time."""
    ref = builtin_reference("square", size=12.0)
    run = track(catalog.load("ackermann"), ref, controller="stanley")
    end = run.tracked[-1, :2]
    assert np.hypot(*(end - ref.pose[-1, :2])) < 5e-3 and _distance_to_polyline(ref.pose[:, :2], end) < 5e-3
    assert run.cross_track[-1] == pytest.approx(_distance_to_polyline(ref.pose[:, :2], end), abs=1e-9)
    at_end = (np.hypot(*(run.tracked[:, :2] - ref.pose[-1, :2]).T) < 5e-3) & (run.t > 1.0)  # not its start
    assert at_end[-1] and 96.0 < run.t[np.argmax(at_end)] <= follower_duration(96.0)
    assert run.summary()["final_error"] < 5e-3


@pytest.mark.parametrize(("controller", "labelled"), [("stanley", True), ("pure-pursuit", True), ("p", False)])
def test_the_path_followers_tracking_error_says_what_it_measures(controller, labelled, capsys):
    """Pure pursuit and Stanley have no time law: their tracking error (from the reference's pose at the same time)
    grows with each corner at any size, and was printed as the thesis law's, which converges."""
    assert main(["track", "diff-drive", "--reference", "line", "--controller", controller, "--duration", "2"]) == 0
    line = next(x for x in capsys.readouterr().out.splitlines() if x.startswith("tracking error [m]: rms "))
    assert ("not its timing" in line) is labelled


def test_cli_track_json(capsys):
    assert main(["track", "forklift", "--reference", "circle", "--from", "0", "0.5", "0deg", "--duration", "4",
                 "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert {"t", "pose", "reference", "wheels", "summary"} <= set(data)
    assert "error" not in data  # the key of a failure (docs/limits.md, JSON answers): the series is tracking_error
    assert len(data["pose"][0]) == 3 and len(data["reference"][0]) == 3 and len(data["t"]) == len(data["pose"])
    assert data["wheels"]["right_drive"]["heading"] is None
    assert len(data["wheels"]["steer"]["heading"]) == len(data["t"])
    assert data["tracking_error"][0] == pytest.approx(0.5) and data["tracking_error"][-1] < 0.5 * math.exp(-3.5)


def test_cli_track_discrete_warns_and_plots(tmp_path, capsys):
    png = tmp_path / "run.png"
    assert main(["track", "mecanum-4", "--reference", "line", "--period", "0.5", "--delay", "1", "--gain", "0.8",
                 "--duration", "5", "--plot", str(png)]) == 0
    captured = capsys.readouterr()
    assert "10 T" in captured.err and "tracking error" in captured.out and png.stat().st_size > 1000


@pytest.mark.parametrize("extra", [(), ("--json",)])
def test_a_diverged_sampled_loop_says_the_sampling_warning_that_foretold_it(capsys, extra):
    """The sampling warning ('unstable with a delay of 2 samples: the error grows by 1.298 times a sample') was
    dropped when the loop then diverged: the error escaped before the warnings were said. It is now in the one line
    of the error (text or JSON)."""
    assert main(["track", "diff-drive", "--reference", "line", "--period", "0.05", "--delay", "2", "--gain", "30",
                 *extra]) == 2
    err = capsys.readouterr().err
    assert len(err.splitlines()) == 1
    message = json.loads(err)["error"] if extra else err
    assert re.search(r"the closed loop diverged at t = .*lower the gain or the period \(discrete loop: 1/a = "
                     r"0\.0333 s < 10 T = 0\.5 s .*unstable with a delay of 2 samples: the error grows by 1\.298 "
                     r"times a sample", message), message


@pytest.mark.parametrize(("controller", "option", "python"), [("pure-pursuit", "--lookahead", "lookahead"),
                                                               ("stanley", "--stanley-gain", "stanley_gain")])
def test_cli_geometric_tracker_options_are_the_python_ones(capsys, controller, option, python):
    """They were not on the command line, and --gain, which these trackers ignore, changed nothing. The JSON answer's
    warnings include the ones Python gives (pure pursuit with a 2.5 m lookahead passes the circle's end 0.12 m beside
    it: an ArrivalWarning, which the test states instead of leaking)."""
    ref, errors = builtin_reference("circle"), []
    for value in (0.4, 2.5):
        assert main(["track", "diff-drive", "--reference", "circle", "--controller", controller, option, str(value),
                     "--json"]) == 0
        answer = json.loads(capsys.readouterr().out)
        errors.append(answer["summary"]["rms_error"])
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always", ArrivalWarning)
            want = track(catalog.load("diff-drive"), ref, controller=controller, **{python: value}).summary()
        assert errors[-1] == pytest.approx(want["rms_error"], rel=1e-9)
        said = [str(w.message) for w in caught if issubclass(w.category, ArrivalWarning)]
        assert said == [w for w in answer["warnings"] if w.startswith("the path follower did not reach")]
    assert abs(errors[0] - errors[1]) > 1e-3 * max(errors)  # the option acts


def test_cli_feasibility_json(capsys):
    assert main(["feasibility", "forklift", "--reference", "square", "--json"]) == 1  # an answer that is no
    data = json.loads(capsys.readouterr().out)
    assert data["feasible"] is False and {"t", "kind", "remedy"} <= set(data["violations"][0])
    assert main(["feasibility", "mecanum-4", "--reference", "circle", "--framework", "dynamic", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["feasible"] is True


@pytest.mark.parametrize("argv, message", [
    (["track", "forklift", "--reference", "nope"], "no built-in reference"),
    (["track", "forklift", "--reference", "line", "--period", "-1"], "--period"),
    (["track", "forklift", "--reference", "line", "--delay", "1"], "needs a sample period"),
    (["track", "forklift", "--reference", "missing.csv"], "no such file"),
    (["track", "diff-drive", "--reference", "line", "--dynamics"], "no mass properties"),
    (["track", "diff-drive", "--reference", "circle", "--controller", "pure-pursuit", "--gain", "3"],
     "--gain applies to --controller p or pi or point, not pure-pursuit (it would be ignored)"),
    (["track", "diff-drive", "--reference", "circle", "--controller", "stanley", "--gate", "1"], "--gate applies"),
    # a negative gain was named as the Python keyword ('gain: expected a pole a >= 0'), not as the option
    (["track", "diff-drive", "--reference", "circle", "--gain", "-1"], "--gain: expected a gain >= 0 [1/s], got -1"),
    (["track", "diff-drive", "--reference", "circle", "--controller", "stanley", "--stanley-gain", "-2"],
     "--stanley-gain: expected a gain >= 0 [1/s], got -2"),
    # the point-to-point law (8.1) has no feedforward: the gate was ignored, exit 0
    (["track", "diff-drive", "--reference", "circle", "--controller", "point", "--gate", "1"],
     "--gate applies to --controller p or pi, not point (it would be ignored)"),
    (["track", "diff-drive", "--reference", "circle", "--lookahead", "1"], "--lookahead applies to --controller "
                                                                           "pure-pursuit, not p"),
    (["track", "diff-drive", "--reference", "circle", "--controller", "pure-pursuit", "--stanley-gain", "2"],
     "--stanley-gain applies to --controller stanley"),
    (["track", "diff-drive", "--reference", "circle", "--controller", "pure-pursuit", "--lookahead", "0"],
     "--lookahead: expected a positive number"),
    # 377 periods measured 10^8 samples late: an open loop printed as a tracking result, exit 0
    (["track", "diff-drive", "--reference", "circle", "--period", "0.1", "--delay", "100000000"],
     "delay: 100000000 samples of 0.1 s reach past the run (37.69 s): the loop would never see a measurement"),
])
def test_cli_errors_exit_2_with_one_line(argv, message, capsys):
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert message in err and "Traceback" not in err


def test_cli_track_through_the_dynamics(capsys):
    assert main(["track", "forklift", "--reference", "line", "--dynamics", "--duration", "2", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["period"] == 0.02 and len(data["t"]) == 101 and data["summary"]["max_error"] < 0.05  # starts at rest


@pytest.mark.parametrize("t0", [100.0, -5.0, 1.6e9])
def test_a_file_whose_times_do_not_start_at_zero_is_tracked_from_its_first_sample(tmp_path, t0, capsys):
    """TUM files carry absolute (Unix) times: the loop ran from t = 0 against a reference held at its first pose
    before its start (t0 > 0: rms 0.48 m, final 0.5 m = v/a behind) or already at its end (t0 < 0: 2 m off)."""
    t = np.arange(0.0, 20.001, 0.1)
    rows = [f"{ti + t0!r} {0.5 * ti!r} 0 0 0 0 0 1" for ti in t.tolist()]
    (tmp_path / "abs.tum").write_text("\n".join(rows) + "\n")
    (tmp_path / "rel.tum").write_text("\n".join(f"{ti!r} {0.5 * ti!r} 0 0 0 0 0 1" for ti in t.tolist()) + "\n")
    robot = catalog.load("mecanum-4")
    absolute, relative = (track(robot, load_reference(tmp_path / f), initial_pose=[0, 0.3, 0])
                          for f in ("abs.tum", "rel.tum"))
    np.testing.assert_allclose(absolute.t, relative.t, atol=1e-6)
    np.testing.assert_allclose(absolute.error, relative.error, atol=1e-5)  # times of 1.6e9 s: 2e-7 s apart
    assert absolute.error[-1] < 1e-5  # 0.5 m (v / a) behind before
    assert main(["track", "mecanum-4", "--reference", str(tmp_path / "abs.tum"), "--from", "0", "0.3", "0",
                 "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["summary"]["final_error"] < 1e-5


@pytest.mark.filterwarnings("error")  # pytest captures warnings: make them fail here
def test_times_whose_differences_overflow_give_one_error_line(tmp_path, capsys):
    """Times 1e300 s apart: numpy's three overflow RuntimeWarnings (file and line of its gradient) came on stderr
    before the error line."""
    f = tmp_path / "huge.csv"
    f.write_text("t,x,y,theta\n0,0,0,0\n1,1,0,0\n1e300,2,0,0\n")
    assert main(["track", "diff-drive", "--reference", str(f)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "RuntimeWarning" not in err


def test_an_animation_that_is_not_a_gif_is_refused_before_the_run(tmp_path, monkeypatch, capsys):
    """--animate run.png wrote a single still PNG and exited 0."""
    monkeypatch.chdir(tmp_path)
    assert main(["track", "diff-drive", "--reference", "line", "--duration", "2", "--animate", "run.png"]) == 2
    out = capsys.readouterr()
    assert out.out == "" and out.err.count("\n") == 1 and "run.png: the animation is written as .gif" in out.err
    assert list(tmp_path.iterdir()) == []


def test_animate_run_refuses_a_file_that_is_not_a_gif(tmp_path):
    from wmrkit.control.plots import animate_run
    from wmrkit.errors import WmrkitError

    run = track(catalog.load("diff-drive"), builtin_reference("line", duration=2.0))
    with pytest.raises(WmrkitError, match=r"run\.png: the animation is written as a GIF"):
        animate_run(run, tmp_path / "run.png")
    assert not (tmp_path / "run.png").exists()


def test_every_frame_of_the_tracking_animation_labels_its_axes_in_metres(tmp_path, monkeypatch):
    """animate_run cleared its axes for each frame and drew the plan without axis labels: x and y in no unit."""
    import wmrkit.plotting.files as files
    from wmrkit.control.plots import animate_run

    labels = []

    def spy(fig, draw, frames, path, **kwargs):
        for k in frames:
            draw(k)
            labels.append((fig.axes[0].get_xlabel(), fig.axes[0].get_ylabel()))

    monkeypatch.setattr(files, "save_gif", spy)
    animate_run(track(catalog.load("diff-drive"), builtin_reference("line", duration=2.0)), tmp_path / "r.gif",
                frames=3)
    assert labels == [("x [m]", "y [m]")] * 3


@pytest.mark.parametrize("frames", [0, 1, -3, 2.5, True, 10**6])
def test_animate_run_takes_a_bounded_number_of_frames(tmp_path, frames):
    """animate_run(frames=) was unchecked: 0 raised an IndexError, -3 numpy's ValueError, 2.5 a TypeError, and
    10**6 drew every sample of the run as a frame (track allows 10^6 samples; a frame is about 0.25 MB until the GIF
    is written). Now 2 to 800 frames, as park --animate."""
    from wmrkit.control.plots import animate_run
    from wmrkit.errors import WmrkitError

    run = track(catalog.load("diff-drive"), builtin_reference("line", duration=2.0))
    with pytest.raises(WmrkitError, match=r"^frames: expected an integer from 2 to 800"):
        animate_run(run, tmp_path / "run.gif", frames=frames)
    assert not (tmp_path / "run.gif").exists()


def test_a_size_for_the_line_is_refused_and_help_gives_each_shapes_default(capsys):
    """'track ... --reference line --size 5' ran the same line as without it (its shape has no size), exit 0; the
    option's help gave no default ('(radius, side...)'). The defaults it states are the shapes' (BUILTIN)."""
    with pytest.raises(ReferenceError, match=r"^reference 'line' has no size .* applies to circle, figure-eight"):
        builtin_reference("line", size=5.0)
    assert main(["track", "diff-drive", "--reference", "line", "--size", "5", "--duration", "1"]) == 2
    assert "reference 'line' has no size" in capsys.readouterr().err
    assert builtin_reference("line", speed=2.0).pose[-1, 0] == pytest.approx(40.0)  # 20 s at 2 m/s, as before
    for command in ("track", "feasibility"):
        with pytest.raises(SystemExit):
            main([command, "--help"])
        text = " ".join(capsys.readouterr().out.split())
        stated = dict(re.findall(r"([a-z-]+) (?:radius|half width|side|leg) \((?:default )?([\d.]+)\)", text))
        assert stated == {n: f"{s0:g}" for n, (_, _, s0, _) in BUILTIN.items() if n != "line"}, stated
        # the car's default circle is 6 m, not the 3 m stated: the help says which shapes grow, and by what rule
        grows = re.search(r"the ([a-z, -]+) are larger by default for a robot whose steering limits its turns: "
                          rf"their tightest turn {TURN_MARGIN:g} times its minimum turning radius", text)
        assert grows and set(re.split(r", | and ", grows[1])) == set(TIGHTEST_TURN), text
        assert f"and the square and corner: legs of that radius plus {CORNER_RECOVERY:g} m" in text, text


@pytest.mark.parametrize("options, advice", [(["--duration", "1e9"], "give a shorter duration (--duration)"),
                                             (["--period", "1e-4", "--duration", "1000"],
                                              "give a shorter duration (--duration) or a longer period (--period)")])
def test_a_run_of_too_many_samples_is_refused_saying_what_to_do(options, advice, capsys):
    """'duration 1e+09 s at an output step of 0.05 s: more than 1000000 samples' said what was wrong, not what to
    change (the continuous loop's own bound, 2000 s, says it)."""
    assert main(["track", "diff-drive", "--reference", "circle", *options]) == 2
    err = capsys.readouterr().err
    assert "more than 1000000 samples" in err and advice in err and len(err.strip().splitlines()) == 1


@pytest.mark.parametrize("controller", ["pure-pursuit", "stanley"])
@pytest.mark.parametrize("name", ["diff-drive", "ackermann", "forklift", "omni-3"])
def test_geometric_trackers_start_with_their_point_on_the_reference(controller, name):
    """Without a start the robot is placed with the *tracked* point on the reference's first pose. It was placed
    with the thesis law's control point there, so pure pursuit, which tracks the axle point, followed the line a
    constant 0.25 m behind (the diff drive; 2.81 m for the car) and reported that as its tracking error from a start
    'on the reference'; Stanley's front point was 0.11 m behind on the car. On the line both are then exact."""
    robot, ref = catalog.load(name), builtin_reference("line")
    run = track(robot, ref, controller=controller)
    np.testing.assert_allclose(run.tracked[0, :2], ref.pose[0, :2], atol=1e-12)
    assert run.cross_track[run.t <= 14.0].max() < 1e-6  # (past the end: the distance from the end point)
    # on time until they slow to stop at the end (over at most the car's 2.7 m wheelbase, 5.4 s of the line's 20)
    assert run.error[run.t <= 14.0].max() < 1e-6 and run.summary()["final_error"] < 1e-3


def test_track_warns_when_the_wheels_must_slip_to_follow(capsys):
    """The skid steer turns only by scrubbing its fixed wheels sideways: the kinematic loop moves it as commanded
    and printed an error of 4e-11 m on the circle with no word on it (the IK's slip was in Python only). Now a
    warning names the slipping wheels and the times; a diff drive on the same circle gets none."""
    assert main(["track", "skid-steer-4", "--reference", "circle", "--duration", "3"]) == 0
    err = capsys.readouterr().err
    assert "must slip sideways" in err and "front_left" in err and "to 3 s)" in err
    assert len(err.strip().splitlines()) == 1
    assert main(["track", "diff-drive", "--reference", "circle", "--duration", "3"]) == 0
    assert capsys.readouterr().err == ""
