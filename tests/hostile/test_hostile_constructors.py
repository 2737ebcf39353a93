"""Python doors checked as the files and the command line are (audit of the Python API, session 14): values built in
Python, arrays that are not finite, sizes without bound. Each of these gave NaN, zero, a wrong verdict or an unbounded
allocation without an error."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from wmrkit import catalog, wheel_commands
from wmrkit.analysis.icr import steer_to_icr, twist_of_icr
from wmrkit.analysis.lines import line_through
from wmrkit.kinematics.realtime import realtime
from wmrkit.slip.weights import SlipWeights
from wmrkit.wheels import Wheel, WheelError


@pytest.mark.parametrize(("change", "message"), [
    ({"r": 0.0}, "wheel 'left': r: must be > 0, got 0.0 m"),  # spins NaN
    ({"r": math.nan}, "wheel 'left': r: expected a finite number, got nan"),
    ({"r": -1.0}, "wheel 'left': r: must be > 0, got -1.0 m"),
    ({"l": -0.5}, r"wheel 'left': l: must be >= 0 \(the direction is alpha\)"),
    ({"beta": "90 deg"}, "wheel 'left': beta: expected a finite number, got '90 deg'"),
    ({"type": "nonsense"}, "wheel 'left': unknown type 'nonsense' \\(types: fixed, steerable"),
    # heading 0 printed for sin/cos of round-off, and a to_file that from_file refused ('1e+300 rad' is more than ...)
    ({"beta": 1e300}, r"wheel 'left': beta: expected an angle of at most 1e\+06 turns \[rad\], got 1e\+300"),
    ({"alpha": -1e7}, r"wheel 'left': alpha: expected an angle of at most 1e\+06 turns \[rad\], got -10000000\.0"),
    ({"l": True}, r"wheel 'left': l: expected a finite number, got True"),  # read as 1 m
    # every heading out of range (ik: never feasible), and a to_dict that from_dict refused
    ({"steer_range": (0.5, -0.5)}, r"wheel 'left': steer_range: a fixed wheel does not steer"),
])
def test_a_wheel_the_model_cannot_use_is_refused_by_field(change, message):
    wheel = catalog.load("diff-drive").wheel("left")
    with pytest.raises(WheelError, match=message):
        dataclasses.replace(wheel, **change)


@pytest.mark.parametrize("steer_range", [(0.5, -0.5), (-7.0, 0.0), (0.0, math.nan), [-1.0, 1.0], (-1.0,)])
def test_a_steering_range_built_in_python_is_checked_as_in_a_description(steer_range):
    """(0.5, -0.5) put every heading out of range (ik: never feasible) and gave a to_dict that from_dict refused."""
    wheel = catalog.load("ackermann").wheel("front_left")
    with pytest.raises(WheelError, match=r"^wheel 'front_left': steer_range: must be a tuple \(min, max\) of headings, "
                                         r"min < max within one turn \[rad\], got "):
        dataclasses.replace(wheel, steer_range=steer_range)


def test_a_wheel_built_in_python_may_be_degenerate_but_not_meaningless():
    """A castor without offset has slip rows (3.12) (a degenerate one: the description refuses it, naming d); a
    Swedish wheel's roller radius must still be > 0."""
    Wheel(name="c", type="castor", l=1.0, alpha=0.0, beta=0.0, r=0.1, d=0.0)
    with pytest.raises(WheelError, match=r"wheel 's': r_r: must be > 0, got 0\.0 m"):
        Wheel(name="s", type="swedish", l=1.0, alpha=0.0, beta=0.0, r=0.1, r_r=0.0, gamma=0.5)


@pytest.mark.parametrize("default", [(0.0, 0.0), (math.nan, 1.0), (1.0, -2.0)])
def test_slip_weights_built_directly_are_checked_as_slip_weights_of(default):
    """SlipWeights(mu=(), default=(0, 0)) gave a zero twist from WLS, (nan, 1) a NaN one."""
    with pytest.raises(ValueError, match=r"friction coefficient of wheel 'default' \((lateral|longitudinal)\) must"):
        SlipWeights((), default)


@pytest.mark.parametrize("tolerances", [{"slip_tol": -1.0}, {"slip_tol": math.nan}, {"speed_tol": math.inf}])
def test_ik_tolerances_are_finite_and_not_negative(tolerances):
    """slip_tol = -1 or NaN called a feasible twist infeasible."""
    dd = catalog.load("diff-drive")
    name = next(iter(tolerances))
    with pytest.raises(ValueError, match=f"{name}: expected a finite tolerance >= 0"):
        wheel_commands(dd, [1.0, 0.0, 0.0], **tolerances)
    with pytest.raises(ValueError, match=f"{name}: expected a finite tolerance >= 0"):
        realtime(dd, **tolerances)
    assert wheel_commands(dd, [1.0, 0.0, 0.0]).feasible


@pytest.mark.parametrize("icr", [[math.nan, 0.0, 1.0], [math.inf, 0.0, 1.0], [0.0, 0.0, 0.0]])
def test_an_icr_that_is_no_point_is_refused(icr):
    """steer_to_icr returned the described angles for these, twist_of_icr NaN."""
    sw = catalog.load("swerve-4")
    with pytest.raises(ValueError, match=r"icr_h: expected finite homogeneous points \(x, y, w\), not all zero"):
        steer_to_icr(sw, icr)
    with pytest.raises(ValueError, match="icr_h: expected finite homogeneous points"):
        twist_of_icr(icr)
    assert np.isfinite(steer_to_icr(sw, [0.0, 1.0, 0.0])).all()


def test_a_line_needs_a_direction():
    with pytest.raises(ValueError, match=r"line_through: expected a finite point and a finite direction"):
        line_through([0.0, 0.0], [0.0, 0.0])


@pytest.mark.parametrize(("call", "message"), [
    (lambda i: i.integrate_exact([0.0, 0.0, 0.0], [math.nan, 0.0, 0.0], 1.0), "twist_robot: expected finite numbers"),
    (lambda i: i.integrate_rk2([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], math.inf), "dt: expected finite numbers, got inf"),
    (lambda i: i.step([math.nan, 0.0, 0.0], [0.1, 0.0, 0.0]), "pose_world_robot: expected finite numbers"),
    (lambda i: i.integrate_increments([0.0, 0.0, 0.0], [[0.1, math.inf, 0.0]]), "increments_robot: expected finite"),
    (lambda i: i.integrate_increments([0.0, 0.0, 0.0], [[0.1, 0.0, 0.0]], heading_world=[0.0, math.nan]),
     "heading_world: expected finite numbers"),
])
def test_the_integrators_refuse_what_is_not_finite(call, message):
    """integrate_exact([0, 0, 0], [nan, 0, 0], 1) gave [nan, nan, 0]: a NaN pose, silently."""
    from wmrkit.odometry import integrators

    with pytest.raises(ValueError, match=message):
        call(integrators)


def test_a_synthetic_run_bounds_its_fine_steps():
    """oversample=10**9 tried to allocate 15 TiB."""
    from wmrkit.errors import WmrkitError
    from wmrkit.odometry.synthetic import simulate, square_path

    with pytest.raises(WmrkitError, match=r"oversample 1000000000 at 100 Hz .* at most 1e\+08 fine steps"):
        simulate(catalog.load("diff-drive"), square_path(1.0), 100.0, oversample=10**9)


def test_small_python_doors_say_what_is_wrong():
    """closure_error said 'the path neither moves nor turns' of a NaN pose; j_model of no samples gave NaN with a
    RuntimeWarning; a JointLog of lists failed later with 'list' object has no attribute; Vehicle refused
    np.int64(1) as 'not a finite number'."""
    from wmrkit.errors import WmrkitError
    from wmrkit.odometry.logs import JointLog
    from wmrkit.parking.problem import load_problem
    from wmrkit.slip import closure_error, j_model

    with pytest.raises(WmrkitError, match="closure_error: poses must be finite, pose 1 is not"):
        closure_error(np.array([[0.0, 0.0, 0.0], [math.nan, 0.0, 0.0]]))
    with pytest.raises(WmrkitError, match="j_model: expected at least one sample"):
        j_model(np.zeros((0, 3)), np.zeros((0, 3)))
    log = JointLog([0, 1], ("a",), [[0], [1]])
    assert isinstance(log.time, np.ndarray) and log.positions.dtype == float and len(log.select(("a",))) == 2
    vehicle = load_problem("thesis-9.1").vehicle
    assert dataclasses.replace(vehicle, track=np.int64(1)).track == 1.0
    with pytest.raises(WmrkitError, match=r"vehicle\.track: must be a finite number, got True"):
        dataclasses.replace(vehicle, track=True)


def test_batch_shapes_and_chunk_sizes_are_named():
    """numpy's 'shape mismatch: objects cannot be broadcast' for wheel_commands; a bare TypeError for chunk=2.5."""
    from wmrkit.batch.engine import BatchError
    from wmrkit.batch.sweep import sweep
    from wmrkit.batch.sweep_kernel import parse_vary

    with pytest.raises(ValueError, match=r"twist_robot \(3, 3\) and the steering \(2, 4\): their batch shapes"):
        wheel_commands(catalog.load("swerve-4"), np.ones((3, 3)), heading=np.zeros((2, 4)))
    robot = catalog.load("omni-3")
    axes = [parse_vary("wheels[0].l=0.2:0.3:2", robot)]
    with pytest.raises(BatchError, match=r"chunk: expected an integer >= 1, got 2\.5"):
        sweep(robot, axes, chunk=2.5)


def test_encoders_and_references_refuse_what_is_not_finite():
    """An incremental encoder quantised a NaN angle to -9223372036854775808 counts, silently; an absolute encoder
    read NaN counts as a NaN angle; a reference sampled at a NaN time gave a NaN pose."""
    from wmrkit.control.references import builtin_reference
    from wmrkit.odometry.encoders import AbsoluteEncoder, EncoderError, IncrementalEncoder

    with pytest.raises(EncoderError, match="angle: expected finite angles"):
        IncrementalEncoder(8290).quantize([0.1, math.nan])
    with pytest.raises(EncoderError, match="angle: expected finite angles"):
        AbsoluteEncoder(0.0246).quantize([math.inf])
    with pytest.raises(EncoderError, match="counts: expected finite readings"):
        AbsoluteEncoder(0.0246).angle([math.nan])
    assert IncrementalEncoder(8290).quantize([1.0]).tolist() == [math.floor(8290 / (2 * math.pi))]
    with pytest.raises(ValueError, match="sample times must be finite"):
        builtin_reference("circle").sample(np.array([0.0, math.nan]))
