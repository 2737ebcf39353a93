"""Skid steering: the simulated slip, calibration of WLS and of the effective track, and the CLI round trip."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from wmrkit import catalog
from wmrkit.cli.main import main
from wmrkit.errors import WmrkitError
from wmrkit.odometry.logs import write_csv
from wmrkit.odometry.model import wrap_angle
from wmrkit.odometry.pipeline import odometry
from wmrkit.odometry.trajectories import Trajectory, write_trajectory
from wmrkit.slip.calibration import calibrate_slip, effective_track_model
from wmrkit.slip.skid import skid_comparison
from wmrkit.slip.synthetic import wheel_speed_run
from wmrkit.slip.weights import SlipWeights, wls_model

SEGMENTS = [(3.0, [8, 12, 8, 12]), (2.0, [10, 10, 10, 10]), (3.0, [12, 8, 12, 8]), (2.0, [6, 14, 6, 14])]


@pytest.fixture(scope="module")
def husky_run():
    return wheel_speed_run(catalog.load("skid-steer-4"), SEGMENTS, 20.0, model="mqe")


def test_wls_ratio_is_an_effective_track_on_a_symmetric_skid_steer(husky_run):
    """Normal equations of WLS on wheels at (+-a, +-b): omega = du / (2 b (1 + k a^2 / b^2)); a = b here."""
    robot = catalog.load("skid-steer-4")
    for k in (0.1, 0.75, 3.0):
        wls = odometry(wls_model(robot, SlipWeights.uniform(k, 1.0)), husky_run.log).poses
        track = odometry(effective_track_model(robot, 1 + k), husky_run.log).poses
        assert np.allclose(wls, track, atol=1e-6)


def test_simulated_skid_steer_slips_like_its_tyres(husky_run):
    """Straight segments roll without slip; turns are slower than the no-slip differential model; the effective
    multiplier is near 1 + c_alpha / c_s, the linear-region ratio of the Dugoff tyres (1500 / 2000)."""
    straight = husky_run.twists[1]
    assert np.allclose(straight, [1.0, 0.0, 0.0], atol=1e-9)
    kinematic = (1.2 - 0.8) / 0.5
    assert 0 < husky_run.twists[0, 2] < kinematic
    cal = calibrate_slip(catalog.load("skid-steer-4"), husky_run.log, (husky_run.log.time, husky_run.truth))
    assert math.isclose(cal.multiplier, 1 + cal.ratio, rel_tol=1e-3)
    assert 0.6 < cal.ratio < 0.95
    rms = dict(cal.rms)
    assert rms["wls"] < 0.1 * rms["no_slip"]
    assert math.isclose(rms["wls"], rms["effective_track"], rel_tol=1e-3, abs_tol=1e-6)


@pytest.mark.parametrize("start", [0.5, 5.0])
def test_a_reference_that_starts_after_the_log_gives_the_same_fit(husky_run, start):
    """The odometry passes through the reference's first pose at its time, not at the log's first sample (it
    used to start there, and a reference from 5 s ran the ratio to its bound, 1e6)."""
    robot, log = catalog.load("skid-steer-4"), husky_run.log
    full = calibrate_slip(robot, log, (log.time, husky_run.truth))
    late = log.time >= start
    part = calibrate_slip(robot, log, (log.time[late], husky_run.truth[late]))
    assert part.ratio == pytest.approx(full.ratio, rel=0.05)
    assert part.multiplier == pytest.approx(full.multiplier, rel=0.05)
    assert dict(part.rms)["wls"] < 0.25 * dict(part.rms)["no_slip"]


def test_a_reference_of_another_run_is_refused(husky_run):
    """A reference that turns the other way: it ran the fit to the bound of its search; now refused before the fit
    (tests/slip/test_reference_consistency.py)."""
    mirrored = husky_run.truth * [1.0, -1.0, -1.0]
    with pytest.raises(WmrkitError, match="slip scales a turn, it does not reverse it"):
        calibrate_slip(catalog.load("skid-steer-4"), husky_run.log, (husky_run.log.time, mirrored))


def test_a_fit_stopped_a_hair_inside_its_bound_is_refused():
    """scipy's trf stops strictly inside a bound and need not flag it active: a reference with x and y swapped ran
    the ratio to 1.0000012e-06 (5e-7 decades from the bound), which was reported as a fit, exit 0 (`wmrkit
    calibrate` offered `lateral: 1.0000003981745279e-06` as a description block on a simulated turn). A swapped
    reference is now refused before the fit; a reference turning three times as fast as the log's wheels allow
    (the same way, so not refused as a mirror image) stops the fit 1.5e-5 decades inside the bound, not active."""
    robot = catalog.load("skid-steer-4")
    run = wheel_speed_run(robot, [(1.0, [10, 10, 10, 10]), (2.0, [10, 12, 10, 12])], 50.0, model="mqe")
    faster = wheel_speed_run(robot, [(1.0, [10, 10, 10, 10]), (2.0, [10, 16, 10, 16])], 50.0, model="mqe")
    with pytest.raises(WmrkitError, match="the WLS ratio ran to the bound of its search"):
        calibrate_slip(robot, run.log, (run.log.time, faster.truth))


def test_a_reference_covering_a_straight_part_of_a_turning_log_says_so(husky_run):
    """Two reference poses 0.05 s apart on a log that turns later: the refusal said "a run without turning?" of a
    run that turns, as if the whole log were straight; it now names the part the reference covers."""
    log = husky_run.log
    with pytest.raises(WmrkitError, match=r"a run without turning\?; that is between the reference's poses, t = 3\.5 "
                                          r"to 3\.55 s of the log's 0 to 10 s\); calibrate on a log that turns"):
        calibrate_slip(catalog.load("skid-steer-4"), log, (log.time[70:72], husky_run.truth[70:72]))


def test_cli_calibrate_then_odometry(tmp_path, capsys, husky_run):
    log = husky_run.log
    log_path, ref_path, w_path = tmp_path / "log.csv", tmp_path / "ref.tum", tmp_path / "w.json"
    write_csv(log_path, ("time", *log.joints), np.column_stack([log.time, log.positions]))
    write_trajectory(ref_path, Trajectory(log.time, husky_run.truth, np.zeros(len(log))), "tum")
    assert main(["calibrate", "skid-steer-4", str(log_path), "--reference", str(ref_path), "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert set(out["rms_position_error"]) == {"no_slip", "wls", "effective_track"}
    w_path.write_text(json.dumps(out))
    assert main(["odometry", "skid-steer-4", str(log_path), "--method", "wls", "--slip-weights", str(w_path),
                 "--json"]) == 0
    pose = json.loads(capsys.readouterr().out)["final_pose"]
    assert math.hypot(pose[0] - husky_run.truth[-1, 0], pose[1] - husky_run.truth[-1, 1]) < 0.2
    assert main(["odometry", "skid-steer-4", str(log_path), "--json"]) == 0
    plain = json.loads(capsys.readouterr().out)["final_pose"]
    assert math.hypot(plain[0] - husky_run.truth[-1, 0], plain[1] - husky_run.truth[-1, 1]) > 0.5
    # the final errors per model, each a number as rms_position_error's (final_error was {position, heading}):
    # the no-slip model's is the plain odometry's distance from the reference's last pose
    assert out["final_position_error"]["no_slip"] == pytest.approx(
        math.hypot(plain[0] - husky_run.truth[-1, 0], plain[1] - husky_run.truth[-1, 1]), rel=1e-6)
    assert out["final_heading_error"]["no_slip"] == pytest.approx(abs(plain[2] - husky_run.truth[-1, 2]), rel=1e-6)
    assert main(["calibrate", "skid-steer-4", str(log_path), "--reference", str(tmp_path / "none.tum")]) == 2
    assert capsys.readouterr().err.startswith("wmrkit: error:")


def test_cli_skid_study_quasi_static(tmp_path, capsys):
    """The docs' comparison on the quasi-static model: WLS = effective track, both far better than no slip on arcs."""
    assert main(["slip-study", "skid-steer-4", "--source", "quasi-static", "--json", "--report", str(tmp_path)]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["source"] == "quasi-static" and len(out["figures"]) == 4
    for name in ("calibration run", "tight loop", "slalom"):
        r = out["runs"][name]
        rms = {model: e["rms_position_error"] for model, e in r.items()}
        assert rms["WLS"] == pytest.approx(rms["effective track"], rel=1e-4, abs=1e-6)
        assert rms["WLS"] < 0.5 * rms["no slip (LS)"]
        assert all(0 <= e["final_position_error"] <= 3 * e["rms_position_error"] + 1 for e in r.values())


def test_a_run_without_turning_determines_no_slip_parameter(tmp_path, capsys):
    """A straight run's poses do not depend on the WLS ratio or the track: the fit returned its start guess (track
    multiplier 10^0.1 = 1.2589) and advised writing it into the description. Now refused, in one line."""
    from wmrkit.errors import WmrkitError
    from wmrkit.odometry.synthetic import TwistProfile, simulate

    robot = catalog.load("skid-steer-4")
    run = simulate(robot, TwistProfile.from_segments([(5.0, 1.0, 0.0, 0.0)]), 50.0)
    with pytest.raises(WmrkitError, match=r"does not determine the WLS ratio.*a run without turning"):
        calibrate_slip(robot, run.log, (run.log.time, run.truth))
    log, ref = tmp_path / "straight.csv", tmp_path / "straight.tum"
    write_csv(log, ("time", *run.log.joints), np.column_stack([run.log.time, run.log.positions]))
    write_trajectory(ref, Trajectory(run.log.time, run.truth, np.zeros(len(run.log))), fmt="tum")
    assert main(["calibrate", "skid-steer-4", str(log), "--reference", str(ref)]) == 2
    assert "does not determine" in capsys.readouterr().err


@pytest.mark.parametrize("name", ["omni-3", "diff-drive"])
def test_a_turning_log_without_slip_determines_no_ratio(name):
    """A turning run without slip: every weighting gives the same odometry. The finite-difference slope of the fit
    (round-off, 1e-13 m over a step of 1e-6) passed the test on omni-3 and its start guess, ratio 1, was reported
    as a calibration; diff-drive's refusal asked for a run that turns. Now both are refused, saying the log turns."""
    from wmrkit.odometry.synthetic import TwistProfile, simulate

    robot = catalog.load(name)
    run = simulate(robot, TwistProfile.from_segments([(3.0, 0.5, 0.0, 0.3), (3.0, 0.5, 0.0, -0.3)]), 50.0)
    with pytest.raises(WmrkitError, match=r"does not determine the WLS ratio.*the log turns: no slip in it"):
        calibrate_slip(robot, run.log, (run.log.time, run.truth))


@pytest.mark.parametrize("scale", [1000.0, 0.01])
def test_a_reference_in_other_units_is_refused(tmp_path, capsys, husky_run, scale):
    """A reference in millimetres (or hectometres) was fitted as well as it could be (a 12 m run: ratio 1.6, RMS
    error 5 km) and the block to paste into the description printed. Now refused by distance travelled, naming the
    file."""
    log = husky_run.log
    with pytest.raises(WmrkitError, match=r"^reference: the reference travels .*more than a factor 2 apart"):
        calibrate_slip(catalog.load("skid-steer-4"), log, (log.time, husky_run.truth * [scale, scale, 1.0]))
    log_path, ref_path = tmp_path / "log.csv", tmp_path / "ref.tum"
    write_csv(log_path, ("time", *log.joints), np.column_stack([log.time, log.positions]))
    write_trajectory(ref_path, Trajectory(log.time, husky_run.truth * [scale, scale, 1.0], np.zeros(len(log))), "tum")
    assert main(["calibrate", "skid-steer-4", str(log_path), "--reference", str(ref_path)]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"wmrkit: error: {ref_path}: the reference travels") and err.count("\n") == 1


def test_the_distance_check_ignores_reference_noise(husky_run):
    """Noise on the reference adds up sample by sample; by chords 1 s apart it does not: 10 cm of noise at 20 Hz
    makes this 9.9 m run 37 m long sample by sample (refused), 9.95 m by chords."""
    log, robot = husky_run.log, catalog.load("skid-steer-4")
    noisy = husky_run.truth + np.random.default_rng(0).normal(0.0, [0.1, 0.1, 0.0], husky_run.truth.shape)
    assert calibrate_slip(robot, log, (log.time, noisy)).ratio == pytest.approx(
        calibrate_slip(robot, log, (log.time, husky_run.truth)).ratio, rel=0.2)


def test_a_sparse_reference_is_not_judged_by_distance():
    """Reference poses many seconds apart (a run's start and end, as batch calibrate passes for a closed path) are
    chords that say nothing of the distance travelled: 1.8 m against 0.33 m was refused. Now left alone."""
    robot = catalog.load("skid-steer-4")
    run = wheel_speed_run(robot, [(2.0, [10] * 4), (5.5, [6, 14, 6, 14]), (2.0, [10] * 4)], 20.0)
    at = [0, len(run.log) - 1]
    assert 0.6 < calibrate_slip(robot, run.log, (run.log.time[at], run.truth[at])).ratio < 0.95


@pytest.mark.parametrize(("reference", "weight", "message"), [
    (lambda t, p: (t, p[:-5]), 1.0, r"expected times \(M,\) and poses \(M, 3\)"),
    (lambda t, p: (t, np.where(np.arange(len(t))[:, None] == 50, np.nan, p)), 1.0, "pose 51: .* finite"),
    (lambda t, p: (t[::-1], p[::-1]), 1.0, "pose 2: time .* does not increase"),
    (lambda t, p: (t, p), math.nan, "heading_weight"),
    (lambda t, p: (t, p), -1.0, "heading_weight"),
])
def test_calibrate_slip_checks_its_arguments(husky_run, reference, weight, message):
    """calibrate_slip from Python: a reference of another length raised IndexError, NaN poses or a NaN heading
    weight scipy's ValueError; unsorted times were taken. Now each is a WmrkitError naming what is wrong."""
    log = husky_run.log
    with pytest.raises(WmrkitError, match=message):
        calibrate_slip(catalog.load("skid-steer-4"), log, reference(log.time, husky_run.truth), heading_weight=weight)


def test_a_run_that_turns_more_than_half_a_turn_on_the_spot():
    """Turning on the spot for 2.5 rad: the heading error was wrapped, so the fit had a minimum every turn and the
    effective track stopped in a wrong one (multiplier 0.96, final heading 94 deg off, a position error of 1e-13 m
    on a run without translation). Headings are compared unwrapped: m = 1 + k, both exact."""
    robot = catalog.load("skid-steer-4")
    run = wheel_speed_run(robot, [(5.0, [-5, 5, -5, 5])], 50.0)
    cal = calibrate_slip(robot, run.log, (run.log.time, run.truth))
    assert cal.ratio == pytest.approx(3.0, rel=1e-6) and cal.multiplier == pytest.approx(4.0, rel=1e-6)
    assert all(h < 1e-9 for name, _, h in cal.final if name != "no_slip")
    # the error is unwrapped along the samples, not the reference: wrapped headings sampled more than half a turn
    # apart (a run's start and end poses) still fit
    run = wheel_speed_run(robot, [(5.5, [6, 14, 6, 14])], 20.0)
    at = [0, len(run.log) - 1]
    ref = run.truth[at].copy()
    ref[:, 2] = wrap_angle(ref[:, 2])
    cal = calibrate_slip(robot, run.log, (run.log.time[at], ref))
    assert 0.6 < cal.ratio < 0.95 and cal.multiplier == pytest.approx(1 + cal.ratio, rel=1e-3)


def test_a_reference_on_another_clock_names_both_spans(husky_run):
    """A reference stamped in epoch seconds against a log from 0: the refusal gives both time spans."""
    log = husky_run.log
    with pytest.raises(WmrkitError, match=r"time span \(0 to 10 s; the reference spans 1.7e\+09 to 1.70000001e\+09 s\)"
                                          r": another clock"):
        calibrate_slip(catalog.load("skid-steer-4"), log, (log.time + 1.7e9, husky_run.truth))
    with pytest.raises(WmrkitError, match=r"time span \(0 to 10 s\)"):
        calibrate_slip(catalog.load("skid-steer-4"), log, (np.zeros(0), np.zeros((0, 3))))


@pytest.mark.parametrize(("call", "message"), [
    (lambda r: wheel_speed_run(r, SEGMENTS, math.nan), "rate nan Hz"),
    (lambda r: wheel_speed_run(r, SEGMENTS, -5.0), "rate -5 Hz"),
    (lambda r: wheel_speed_run(r, SEGMENTS, 1e9), "at most 10000000 sample periods"),
    (lambda r: wheel_speed_run(r, [(math.inf, [1, 1, 1, 1])], 20.0), "finite durations"),
    (lambda r: skid_comparison(r, source="qs"), "source must be 'md' or 'quasi-static'"),
    (lambda r: skid_comparison(r, rate=0.0), "rate must be a finite number > 0"),
])
def test_simulated_runs_check_their_arguments(call, message):
    """A NaN rate raised numpy's ValueError, a negative one IndexError, 1e9 Hz MemoryError (97 GiB), an unknown
    source ran the dynamic model, rate 0 divided by zero: each is now a WmrkitError."""
    with pytest.raises(WmrkitError, match=message):
        call(catalog.load("skid-steer-4"))



def test_a_log_of_one_sample_is_refused_as_such(husky_run):
    """A one-row log was refused as 'fewer than two poses within the log's time span (0 to 0 s): another clock?'."""
    from wmrkit.odometry.logs import JointLog

    log = husky_run.log
    one = JointLog(log.time[:1], log.joints, log.positions[:1], source="one.csv")
    with pytest.raises(WmrkitError, match=r"^one\.csv: 1 sample\(s\): a log to calibrate on needs a run"):
        calibrate_slip(catalog.load("skid-steer-4"), one, (log.time, husky_run.truth))


def test_cli_calibrate_reads_the_log_header_units(tmp_path, capsys, husky_run):
    """A log whose header says milliseconds ('time [ms]', 'WHEEL.spin [rad]'), read as 'wmrkit odometry' reads it,
    gives the fit of the same log in seconds (it was refused: missing column 'time')."""
    log = husky_run.log
    plain, units, ref = tmp_path / "log.csv", tmp_path / "log_ms.csv", tmp_path / "ref.tum"
    write_csv(plain, ("time", *log.joints), np.column_stack([log.time, log.positions]))
    write_csv(units, ("time [ms]", *(f"{j} [rad]" for j in log.joints)),
              np.column_stack([log.time * 1000, log.positions]))
    write_trajectory(ref, Trajectory(log.time, husky_run.truth, np.zeros(len(log))), "tum")
    fits = []
    for path in (plain, units):
        assert main(["calibrate", "skid-steer-4", str(path), "--reference", str(ref), "--json"]) == 0
        fits.append(json.loads(capsys.readouterr().out))
    for key in ("ratio", "wheel_separation_multiplier"):  # times / 1000 differ in the last bits: the fit's tolerance
        assert fits[1][key] == pytest.approx(fits[0][key], rel=1e-7)


@pytest.mark.parametrize(("rms", "best", "block", "track_line"), [
    ((0.155, 0.147, 0.050), "effective_track", True, True),  # the forklift's rectangle (2 m/s, simulated)
    ((0.049, 0.041, 0.042), "wls", True, False),
    ((0.030, 0.031, 0.035), "no_slip", False, False),
])
def test_the_summary_recommends_what_fits_the_run(rms, best, block, track_line):
    """`wmrkit calibrate` offered WLS's description block whatever the errors: on the forklift's rectangle WLS was
    three times the effective track's rms error; a WLS no better than no slip is no recommendation at all."""
    from wmrkit.slip.calibration import SlipCalibration

    names = ("no_slip", "wls", "effective_track")
    cal = SlipCalibration("r", 0.35, 1.0065, tuple(zip(names, rms, strict=True)),
                          tuple((n, 0.0, 0.0) for n in names))
    text = cal.format()
    assert cal.best == best and cal.to_dict()["best"] == best
    assert ("to use WLS by default" in text) == block and ("  method: wls" in text) == block
    assert ("the effective track fits this run best" in text) == track_line
    assert ("no slip weights to add" in text) == (not block)


def test_the_multiplier_has_one_json_name(capsys):
    """slip-study skid-steer-4 --json called it 'multiplier' where calibrate --json says
    'wheel_separation_multiplier' (the ROS parameter)."""
    import json

    from wmrkit.cli.main import main

    assert main(["slip-study", "skid-steer-4", "--source", "quasi-static", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert "multiplier" not in data and data["wheel_separation_multiplier"] > 1
