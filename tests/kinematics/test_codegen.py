"""Generated code (wmrkit.kinematics.codegen): C99 compiled with gcc and called through ctypes, and the numpy module,
against the numeric models (Robot.constraint_matrix + linalg.solve_assigned, 4.11) on random inputs."""

from __future__ import annotations

import ctypes
import importlib.util
import math
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

from wmrkit import Robot, SingularError, Wheel, catalog
from wmrkit.kinematics.codegen import CodegenError, identifier, write_code
from wmrkit.kinematics.linalg import solve_assigned
from wmrkit.kinematics.symbolic import sensed_rates


def _robot(name, wheels):
    return Robot.from_dict({"name": name, "wheels": wheels})


ROBOTS = {
    "diff-castor": _robot("diff-castor", [
        {"name": "left", "type": "fixed", "position": [0, 0.2], "beta": "90 deg", "r": 0.05, "sensed": ["spin"]},
        {"name": "right", "type": "fixed", "position": [0, -0.2], "beta": "90 deg", "r": 0.05, "sensed": ["spin"]},
        {"name": "caster", "type": "castor", "position": [-0.3, 0.02], "d": 0.04, "r": 0.03}]),
    "forklift": catalog.load("forklift"),
    "mecanum": _robot("mecanum", [
        {"name": n, "type": "swedish", "position": [x, y], "beta": "90 deg", "gamma": g, "r": 0.05, "r_r": 0.01,
         "sensed": ["spin"]}
        for n, x, y, g in [("fl", 0.2, 0.15, "45 deg"), ("fr", 0.2, -0.15, "-45 deg"),
                           ("rl", -0.2, 0.15, "-45 deg"), ("rr", -0.2, -0.15, "45 deg")]]),
    "swerve": _robot("swerve", [
        {"name": n, "type": "steerable", "position": [x, y], "r": 0.05, "sensed": ["spin", "steer"]}
        for n, x, y in [("fl", 0.3, 0.25), ("fr", 0.3, -0.25), ("rl", -0.3, 0.25), ("rr", -0.3, -0.25)]]),
    "omni castors": _robot("omni castors", [  # a name that is no C identifier
        *({"name": f"o{i}", "type": "swedish", "l": 0.25, "alpha": f"{a} deg", "beta": f"{a} deg",
           "gamma": "90 deg", "r": 0.04, "r_r": 0.01, "sensed": ["spin"]} for i, a in enumerate((0, 120, 240))),
        {"name": "c1", "type": "castor", "position": [0.3, 0.1], "d": 0.03, "delta": "10 deg", "r": 0.02},
        {"name": "c2", "type": "castor", "position": [-0.3, 0.1], "d": -0.03, "r": 0.02}]),
    "double castor": _robot("double castor", [
        {"name": "unit", "type": "double_castor", "position": [0.3, 0], "d": 0.08, "b": 0.1, "r": 0.05,
         "sensed": ["spin1", "spin2"]},
        {"name": "left", "type": "fixed", "position": [-0.2, 0.25], "beta": "90 deg", "r": 0.05},
        {"name": "right", "type": "fixed", "position": [-0.2, -0.25], "beta": "90 deg", "r": 0.05}]),
    "double units": _robot("double units", [  # a double wheel: its steering rate is an input of the inverse
        {"name": "drive", "type": "double", "position": [0.3, 0.05], "heading": 0, "b": 0.06, "r": 0.08,
         "sensed": ["steer", "spin1", "spin2"]},
        {"name": "rear", "type": "double", "position": [-0.3, 0], "heading": 0, "b": 0.05, "r": 0.07,
         "sensed": ["steer"]},
        {"name": "trailer", "type": "double_castor", "position": [-0.5, 0.1], "d": 0.1, "b": 0.05, "r": 0.04}]),
}
N = 6  # random samples per robot


def numeric(robot: Robot, sensed, beta, twist, q_sensed, steer_rate=None):
    """Reference: the ranks method (4.11) on the numeric constraint matrix; the double wheels' steering rates
    `steer_rate` assigned with the twist."""
    a = robot.constraint_matrix(beta)
    free = [robot.velocity_index(n) for n in robot.free_steering]
    assigned = np.concatenate([twist, np.broadcast_to(steer_rate, (*twist.shape[:-1], len(free)))], axis=-1) \
        if free else twist
    q = solve_assigned(a, [0, 1, 2, *free], assigned)[0]
    rates = np.delete(q, [0, 1, 2, *free], axis=-1)
    q, slip = solve_assigned(a, [robot.velocity_index(n) for n in sensed], q_sensed)
    return rates, q[..., :3], np.linalg.norm(slip, axis=-1)


def inputs(robot: Robot, sensed, seed=0):
    rng = np.random.default_rng(seed)
    beta = rng.uniform(-math.pi, math.pi, (N, len(robot.steer_names)))
    steer_rate = rng.normal(size=(N, len(robot.free_steering)))
    return beta, rng.normal(size=(N, 3)), rng.normal(size=(N, len(sensed))), steer_rate


def _inverse(mod, twist, steer_rate, beta):
    return mod.inverse(twist, steer_rate, beta) if mod.FREE_STEER_NAMES else mod.inverse(twist, beta)


def load_module(path: Path):
    spec = importlib.util.spec_from_file_location(path.stem, path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


ALL = {**ROBOTS, **{f"catalog:{n}": catalog.load(n) for n in catalog.names()}}


@pytest.mark.parametrize("name", list(ALL))
def test_python_module_equals_numeric_model(name, tmp_path):
    robot = ALL[name]
    (path,) = write_code(robot, "python", tmp_path)
    mod = load_module(path)
    sensed, free = sensed_rates(robot), robot.free_steering
    assert mod.SENSED_NAMES == sensed and mod.FREE_STEER_NAMES == free
    assert mod.RATE_NAMES == tuple(n for n in robot.rate_names if n not in free)
    beta, twist, q_s, s = inputs(robot, sensed)
    heading = robot.heading_of_beta(beta)  # the generated code takes headings (it took the thesis's beta)
    rates, twist_fw, slip = numeric(robot, sensed, beta, twist, q_s, s)
    np.testing.assert_allclose(mod.constraint_matrix(heading), robot.constraint_matrix(beta), atol=1e-12)
    np.testing.assert_allclose(_inverse(mod, twist, s, heading), rates, rtol=1e-9, atol=1e-9)
    got_twist, got_slip = mod.forward_with_residual(q_s, heading)
    np.testing.assert_allclose(got_twist, twist_fw, rtol=1e-8, atol=1e-9)
    np.testing.assert_allclose(got_slip, slip, rtol=1e-8, atol=1e-9)
    # batches broadcast: one configuration for many twists, and (2, 3) leading axes
    np.testing.assert_allclose(_inverse(mod, twist, s, heading[0]), numeric(robot, sensed, beta[0], twist, q_s, s)[0],
                               rtol=1e-9, atol=1e-9)
    assert mod.forward(q_s.reshape(2, 3, -1), heading.reshape(2, 3, -1)).shape == (2, 3, 3)
    np.testing.assert_allclose(mod.HEADING_DESCRIBED, robot.heading, atol=1e-15)


def test_python_module_consistent_rates_give_the_twist_without_slip(tmp_path):
    """Rates of a no-slip motion (the inverse of an assignable twist) come back as that twist, residual 0."""
    robot = ROBOTS["diff-castor"]
    mod = load_module(write_code(robot, "python", tmp_path)[0])
    heading = np.array([0.7])
    twist = np.array([0.3, 0.0, -0.4])  # vy = 0: the fixed wheels' lateral constraint
    rates = mod.inverse(twist, heading)
    got, slip = mod.forward_with_residual(rates[:2], heading)
    np.testing.assert_allclose(got, twist, atol=1e-12)
    assert slip == pytest.approx(0, abs=1e-12)
    with pytest.raises(ValueError, match=r"twist: expected shape \(\.\.\., 3\)"):
        mod.inverse([1.0, 2.0], heading)


GCC = shutil.which("gcc")


def compile_c(robot: Robot, directory: Path) -> tuple[ctypes.CDLL, str]:
    header, source = write_code(robot, "c", directory)
    lib = directory / f"lib{identifier(robot.name)}.so"
    subprocess.run([GCC, "-O2", "-shared", "-fPIC", "-std=c99", "-Wall", "-Wextra", "-pedantic", "-Werror",
                    "-o", str(lib), str(source), "-lm"], check=True, capture_output=True, text=True)
    main = directory / "main.c"  # the header alone is enough for a user's program
    main.write_text(f'#include "{header.name}"\nint main(void) {{ return 0; }}\n')
    subprocess.run([GCC, "-std=c99", "-Wall", "-Werror", "-fsyntax-only", str(main)], check=True, cwd=directory)
    return ctypes.CDLL(str(lib)), identifier(robot.name)


def _ptr(a: np.ndarray):
    return np.ascontiguousarray(a, dtype=float).ctypes.data_as(ctypes.POINTER(ctypes.c_double))


@pytest.mark.skipif(GCC is None, reason="gcc not installed")
@pytest.mark.parametrize("name", list(ALL))
def test_c_code_equals_numeric_model(name, tmp_path):
    robot = ALL[name]
    lib, ident = compile_c(robot, tmp_path)
    sensed = sensed_rates(robot)
    beta, twist, q_s, s = inputs(robot, sensed, seed=1)
    heading = robot.heading_of_beta(beta)  # the generated code takes headings
    rates, twist_fw, slip = numeric(robot, sensed, beta, twist, q_s, s)
    forward = getattr(lib, f"{ident}_forward")
    forward.restype = ctypes.c_int
    n_rows, n_vel = robot.constraint_matrix().shape
    for k in range(N):
        b = heading[k] if beta.shape[1] else None
        a_out, out, tw = np.zeros(n_rows * n_vel), np.zeros(rates.shape[-1]), np.zeros(3)
        res = ctypes.c_double(-1.0)
        getattr(lib, f"{ident}_constraint")(_ptr(b) if b is not None else None, _ptr(a_out))
        np.testing.assert_allclose(a_out.reshape(n_rows, n_vel), robot.constraint_matrix(beta[k]), atol=1e-12)
        steer = (_ptr(s[k]),) if s.shape[1] else ()  # the double wheels' steering rates
        getattr(lib, f"{ident}_inverse")(_ptr(twist[k]), *steer, _ptr(b) if b is not None else None, _ptr(out))
        np.testing.assert_allclose(out, rates[k], rtol=1e-9, atol=1e-9)
        status = forward(_ptr(q_s[k]), _ptr(b) if b is not None else None, _ptr(tw), ctypes.byref(res))
        assert status == 0
        np.testing.assert_allclose(tw, twist_fw[k], rtol=1e-8, atol=1e-9)
        assert res.value == pytest.approx(slip[k], rel=1e-8, abs=1e-9)


@pytest.mark.skipif(GCC is None, reason="gcc not installed")
def test_c_forward_reports_a_singular_configuration(tmp_path):
    """Three castors sensing their spins: with parallel axles the rolling rows lose rank, the twist is undetermined."""
    robot = _robot("castors", [
        {"name": f"c{i}", "type": "castor", "l": 0.3, "alpha": f"{a} deg", "d": 0.05, "r": 0.03, "sensed": ["spin"]}
        for i, a in enumerate((0, 120, 240))])
    lib, ident = compile_c(robot, tmp_path)
    forward = getattr(lib, f"{ident}_forward")
    tw, res = np.zeros(3), ctypes.c_double(0.0)
    assert forward(_ptr(np.ones(3)), _ptr(np.zeros(3)), _ptr(tw), ctypes.byref(res)) == -1
    assert np.isnan(tw).all() and math.isnan(res.value)
    assert forward(_ptr(np.ones(3)), _ptr(np.array([0.0, 1.0, 2.0])), _ptr(tw), None) == 0
    assert np.isfinite(tw).all()
    # a NaN or inf sensor value or heading: -1 and NaN, not 0 with a NaN twist a controller would take as valid
    for sensed, heading in [([1.0, math.nan, 1.0], [0.0, 1.0, 2.0]), ([1.0, math.inf, 1.0], [0.0, 1.0, 2.0]),
                            ([1.0, 1.0, 1.0], [0.0, math.nan, 2.0]), ([1.0, 1.0, 1.0], [0.0, math.inf, 2.0])]:
        tw[:] = 0.0
        assert forward(_ptr(np.array(sensed)), _ptr(np.array(heading)), _ptr(tw), ctypes.byref(res)) == -1
        assert np.isnan(tw).all() and math.isnan(res.value)


def test_python_forward_reports_a_singular_configuration_as_the_c_does(tmp_path):
    """Three castors sensing their spins, axles parallel: the sensed rates do not determine the twist. The generated
    Python returned pinv's minimum-norm guess (0.03, 0, 0) with residual 0 (no slip), where the C returns -1 and NaN,
    and a NaN heading raised numpy's 'SVD did not converge'. Now NaN twist and residual, row by row in a batch."""
    robot = _robot("castors", [
        {"name": f"c{i}", "type": "castor", "l": 0.3, "alpha": f"{a} deg", "d": 0.05, "r": 0.03, "sensed": ["spin"]}
        for i, a in enumerate((0, 120, 240))])
    mod = load_module(write_code(robot, "python", tmp_path)[0])
    headings = np.array([[0.0, 0.0, 0.0], [0.0, 1.0, 2.0], [0.0, math.nan, 2.0], [0.0, 1.0, 2.0]])
    sensed = np.array([[1.0, 1.0, 1.0], [1.0, 1.0, 1.0], [1.0, 1.0, 1.0], [1.0, math.inf, 1.0]])
    twist, slip = mod.forward_with_residual(sensed, headings)
    assert np.isnan(twist[[0, 2, 3]]).all() and np.isnan(slip[[0, 2, 3]]).all()
    beta = robot.beta_of_heading(headings[1])  # the determined row: the numeric model (4.11)
    expected, residual = solve_assigned(robot.constraint_matrix(beta), [robot.velocity_index(n) for n in
                                                                          sensed_rates(robot)], sensed[1])
    np.testing.assert_allclose(twist[1], expected[:3], rtol=1e-9, atol=1e-12)
    assert slip[1] == pytest.approx(np.linalg.norm(residual), abs=1e-12)
    assert np.isnan(mod.forward([1.0, 1.0, 1.0], [0.0, 0.0, 0.0])).all()


def test_names_that_are_no_identifiers_or_break_comments(tmp_path):
    """Robot and wheel names end up in identifiers, C comments and Python docstrings: none may break the code."""
    robot = Robot('3 wheels */ /* """ \\', (  # built directly: description files allow only plain wheel names
        Wheel('w */"""', "fixed", 0.2, math.pi / 2, math.pi / 2, 0.05, sensed=("spin",)),
        Wheel("right", "fixed", 0.2, -math.pi / 2, math.pi / 2, 0.05, sensed=("spin",)),
        Wheel("c/*", "castor", 0.3, math.pi, 0.0, 0.03, d=0.04)))
    mod = load_module(write_code(robot, "python", tmp_path)[0])
    assert mod.RATE_NAMES[0] == 'w */""".spin'
    if GCC is not None:
        compile_c(robot, tmp_path)


def test_identifiers_and_errors(tmp_path):
    assert identifier("omni castors") == "omni_castors"
    assert identifier("3-wheel bot!") == "robot_3_wheel_bot"
    assert identifier("double") == "double_"
    with pytest.raises(CodegenError, match="lang: expected 'c' or 'python', got 'rust'"):
        write_code(ROBOTS["forklift"], "rust", tmp_path)
    with pytest.raises(CodegenError, match=r"sensed: expected a sequence of names, got the string 'steer\.spin'"):
        write_code(ROBOTS["forklift"], "python", tmp_path, sensed="steer.spin")  # said "no velocity 's'"
    with pytest.raises(CodegenError, match="'vx' is a body velocity"):
        write_code(ROBOTS["forklift"], "python", tmp_path, sensed=["vx"])
    with pytest.raises(SingularError, match=r"the sensed rates \(fl.spin, fr.spin\) do not determine"):
        write_code(ROBOTS["mecanum"], "python", tmp_path, sensed=["fl.spin", "fr.spin"])


def test_the_refusal_names_the_rates_left_free_not_every_unknown(tmp_path):
    """A differential drive's two wheel spins fix the twist; a double wheel beside them can still turn on the spot
    (3.29), which the generated forward model (every unsensed rate solved) cannot tell. The refusal listed every
    unknown, (vx, vy, omega, unit.steer, ...), a false claim about the twist; now the three rates left free."""
    robot = _robot("dd-double", [
        {"name": "left", "type": "fixed", "position": [0, 0.2], "heading": 0, "r": 0.075, "sensed": ["spin"]},
        {"name": "right", "type": "fixed", "position": [0, -0.2], "heading": 0, "r": 0.075, "sensed": ["spin"]},
        {"name": "unit", "type": "double", "position": [0.5, 0], "heading": 0, "b": 0.05, "r": 0.05}])
    with pytest.raises(SingularError, match=r"do not determine \(unit\.steer, unit\.spin1, unit\.spin2\);"):
        write_code(robot, "python", tmp_path)
    assert list(tmp_path.iterdir()) == []


def test_cli_symbolic_and_codegen_end_to_end(capsys, tmp_path):
    """`wmrkit kinematics forklift --symbolic --codegen python DIR`: closed forms printed, a working module written."""
    from wmrkit.cli.main import main

    assert main(["kinematics", "forklift", "--symbolic", "--codegen", "python", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    assert "direct model (sensed), assigned: right_drive.spin, left_drive.spin" in out
    assert "inverse model, assigned: vx" in out
    mod = load_module(tmp_path / "forklift_kinematics.py")
    robot = catalog.load("forklift")
    # straight ahead (steer axle along +y): vx = r phi for both drive wheels, the steered wheel rolls as fast
    np.testing.assert_allclose(mod.inverse([0.46, 0, 0], [0.0]), [2.0, 2.0, 2.0], atol=1e-12)  # heading 0
    np.testing.assert_allclose(mod.inverse([0.46, 0, 0], robot.heading), [2.0, 2.0, 2.0], atol=1e-12)
    assert main(["kinematics", "forklift", "--codegen", "python", str(tmp_path / "forklift_kinematics.py")]) == 2


def test_a_double_wheel_turns_on_the_spot_by_rolling_its_sub_wheels_apart(tmp_path):
    """A double wheel's steering rate is free (3.29): the twist does not fix it, so it is an input of the generated
    inverse (before, codegen and ``kinematics --symbolic`` refused every robot with a double wheel). Closed form:
    the robot at rest, the unit turning at s rad/s, its sub-wheels at +-b roll at -+b s / r (3.24)."""
    double = _robot("double", [
        {"name": "unit", "type": "double", "position": [0.2, 0], "b": 0.1, "r": 0.05, "sensed": ["steer"]},
        {"name": "back", "type": "fixed", "position": [-0.2, 0], "beta": "90 deg", "r": 0.05, "sensed": ["spin"]}])
    mod = load_module(write_code(double, "python", tmp_path)[0])
    assert mod.FREE_STEER_NAMES == ("unit.steer",) and "unit.steer" not in mod.RATE_NAMES
    rates = dict(zip(mod.RATE_NAMES, mod.inverse([0.0, 0.0, 0.0], [0.7], [0.4 - math.pi / 2]), strict=True))
    assert rates["unit.spin1"] == pytest.approx(-0.1 * 0.7 / 0.05) and rates["unit.spin2"] == pytest.approx(0.7 * 2)
    assert rates["back.spin"] == pytest.approx(0.0, abs=1e-15)
    with pytest.raises(ValueError, match=r"steer_rate: expected shape \(\.\.\., 1\)"):
        mod.inverse([0.0, 0.0, 0.0], [0.7, 0.1])
    # the numeric inverse model (ranks method) assigns the free steering rate too (before: "no 1 of (vx, vy,
    # omega) can be assigned"); its twist, a bicycle's (vy = 0 at the back axle, omega from the unit's heading),
    # gives the generated rates
    from wmrkit.kinematics.models import inverse_model

    model = inverse_model(double, beta=[0.4])
    assert model.assigned == ("vx", "unit.steer")
    solved = dict(zip(model.solved, model.matrix @ np.array([0.3, 0.7]), strict=True))
    heading = 0.4 - math.pi / 2  # the unit's rolling direction
    assert solved["omega"] == pytest.approx(0.3 * math.tan(heading) / 0.4) and solved["vy"] == pytest.approx(
        0.2 * solved["omega"])
    twist = [0.3, solved["vy"], solved["omega"]]
    expected = dict(zip(mod.RATE_NAMES, mod.inverse(twist, [0.7], double.heading_of_beta([0.4])), strict=True))
    for name, value in expected.items():
        assert solved[name] == pytest.approx(value, rel=1e-12, abs=1e-12)


MICRO = _robot("micro", [  # 1 um across, a castor of 1 nm: within docs/limits.md
    {"name": "left", "type": "fixed", "position": [0, 0.4e-6], "heading": 0, "r": 1e-7, "sensed": ["spin"]},
    {"name": "right", "type": "fixed", "position": [0, -0.4e-6], "heading": 0, "r": 1e-7, "sensed": ["spin"]},
    {"name": "caster", "type": "castor", "position": [-1e-6, 0], "d": 1e-7, "r": 1e-9}])


def _micro_reference():
    """Rates of a no-slip motion of the micro robot (1 um/s, 0.5 rad/s) at three castor headings, and its twist."""
    heading = np.array([[0.3], [-2.0], [3.1]])
    twist = np.array([1e-6, 0.0, 0.5])
    a = MICRO.constraint_matrix(heading=heading)
    rates = solve_assigned(a, [0, 1, 2], np.broadcast_to(twist, (3, 3)))[0][..., 3:5]  # left, right spins
    return heading, twist, rates


def test_python_forward_of_a_micro_robot(tmp_path):
    """The generated forward's rank test was absolute (smallest singular value <= 1e-9 rows max(1, max|A_ij|)): the
    castor-spin column of a 1 um robot with a 1 nm castor (entries 1e-9) fell below it, and every twist came out
    NaN, 'not determined'. The columns are now scaled to norm 1 first, whatever their units."""
    mod = load_module(write_code(MICRO, "python", tmp_path)[0])
    heading, twist, rates = _micro_reference()
    got, slip = mod.forward_with_residual(rates, heading)
    np.testing.assert_allclose(got, np.broadcast_to(twist, (3, 3)), rtol=1e-8, atol=1e-18)
    assert (slip < 1e-18).all()  # m/s: the rates are those of a motion without slip


@pytest.mark.skipif(GCC is None, reason="gcc not installed")
def test_c_forward_of_a_micro_robot(tmp_path):
    """The C lstsq refused a column whose remaining norm was <= 1e-9 m max(1, max|A_ij|): -1 (not determined) for
    every heading of the micro robot. Now relative to the column's own norm."""
    lib, ident = compile_c(MICRO, tmp_path)
    heading, twist, rates = _micro_reference()
    for k in range(3):
        tw, res = np.zeros(3), ctypes.c_double(-1.0)
        assert getattr(lib, f"{ident}_forward")(_ptr(rates[k]), _ptr(heading[k]), _ptr(tw), ctypes.byref(res)) == 0
        np.testing.assert_allclose(tw, twist, rtol=1e-8, atol=1e-18)
        assert res.value < 1e-18
