"""The kinematic loop (§8.2-8.3): exact exponential decay in continuous time, the delayed discrete recursion."""

from __future__ import annotations

import math
import warnings
from dataclasses import replace

import numpy as np
import pytest

from wmrkit import catalog
from wmrkit.control.actuators import ActuatorLoop, LowLevelLoops
from wmrkit.control.laws import GateWarning, PositionLaw, SamplingWarning, check_sampling, law_velocity, sampled_root
from wmrkit.control.loop import law_controller, simulate
from wmrkit.control.points import ControlError, control_point, point_pose
from wmrkit.control.references import builtin_reference
from wmrkit.control.track import track


def _errors(robot, ref, a, pose0, duration, kind="p", period=None, delay=0):
    cp = control_point(robot)
    law = PositionLaw.uniform(kind, a, a * a / 4 if kind == "pi" else 0.0)
    out = simulate(robot, law_controller(cp, law, ref), np.asarray(pose0, float), duration, period=period,
                   delay=delay, output_dt=0.1)
    got = point_pose(cp, out["pose"])
    want = ref.sample(out["t"])
    e = want - got
    e[:, 2] = np.angle(np.exp(1j * e[:, 2]))
    return out["t"], e, cp


@pytest.mark.parametrize("name", ["mecanum-4", "swerve-4", "omni-3"])
def test_holonomic_pose_error_decays_exactly_as_exp(name):
    """(8.5): every pose coordinate's error is e(0) exp(-a t) (ideal continuous loop, full references)."""
    t, e, cp = _errors(catalog.load(name), builtin_reference("circle"), 1.3, [0.4, -0.3, 0.5], 4.0)
    assert not cp.reduced
    np.testing.assert_allclose(e, e[:1] * np.exp(-1.3 * t)[:, None], atol=2e-7)


@pytest.mark.parametrize("name", ["forklift", "diff-drive", "line-follower", "ackermann"])
def test_reduced_mobility_point_error_decays_exactly_as_exp(name):
    """Types 2 and 4: the controlled point's (x, y) error is e(0) exp(-a t); the heading is zero dynamics. The law
    asks the car's front wheels for up to 70 deg on this start: the theory's unlimited steering (the catalog car's
    +-40 deg range is tested in tests/control/test_steering.py)."""
    robot = catalog.load(name)
    robot = replace(robot, wheels=tuple(replace(w, steer_range=None) for w in robot.wheels))
    t, e, cp = _errors(robot, builtin_reference("figure-eight"), 0.8, [0.3, 0.4, 0.2], 4.0)
    assert cp.reduced
    np.testing.assert_allclose(e[:, :2], e[:1, :2] * np.exp(-0.8 * t)[:, None], atol=2e-7)


def test_pi_law_error_is_the_critically_damped_solution():
    """(8.6) with b = a^2/4 and no initial integral: e(t) = e0 (1 - a t / 2) exp(-a t / 2) (e'(0) = -a e0)."""
    a = 1.2
    t, e, _ = _errors(catalog.load("mecanum-4"), builtin_reference("circle"), a, [0.2, -0.1, 0.3], 5.0, kind="pi")
    want = e[:1] * ((1 - a * t / 2) * np.exp(-a * t / 2))[:, None]
    np.testing.assert_allclose(e, want, atol=2e-7)


def test_point_to_point_law_lags_a_ramp_by_v_over_a():
    """(8.1) has a constant error v / a on a ramp (why the thesis rejects it)."""
    run = track(catalog.load("mecanum-4"), builtin_reference("line", speed=0.4), controller="point", gain=2.0,
                duration=8.0)
    assert run.error[-1] == pytest.approx(0.4 / 2.0, rel=1e-5)


def test_gated_feedforward_switches_off_beyond_the_gate():
    """(8.53): the feedforward is applied only within d_max (binary), never weighted."""
    law = PositionLaw.uniform("p", 1.0, gate=0.5)
    vel = np.array([0.5, 0.0, 0.0])
    near = law_velocity(law, np.array([0.3, 0, 0]), vel, np.zeros(3), np.zeros(3))
    far = law_velocity(law, np.array([0.6, 0, 0]), vel, np.zeros(3), np.zeros(3))
    np.testing.assert_allclose(near, [0.8, 0, 0])
    np.testing.assert_allclose(far, [0.6, 0, 0])


@pytest.mark.parametrize(("gate", "final"), [(0.15, 0.2), (0.25, 0.0)])
def test_a_gate_below_v_over_a_never_switches_the_feedforward_on(gate, final):
    """(8.53) qualified (docs/errata.md): closed, the gate leaves the point-to-point lag v / a = 0.2 m; a gate d_max
    below it is never reached and the error stays there, one above it lets the feedforward take the error to 0.
    The first is warned of (GateWarning, on stderr from ``wmrkit track``); it ended with exit 0 and no word."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        run = track(catalog.load("mecanum-4"), builtin_reference("line", speed=0.4), controller="p", gain=2.0,
                    gate=gate, duration=8.0, initial_pose=[0.0, 1.0, 0.0])
    said = [str(w.message) for w in caught if issubclass(w.category, GateWarning)]
    assert said == (["feedforward gate 0.15 m (8.53) is below the point-to-point lag v / a = 0.2 m (reference speed "
                     "0.4 m/s, a = 2 1/s): once the error exceeds the gate the feedforward stays off and the error "
                     "settles at v / a instead of 0 (docs/errata.md, (8.53)); give a gate above 0.2 m or a larger "
                     "gain"] if final else [])
    assert run.error[0] == pytest.approx(1.0)
    assert run.error[-1] == pytest.approx(final, abs=1e-5)


def _lateral(a, period, n=40, delay=1):
    robot = catalog.load("mecanum-4")
    ref = builtin_reference("line", duration=n * period + 1)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", SamplingWarning)
        _, e, _ = _errors(robot, ref, a, [0.0, 0.3, 0.0], n * period, period=period, delay=delay)
    return e[:, 1]


@pytest.mark.parametrize("a", [0.3, 0.8, 1.5])
def test_delayed_discrete_loop_follows_the_recursion(a):
    """With a one-sample-old measurement: y_{k+1} = y_k - a T y_{k-1} (digest §2.6), exactly."""
    y, aT = _lateral(a, 0.5), a * 0.5
    np.testing.assert_allclose(y[2:], y[1:-1] - aT * y[:-2], atol=1e-12)


def test_delayed_loop_oscillates_at_0_8_not_at_0_3():
    """Thesis §9.2.3 cases 1 and 3 (T = 0.5 s); roots of z^2 - z + aT are real for aT <= 1/4."""
    slow, fast = -_lateral(0.3, 0.5), -_lateral(0.8, 0.5)  # the robot starts 0.3 m to the left: error -0.3
    assert np.all(slow > 0) and np.all(np.diff(slow) <= 0)
    assert np.any(fast < 0) and np.any(fast[np.argmax(fast < 0):] > 0)
    assert np.all(np.isreal(np.roots([1, -1, 0.15]))) and not np.all(np.isreal(np.roots([1, -1, 0.4])))


@pytest.mark.parametrize("aT, grows", [(0.9, False), (1.1, True)])
def test_delayed_loop_is_unstable_above_aT_1(aT, grows):
    y = _lateral(aT / 0.5, 0.5, n=80)
    assert (abs(y[-1]) > abs(y[0])) == grows
    assert (max(abs(np.roots([1, -1, aT]))) > 1) == grows


def test_without_delay_the_discrete_loop_is_first_order():
    y = _lateral(0.8, 0.5, delay=0)
    np.testing.assert_allclose(y[1:], (1 - 0.4) * y[:-1], atol=1e-12)


def test_sampling_rule_warns():
    with pytest.warns(SamplingWarning, match="10 T"):
        assert not check_sampling(PositionLaw.uniform("p", 0.8), 0.5)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert check_sampling(PositionLaw.uniform("p", 0.2), 0.5)


@pytest.mark.parametrize(("a", "b", "period", "delay"), [(15.0, 0.0, 0.1, 0), (25.0, 0.0, 0.1, 0), (5.0, 0.0, 0.1, 3),
                                                      (3.0, 0.0, 0.1, 3), (0.2, 5.0, 0.5, 0), (1.0, 2.0, 0.5, 1)])
def test_sampled_root_is_the_slowest_mode_of_the_simulated_loop(a, b, period, delay):
    """sampled_root (a polynomial root) against the sampled loop itself (mecanum, lateral error, P or PI law),
    written here as a state recursion: x = (e_k, ..., e_{k-d}, I_k), e_{k+1} = e_k - T (a e_{k-d} + b I_k),
    I_{k+1} = I_k + T e_{k-d}. The simulation follows it exactly, and the root's modulus is the matrix's spectral
    radius: without delay e_{k+1} = (1 - a T) e_k (a T = 1.5: a decaying oscillation; 2.5: grows 1.5 a sample)."""
    robot, n = catalog.load("mecanum-4"), 24
    ref = builtin_reference("line", duration=n * period + 1)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", SamplingWarning)
        out = simulate(robot, law_controller(control_point(robot), PositionLaw.uniform("pi" if b else "p", a, b), ref),
                       np.array([0.0, 0.3, 0.0]), n * period, period=period, delay=delay)
    m = np.zeros((delay + 2, delay + 2))
    m[0, 0], m[0, -1] = 1.0, -b * period
    m[0, delay] -= a * period
    m[1:delay + 1, :delay] += np.eye(delay)
    m[-1, delay], m[-1, -1] = period, 1.0
    x, e = np.r_[np.full(delay + 1, -0.3), 0.0], []
    for _ in range(n + 1):
        e.append(x[0])
        x = m @ x
    np.testing.assert_allclose(-out["pose"][:, 1], e, atol=1e-9 * max(1.0, np.abs(e).max()))
    if b == 0:  # the integral then feeds nothing back: its mode (z = 1) is not the error's
        m = m[:-1, :-1]
    assert abs(sampled_root(a, b, period, delay)) == pytest.approx(max(abs(np.linalg.eigvals(m))), rel=1e-6)
    if b == 0 and delay == 0:
        assert sampled_root(a, b, period, delay) == pytest.approx(1 - a * period)


def test_sampling_warning_says_when_the_sampled_loop_diverges():
    """The warning said 'expect oscillation; unstable with a one-sample delay once a T > 1' for every fast pole: a
    loop without delay at a T = 2.5 (unstable: its error grows 1.5 times a sample) or with 3 samples of delay at
    a T = 0.5 (unstable from 0.445) printed its diverging run with that warning; without delay at a T = 0.4 it
    promised an oscillation that a first-order recursion never has. A PI law with a large integral gain diverges
    sampled whatever 1/a (b T^2 = 1.25 here), and was not warned of."""
    def message(law, period, delay=0):
        with pytest.warns(SamplingWarning) as caught:
            assert not check_sampling(law, period, delay=delay)
        return str(caught[0].message)

    assert "unstable" in message(PositionLaw.uniform("p", 25.0), 0.1) and "1.5 times" in message(
        PositionLaw.uniform("p", 25.0), 0.1)
    assert "unstable with a delay of 3 samples" in message(PositionLaw.uniform("p", 5.0), 0.1, 3)
    assert "oscillation" not in message(PositionLaw.uniform("p", 0.8), 0.5)
    assert "expect oscillation; unstable from a T = 1 with a delay of 1 sample" in message(
        PositionLaw.uniform("p", 0.8), 0.5, 1)
    assert "unstable" in message(PositionLaw.uniform("pi", 0.2, 5.0), 0.5)
    assert abs(sampled_root(0.2, 5.0, 0.5)) > 1


def test_bad_options_raise_located_errors():
    robot, ref = catalog.load("forklift"), builtin_reference("line")
    with pytest.raises(ControlError, match="unknown controller"):
        track(robot, ref, controller="lqr")
    with pytest.raises(ControlError, match="period"):
        track(robot, ref, delay=2)
    with pytest.raises(ControlError, match="on its fixed axle"):
        control_point(catalog.load("diff-drive"), (0.0, 0.1))
    with pytest.raises(ControlError, match="gain a"):
        PositionLaw("p", (1.0, -1.0, 1.0))


def test_skid_steer_is_controlled_with_slip_reported():
    """Degenerate skid steering: the admissible space of the wheels' linear rows; IK reports the turning slip."""
    run = track(catalog.load("skid-steer-4"), builtin_reference("circle"), duration=3.0)
    assert run.error.max() < 1e-6
    assert not np.all(run.commands.feasible)
    assert math.isfinite(run.summary()["rms_error"])


def test_a_long_sampled_loop_is_refused_before_it_runs():
    """A sampled loop of 1e6 periods passed the sample limit and ran for about an hour (a diff drive at 0.02 s: four
    evaluations of an RK4 step for its castor each period). It is refused before the first period; a run within
    the bound still goes."""
    from wmrkit.control.loop import MAX_SAMPLED_EVALUATIONS

    def never(t, pose, integral):
        raise AssertionError("the loop ran")

    diff = catalog.load("diff-drive")
    with pytest.raises(ControlError, match=f"more than {MAX_SAMPLED_EVALUATIONS} evaluations"):
        simulate(diff, never, np.zeros(3), 19_999.0, period=0.02)
    with pytest.raises(ControlError, match="evaluations"):  # the exact step of the ideal plant: one a period
        simulate(catalog.load("mecanum-4"), never, np.zeros(3), (MAX_SAMPLED_EVALUATIONS + 1) * 0.01, period=0.01)
    run = track(diff, builtin_reference("line"), period=0.02, duration=2.0)
    assert run.error.max() < 1e-6


def test_sampled_loop_with_fast_actuator_loops_steps_within_their_time_scale():
    """The sampled loop stepped low-level loops with RK4 at 0.02 s whatever their speed: a 50 ms servo with 15 %
    overshoot (omega_n 151 rad/s) diverged numerically and ended in 'rates: steer.spin: expected finite numbers
    within 1e+06', a 10 ms first-order one likewise. The substeps are now at most the fastest loop's time scale:
    the forklift 0.3 m off a circle then closes on it as the continuous loop does; a loop too fast to step through
    the run is refused by the evaluation bound, naming its time scale."""
    robot, circle = catalog.load("forklift"), builtin_reference("circle")
    for steer, spin in ((ActuatorLoop(0.01), ActuatorLoop(0.01)), (ActuatorLoop(0.05), ActuatorLoop(0.05, 0.15))):
        loops = LowLevelLoops(("steer.steer", "steer.spin"), (steer, spin))
        sampled = track(robot, circle, loops=loops, period=0.1, duration=5.0, initial_pose=[0.0, 0.3, 0.0])
        continuous = track(robot, circle, loops=loops, duration=5.0, initial_pose=[0.0, 0.3, 0.0])
        assert sampled.error[-1] < 0.01 and continuous.error[-1] < 0.01
        assert np.abs(sampled.error - continuous.error[::2]).max() < 0.05  # the law held 0.1 s against continuous
    loops = LowLevelLoops(("steer.steer",), (ActuatorLoop(1e-300),))
    with pytest.raises(ControlError, match="time scale"):
        track(robot, circle, loops=loops, period=0.1, duration=5.0)


def test_a_numpy_integer_delay_past_the_run_is_refused():
    """A delay counted with numpy (np.int64, e.g. from an array of settings) skipped the check that it reaches past
    the run (isinstance int): 100 samples of 0.1 s over 5 s ran open loop to a final error of 6.1 m."""
    for delay in (100, np.int64(100)):
        with pytest.raises(ControlError, match="reach past the run"):
            track(catalog.load("mecanum-4"), builtin_reference("line"), period=0.1, delay=delay, duration=5.0)


def test_the_point_to_point_law_has_no_feedforward_to_gate():
    """(8.1) has no feedforward: a gate on it was ignored (the run equal to the ungated one, exit 0)."""
    with pytest.raises(ControlError, match="no feedforward to gate"):
        PositionLaw.uniform("point", 1.0, gate=0.5)
    with pytest.raises(ControlError, match="no feedforward to gate"):
        track(catalog.load("mecanum-4"), builtin_reference("line"), controller="point", gate=0.5, duration=1.0)


@pytest.mark.parametrize("name", ["mecanum-4", "diff-drive", "ackermann"])
def test_a_run_started_on_the_reference_ends_on_it(name):
    """Started on the line (x = 0.5 t for 20 s), the ideal loop's point is at x = 0.5 t exactly, the last sample
    included: the reference's velocity at its last sample is its own (0.5 m/s), rest only after. It was rest at the
    last sample already, so the integrator's last step saw the feedforward drop at t = 20 s and the summary's final
    error was 1.2e-6 to 1.8e-6 m (max_error too), all earlier samples 0."""
    run = track(catalog.load(name), builtin_reference("line"))
    np.testing.assert_allclose(run.tracked[:, 0], 0.5 * run.t, rtol=0, atol=1e-9)
    assert run.summary()["final_error"] < 1e-9
