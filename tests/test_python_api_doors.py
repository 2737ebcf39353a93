"""The Python doors of `wmrkit.parking`, `wmrkit.analysis` and `wmrkit.odometry` read no units
(docs/conventions.md): text, booleans and arrays where one number goes are refused naming the argument, and so are a
name where a Vehicle or Space goes and NaN where it would be returned. Before, each raised a bare TypeError,
AttributeError or IndexError from deep inside, or read '1' as 1 (rad, m)."""

from __future__ import annotations

import math
import re

import numpy as np
import pytest

from wmrkit import catalog
from wmrkit.analysis import (
    analyze,
    best_configurations,
    condition_map,
    condition_number,
    is_singular,
    isotropy_matrix,
    optimize_geometry,
    singularity_distance,
    twist_condition_number,
)
from wmrkit.errors import WmrkitError
from wmrkit.odometry import (
    AbsoluteEncoder,
    CalibrationRun,
    IncrementalEncoder,
    JointLog,
    LogFormat,
    Slip,
    TwistProfile,
    apply_parameters,
    calibrate,
    catalog_encoders,
    integrate_increments,
    odometry,
    odometry_model,
    propagate_covariance,
    simulate,
    square_path_error,
)
from wmrkit.parking import Space, Vehicle, blackburn_min_length, length_ratio, plan_parking, shortest_slot

CAR = Vehicle(a1=3.5, b1=0.9, c1=1.7, h1=2.6, track=1.4, phi_max=0.6)
SLOT = Space(H=6.0, J=2.2, MS=0.2, dx2=0.5, final_gap=0.2)
TEXT = "got the text '1', but the Python API reads no units"
BOOLEANS = r"expected real numbers in SI units \(m, rad, m/s, rad/s\), got booleans$"


@pytest.mark.parametrize(("call", "name"), [
    (lambda v: plan_parking(CAR, SLOT, phi_step=v), "phi_step"),
    (lambda v: shortest_slot(CAR, SLOT, step=v), "step"),
    (lambda v: shortest_slot(CAR, SLOT, span=v), "span"),
    (lambda v: blackburn_min_length(CAR, v), "rho"),
])
def test_parking_numbers_refuse_text_and_booleans(call, name):
    """'1' raised "'<=' not supported between instances of 'float' and 'str'"; True was read as 1 rad (a plan) or
    1 m (a slot length)."""
    with pytest.raises(WmrkitError, match=f"^{name}: {re.escape(TEXT)}"):
        call("1")
    with pytest.raises(WmrkitError, match=f"^{name}: {BOOLEANS}"):
        call(True)


@pytest.mark.parametrize(("call", "message"), [
    (lambda: plan_parking("example1", SLOT), "vehicle: expected a wmrkit.parking.Vehicle(a1, b1, c1, h1, track, "
                                             "phi_max), got str 'example1'"),
    (lambda: plan_parking(CAR, {"H": 6.0}), "space: expected a wmrkit.parking.Space(H, J, MS, dx2, final_gap), got "
                                            "dict {'H': 6.0}"),
    (lambda: shortest_slot(CAR, None), "space: expected a wmrkit.parking.Space"),
    (lambda: length_ratio(CAR, 6.0), "space: expected a wmrkit.parking.Space"),
    (lambda: blackburn_min_length(None), "vehicle: expected a wmrkit.parking.Vehicle"),
])
def test_parking_names_a_vehicle_or_space_that_is_none(call, message):
    """Each raised AttributeError: "'str' object has no attribute 'phi_max'"."""
    with pytest.raises(WmrkitError, match=f"^{re.escape(message)}"):
        call()


def test_parking_takes_numpy_numbers():
    assert blackburn_min_length(CAR, np.float32(4.0)) == blackburn_min_length(CAR, 4.0)
    assert plan_parking(CAR, SLOT, phi_step=np.float64(0.02)).arcs == plan_parking(CAR, SLOT, phi_step=0.02).arcs


SWERVE = catalog.load("swerve-4")
ACKERMANN = catalog.load("ackermann")
TWIST = ("vx", "vy", "omega")


@pytest.mark.parametrize(("call", "name"), [
    (lambda v: analyze(ACKERMANN, length=v), "length"),
    (lambda v: condition_map(SWERVE, length=v), "length"),
    (lambda v: twist_condition_number(SWERVE, length=v), "length"),
    (lambda v: singularity_distance(SWERVE, None, TWIST, length=v), "length"),
    (lambda v: isotropy_matrix(SWERVE, None, TWIST, ("front_left.spin",), length=v), "length"),
    (lambda v: best_configurations(SWERVE, length=v, resolution=8), "length"),
    (lambda v: is_singular(SWERVE, None, TWIST, rtol=v), "rtol"),
    (lambda v: optimize_geometry(lambda x: SWERVE, v), "x0"),
])
def test_analysis_numbers_refuse_text_and_booleans(call, name):
    """'1' raised "'<' not supported between instances of 'int' and 'str'" (or was read as 1 m by
    best_configurations, 1 by optimize_geometry); True was 1 m."""
    with pytest.raises(WmrkitError, match=f"^{name}: {re.escape(TEXT)}"):
        call("1")
    with pytest.raises(WmrkitError, match=f"^{name}: {BOOLEANS}"):
        call(True)


@pytest.mark.parametrize(("call", "message"), [
    (lambda: best_configurations(SWERVE, length=math.nan, resolution=8), "length: must be a finite number > 0 m, "
                                                                          "got nan"),
    (lambda: best_configurations(SWERVE, length=-1.0, resolution=8), "length: must be a finite number > 0 m, got -1"),
    (lambda: is_singular(SWERVE, None, TWIST, rtol=math.nan), "rtol: expected a finite relative tolerance >= 0, got "
                                                             "nan"),
    (lambda: is_singular(SWERVE, None, TWIST, rtol=-1.0), "rtol: expected a finite relative tolerance >= 0"),
    (lambda: is_singular(SWERVE, None, TWIST, rtol=[1e-8]), "rtol: expected one real number, got an array"),
    (lambda: condition_number("1 m"), "condition_number: h: got the text '1 m'"),
    (lambda: optimize_geometry(lambda x: SWERVE, None), "x0: expected a vector of finite numbers"),
    (lambda: optimize_geometry(lambda x: SWERVE, [math.nan]), "x0: expected a vector of finite numbers"),
    (lambda: optimize_geometry(lambda x: SWERVE, [1.0], bounds=1.0), "bounds: expected one finite (low, high) per "
                                                                      "parameter, shape (1, 2), got 1.0"),
    (lambda: optimize_geometry(lambda x: SWERVE, [1.0], starts=1e9), "starts must be an integer >= 1, got 1000000000"),
    (lambda: optimize_geometry(lambda x: SWERVE, [1.0], seed="1"), "seed must be an integer >= 0, got '1'"),
    (lambda: optimize_geometry(lambda x: SWERVE, [1.0], samples=10**9), "samples must be at most 100000"),
])
def test_analysis_values_that_were_taken_or_raised_bare_errors_are_named(call, message):
    """best_configurations returned configurations of length nan or -1 m; is_singular(rtol=nan) answered False,
    -1 False, [1e-8] an array; optimize_geometry returned x = [nan] from x0 = None or NaN and raised bare
    TypeErrors for bounds, starts and seed ('SeedSequence expects int ...')."""
    with pytest.raises(WmrkitError, match=f"^{re.escape(message)}"):
        call()


def test_analysis_takes_numpy_numbers():
    np.testing.assert_array_equal(twist_condition_number(SWERVE, length=np.float32(0.5)),
                                  twist_condition_number(SWERVE, length=float(np.float32(0.5))))
    assert is_singular(SWERVE, None, TWIST, rtol=np.float64(1e-8)) == is_singular(SWERVE, None, TWIST)


DIFF = catalog.load("diff-drive")
PROFILE = TwistProfile([1.0], [[0.5, 0.0, 0.1]])
RUN = simulate(DIFF, TwistProfile(np.array([1.0]), np.array([[0.5, 0.0, 0.1]])), 10.0)


@pytest.mark.parametrize(("call", "message"), [
    (lambda: integrate_increments([0.0, 0.0, 0.0], [["1 m", 0.0, 0.0]]), "increments_robot: got the text '1 m'"),
    (lambda: integrate_increments([0.0, 0.0, 0.0], [[0.1, 0.0, 0.0]], heading_world=["1", "2"]),
     "heading_world: got the text '1'"),
    (lambda: integrate_increments([0.0, 0.0, 0.0], [[0.1, 0.0, 0.0]], ["exact"]), "unknown integration method "
                                                                                  "'['exact']'"),
    (lambda: propagate_covariance([[0.0] * 3] * 2, 0.1, [[[0.0] * 3] * 3]), "propagate_covariance: expected shapes "
                                                                             "(N + 1, 3), (N, 3), (N, 3, 3); got"),
    (lambda: propagate_covariance([["1 m"] * 3] * 2, [[0.1] * 3], [[[0.0] * 3] * 3]), "poses_world_robot: got the "
                                                                                       "text '1 m'"),
    (lambda: square_path_error([["1 m", 0.0]], [[0.1, 0.1]]), "errors_cw: got the text '1 m'"),
    (lambda: TwistProfile(["1 s"], [[0.5, 0.0, 0.0]]), "profile: durations: got the text '1 s'"),
    (lambda: TwistProfile(["1"], [[0.5, 0.0, 0.0]]), "profile: durations: got the text '1'"),
    (lambda: Slip("left.spin", "1", 2.0, 0.5), "slip: start: got the text '1'"),
    (lambda: Slip("left.spin", 0.0, 2.0, True), "slip: ratio: expected real numbers in SI units"),
    (lambda: Slip(1, 0.0, 2.0, 0.5), "slip: joint: expected a joint's name such as 'left.spin', got 1"),
    (lambda: simulate(DIFF, PROFILE, 10.0, pose0=["1 m", 0.0, 0.0]), "pose0: got the text '1 m'"),
    (lambda: simulate(DIFF, PROFILE, 10.0, sensed="left.spin"), "sensed: expected a sequence of joint names, got the "
                                                               "string 'left.spin'"),
    (lambda: simulate(DIFF, PROFILE, 10.0, slips=[0.5]), "slips: expected a sequence of Slip(joint, start, stop, "
                                                        "ratio), got [0.5]"),
    (lambda: simulate(DIFF, PROFILE, 10.0, encoders=["left.spin"]), "encoders: expected a mapping {joint: encoder}, "
                                                                   "got list"),
    (lambda: simulate(DIFF, [(1.0, 0.5, 0.0, 0.0)], 10.0), "profile: expected a TwistProfile"),
    (lambda: odometry_model("diff-drive"), "robot: expected a Robot (wmrkit.catalog.load(name), Robot.from_file("
                                           "path)), got str 'diff-drive'"),
    (lambda: odometry_model(DIFF, weights=["left"]), "weights: expected a mapping {wheel name: weight}, got list"),
    (lambda: odometry(DIFF, "run.csv"), "log: expected a JointLog (read_csv(path, joints, robot=robot), "
                                        "JointLog.from_headings), got str 'run.csv'"),
    (lambda: JointLog(1.0, ("left.spin",), [[0.0]]), "<log>: expected time (N,) and positions (N, 1), got () and "
                                                     "(1, 1)"),
    (lambda: apply_parameters(DIFF, ["left.r"], 0.01), "p: expected 1 finite values, one per parameter group, got "
                                                       "0.01"),
    (lambda: apply_parameters(DIFF, [0.01], [0.01]), "calibrate: parameters: expected a sequence of parameter names"),
    (lambda: calibrate(DIFF, "run.csv", ["left.r"]), "calibrate: runs: expected a sequence of CalibrationRun, got "
                                                     "str"),
    (lambda: CalibrationRun(RUN.log, RUN.truth[-1], pose0="1 m"), "CalibrationRun.pose0: got the text '1 m'"),
    (lambda: CalibrationRun(RUN.log, RUN.truth[-1], pose0=[0.0, math.nan, 0.0]), "CalibrationRun.pose0: expected a "
                                                                                  "finite pose (x, y, theta)"),
    (lambda: CalibrationRun(RUN.log, [["1 m", 0.0, 0.0]]), "CalibrationRun.reference: got the text '1 m'"),
    (lambda: calibrate(DIFF, [CalibrationRun(RUN.log, RUN.truth[-1])], ["left.r"], run_weights=1.0),
     "calibrate: run_weights: expected a function of a CalibrationRun, got float"),
    (lambda: IncrementalEncoder(1024, sign=True), "sign must be +1 or -1, got True"),
    (lambda: AbsoluteEncoder(0.01, sign=np.array([])), "sign must be +1 or -1, got array"),
    (lambda: LogFormat(columns=3), "LogFormat.columns: expected (joint, column) pairs"),
    (lambda: catalog_encoders(["forklift"]), "no encoder data for robot '['forklift']'"),
])
def test_odometry_doors_name_what_is_wrong(call, message):
    """Each raised a bare error (numpy's 'could not convert string to float', IndexError, 'unhashable type: list',
    "'str' object has no attribute 'sensed'", "len() of unsized object", "'float' object is not callable" deep in
    the solver), or took the value: TwistProfile's '1' as 1 s, a CalibrationRun's pose0 of text or NaN, an encoder's
    sign True."""
    with pytest.raises(WmrkitError, match=f"^{re.escape(message)}"):
        call()


def test_a_twist_profile_given_as_lists_drives_its_arc():
    """TwistProfile kept the lists it was given: simulate raised "'list' object has no attribute 'sum'"."""
    assert PROFILE.duration == 1.0
    v, omega = 0.5, 0.1  # one second on the arc of radius v / omega
    arc_end = [v / omega * math.sin(omega), v / omega * (1 - math.cos(omega)), omega]
    np.testing.assert_allclose(simulate(DIFF, PROFILE, 10.0).truth[-1], arc_end, atol=1e-12)
