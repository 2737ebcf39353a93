"""The simulator: integrators agree, friction dissipates, results are frozen, programs and torque files."""

from __future__ import annotations

import math
import re

import numpy as np
import pytest
from dynamics_robots import castor_robot, double_unit_robot, tricycle

from wmrkit import catalog
from wmrkit.dynamics.model import DynamicModel
from wmrkit.dynamics.programs import PATHS, feasible_twists, path_program, read_torques, twist_program
from wmrkit.dynamics.simulate import METHODS, Inputs, simulate
from wmrkit.dynamics.tyres import Tyre
from wmrkit.errors import ShapeError, WmrkitError


@pytest.fixture(scope="module")
def forklift():
    return DynamicModel.of(catalog.load("forklift"))


def test_semi_implicit_and_rk4_agree_with_the_adaptive_solution():
    model = DynamicModel.of(castor_robot({"model": "dugoff", "cs": 800, "calpha": 600}))
    inputs = Inputs.torques_only(model, [0.0, 1.0], {"left.spin": [0.1, 0.1], "right.spin": [0.3, 0.3]})
    ref = simulate(model, inputs, 1.0, method="adaptive", rtol=1e-9, record_step=0.01, initial_twist=[0.4, 0, 0])
    for method, step, tol in (("rk4", 2e-4, 1e-4), ("semi-implicit", 2e-4, 5e-3)):
        sim = simulate(model, inputs, 1.0, method=method, step=step, record_step=0.01, initial_twist=[0.4, 0, 0])
        assert np.allclose(sim.t, ref.t)
        assert np.allclose(sim.pose, ref.pose, atol=tol), method
        assert np.allclose(sim.twist, ref.twist, atol=tol), method


def test_an_adaptive_run_is_bounded_in_evaluations(monkeypatch):
    """The adaptive method had no bound on its work: the forklift's 3 s turn takes 1e6 evaluations (14 s), so a
    long --duration ran for hours, and a discontinuous Coulomb law (k = inf) did not finish 0.05 s in 3 min."""
    import wmrkit.dynamics.runs as sim_module

    model = DynamicModel.of(castor_robot({"model": "dugoff", "cs": 800, "calpha": 600}))
    inputs = Inputs.torques_only(model, [0.0, 1.0], {"left.spin": [0.1, 0.1], "right.spin": [0.3, 0.3]})
    used = simulate(model, inputs, 0.2, method="adaptive", initial_twist=[0.4, 0, 0]).info["evaluations"]
    monkeypatch.setattr(sim_module, "MAX_EVALUATIONS", used // 2)
    with pytest.raises(WmrkitError, match=re.escape(f"more than {used // 2:.0e} evaluations of the model by t = ")
                       + r"\S+ s of 0.2 s .* use the semi-implicit method"):
        simulate(model, inputs, 0.2, method="adaptive", initial_twist=[0.4, 0, 0])


def test_dugoff_at_low_speed_the_energy_the_semi_implicit_step_adds_vanishes_with_the_step():
    """Dugoff's law dissipates (test_tyres), but its slope at zero slip, cs / speed, is steep at low speed: the
    semi-implicit step overshoots across zero slip and adds energy (docs/dynamics.md: measured sizes)."""
    model = DynamicModel.of(catalog.load("skid-steer-4"))  # Dugoff tyres, no torque
    inputs = Inputs.torques_only(model, [0.0, 1.0], {})

    def gain(**kw):  # largest rise of the kinetic energy over the run, relative to the initial one
        sim = simulate(model, inputs, 0.5, initial_twist=[0.028, 0.017, 0.025], record_step=1e-3, **kw)
        assert np.all(sim.friction_power() <= 1e-9)  # every sample dissipates: the gain is the integrator's
        states = np.column_stack([sim.pose, sim.joint_positions, sim.twist, sim.joint_rates])
        e = np.array([model.kinetic_energy(s[list(model.steer_columns)], s[model.n:]) for s in states])
        return (np.maximum.accumulate(e[::-1])[::-1] - e).max() / e[0]

    gains = [gain(step=step) for step in (1e-3, 2.5e-4, 6.25e-5)]
    assert gains[1] <= gains[0] / 8 and gains[2] <= 1e-12
    assert gain(method="adaptive", rtol=1e-7) <= 1e-12


def test_forklift_pacejka_friction_never_adds_energy_and_the_truck_follows_its_program(forklift):
    model = DynamicModel.of(catalog.load("forklift"), Tyre.of("pacejka", {"shifts": 0.0}))
    inputs, duration = path_program(model, "turn", speed=2.0)
    sim = simulate(model, inputs, duration, record_step=0.01)
    assert np.all(sim.friction_power() <= 1e-9)
    assert sim.twist[-1, 0] == pytest.approx(2.0, abs=0.05)  # forward speed of the program
    assert sim.twist[-1, 2] == pytest.approx(2.0 / 3.0, abs=0.05)  # radius 3 m
    assert np.all(sim.loads > 0) and np.allclose(sim.loads.sum(axis=1), 2500 * 9.81, rtol=1e-6)


def test_simulation_is_frozen(forklift):
    inputs, _ = path_program(forklift, "straight")
    sim = simulate(forklift, inputs, 0.2, step=1e-3)
    assert sim.pose.shape == (201, 3) and sim.forces.shape == (201, 3, 2) and sim.joint_rates.shape == (201, 4)
    for arr in (sim.t, sim.pose, sim.twist, sim.joint_rates, sim.forces, sim.loads, sim.slip, sim.heading):
        with pytest.raises(ValueError):
            arr[0] = 0
    assert sim.joint_names == forklift.names[3:]


def test_skid_steer_turns_less_than_its_kinematics_say():
    """The Husky effect of the issue: wheel speeds for omega are held, the robot turns much less."""
    model = DynamicModel.of(catalog.load("skid-steer-4"))
    inputs, duration = path_program(model, "turn", speed=1.0)
    sim = simulate(model, inputs, duration, record_step=0.01)
    assert 0.1 < sim.twist[-1, 2] < 0.8 * (1 / 3)


def test_feasible_twists_move_sideways_at_the_fork_tips(forklift):
    tw = feasible_twists(forklift, [[2.0, 0.0, 0.5]])
    assert tw[0, 1] == pytest.approx(0.5 * 1.0)  # omega x (distance to the drive axle, 1 m)


def test_a_twist_without_a_no_slip_motion_is_refused_unless_slip_is_allowed(forklift):
    turning = [(2.0, 0.0, 0.0), (2.0, 0.0, 0.5)]  # at the fork tips, 1 m ahead of the drive axle: needs vy = 0.5
    with pytest.raises(WmrkitError, match=r"\(2\.0, 0\.0, 0\.5\) at t = 1 s .*'(left|right)_drive' would slip "
                                          r"sideways at 0\.5 m/s"):
        twist_program(forklift, [0.0, 1.0], turning)
    feasible = twist_program(forklift, [0.0, 1.0], feasible_twists(forklift, turning))
    slipping = twist_program(forklift, [0.0, 1.0], turning, allow_slip=True)
    # the drive wheels roll the same either way (vy is along their axles); the steered wheel points elsewhere
    drives = [forklift.names.index(j) for j in ("right_drive.spin", "left_drive.spin")]
    np.testing.assert_array_equal(slipping.rate_reference[:, drives], feasible.rate_reference[:, drives])
    assert not np.allclose(slipping.heading_reference, feasible.heading_reference)
    skid = DynamicModel.of(catalog.load("skid-steer-4"))  # no twist that turns is feasible: the tyres must slip
    with pytest.raises(WmrkitError, match="skid steering"):
        twist_program(skid, [0.0], feasible_twists(skid, [(1.0, 0.0, 0.3)]))
    twist_program(skid, [0.0], [(1.0, 0.0, 0.3)], allow_slip=True)
    for wrong in (math.nan, math.inf, 1e300):  # one line naming the knot, no overflow warnings
        with pytest.raises(ShapeError, match=r"at t = 1 s: expected finite speeds within 1000 m/s"):
            twist_program(forklift, [0.0, 1.0], [(1.0, 0.0, 0.0), (wrong, 0.0, 0.0)], allow_slip=True)


def test_every_path_program_runs(forklift):
    for name in PATHS:
        inputs, duration = path_program(forklift, name)
        assert duration >= 2 and inputs.rate_reference.shape[1] == forklift.n


def test_torque_file(tmp_path, forklift):
    path = tmp_path / "tau.csv"
    path.write_text("time,right_drive.spin,left_drive.spin,steer.heading\n0,50,50,0\n1,50,50,0.2\n2,0,0,0.2\n")
    inputs = read_torques(forklift, path)
    sim = simulate(forklift, inputs, 2.0, initial_twist=[1, 0, 0], record_step=0.01)
    assert sim.twist[100, 0] > 1.0
    assert sim.heading[-1, 0] == pytest.approx(0.2, abs=0.02)
    for text, match in (("time,steer.spin\n0,1\n", "not actuated"), ("time,nope.spin\n0,1\n", "no joint"),
                        ("time,left_drive.spin\n0,x\n", ":2: column 'left_drive.spin': cannot read 'x' as a number"),
                        ("t,a\n", "header"),
                        ("time,left_drive.spin\n1,0\n0,0\n", "increasing"),
                        ("time,left_drive.spin\n100,9\n101,9\n", r":2: the first row is at t = 100 s")):
        path.write_text(text)
        with pytest.raises(WmrkitError, match=match):
            read_torques(forklift, path)
    path.write_text("time,left_drive.spin\n-1,9\n1,9\n")  # starting before t = 0 is fine
    assert read_torques(forklift, path).torques[0, forklift.names.index("left_drive.spin")] == 9


def test_a_torque_file_may_write_its_units_as_the_other_csv_files_do(tmp_path, forklift):
    """'time [s],left_drive.spin [N m]' (the header style of every other CSV of wmrkit, `simulate --out`'s too) was
    refused as "expected a header 'time,<wheel>.<joint>,...'". Units are read; a unit a column does not take is
    refused naming the column."""
    bare, units = tmp_path / "bare.csv", tmp_path / "units.csv"
    bare.write_text("time,right_drive.spin,left_drive.spin,steer.heading\n0,50,50,0\n1,50,40,0.2\n")
    units.write_text("time [s],right_drive.spin [N m],left_drive.spin [Nm],steer.heading [deg]\n"
                     f"0,50,50,0\n1,50,40,{math.degrees(0.2)!r}\n")
    a, b = read_torques(forklift, bare), read_torques(forklift, units)
    np.testing.assert_array_equal(a.time, b.time)
    np.testing.assert_array_equal(a.torques, b.torques)
    np.testing.assert_allclose(b.heading_reference, a.heading_reference, rtol=1e-15)
    for header, match in (("time [ms],left_drive.spin", r"column 'time \[ms\]': the time is read in \[s\]"),
                          ("time,left_drive.spin [rad]", r"column 'left_drive.spin \[rad\]': a torque .* \[N m\]"),
                          ("time,steer.heading [N m]", r"column 'steer.heading \[N m\]': a heading is read in")):
        units.write_text(f"{header}\n0,1\n")
        with pytest.raises(WmrkitError, match=r"units.csv:1: " + match):
            read_torques(forklift, units)


def test_a_heading_column_for_a_passive_castor_is_refused(tmp_path):
    """'caster.heading' gave the castor, whose steering no motor drives, a PD servo (kp 37 N m/rad) that steered
    it; torque columns on joints that are not actuated were already refused."""
    model = DynamicModel.of(castor_robot())
    path = tmp_path / "tau.csv"
    path.write_text("time,left.spin,caster.heading\n0,1,0.1\n1,1,0.1\n")
    with pytest.raises(WmrkitError, match=r"^.*tau.csv:1: column 'caster.heading': the steering of wheel 'caster' is "
                                          r"not actuated .* \(actuated: left.spin, right.spin\)$"):
        read_torques(model, path)


def test_bad_arguments_are_errors(forklift):
    inputs = Inputs.torques_only(forklift, [0.0], {})
    with pytest.raises(ShapeError):
        simulate(forklift, inputs, -1.0)
    with pytest.raises(WmrkitError):
        simulate(forklift, inputs, 1.0, method="euler")  # type: ignore[arg-type]
    with pytest.raises(WmrkitError, match="not actuated"):
        Inputs.torques_only(forklift, [0.0], {"steer.spin": 1.0})


def test_block_counter_example_7_4_to_7_8():
    """Minimising dissipation = quasi-static balance only when f + |v| f' = k f (7.8): true for the Coulomb and
    linear laws, false for the smoothed Coulomb law (7.28) (f = (2/pi) atan(k v), neither constant nor a power)."""
    def k_ratio(tyre, v, h=1e-6):
        f = lambda x: -tyre.forces(1.0, 0.0, x, x, 0.0).longitudinal  # noqa: E731 (block friction magnitude)
        df = (f(v + h) - f(v - h)) / (2 * h)
        return (f(v) + v * df) / f(v)

    speeds = [0.05, 0.3, 2.0]
    for tyre, law_holds in ((Tyre.of("coulomb", {"k": math.inf}), True), (Tyre.of("linear"), True),
                            (Tyre.of("coulomb", {"k": 5.0}), False)):
        ratios = [k_ratio(tyre, v) for v in speeds]
        assert (np.ptp(ratios) < 1e-6) == law_holds, (tyre.model, ratios)
    # the power laws of the text: f = 1, |v|, |v|^2, |v|^3 give k = 1, 2, 3, 4; f = 1 + |v| etc. give no constant k
    for f, df, holds in ((lambda v: 1.0, lambda v: 0.0, True), (lambda v: v ** 3, lambda v: 3 * v ** 2, True),
                         (lambda v: 1 + v, lambda v: 1.0, False), (lambda v: v + v ** 2, lambda v: 1 + 2 * v, False)):
        ratios = [(f(v) + v * df(v)) / f(v) for v in speeds]
        assert (np.ptp(ratios) < 1e-12) == holds


def test_tricycle_straight_run_keeps_equal_drive_loads():
    model = DynamicModel.of(tricycle(0.0, {"model": "pacejka", "shifts": 0}))  # no lateral bias
    inputs = Inputs.torques_only(model, [0.0, 1.0], {"w1.spin": [-20, -20], "w2.spin": [-20, -20]})
    sim = simulate(model, inputs, 0.5, initial_twist=[0, 1.0, 0], record_step=0.01)
    assert np.allclose(sim.loads[:, 0], sim.loads[:, 1])
    assert sim.twist[-1, 1] > 1.0  # -20 N m drives forward in the thesis convention (phi_dot < 0 forward)


def test_mecanum_with_rollers_follows_its_program():
    """Swedish wheels: the roller is a joint with its own inertia; a Mecanum robot turns as commanded."""
    from wmrkit import Robot

    data = catalog.load("mecanum-4").to_dict()
    data["body"] = {"mass": 20, "inertia": 0.8, "com": [0, 0], "com_height": 0.1}
    for w in data["wheels"]:
        w["inertia"], w["tyre"] = {"spin": 0.005, "roller": 1e-5}, {"model": "coulomb", "k": 200}
    model = DynamicModel.of(Robot.from_dict(data))
    assert "front_left.roller" in model.names
    inputs, duration = path_program(model, "turn", speed=0.5)
    sim = simulate(model, inputs, duration, record_step=0.01)
    assert sim.twist[-1] == pytest.approx([0.5, 0.0, 0.5 / 3], abs=2e-3)


def test_a_double_wheel_is_driven_by_its_two_spins(tmp_path):
    """A double wheel's actuated joints are ``spin1`` and ``spin2``. Before, the servos and torque files looked
    for ``spin`` (the joint name with its digit stripped): the unit had no servo, the robot stood still through
    the whole program (exit 0 from ``simulate``), and a torque file for ``drive.spin1`` was refused."""
    model = DynamicModel.of(double_unit_robot())
    assert [model.names[c] for c in range(3, model.n) if model.is_actuated(c)] == ["drive.spin1", "drive.spin2"]
    sim = simulate(model, twist_program(model, [0.0], [(0.5, 0.0, 0.0)]), 2.0, record_step=0.01)
    assert sim.twist[-1] == pytest.approx([0.5, 0.0, 0.0], abs=5e-3)
    path = tmp_path / "tau.csv"
    path.write_text("time,drive.spin1,drive.spin2\n0,2,2\n1,2,2\n")
    assert simulate(model, read_torques(model, path), 1.0, record_step=0.01).twist[-1, 0] > 0.1


def test_a_robot_without_motors_is_refused_instead_of_standing_still():
    bare = double_unit_robot(actuated=())
    with pytest.raises(WmrkitError, match="has no actuated joint"):
        twist_program(DynamicModel.of(bare), [0.0], [(0.5, 0.0, 0.0)])


def test_progress_bar_runs_in_chunks_with_the_same_result(forklift, capsys):
    inputs, _ = path_program(forklift, "turn")
    plain = simulate(forklift, inputs, 0.5, record_step=0.01)
    shown = simulate(forklift, inputs, 0.5, record_step=0.01, progress=True)
    assert np.array_equal(plain.pose, shown.pose) and np.array_equal(plain.t, shown.t)


def test_a_wheel_that_lifts_off_stops_the_run_where_the_load_reaches_zero():
    """Braking the forklift from 1 m/s at the grip (rate servos referenced to 0) tips it forward: the steered rear
    wheel loses its load. The planar model cannot follow, so every integrator and the stepper refuse to go on; with
    ``allow_lift_off`` the run goes on and its records show the load at 0 from the reported time."""
    from wmrkit.dynamics.programs import twist_program
    from wmrkit.dynamics.simulate import Stepper, initial_state

    model = DynamicModel.of(catalog.load("forklift"), "pacejka")
    brake = twist_program(model, [0.0], [(0.0, 0.0, 0.0)])
    for method in ("semi-implicit", "rk4", "adaptive"):
        with pytest.raises(WmrkitError, match=r"contact 'steer' lifts off the ground at t = (\S+) s") as err:
            simulate(model, brake, 0.3, method=method, initial_twist=(1.0, 0.0, 0.0))
        assert 0 < float(err.value.args[0].split("t = ")[1].split(" s")[0]) < 0.3
    with pytest.raises(WmrkitError, match="contact 'steer' lifts off"):
        Stepper(model, initial_state(model, (1.0, 0.0, 0.0))).advance(brake, 0.3)
    sim = simulate(model, brake, 0.3, initial_twist=(1.0, 0.0, 0.0), allow_lift_off=True)
    steer = model.contacts.index("steer")
    first = int(np.argmax(sim.loads[:, steer] <= 0))
    assert sim.loads[first, steer] == 0 and np.all(sim.loads[:first, steer] > 0)
    with pytest.raises(WmrkitError, match=f"at t = {sim.t[first]:.6g} s"):
        simulate(model, brake, 0.3, initial_twist=(1.0, 0.0, 0.0))
    # braking over 2 s (0.5 m/s^2) keeps every wheel down
    gentle = twist_program(model, [0.0, 2.0], [(1.0, 0.0, 0.0), (0.0, 0.0, 0.0)])
    sim = simulate(model, gentle, 2.5, initial_twist=(1.0, 0.0, 0.0))
    assert sim.loads.min() > 0.5 * model.normal_loads().min()


def test_a_record_step_beyond_the_run_records_its_start_with_every_method(forklift):
    # the adaptive method raised AttributeError ('list' object has no attribute 'T'): LSODA over (0, 0)
    inputs = Inputs.torques_only(forklift, [0.0], {})
    runs = [simulate(forklift, inputs, 1.0, method=method, record_step=5.0) for method in METHODS]
    for sim in runs:
        assert sim.t.tolist() == [0.0]
        np.testing.assert_array_equal(sim.loads, runs[0].loads)


@pytest.mark.parametrize("duration, record, last", [(0.05, 0.03, 0.03), (0.1, 0.03, 0.09), (0.09, 0.03, 0.09)])
def test_an_adaptive_run_records_as_the_fixed_steps_and_stops_at_its_duration(forklift, duration, record, last):
    """The adaptive method sampled ``round(duration / record_step)`` record steps: asked for 0.05 s recorded every
    0.03 s it integrated to 0.06 s, past the duration ('wmrkit simulate --method adaptive --duration 0.05 --step
    0.03' printed '0.05 s simulated' above a final pose at t = 0.06 s). Like the fixed steps, it records the
    multiples of the record step within the duration."""
    inputs = Inputs.torques_only(forklift, [0.0], {})
    for method in METHODS:
        sim = simulate(forklift, inputs, duration, method=method, step=0.01, record_step=record,
                       initial_twist=[0.4, 0, 0])
        assert sim.t[-1] == pytest.approx(last) and sim.t[-1] <= duration, method
        assert np.allclose(np.diff(sim.t), record)


def test_recorded_samples_are_bounded_in_memory_and_the_refusal_names_a_step_that_fits(forklift):
    """5e7 steps recorded at every step were allowed: 16 GB of samples for the forklift (40 numbers a sample)."""
    from wmrkit.dynamics import simulate as module

    inputs = Inputs.torques_only(forklift, [0.0], {})
    capacity = module.record_capacity(forklift)
    assert capacity == module.MAX_RECORD_VALUES // (3 * forklift.n + 6 * len(forklift.contacts) + 1)
    for method in METHODS:  # refused before integrating: no time is spent on a run that cannot be kept
        with pytest.raises(ShapeError, match=r"records \d+ samples, more than the \d+ of robot 'forklift'"):
            simulate(forklift, inputs, 49_000.0, step=1e-3, record_step=1e-3, method=method)
    every = module.recordable_step(forklift, 49_000.0, 1e-3, 1e-3)
    steps = round(every / 1e-3)  # the least whole number of steps that fits
    assert 49_000_000 // steps + 1 <= capacity < 49_000_000 // (steps - 1) + 1
    assert module.recordable_step(forklift, 10.0, 1e-3, 0.01) == 0.01  # short runs keep what was asked


def test_cli_simulate_records_within_the_memory_bound(capsys, tmp_path, monkeypatch):
    """The CLI picks a record step that fits (here a bound of 100 samples) instead of failing or exhausting memory."""
    import json

    from wmrkit.cli.main import main
    from wmrkit.dynamics import simulate as module

    monkeypatch.setattr(module, "MAX_RECORD_VALUES", 100 * 40)
    assert main(["simulate", "forklift", "--path", "straight", "--duration", "3", "--json"]) == 0
    samples = json.loads(capsys.readouterr().out)["samples"]
    assert 50 < samples <= 100  # at 0.01 s, 301 samples


@pytest.mark.parametrize(("time", "torques", "message"), [
    # a list raised "'list' object has no attribute 'items'"
    ([0.0, 1.0], [100.0, 100.0], r"torques: expected a mapping \{joint: values \[N m\]\}"),
    # text was read as numbers: "100" as 100 N m, times "0", "1" as seconds
    ([0.0, 1.0], {"right_drive.spin": "100"}, r"torques\['right_drive.spin'\]: got the text '100'"),
    (["0", "1"], {"right_drive.spin": 100.0}, "time: got the text '0'"),
])
def test_torques_only_refuses_what_is_not_a_mapping_of_numbers(forklift, time, torques, message):
    with pytest.raises(ValueError, match=message):
        Inputs.torques_only(forklift, time, torques)


@pytest.mark.parametrize(("call", "message"), [
    # text raised TypeError "must be real number, not str" (no argument named); True ran for 1 s
    (lambda m, i: simulate(m, i, "1"), "duration and step must be finite numbers .*, got '1', 0.001"),
    (lambda m, i: simulate(m, i, True), "duration and step must be finite numbers .*, got True, 0.001"),
    (lambda m, i: simulate(m, i, 0.1, step="0.001"), "duration and step .*, got 0.1, '0.001'"),
    (lambda m, i: simulate(m, i, 0.1, record_step="0.01"), r"record_step: expected a finite number > 0 \[s\]"),
    # AttributeError "'dict' object has no attribute 'torques'", "'str' object has no attribute 'body'"
    (lambda m, i: simulate(m, {"right_drive.spin": 1.0}, 0.1), r"inputs: expected Inputs \(Inputs.torques_only"),
    (lambda m, i: simulate("forklift", i, 0.1), r"robot: expected a Robot \(wmrkit.catalog.load\(name\)"),
    (lambda m, i: DynamicModel.of(catalog.load("forklift"), gravity="9.81"), "gravity: expected a finite number"),
    # text raised "'<' not supported between instances of 'int' and 'str'"; twists' text was read as numbers
    (lambda m, i: path_program(m, "straight", speed="2"), r"speed: expected a program speed in .*, got '2'"),
    (lambda m, i: twist_program(m, [0.0, 1.0], [["1", 0, 0], [1, 0, 0]]), "twists: got the text '1'"),
    (lambda m, i: twist_program(m, [0.0, 1.0], [[1.0, 0, 0]]), r"twists: expected one \(vx, vy, omega\) per time"),
])
def test_simulation_doors_refuse_what_is_not_their_argument_by_name(forklift, call, message):
    inputs = Inputs.torques_only(forklift, [0.0], {"right_drive.spin": 1.0})
    with pytest.raises((WmrkitError, TypeError), match=message):
        call(forklift, inputs)
