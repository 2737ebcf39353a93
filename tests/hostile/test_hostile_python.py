"""Hostile input at the Python doors (the functions ``wmrkit`` and its subpackages export), found by an audit that
called them with NaN, infinities, empty or mismatched arrays and out-of-range numbers. Each case returned NaN or a
number without meaning, or raised a bare numpy/Python exception; each now raises one :class:`WmrkitError` naming
the argument."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

import wmrkit
import wmrkit.analysis
import wmrkit.slip
from wmrkit import catalog, direct_model, forward_kinematics, inverse_model, mobility, wheel_commands
from wmrkit.analysis import icr, is_singular, singularity_distance
from wmrkit.dynamics.model import DynamicModel
from wmrkit.dynamics.simulate import Inputs, Stepper, advance, simulate
from wmrkit.dynamics.tyres import Tyre
from wmrkit.errors import ShapeError, WmrkitError


@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf, 1e300])
@pytest.mark.parametrize("keyword", ["heading", "beta"])
def test_a_steering_configuration_that_is_not_finite_is_refused_by_name(bad, keyword):
    # heading=[nan] * 4 reached the SVD of inverse_model, direct_model, mobility and icr (LinAlgError 'SVD did not
    # converge'), and gave NaN constraint matrices and wheel commands; beta = 1e300 rad gave round-off sines
    robot = catalog.load("swerve-4")
    config = {keyword: [0.0, 0.0, bad, 0.0]}
    for call in (lambda: inverse_model(robot, **config), lambda: direct_model(robot, **config),
                 lambda: mobility(robot, **config), lambda: icr(robot, **config),
                 lambda: robot.constraint_matrix(**config), lambda: wheel_commands(robot, [1.0, 0.0, 0.0], **config),
                 lambda: forward_kinematics(robot, {"front_left": 1.0, "front_right": 1.0}, **config)):
        with pytest.raises(ShapeError, match=f"^{keyword}: angles must be finite"):
            call()
    joints = ("front_left.spin", "front_right.spin", "rear_left.spin")
    with pytest.raises(ShapeError, match=r"^beta: angles must be finite"):
        singularity_distance(robot, [0.0, 0.0, bad, 0.0], joints)
    with pytest.raises(ShapeError, match=r"^beta: angles must be finite"):
        is_singular(robot, [0.0, 0.0, bad, 0.0], joints)


@pytest.mark.parametrize("bad", [np.nan, np.inf, 1e300])
def test_a_robot_is_never_steered_to_an_angle_that_is_not_finite(bad):
    robot = catalog.load("swerve-4")
    with pytest.raises(ShapeError, match=r"^front_left: heading: angles must be finite"):
        robot.with_steering({"front_left": bad})
    with pytest.raises(ShapeError, match=r"^front_left: beta: angles must be finite"):
        robot.with_beta_angles({"front_left": bad})
    with pytest.raises(ShapeError, match=r"^beta: angles must be finite"):
        robot.with_beta([bad, 0.0, 0.0, 0.0])


@pytest.mark.parametrize("twist", [[np.nan, 0.0, 0.0], [np.inf, 0.0, 0.0], [1e300, 0.0, 0.0], [0.0, 0.0, -1e7]])
@pytest.mark.parametrize("name", ["diff-drive", "swerve-4", "ackermann"])
def test_wheel_commands_refuse_a_twist_that_is_not_finite_or_beyond_the_query_bound(twist, name):
    # a NaN or infinite twist gave NaN spins (numpy warned 'invalid value'), 1e300 m/s spins of inf: wmrkit ik
    # and the studio refuse beyond 1e6 (limits.MAX_QUERY_RATE), the Python door did not
    with pytest.raises(ShapeError, match=r"^twist_robot: expected finite speeds and turn rates within 1e\+06"):
        wheel_commands(catalog.load(name), twist)
    with pytest.raises(ShapeError, match=r"^twist_robot"):
        wheel_commands(catalog.load(name), [[0.1, 0.0, 0.0], twist])


@pytest.mark.parametrize("bad", [np.nan, np.inf, 1e300])
def test_forward_kinematics_refuses_a_rate_that_is_not_finite_by_name(bad):
    # NaN gave the twist (nan, nan, nan); left = 1e300, right = -1e300 (a turn in place) gave vx = 1.5e282 m/s and an
    # infinite residual
    robot = catalog.load("diff-drive")
    with pytest.raises(ShapeError, match=r"^rates: right: expected finite numbers within 1e\+06"):
        forward_kinematics(robot, {"left": -1.0, "right": bad})
    with pytest.raises(ShapeError, match=r"^rates: right: expected finite numbers"):
        forward_kinematics(robot, {"left": [1.0, 2.0], "right": [1.0, bad]})


def test_forward_kinematics_of_rates_that_do_not_broadcast_or_are_empty():
    # shapes (2,) and (3,) raised numpy's 'shape mismatch' ValueError; empty arrays a LAPACK error (dgelsy: lwork)
    robot = catalog.load("diff-drive")
    with pytest.raises(ShapeError, match=r"^rates: the rates' shapes do not broadcast together: left \(2,\), right "):
        forward_kinematics(robot, {"left": [1.0, 2.0], "right": [1.0, 2.0, 3.0]})
    twist, residual = forward_kinematics(robot, {"left": [], "right": []})
    assert twist.shape == (0, 3) and residual.shape == (0,)


@pytest.mark.parametrize(("call", "message"), [
    (lambda o: o.square_path(1.0, speed=0.0), "square_path: speed must be a finite number > 0, got 0"),
    (lambda o: o.square_path(np.nan), "square_path: side must be a finite number > 0, got nan"),
    (lambda o: o.TwistProfile.from_segments([(np.nan, 1.0, 0.0, 0.0)]), "every segment needs a finite duration"),
    (lambda o: o.TwistProfile.from_segments([(1.0, np.nan, 0.0, 0.0)]), "profile: segment 0: twist [nan, 0.0, 0.0]"),
    (lambda o: o.TwistProfile(np.ones(2), np.zeros((1, 3))), "profile: expected durations (S,) and twists (S, 3)"),
])
def test_synthetic_profiles_refuse_what_has_no_duration_or_speed(call, message):
    # square_path(1, speed=0) raised ZeroDivisionError; square_path(nan) and NaN segments made profiles of NaN
    from wmrkit import odometry

    with pytest.raises(WmrkitError) as err:
        call(odometry)
    assert str(err.value).startswith(message)


@pytest.mark.parametrize(("options", "message"), [
    ({"pose0": (np.nan, 0.0, 0.0)}, "pose0: expected (x, y, theta), finite"),  # NaN poses, exit 'OK'
    ({"seed": -1}, "seed must be an integer >= 0, got -1"),  # numpy's ValueError
    ({"sensed": ["nope.spin"]}, "sensed: robot 'diff-drive' has no joint 'nope.spin'"),  # tuple.index ValueError
    ({"spin_noise_per_rad": -1e-4}, "spin_noise_per_rad: a noise must be a finite number >= 0"),  # noiseless run
    ({"steer_noise": np.nan}, "steer_noise: a noise must be a finite number >= 0"),
    ({"oversample": 0}, "oversample: expected an integer >= 1"),
    ({"slips": [("right.spn", 0.0, 1.0, 0.1)]}, "slips[0]: 'right.spn' is not a sensed spin joint"),  # ignored
    ({"slips": [("right.spin", 3.0, 1.0, 0.1)]}, "slips[0]: expected finite times start < stop"),  # ignored
    ({"slips": [("right.spin", 0.0, 1.0, np.nan)]}, "slips[0]: expected finite times start < stop and a finite"),
])
def test_a_synthetic_run_refuses_its_arguments_by_name(options, message):
    from wmrkit import odometry

    if "slips" in options:
        options = {"slips": [odometry.Slip(*s) for s in options["slips"]]}
    with pytest.raises(WmrkitError) as err:
        odometry.simulate(catalog.load("diff-drive"), odometry.square_path(1.0), 20.0, **options)
    assert str(err.value).startswith(message)


def test_a_synthetic_profile_without_segments_is_refused_by_name():
    # TwistProfile.from_segments([]) was accepted and simulate() then raised numpy's 'zero-size array to reduction
    # operation maximum' ValueError (found by the smoke matrix: a skid steer's twists projected to nothing)
    from wmrkit import odometry

    with pytest.raises(WmrkitError, match=r"^profile: expected at least one segment"):
        odometry.TwistProfile.from_segments([])


@pytest.mark.parametrize(("profile", "wheel"), [
    (lambda o: o.square_path(2.0, speed=0.5, turn_rate=0.5), "front_left"),  # turns in place: -74 deg
    (lambda o: o.TwistProfile.from_segments([(2.0, 0.5, 0.0, 0.3)]), "front_left"),  # 2.7 m wheelbase, r 1.7 m
])
def test_a_synthetic_run_refuses_a_profile_beyond_a_wheels_steer_range(profile, wheel):
    # simulate() steered the catalog car's front wheels to -74 deg (steer_range +-40 deg) without a word: the log it
    # wrote was refused by 'wmrkit odometry' ('outside the wheel's steer_range'), and 'wmrkit batch montecarlo
    # ackermann --path square' integrated the impossible path and printed its covariance (exit 0; smoke matrix)
    from wmrkit import odometry

    with pytest.raises(WmrkitError, match=rf"^profile: at t = [0-9.]+ s wheel '{wheel}' would steer to heading "
                                          r"-?[0-9.]+ deg, outside its steer_range \[-40, 40\] deg"):
        odometry.simulate(catalog.load("ackermann"), profile(odometry), 20.0)
    odometry.simulate(catalog.load("ackermann"), odometry.TwistProfile.from_segments([(2.0, 1.5, 0.0, 0.3)]), 20.0)


@pytest.mark.parametrize("name", ["swerve-4", "forklift"])
@pytest.mark.parametrize("noise", [False, True], ids=["fused", "model"])
def test_a_steering_angle_beyond_a_million_turns_in_a_log_is_named_at_its_sample(name, noise):
    # 1e300 rad in a steering column was integrated with round-off sines (a pose, exit 0); with the steering
    # configurations checked (as_angles) it became an unlocated 'beta: ...' error: now the sample and joint
    from wmrkit.odometry import CrowleyNoise, JointLog, LogError, odometry, odometry_model

    robot = catalog.load(name)
    joints = odometry_model(robot).joints
    positions = np.zeros((9, len(joints)))
    steer = next(c for c, j in enumerate(joints) if j.endswith(".steer"))
    positions[6, steer] = 1e300
    with pytest.raises(LogError, match=rf"^<log>: sample 6: {joints[steer]}: steering angle 1e\+300 rad is more "):
        odometry(robot, JointLog(np.arange(9) * 0.1, joints, positions), chunk_size=4,
                 noise=CrowleyNoise() if noise else None)


@pytest.mark.parametrize("chunk_size", [0, -5, 2.5, 1 << 23])
def test_odometry_refuses_a_chunk_size_outside_the_limits_by_name(chunk_size):
    # 0 raised range()'s ValueError, 2.5 a TypeError, -5 ran no chunk ('the log has no samples'); read_csv and the
    # CLI's --chunk-size were already bounded (limits.check_chunk_size)
    from wmrkit.odometry import JointLog, LogError, odometry

    log = JointLog(np.arange(4) * 0.1, ("left.spin", "right.spin"), np.zeros((4, 2)))
    with pytest.raises(LogError, match=r"^chunk_size must be in \[1, 4194304\] samples"):
        odometry(catalog.load("diff-drive"), log, chunk_size=chunk_size)


@pytest.mark.parametrize("length", [0.0, -1.0, np.nan, np.inf])
def test_a_characteristic_length_that_is_not_a_positive_number_is_refused_by_name(length):
    # singularity_distance(length=0) silently used the default length ('length or robot_size'), length=-1 gave
    # another number; twist_condition_number(length=nan) and analyze(length=nan) raised LinAlgError
    from wmrkit.analysis import condition_map, isotropy_matrix

    robot = catalog.load("swerve-4")
    with pytest.raises(WmrkitError, match=r"^length: must be a finite number > 0 m"):
        singularity_distance(robot, None, ("front_left.spin", "front_right.spin", "rear_left.spin"), length=length)
    with pytest.raises(WmrkitError, match=r"^length: must be a finite number > 0 m"):
        condition_map(catalog.load("diff-drive"), np.zeros((2, 1)), length=length)
    with pytest.raises(WmrkitError, match=r"^length: must be a finite number > 0 m"):
        isotropy_matrix(catalog.load("diff-drive"), None, ("left.spin", "right.spin"), ("vx", "omega"), length=length)


@pytest.mark.parametrize("length", [0.0, np.nan, 1e-9, 1e9])
def test_analyze_bounds_its_length_as_analyze_length_does(length):
    # analyze(length=nan) raised LinAlgError, analyze(length=1e-9) called the twist undetermined: the CLI's
    # --length was bounded (limits.check_length), the Python door was not
    from wmrkit.analysis import analyze

    with pytest.raises(WmrkitError, match=r"^length: .* m is outside the lengths wmrkit handles \(1e-06 to 1000 m\)"):
        analyze(catalog.load("diff-drive"), length=length)


@pytest.mark.parametrize(("options", "message"), [
    # lookahead 0 ran 82 s to end in 'the closed loop is too stiff ... start closer to the reference'; -1 aimed
    # behind the robot and 'tracked' the circle 3.5 m off, exit OK
    ({"controller": "pure-pursuit", "lookahead": 0.0}, "lookahead: expected a distance in (0, 1e+09] m along the path"),
    ({"controller": "pure-pursuit", "lookahead": -1.0}, "lookahead: expected a distance in (0, 1e+09] m"),
    # NaN reached the wheel IK, whose message named twist_robot, not the gain
    ({"controller": "stanley", "stanley_gain": np.nan}, "stanley gain: expected a cross-track gain >= 0"),
    ({"initial_pose": [np.nan, 0.0, 0.0]}, "initial_pose: expected one pose (x, y, theta), finite"),  # scipy's y0
    ({"point": [np.nan, 0.0]}, "point: expected finite coordinates"),  # '(nan, 0) m ... lies on its fixed axle'
])
def test_track_refuses_its_controller_options_by_name(options, message):
    from wmrkit.control import builtin_reference, track

    with pytest.raises(WmrkitError) as err:
        track(catalog.load("diff-drive"), builtin_reference("circle"), **options)
    assert str(err.value).startswith(message)


@pytest.mark.parametrize(("options", "message"), [
    ({"point": (np.nan, 0.0)}, "point: expected (x, y), finite"),  # read as a point on the axle: feasible
    ({"jump_factor": 0.0}, "jump_factor: expected a finite number > 1"),  # every step a jump: not feasible
    ({"jump_factor": np.nan}, "jump_factor: expected a finite number > 1"),
])
def test_feasibility_refuses_a_point_or_jump_factor_that_is_not_a_number_it_can_use(options, message):
    from wmrkit.control import builtin_reference, feasibility

    with pytest.raises(WmrkitError) as err:
        feasibility(catalog.load("diff-drive"), builtin_reference("circle"), **options)
    assert str(err.value).startswith(message)


@pytest.mark.parametrize(("call", "message"), [
    # NaN or 1e300 rates gave NaN or infinite velocities and forces as a solution
    (lambda s, r, a: s.wls(r, a, [np.nan, 1.0]), "q_assigned: front_left.spin: expected finite numbers within 1e+06"),
    (lambda s, r, a: s.mcd(r, a, [1.0, 1e300], s.tyre_friction(r)), "q_assigned: front_right.spin: expected finite"),
    (lambda s, r, a: s.wls(r, a, [1.0]), "q_assigned: expected shape (..., 2), one value per assigned velocity"),
    (lambda s, r, a: s.wls(r, [], []), "assigned: expected distinct velocity names, at least one, got []"),
    (lambda s, r, a: s.wls(r, [a[0], a[0]], [1.0, 2.0]), "assigned: expected distinct velocity names"),  # last won
    (lambda s, r, a: s.mqe(r, a, [1.0, 2.0], s.tyre_friction(r), g=-9.81), "g: expected a finite gravity > 0"),
    (lambda s, r, a: s.mcd(r, a, [1.0, 2.0], s.tyre_friction(r), loads=[-1.0] * 4), "loads: expected finite normal"),
    (lambda s, r, a: s.mcd(r, a, [1.0, 2.0], s.tyre_friction(r), tol=np.nan), "tol: expected a finite tolerance > 0"),
])
def test_the_slip_models_refuse_their_inputs_by_name(call, message):
    # q_assigned of the wrong length raised numpy's 'cannot reshape'; g < 0, negative loads and tol = nan gave
    # answers
    from wmrkit import slip

    robot = catalog.load("skid-steer-4")
    with pytest.raises(ShapeError) as err:  # a ValueError, as docs/conventions.md says
        call(slip, robot, ["front_left.spin", "front_right.spin"])
    assert str(err.value).startswith(message)


@pytest.mark.parametrize(("call", "message"), [
    (lambda: wmrkit.analysis.classify(catalog.load("forklift"), samples=0), r"samples must be an integer in \[1, "),
    (lambda: wmrkit.analysis.classify(catalog.load("forklift"), seed=-1), "seed must be an integer >= 0"),
    (lambda: catalog.load("forklift").constraint_matrix(frame="x"), "frame must be 'roller' or 'robot'"),
    (lambda: wmrkit.slip.normal_loads(catalog.load("forklift"), g=math.nan), "g = nan"),  # NaN loads
    (lambda: wmrkit.slip.normal_loads(catalog.load("forklift"), accel_cm=(math.nan, 0.0)), "finite accelerations"),
    (lambda: wmrkit.slip.closure_error(np.zeros((0, 3))), r"at least 2 poses \(N, 3\), got shape \(0, 3\)"),
    (lambda: wmrkit.slip.closure_error(np.zeros((4, 2))), r"poses: expected shape \(\.\.\., 3\)"),  # IndexError
    (lambda: _blackburn(math.nan), "rho = nan m: a finite radius >= c1/2"),  # NaN length before
    (lambda: _line_position(focal_px=0.0), "focal_px: expected a finite number > 0, got 0.0"),  # ZeroDivisionError
    (lambda: _line_position(tilt=math.nan), "tilt, z_p, spacing: expected finite numbers"),  # NaN pose before
])
def test_more_python_doors_refuse_by_name(call, message):
    """From the audit of the Python doors: numpy's ValueError for classify(samples=0) or seed=-1, a plain
    ValueError (not a WmrkitError) for an unknown frame, NaN loads for a NaN gravity or acceleration."""
    with pytest.raises(WmrkitError, match=message):
        call()


def _blackburn(rho: float) -> float:
    from wmrkit.parking import Vehicle
    from wmrkit.parking.geometry import blackburn_min_length

    return blackburn_min_length(Vehicle(a1=3.5, b1=0.9, c1=1.8, h1=2.6, track=1.5, phi_max=0.6), rho)


def _line_position(focal_px: float = 500.0, tilt: float = 0.3):
    from wmrkit.vision.positioning import line_position

    return line_position([[10.0, 40.0], [-5.0, 80.0]], 0, focal_px=focal_px, tilt=tilt, height=0.5)


@pytest.mark.parametrize("h", [np.zeros((0, 0)), np.zeros((2, 0)), np.ones(3), np.array([[1.0, np.nan], [0.0, 1.0]])])
def test_condition_number_refuses_what_is_not_a_finite_matrix(h):
    # an empty matrix raised IndexError, a vector LinAlgError, NaN 'SVD did not converge'
    from wmrkit.analysis.isotropy import condition_number

    with pytest.raises(WmrkitError, match=r"^condition_number: expected matrices"):
        condition_number(h)


def _forklift_model():
    return DynamicModel.of(catalog.load("forklift"))  # n = 7: vx, vy, omega, two drives, steer.spin, steer.steer


def _inputs(**fields):
    """Inputs of the forklift (K = 2 times), standstill torques, with `fields` replaced."""
    k, n = len(fields.get("time", (0.0, 1.0))), 7
    values = {"time": np.array([0.0, 1.0]), "torques": np.zeros((k, n)), "rate_reference": np.zeros((k, n)),
              "rate_gain": np.zeros(n), "torque_limit": np.full(n, np.inf), "heading_reference": np.zeros((k, 1)),
              "steer_kp": np.zeros(1), "steer_kd": np.zeros(1)}
    return Inputs(**{**values, **{key: np.asarray(v, dtype=float) for key, v in fields.items()}})


def _simulate(inputs=None, duration=1.0, **options):
    return simulate(_forklift_model(), _inputs() if inputs is None else inputs, duration, **options)


def _body(**fields):
    return replace(catalog.load("forklift").body, **fields)


@pytest.mark.parametrize(("call", "message"), [
    # inputs of another robot's width (n = 3, one steering joint) made the kernels read out of bounds: numbers that
    # changed from run to run
    (lambda: _simulate(_inputs(time=[0.0, 1.0], torques=np.zeros((2, 3)), rate_reference=np.zeros((2, 3)),
                               rate_gain=np.zeros(3), torque_limit=np.full(3, np.inf))),
     r"^torques: expected 7 columns for robot 'forklift' \(n = 7 velocities of model.names, n_steer = 1\), got "
     r"shape \(2, 3\)"),
    (lambda: _inputs(time=[1.0, 0.0]), r"^time: input times must be at least one, finite and strictly increasing, "
                                       r"got \[1.0, 0.0\]"),  # ran, holding the inputs of t = 0
    (lambda: _inputs(time=[]), r"^time: input times must be at least one"),  # numpy's reshape error
    (lambda: _inputs(rate_gain=[-1.0] * 7), r"^rate_gain: expected finite numbers >= 0, got -1.0"),  # ran
    (lambda: _inputs(steer_kd=[np.nan]), r"^steer_kd: expected finite numbers >= 0, got nan"),
    (lambda: _inputs(torque_limit=[np.nan] * 7), r"^torque_limit: expected numbers >= 0 \(inf: no limit\), got nan"),
    (lambda: _inputs(torques=np.full((2, 7), np.inf)),
     r"^torques: expected torques within 1e\+10 N m \(limits\.MAX_TORQUE\), got inf"),
    (lambda: _inputs(heading_reference=np.zeros((3, 1))), r"^heading_reference: expected shape \(K, n_steer\) "
                                                          r"with K = 2 rows, one per time, got \(3, 1\)"),
    (lambda: _inputs(steer_kp=np.zeros(2)), r"^steer_kp: expected shape \(1,\)"),
    # numpy's 'operands could not be broadcast together'
    (lambda: Inputs.torques_only(
        _forklift_model(), [0.0, 1.0], {"right_drive.spin": [1.0, 2.0, 3.0]}),
     r"^torques\['right_drive.spin'\]: expected one value or 2, one per time, got shape \(3,\)"),
    # the Python doors did not bound the work as the CLI does: 7 TiB of records, an endless loop, 38 s of LSODA
    (lambda: _simulate(duration=1e6, step=1e-6), r"^duration 1e\+06 s at step 1e-06 s: more than 5e\+07 integration"),
    (lambda: _simulate(duration=1e3, method="adaptive", record_step=1e-9),
     r"^record_step: 1e-09 s over 1000 s is more than 5e\+07 samples"),
    (lambda: _simulate(method="adaptive", rtol=np.nan), r"^rtol: expected a relative tolerance in \(0, 1\), got nan"),
    (lambda: _simulate(record_step=-0.1), r"^record_step: expected a finite number > 0"),  # IndexError
    (lambda: _simulate(record_step=np.nan), r"^record_step: expected a finite number > 0"),  # NaN to integer
    (lambda: Stepper(_forklift_model()).advance(
        _inputs(), 1e9), r"^duration must be >= 0 and at most 5e\+07 steps of 0.001 s, got 1000000000.0"),
    (lambda: advance(
        _forklift_model(), np.zeros(14), _inputs(), np.inf), r"^duration must be >= 0 and at most 5e\+07 steps"),
    # impossible loads: a wheel pulled down, negative or NaN loads, LinAlgError
    (lambda: wmrkit.slip.normal_loads(catalog.load("forklift"), accel_cm=(0.0, 30.0)),
     r"^normal_loads: contact 'left_drive' lifts off the ground: its load would be -5.016e\+04 N < 0 \(body.com "
     r"\[-1.45, 0.0\] m, accel_cm \[0.0, 30.0\] m/s\^2\)"),
    (lambda: wmrkit.slip.normal_loads(catalog.load("forklift"), accel_cm=[(0.0, 0.0), (0.0, -30.0)]),
     r"^normal_loads: contact 'right_drive' lifts off the ground: its load would be .* sample \(1,\)\)"),
    (lambda: wmrkit.slip.normal_loads(catalog.load("forklift"), body=_body(com=(10.0, 0.0))),
     r"^normal_loads: contact 'steer' lifts off the ground: its load would be -1.998e\+05 N"),
    (lambda: wmrkit.slip.normal_loads(catalog.load("forklift"), body=_body(mass=-5.0)),
     r"^body.mass: expected a finite number > 0 kg, got -5.0"),
    (lambda: wmrkit.slip.normal_loads(catalog.load("forklift"), body=_body(mass=np.nan)), r"^body.mass: expected"),
    (lambda: wmrkit.slip.normal_loads(catalog.load("forklift"), body=_body(com=(np.nan, 0.0))),
     r"^body.com: expected two lengths within 1000 m, got \(nan, 0.0\)"),
    (lambda: wmrkit.slip.mqe(catalog.load("forklift"), ["right_drive.spin", "left_drive.spin"], [1.0, 1.0],
                             wmrkit.slip.tyre_friction(catalog.load("forklift")), body=_body(com_height=-1.0)),
     r"^body.com_height: expected a length in \[0, 1000\] m"),
    (lambda: DynamicModel.of(
        replace(catalog.load("forklift"), body=_body(mass=np.nan))),
     r"^robot 'forklift': body.mass: expected a finite number > 0 kg, got nan"),  # a model of NaN loads
    # DynamicModel: zero forces from NaN or negative loads, loads of 0 or NaN, numba typing errors on batches, NaN
    (lambda: _forklift_model().contact_forces(None, np.ones(7), [np.nan] * 3), r"^loads: expected finite numbers"),
    (lambda: _forklift_model().contact_forces(None, np.ones(7), [-1000.0] * 3),
     r"^loads: expected normal loads >= 0 N, got \[-1000.0, -1000.0, -1000.0\]"),
    (lambda: DynamicModel.of(catalog.load("forklift"),
                                                                                gravity=-9.8),
     r"^gravity: expected a finite number > 0 m/s\^2, got -9.8"),
    (lambda: DynamicModel.of(catalog.load("forklift"),
                                                                                gravity=np.nan), r"^gravity: "),
    (lambda: _forklift_model().mass_matrix([[0.1], [0.2]]), r"^beta: expected shape \(1,\), one state at a time"),
    (lambda: _forklift_model().normal_loads(None, np.ones((2, 7))), r"^nu: expected shape \(7,\), one state at a "),
    (lambda: _forklift_model().contact_forces(None, np.ones((2, 7))), r"^nu: expected shape \(7,\), one state"),
    (lambda: _forklift_model().accelerations(None, np.ones((2, 7))), r"^nu: expected shape \(7,\), one state"),
    (lambda: _forklift_model().accelerations(None, np.ones(7), forces=np.ones((2, 3))),  # read as (3, 2)
     r"^forces: expected shape \(3, 2\), one state at a time, got \(2, 3\)"),
    (lambda: _forklift_model().velocity([[1.0, 0.0, 0.0], [2.0, 0.0, 0.0]]), r"^twist: expected shape \(3,\), one "),
    (lambda: _forklift_model().kinetic_energy(None, [np.nan] * 7), r"^nu: expected finite numbers"),
    (lambda: _forklift_model().normal_loads(None, [np.nan] * 7), r"^nu: expected finite numbers"),
    (lambda: _forklift_model().accelerations(None, np.ones(7), [np.nan] * 7), r"^torques: expected finite numbers"),
    # tyre forces from a load < 0 pushed with the slip; NaN and infinite loads gave NaN, finite or infinite forces
    (lambda: Tyre.of("coulomb").forces_at_slip(-1000, 0.1, 0.05),
     r"^fz: expected normal loads in \[0, 1e\+07\] N, got -1000"),
    (lambda: Tyre.of("pacejka").forces_at_slip(np.nan, 0.1, 0.0),
     r"^fz: expected normal loads in \[0, 1e\+07\] N, got nan"),
    (lambda: Tyre.of("dugoff").forces_at_slip(np.inf, 0.1, 0.0),
     r"^fz: expected normal loads in \[0, 1e\+07\] N, got inf"),
    (lambda: Tyre.of("pacejka").forces(
        [1000.0, 1000.0], [0.0, np.nan], 0.0, 1.0, -1.0), r"^v_lat: expected finite velocities \[m/s\], got nan"),
])
def test_the_dynamics_doors_refuse_by_name(call, message):
    """From the audit of the Python dynamics API (simulator inputs and work, normal loads, the model's methods,
    tyres): out-of-bounds reads, unbounded work, impossible loads and forces, numpy and numba errors."""
    with pytest.raises(WmrkitError, match=message):
        call()


def test_a_dynamic_model_refuses_a_tyre_that_is_not_one_by_name():
    with pytest.raises(TypeError, match=r"^tyre: expected a Tyre, a tyre model's name or None, got int"):
        DynamicModel.of(catalog.load("forklift"), tyre=3)  # type: ignore[arg-type]  # AttributeError before
