"""Slip-aware odometry: WLS on slip-free logs is the exact odometry; FK1/FK2 streaming; the CLI's --method."""

from __future__ import annotations

import json

import numpy as np
import pytest

from wmrkit import catalog
from wmrkit.cli.main import main
from wmrkit.odometry.logs import JointLog, write_log
from wmrkit.odometry.pipeline import odometry
from wmrkit.odometry.synthetic import TwistProfile, simulate
from wmrkit.slip.estimators import estimator
from wmrkit.slip.kalman import KalmanNoise
from wmrkit.slip.weights import SlipWeights

PROFILE = TwistProfile.from_segments([(2.0, 1.0, 0.0, 0.0), (3.0, 1.2, 0.0, 0.4), (2.0, 0.8, 0.0, -0.5)])
# one arc: a steering jump at a segment boundary would fall inside a sample interval (not slip-free when sampled);
# the drive axle's twist, the forklift's origin being at the fork tips
FORKLIFT = TwistProfile.from_segments([(6.0, 1.2, 0.0, 0.4)]).about((-1.0, 0.0))


@pytest.fixture(scope="module")
def forklift_run():
    return simulate(catalog.load("forklift"), FORKLIFT, 50.0)


@pytest.mark.parametrize("name", ["forklift", "mecanum-4", "diff-drive"])
def test_wls_on_slip_free_logs_is_exact_odometry(name):
    """Without slip the sensors satisfy A dq = 0, so every weighting gives the exact poses."""
    robot = catalog.load(name)
    profile = {"forklift": FORKLIFT, "mecanum-4": TwistProfile.from_segments([(2.0, 0.5, 0.3, 0.2)])}.get(name, PROFILE)
    run = simulate(robot, profile, 50.0)
    rng = np.random.default_rng(0)
    weights = SlipWeights.of({w.name: tuple(10.0 ** rng.uniform(-3, 3, 2)) for w in robot.wheels})
    wls = odometry(estimator(robot, "wls", weights=weights), run.log)
    plain = odometry(robot, run.log)
    assert np.allclose(wls.poses, run.truth, atol=1e-9)
    assert np.allclose(wls.poses, plain.poses, atol=1e-12)


def test_filters_stream_in_chunks_and_track_slip_free_motion(forklift_run):
    """FK2 over chunks equals FK2 over the whole log; on a slip-free log it stays near the truth."""
    robot = catalog.load("forklift")
    est = estimator(robot, "fk2", noise=KalmanNoise(2.0, 0.05, 0.05))
    log = forklift_run.log
    parts = []
    whole = est.run([log], sinks=[parts.append])
    chunked_parts = []
    chunked = est.run([log.slice(i, i + 37) for i in range(0, len(log), 37)], sinks=[chunked_parts.append])
    assert np.allclose(whole.final_pose, chunked.final_pose, atol=1e-12)
    poses = np.vstack([p.poses for p in parts])
    assert poses.shape == (len(log), 3)
    err = np.hypot(*(poses[:, :2] - forklift_run.truth[:, :2]).T)
    assert err.max() < 0.05 * whole.path_length


def test_cli_methods(tmp_path, forklift_run):
    log = forklift_run.log
    path = tmp_path / "log.csv"
    write_log(path, log, catalog.load("forklift"))
    out = {}
    for method, options in (("wls", ["--mu", "steer=0.01,1"]), ("fk1", ["--kf-noise", "2", "0.05", "0.05"]),
                            ("fk2", ["--kf-noise", "2", "0.05", "0.05"])):
        assert main(["odometry", "forklift", str(path), "--method", method, "--json", *options]) == 0
    for method, options in (("wls", ["--kf-noise", "2", "0.05", "0.05"]), ("fk2", ["--mu", "steer=0.01,1"])):
        assert main(["odometry", "forklift", str(path), "--method", method, *options]) == 2  # ignored before
    import contextlib
    import io

    for method in ("exact", "wls"):
        buf = io.StringIO()
        with contextlib.redirect_stdout(buf):
            args = ["odometry", "forklift", str(path), "--method", method, "--json"]
            assert main(args + (["--mu", "steer=0.01,1"] if method == "wls" else [])) == 0
        out[method] = json.loads(buf.getvalue())
    assert out["wls"]["method"] == "wls (exact)"
    assert np.allclose(out["wls"]["final_pose"], out["exact"]["final_pose"], atol=1e-9)
    assert np.allclose(out["wls"]["final_pose"], forklift_run.truth[-1], atol=1e-9)


def test_cli_refuses_bad_estimator_options(tmp_path, capsys, forklift_run):
    log = forklift_run.log
    path = tmp_path / "log.csv"
    write_log(path, log, catalog.load("forklift"))
    for extra, message in ((["--method", "wls", "--mu", "steer=0,1"], "> 0"),
                           (["--method", "wls", "--mu", "nope=1,1"], "--mu nope: robot 'forklift' has no wheel"),
                           (["--method", "fk2", "--kf-wheel", "nope=1,1"],
                            "--kf-wheel nope: robot 'forklift' has no wheel"),  # the option was not named
                           (["--method", "fk2", "--kf-noise", "1", "-1", "1"], "--kf-noise: Kalman noise lateral: "
                                                                                "must be a finite number in [1e-150"),
                           (["--method", "fk2", "--kf-noise", "1e308", "1", "1"], "--kf-noise: Kalman noise process: "
                                                                                  "must be"),
                           (["--method", "fk2", "--kf-noise", "1", "1e-30", "1"], "--kf-noise: Kalman noise lateral "
                                                                                 "(1e-30) and process (1) differ by"),
                           (["--method", "fk2", "--kf-wheel", "steer=1e9,1"], "--kf-wheel: Kalman noise process (1) "
                                                                              "and steer (lateral) (1e+09) differ by"),
                           (["--method", "wls", "--mu", "steer=abc"], "two numbers"),
                           (["--method", "fk1", "--covariance"], "not available")):
        assert main(["odometry", "forklift", str(path), *extra]) == 2
        err = capsys.readouterr().err
        assert err.startswith("wmrkit: error:") and message in err, err


def test_a_filter_that_lags_a_spike_warns_in_one_line_without_naming_wheels(tmp_path, capsys):
    """A differential drive's two spins cannot contradict each other (no redundancy: the no-slip residual has no
    rows), but a filter lags a spike in the log and its residual says so: one warning line, no wheel named (this
    used to raise an IndexError from the per-wheel slip)."""
    from wmrkit.odometry.model import odometry_model, wheel_slip

    robot = catalog.load("diff-drive")
    model = odometry_model(robot)
    t = np.arange(50) * 0.02
    spins = np.column_stack([t * 10, t * 12])
    spins[7, 0] = 0.0  # one reading dropped to zero
    assert wheel_slip(model, spins) == {}
    path = tmp_path / "spike.csv"
    write_log(path, JointLog(t, model.joints, spins), robot)
    capsys.readouterr()
    assert main(["odometry", "diff-drive", str(path), "--method", "fk2", "--json"]) == 0
    captured = capsys.readouterr()
    assert json.loads(captured.out)["consistent"] is False
    assert captured.err.count("\n") == 1 and captured.err.startswith("wmrkit: warning: the fk2 filter's residual")
    assert "slip per wheel" not in captured.err and "contradict" not in captured.err


def test_filter_refuses_a_non_increasing_log():
    robot = catalog.load("diff-drive")
    log = JointLog(np.array([0.0, 0.1, 0.1]), ("left.spin", "right.spin"), np.zeros((3, 2)))
    from wmrkit.odometry.logs import LogError

    with pytest.raises(LogError, match="repeats"):
        estimator(robot, "fk2").run([log])


def test_filter_refuses_an_external_heading():
    """A heading column would be silently ignored by the filters: refused instead."""
    robot = catalog.load("diff-drive")
    log = JointLog(np.array([0.0, 0.1, 0.2]), ("left.spin", "right.spin"), np.zeros((3, 2)),
                   heading_world=np.zeros(3))
    from wmrkit.errors import WmrkitError

    with pytest.raises(WmrkitError, match="external heading"):
        estimator(robot, "fk2").run([log])


@pytest.mark.parametrize(("robot", "sensed", "advice"), [
    ("forklift", ["steer.steer"], ""),
    ("forklift", ["right_drive.spin", "steer.steer"], "use fk2"),  # FK2 has the drive wheels' lateral rows
    ("diff-drive", None, "use fk2")])
def test_fk1_refuses_rows_that_do_not_determine_the_twist(robot, sensed, advice):
    """FK1 used to run on them: the random walk carried the unmeasured directions (a forklift's log of 24 m gave
    a path of 0 m, or a heading 100 deg off FK2's)."""
    from wmrkit.errors import WmrkitError
    from wmrkit.slip.kalman import kalman_model

    with pytest.raises(WmrkitError, match=f"fk1: the sensed rows .* do not determine its twist.*{advice}"):
        kalman_model(catalog.load(robot), "fk1", sensed=sensed)


def test_only_the_ratios_of_the_kalman_noises_matter(forklift_run):
    """Scaling every standard deviation by c scales the covariance by c^2 and leaves the gain (the reason the spread,
    not the size, of the noises is bounded): the same poses, to round-off."""
    from wmrkit.slip.kalman import KalmanNoise, kalman_model, kalman_odometry

    robot = catalog.load("forklift")
    base = kalman_odometry(kalman_model(robot, "fk2", KalmanNoise(0.5, 0.05, 0.2)), forklift_run.log).poses
    for c in (1e-4, 1e4):
        scaled = kalman_odometry(kalman_model(robot, "fk2", KalmanNoise(0.5 * c, 0.05 * c, 0.2 * c)),
                                 forklift_run.log).poses
        np.testing.assert_allclose(scaled, base, rtol=0, atol=1e-9 * np.abs(base).max())


def test_a_noise_spread_beyond_double_precision_is_refused():
    from wmrkit.errors import WmrkitError
    from wmrkit.slip.kalman import MAX_SPREAD, KalmanNoise

    KalmanNoise(1.0, 1.0 / MAX_SPREAD, 1.0)  # the widest spread accepted
    with pytest.raises(WmrkitError, match=r"front \(longitudinal\) \(1e-07\) and process \(1\)"):
        KalmanNoise(1.0, 1.0, 1.0, (("front", 1.0, 1e-7),))



def test_a_noise_that_is_not_a_number_is_refused_by_name():
    """Text raised numpy's 'ufunc isfinite not supported' TypeError, naming nothing."""
    from wmrkit.errors import WmrkitError
    from wmrkit.slip.kalman import KalmanNoise

    with pytest.raises(WmrkitError, match="Kalman noise process: must be a finite number"):
        KalmanNoise("1", 1.0, 1.0)  # type: ignore[arg-type]
    with pytest.raises(WmrkitError, match=r"Kalman noise front \(lateral\): must be a finite number"):
        KalmanNoise(1.0, 1.0, 1.0, (("front", None, 1.0),))  # type: ignore[arg-type]


def test_a_filter_lagging_its_measurements_is_not_called_a_contradiction(tmp_path, capsys):
    """Right wheel and steering only: the sensors cannot contradict each other (no redundancy), but FK2's slip
    indicator, the rows' residual at the filtered twist, holds the filter's lag where the motion changes; the
    warning said "the sensed joints contradict each other", listing slips of 1e-17 m. It now says what the
    residual shows: a log changing faster than the filter's process noise allows."""
    robot = catalog.load("forklift")
    profile = TwistProfile.from_segments([(2.0, 0.5, 0.0, 0.0), (2.0, 1.5, 0.0, 0.6), (2.0, 0.3, 0.0, -0.5)])
    path = tmp_path / "log.csv"
    write_log(path, simulate(robot, profile.about((-1.0, 0.0)), 50.0).log, robot)
    args = ["odometry", "forklift", str(path), "--sensed", "right_drive.spin", "--sensed", "steer.steer", "--json"]
    assert main([*args, "--method", "fk2"]) == 0
    out, err = capsys.readouterr()
    data = json.loads(out)
    motion = data["path_length"] / (data["samples"] - 1)
    assert data["rms_slip"] > 0.02 * motion  # the filter's indicator: above the tolerance
    assert "contradict" not in err and "the sensed joints themselves agree" in err


def test_a_filter_whose_rows_barely_fix_the_twist_of_a_robot_that_does_not_steer_names_no_heading(tmp_path, capsys):
    """A differential drive whose lateral rows are 1e3 times noisier than its rolling rows: the weighted rows fix vy
    1e3 times more weakly than vx (their condition number, worked by hand: 1e3). The warning said "at a steering
    heading of the log () ...", naming an empty list of steered wheels."""
    t = np.arange(0, 2.0001, 0.02)
    path = tmp_path / "dd.csv"
    path.write_text("time,left.spin,right.spin\n" + "".join(f"{a:.2f},{8 * a:.6f},{12 * a:.6f}\n" for a in t))
    assert main(["odometry", "diff-drive", str(path), "--method", "fk2", "--kf-noise", "1", "1e3", "1", "--json"]) == 0
    err = capsys.readouterr().err
    assert err.splitlines() == ["wmrkit: warning: fk2: its measurement rows barely fix the twist (condition number "
                                "1e+03 > 100): there the filter carries its prediction and the trajectory can be far "
                                "off"]


def test_fk1_warns_where_its_rows_do_not_fix_the_twist(tmp_path, capsys):
    """The forklift turning on the spot with its steered wheel at heading 90 deg: FK1's kept rows (the steered
    wheel's and the drive wheels' rolling rows, (7.69)) lose the sideways speed there, so FK1 ended at (0, 0),
    exit 0 and "consistent", where the robot went to (-0.61, -0.92) m (FK2 and WLS: exact). Now a warning names the
    heading; driving straight, none. The condition number is checked against an SVD of the rows done here."""
    from wmrkit.analysis.singularity import robot_size
    from wmrkit.slip.kalman import ILL_CONDITIONED, kalman_model

    t = np.arange(0, 5.0001, 0.01)
    header = "time [s],right_drive.spin [rad],left_drive.spin [rad],steer.steer [deg]\n"
    for name, left, heading, warned in (("spin", -2.0, 90, True), ("straight", 2.0, 0, False)):
        path = tmp_path / f"{name}.csv"
        path.write_text(header + "".join(f"{a:.4f},{2 * a:.6f},{left * a:.6f},{heading}\n" for a in t))
        for method in ("fk1", "fk2"):
            assert main(["odometry", "forklift", str(path), "--method", method, "--json"]) == 0
            err = capsys.readouterr().err
            said = f"wmrkit: warning: {method}: at a steering heading of the log (steer 90 deg)" in err
            assert said == (warned and method == "fk1"), (name, method, err)
            assert not said or ("rows do not fix the twist" in err and err.count("\n") == 1)
    robot = catalog.load("forklift")
    model = kalman_model(robot, "fk1")
    for heading, ill in ((0.0, False), (np.radians(89.5), True)):
        beta = np.array([[heading + np.pi / 2]])
        model.configuration_maps(beta)
        c = robot.constraint_matrix(beta)[0][model.rows, :3] / model.sigma[:, None]
        c[:, 2] *= robot_size(robot)
        s = np.linalg.svd(c, compute_uv=False)
        assert model.worst_conditioning[0] == pytest.approx(s[0] / s[-1], rel=1e-9)
        assert (model.worst_conditioning[0] > ILL_CONDITIONED) == ill


def test_coefficients_of_a_wheel_without_rows_are_refused(tmp_path, capsys):
    """With only the forklift's drive spins sensed the steered wheel has no row in the model (its rows hold its
    unsensed spin), so '--mu steer=1,2' weighed nothing and was ignored silently (exit 0)."""
    path = tmp_path / "drive.csv"
    path.write_text("time [s],right_drive.spin [rad],left_drive.spin [rad]\n0,0,0\n1,1,1\n2,2,2\n")
    argv = ["odometry", "forklift", str(path), "--method", "wls", "--sensed", "right_drive.spin", "--sensed",
            "left_drive.spin"]
    assert main([*argv, "--mu", "steer=1,2"]) == 2
    err = capsys.readouterr().err
    assert "--mu steer: wheel 'steer' has no no-slip rows" in err and err.count("\n") == 1
    assert main([*argv, "--mu", "right_drive=1,2"]) == 0  # a wheel with rows: used


@pytest.mark.parametrize(("method", "instead"), [("wls", "--mu"), ("fk1", "--kf-wheel"), ("fk2", "--kf-wheel")])
def test_weight_with_a_slip_aware_method_names_that_methods_option(method, instead, tmp_path, capsys):
    """'--method fk2 --weight left=2' said 'with --method wls use --mu', an option fk2 refuses."""
    log = tmp_path / "d.csv"
    log.write_text("time,left.spin,right.spin\n0,0,0\n1,1,1.2\n")
    assert main(["odometry", "diff-drive", str(log), "--method", method, "--weight", "left=2"]) == 2
    assert capsys.readouterr().err == (f"wmrkit: error: --weight applies to the kinematic methods; with --method "
                                       f"{method} use {instead} WHEEL=LAT,LONG\n")


@pytest.mark.parametrize("gap", [1e9, 1e308])
def test_a_filter_whose_pose_leaves_the_range_handled_is_refused_at_that_row(gap, tmp_path, capsys):
    """A pause of about `gap` seconds after 11 samples of a turning differential drive. With Q per sample the filters
    carried the twist from before it across the whole pause: fk2 printed a heading of 5.7e8 rad (1e9 s; exit 0 with a
    warning), or 'a numerical overflow in wmrkit; please report it' (1e308 s). Now a step of n periods adds n Q
    (docs/errata.md): over 1e9 s the prediction's share of the twist falls as 1/n, and the pause adds to the wheels'
    heading r (right - left) / track (0.075 m, 0.4 m) only what it adds in the limit, T H^-1 x: the twist before it
    (omega 0.75 rad/s) over the information of the rows (2 (track/2)^2 for omega, unit noises) times the period
    (0.02 s). 1e308 s is beyond the 1e90 periods Q counts at most (``_kalman_kernel.MAX_PERIODS``): the filters
    hold the bounds the no-slip odometry holds (a pose beyond 1e9 m or 1e6 turns: refused at its row)."""
    rows = [f"{0.02 * k if k <= 10 else gap!r},{0.16 * k!r},{0.24 * k!r}" for k in range(12)]  # the last after it
    log = tmp_path / "gap.csv"
    log.write_text("time,left.spin,right.spin\n" + "\n".join(rows) + "\n")
    wheels = 0.075 * (0.24 - 0.16) * 11 / 0.4
    for method in ("fk2", "wls", "exact"):
        code = main(["odometry", "diff-drive", str(log), "--method", method, "--quiet", "--json"])
        out, err = capsys.readouterr()
        if method == "fk2" and gap > 1e100:
            assert code == 2 and out == "" and err.count("\n") == 1
            data = json.loads(err)
            assert data["line"] == 13 and data["file"] == str(log)  # the first sample after the gap
            assert data["error"].startswith("the pose [") and "is beyond 1e+09 m or 1e+06 turns here" in data["error"]
        else:  # fk2 says that its residual shows a log changing faster than its process noise allows: the pause
            assert code == 0 and err == ("" if method != "fk2" else err.splitlines()[0] + "\n")
            assert method != "fk2" or err.startswith("wmrkit: warning: the fk2 filter's residual")
            added = 0.02 * 0.75 / (2 * 0.2**2) if method == "fk2" else 0.0
            assert json.loads(out)["final_pose"][2] == pytest.approx(wheels + added, rel=1e-9)


def test_the_plot_legend_names_the_slip_aware_method(tmp_path, monkeypatch):
    """`wmrkit odometry LOG --method fk2 --plot P` labelled its path 'diff-drive (exact)', the integration scheme
    alone: a plot of each estimator said the same. The legend names the estimator and its scheme."""
    from wmrkit.odometry import plot

    robot = catalog.load("diff-drive")
    path = tmp_path / "log.csv"
    write_log(path, simulate(robot, PROFILE, 50.0).log, robot)
    drawn = []
    monkeypatch.setattr(plot, "save_trajectory_plot", lambda out, paths, **_: drawn.append(list(paths)))
    for method in ("fk2", "wls", "exact"):
        assert main(["odometry", "diff-drive", str(path), "--method", method, "--plot", str(tmp_path / "p.png")]) == 0
    assert drawn == [["diff-drive (fk2, exact)"], ["diff-drive (wls, exact)"], ["diff-drive (exact)"]]


@pytest.mark.parametrize("sensed", [("front_left.spin",), ("front_left.spin", "rear_left.spin")])
def test_one_side_of_a_skid_steer_is_refused_for_the_slip_aware_methods(tmp_path, capsys, sensed):
    """One side's wheels of a skid steer: the no-slip lateral rows fix its turn rate at 0, so `--method wls` (and
    fk2) drove a turning run straight, exit 0. They never report the turn the four wheels report: refused as plain
    odometry refuses sensors that do not determine the no-slip motion, '--sensed: ...', exit 2."""
    from wmrkit.odometry.model import SensingError
    from wmrkit.slip.synthetic import wheel_speed_run

    robot = catalog.load("skid-steer-4")
    run = wheel_speed_run(robot, [(3.0, [8, 12, 8, 12])], 20.0)
    assert run.truth[-1, 2] > 0.5  # the run turns (its no-slip rows would say it cannot)
    for name in ("wls", "fk1", "fk2"):
        with pytest.raises(SensingError, match=r"they never report a turn \(the no-slip rows hold omega at 0"):
            estimator(robot, name, sensed=sensed)
    log = tmp_path / "skid.csv"
    write_log(log, run.log)
    args = ["odometry", "skid-steer-4", str(log), *(a for s in sensed for a in ("--sensed", s))]
    for method in ("wls", "fk2"):
        assert main([*args, "--method", method]) == 2
        err = capsys.readouterr().err
        assert err.startswith("wmrkit: error: --sensed: the sensed joints of robot 'skid-steer-4' (") \
            and "do not determine its motion with slip" in err and err.count("\n") == 1


def test_sensors_that_see_every_turn_are_not_refused():
    """Both front wheels of the skid steer report its turn; the forklift's drive wheels alone (differential odometry,
    (7.79)) or one of them with the steering (its sideways speed at the fork tips tied to the turn), and a car's rear
    wheels (its sideways speed held at 0 at their axle, as by the no-slip model): all run."""
    cases = {"skid-steer-4": [("front_left.spin", "front_right.spin"), ("front_left.spin", "rear_right.spin")],
             "forklift": [("right_drive.spin", "left_drive.spin"), ("right_drive.spin", "steer.steer")],
             "ackermann": [("rear_left.spin", "rear_right.spin")]}
    for robot, sets in cases.items():
        for sensed in sets:
            for name in ("wls", "fk2"):
                estimator(catalog.load(robot), name, sensed=sensed)
