"""The built-in robots: they load, round-trip, have the thesis's mobility and equations, and match peers."""

from __future__ import annotations

import itertools
import math
import re
from pathlib import Path

import numpy as np
import pytest

from wmrkit import Robot, catalog
from wmrkit.analysis import classify
from wmrkit.errors import UnknownNameError
from wmrkit.kinematics.linalg import matrix_rank, solve_assigned

NAMES = catalog.names()
THESIS = [n for n in NAMES if n.startswith("thesis-")]

#: Degree of mobility m = k - rank A at the described configuration. Thesis vehicles: Table 5.1 (types 1-5)
#: and (4.79); templates: a skid steer is degenerate (two parallel fixed axles, (5.11)), a swerve or Ackermann
#: robot with its axles through one ICR has m = 1 (the steering adds non-instantaneous DOF); the AGV's double wheel
#: adds its free turntable (3.29) to the body's 1.
MOBILITY = {
    "thesis-omni-swedish": 3, "thesis-omni-castor": 3,
    "thesis-diff-swedish": 2, "thesis-diff-castor": 2,
    "thesis-steer-swedish": 2, "thesis-steer-castor": 2,
    "thesis-tricycle": 1, "thesis-tricycle-ch4": 1, "thesis-bicycle-swedish": 1, "thesis-bicycle-castor": 1,
    "thesis-two-steer-swedish": 1, "thesis-two-steer-castor": 1,
    "diff-drive": 2, "line-follower": 2, "skid-steer-4": 1, "mecanum-4": 3, "omni-3": 3, "omni-4": 3,
    "swerve-4": 1, "ackermann": 1, "bicycle": 1, "forklift": 1, "agv-drive-unit": 2,
}


def mobility(robot: Robot, beta=None) -> np.ndarray:
    a = robot.constraint_matrix(beta)
    return a.shape[-1] - matrix_rank(a)


def test_catalog_lists_every_robot_of_the_brief():
    """...and every catalog robot has its degree of mobility checked (agv-drive-unit's was not)."""
    assert set(MOBILITY) == set(NAMES)


@pytest.mark.parametrize("name", NAMES)
def test_robot_loads_with_its_sources_and_a_one_line_note(name):
    robot = catalog.load(name)
    assert robot.name == name
    text = catalog.source_text(name)
    header = text.split("\nname:")[0]
    assert header.startswith("# ") and all(line.startswith("#") for line in header.splitlines())
    assert ("thesis" in header.lower() and "§" in header) or "typical values" in header.lower()
    assert robot.notes and "\n" not in robot.notes.strip()


@pytest.mark.parametrize("name", NAMES)
@pytest.mark.parametrize("suffix", [".yaml", ".json"])
def test_round_trip_through_files(name, suffix, tmp_path):
    robot = catalog.load(name)
    path = tmp_path / f"{name}{suffix}"
    robot.to_file(path)
    again = Robot.from_file(path)
    assert again == robot
    assert hash(again) == hash(robot)


@pytest.mark.parametrize("name", sorted(MOBILITY))
def test_degree_of_mobility(name):
    assert mobility(catalog.load(name)) == MOBILITY[name]


@pytest.mark.parametrize("name", NAMES)
def test_actuated_and_sensed_joints_determine_the_motion(name):
    """Given the actuated (or the sensed) joint rates, every other velocity follows: (4.10) with A_na of full
    column rank. A steerable wheel's steering enters through beta, not as a rate."""
    robot = catalog.load(name)
    a = robot.constraint_matrix()
    k = a.shape[-1]
    for joints in (robot.actuated, robot.sensed):
        columns = [robot.velocity_index(j) for j in joints if j in robot.velocity_names]
        free = [c for c in range(k) if c not in columns]
        assert matrix_rank(a[:, free]) == len(free), joints


@pytest.mark.parametrize("name", [n for n in THESIS if catalog.load(n).steer_names])
def test_thesis_vehicles_are_not_at_a_singular_configuration(name):
    """No set of m assigned velocities (roller rates aside, §6.2) is singular here unless it is singular at
    every configuration (Ch. 6: 'singularity must be avoided'); singular = rank A_na < rank A (6.12)."""
    robot = catalog.load(name)
    a = robot.constraint_matrix()
    k, rank = a.shape[-1], matrix_rank(a)
    others = robot.beta + np.random.default_rng(7).uniform(-1.5, 1.5, size=(40, len(robot.steer_names)))
    a_others = robot.constraint_matrix(others)
    candidates = [c for c in range(k) if not robot.velocity_names[c].endswith(".roller")]
    for assigned in itertools.combinations(candidates, k - rank):
        free = [c for c in range(k) if c not in assigned]
        if matrix_rank(a[:, free]) < rank:
            generic = matrix_rank(a_others[..., free]) == matrix_rank(a_others)
            assert not generic.any(), [robot.velocity_names[c] for c in assigned]


# ---- the thesis's own null-space solutions (§5.5) hold for the catalog vehicles --------------------------------
def _p(robot: Robot, wheel: str) -> dict[str, float]:
    w = robot.wheel(wheel)
    return {"l": w.l, "a": w.alpha, "b": w.beta, "r": w.r, "d": w.d}


def _omni_swedish(rob):  # (5.37): phi_dot = (1/r) [[0, -1, -L], [sqrt3/2, 1/2, -L], [-sqrt3/2, 1/2, -L]] p_dot
    big_l, r = rob.wheel("s1").l, rob.wheel("s1").r
    inv = np.array([[0, -1, -big_l], [math.sqrt(3) / 2, 0.5, -big_l], [-math.sqrt(3) / 2, 0.5, -big_l]]) / r
    return ["vx", "vy", "omega", "s1.spin", "s2.spin", "s3.spin"], np.vstack([np.eye(3), inv])


def _omni_castor(rob):  # (5.40): (p; beta_dot; phi_dot) = (I; A_p1 / d; -A_p2 / r) eta
    w = [_p(rob, f"c{i}") for i in (1, 2, 3)]
    a1 = np.array([[math.cos(p["b"]), math.sin(p["b"]), p["l"] * math.sin(p["b"] - p["a"]) - p["d"]] for p in w])
    a2 = np.array([[-math.sin(p["b"]), math.cos(p["b"]), p["l"] * math.cos(p["b"] - p["a"])] for p in w])
    names = ["vx", "vy", "omega", "c1.steer", "c2.steer", "c3.steer", "c1.spin", "c2.spin", "c3.spin"]
    return names, np.vstack([np.eye(3), a1 / w[0]["d"], -a2 / w[0]["r"]])


def _diff(rob, third):  # (5.44) Swedish, (5.55)-(5.56) castor
    l12, r1, r2 = rob.wheel("f1").l, rob.wheel("f1").r, rob.wheel("f2").r
    p = _p(rob, f"{third}3")
    l3, a3, b3, r3, d = p["l"], p["a"], p["b"], p["r"], p["d"]
    c, s, cc, ss = math.cos(b3), math.sin(b3), math.cos(b3 - a3), math.sin(b3 - a3)
    a_1, a_2, a_3, a_4 = l12 * c + l3 * cc, l12 * c - l3 * cc, l12 * s + l3 * ss, l12 * s - l3 * ss
    rows = [[0, 0], [-l12, -l12], [-1, 1], [2 * l12 / r1, 0], [0, 2 * l12 / r2], [a_1 / r3, a_2 / r3]]
    names = ["vx", "vy", "omega", "f1.spin", "f2.spin", f"{third}3.spin"]
    if third == "c":
        rows.append([-a_3 / d + 1, -a_4 / d - 1])
        names.append("c3.steer")
    return names, np.array(rows)


def _steer(rob, third):  # (5.64) Swedish, (5.68) castor
    b1 = rob.wheel("o1").beta
    p2, p3 = _p(rob, f"{third}2"), _p(rob, f"{third}3")
    r1, r2, r3 = rob.wheel("o1").r, p2["r"], p3["r"]
    rows = [[math.sin(b1), 0], [-math.cos(b1), 0], [0, 1], [1 / r1, 0],
            [math.cos(b1 - p2["b"]) / r2, -p2["l"] * math.cos(p2["b"] - p2["a"]) / r2],
            [math.cos(b1 - p3["b"]) / r3, -p3["l"] * math.cos(p3["b"] - p3["a"]) / r3]]
    names = ["vx", "vy", "omega", "o1.spin", f"{third}2.spin", f"{third}3.spin"]
    if third == "c":
        for p, i in ((p2, 2), (p3, 3)):
            rows.append([math.sin(b1 - p["b"]) / p["d"], p["l"] * math.sin(p["b"] - p["a"]) / p["d"] - 1])
            names.append(f"c{i}.steer")
    return names, np.array(rows)


def _tricycle(rob):  # (5.72), L = l12
    l12, r = rob.wheel("f1").l, rob.wheel("f1").r
    l3, b3 = rob.wheel("o3").l, rob.wheel("o3").beta
    c, s = math.cos(b3), math.sin(b3)
    col = [0, l3 * c, s, -(l12 * s + l3 * c) / r, (l12 * s - l3 * c) / r, -l3 / r]
    return ["vx", "vy", "omega", "f1.spin", "f2.spin", "o3.spin"], np.array(col)[:, None]


def _bicycle(rob, third):  # (5.74) Swedish, (5.76) castor
    l2, b2, r = rob.wheel("o2").l, rob.wheel("o2").beta, rob.wheel("f1").r
    p = _p(rob, f"{third}3")
    c2, s2 = math.cos(b2), math.sin(b2)
    col = [0, l2 * c2, s2, -l2 * c2 / r, -l2 / r,
           -(p["l"] * math.cos(p["b"] - p["a"]) * s2 + l2 * c2 * math.cos(p["b"])) / p["r"]]
    names = ["vx", "vy", "omega", "f1.spin", "o2.spin", f"{third}3.spin"]
    if third == "c":
        col.append(((p["l"] * math.sin(p["b"] - p["a"]) - p["d"]) * s2 + l2 * c2 * math.sin(p["b"])) / p["d"])
        names.append("c3.steer")
    return names, np.array(col)[:, None]


def _two_steer(rob, third):  # (5.79) Swedish, (5.80) castor
    l12, r = rob.wheel("o1").l, rob.wheel("o1").r
    b1, b2 = rob.wheel("o1").beta, rob.wheel("o2").beta
    p = _p(rob, f"{third}3")
    s1, s2, s12, s21 = math.sin(b1), math.sin(b2), math.sin(b1 + b2), math.sin(b2 - b1)
    col = [-2 * l12 * s1 * s2, l12 * s12, s21, -2 * l12 * s2 / r, -2 * l12 * s1 / r,
           -(s21 * p["l"] * math.cos(p["b"] - p["a"]) + 2 * l12 * s1 * s2 * math.sin(p["b"])
             + l12 * s12 * math.cos(p["b"])) / p["r"]]
    names = ["vx", "vy", "omega", "o1.spin", "o2.spin", f"{third}3.spin"]
    if third == "c":
        col.append((-2 * l12 * s1 * s2 * math.cos(p["b"]) + l12 * s12 * math.sin(p["b"])
                    + s21 * (p["l"] * math.sin(p["b"] - p["a"]) - p["d"])) / p["d"])
        names.append("c3.steer")
    return names, np.array(col)[:, None]


THESIS_SOLUTIONS = {
    "thesis-omni-swedish": _omni_swedish, "thesis-omni-castor": _omni_castor,
    "thesis-diff-swedish": lambda r: _diff(r, "s"), "thesis-diff-castor": lambda r: _diff(r, "c"),
    "thesis-steer-swedish": lambda r: _steer(r, "s"), "thesis-steer-castor": lambda r: _steer(r, "c"),
    "thesis-tricycle": _tricycle,  # thesis-tricycle-ch4 (alpha3 = -90 deg) has its own oracle below
    "thesis-bicycle-swedish": lambda r: _bicycle(r, "s"), "thesis-bicycle-castor": lambda r: _bicycle(r, "c"),
    "thesis-two-steer-swedish": lambda r: _two_steer(r, "s"), "thesis-two-steer-castor": lambda r: _two_steer(r, "c"),
}


@pytest.mark.parametrize("name", sorted(THESIS_SOLUTIONS))
def test_thesis_null_space_solution_holds(name):
    """The closed-form solution of §5.5 (every velocity but the Swedish rollers', which (3.14) drops) is a
    no-slip motion of the catalog vehicle, for each of its m parameters; and they span the mobility."""
    robot = catalog.load(name)
    names, basis = THESIS_SOLUTIONS[name](robot)
    assigned = [robot.velocity_index(n) for n in names]
    a = robot.constraint_matrix()
    _, residual = solve_assigned(a, assigned, basis.T)
    np.testing.assert_allclose(residual, 0, atol=1e-12)
    assert matrix_rank(basis) == basis.shape[1] == mobility(robot)
    assert len(names) + sum(n.endswith(".roller") for n in robot.velocity_names) == len(robot.velocity_names)


def test_tricycle_ch4_matches_the_numeric_oracle():
    """Digest ch3-4 C.5: with r = 0.1, l12 = 0.5, l3 = 1.2, beta3 = 0.4 rad and phi3_dot = 1 the velocities are
    (0, -0.092106, 0.032452, 0.758803, 1.083319, 1)."""
    robot = catalog.load("thesis-tricycle-ch4")
    q, residual = solve_assigned(robot.constraint_matrix(), [robot.velocity_index("o3.spin")], [1.0])
    np.testing.assert_allclose(residual, 0, atol=1e-12)
    np.testing.assert_allclose(q, [0, -0.092106, 0.032452, 0.758803, 1.083319, 1], atol=6e-7)


def test_forklift_numbers():
    """Thesis Fig. 8.4 / §8.6: half track 0.45 m, l3 = 2.35 m, e = 1 m (fork tips to the drive axle), r = 0.23 m."""
    robot = catalog.load("forklift")
    np.testing.assert_allclose(robot.wheel("left_drive").position, (-1.0, 0.45), atol=1e-12)
    np.testing.assert_allclose(robot.wheel("right_drive").position, (-1.0, -0.45), atol=1e-12)
    np.testing.assert_allclose(robot.wheel("steer").position, (-2.35, 0.0), atol=1e-12)
    assert {w.r for w in robot.wheels} == {0.23}


def test_swerve_mobility_is_one_with_axles_through_an_icr_and_zero_otherwise():
    robot = catalog.load("swerve-4")
    rng = np.random.default_rng(3)
    icr = rng.uniform(-3, 3, size=(20, 1, 2))
    mounts = np.array([w.position for w in robot.wheels])
    axle = icr - mounts  # each axle points at the ICR
    beta = np.arctan2(axle[..., 1], axle[..., 0]) + np.pi * rng.integers(0, 2, size=(20, 4))
    assert (mobility(robot, beta) == 1).all()
    assert (mobility(robot, rng.uniform(-np.pi, np.pi, size=(20, 4))) == 0).all()


# ---- the same wheel rates as the peers' kinematics --------------------------------------------------------------
TWISTS = np.random.default_rng(11).uniform(-2, 2, size=(6, 3))


def _no_slip_rates(robot: Robot, twist: np.ndarray, beta=None) -> np.ndarray:
    q, residual = solve_assigned(robot.constraint_matrix(beta), [0, 1, 2], twist)
    np.testing.assert_allclose(residual, 0, atol=1e-10)
    return q


def test_mecanum_matches_wpimath():
    kin = pytest.importorskip("wpimath.kinematics")
    geometry = pytest.importorskip("wpimath.geometry")
    robot = catalog.load("mecanum-4")
    wheels = [robot.wheel(n) for n in ("front_left", "front_right", "rear_left", "rear_right")]
    peer = kin.MecanumDriveKinematics(*(geometry.Translation2d(*w.position) for w in wheels))
    for twist in TWISTS:
        s = peer.toWheelSpeeds(kin.ChassisSpeeds(*twist))
        expected = np.array([s.frontLeft, s.frontRight, s.rearLeft, s.rearRight]) / np.array([w.r for w in wheels])
        q = _no_slip_rates(robot, twist)
        np.testing.assert_allclose(q[[robot.velocity_index(f"{w.name}.spin") for w in wheels]], expected,
                                   rtol=1e-12, atol=1e-12)


def test_diff_drive_matches_wpimath():
    kin = pytest.importorskip("wpimath.kinematics")
    robot = catalog.load("diff-drive")
    left, right = robot.wheel("left"), robot.wheel("right")
    peer = kin.DifferentialDriveKinematics(left.position[1] - right.position[1])
    for vx, _, omega in TWISTS:
        s = peer.toWheelSpeeds(kin.ChassisSpeeds(vx, 0.0, omega))
        q = _no_slip_rates(robot, np.array([vx, 0.0, omega]))  # the castor never constrains: any beta
        spins = [robot.velocity_index("left.spin"), robot.velocity_index("right.spin")]
        np.testing.assert_allclose(q[spins], [s.left / left.r, s.right / right.r], rtol=1e-12, atol=1e-12)


def test_swerve_matches_wpimath():
    """At the module angles WPILib chooses (axle = module angle + 90 deg), our spin rates are its speeds / r."""
    kin = pytest.importorskip("wpimath.kinematics")
    geometry = pytest.importorskip("wpimath.geometry")
    robot = catalog.load("swerve-4")
    peer = kin.SwerveDrive4Kinematics(*(geometry.Translation2d(*w.position) for w in robot.wheels))
    for twist in TWISTS:
        states = peer.toSwerveModuleStates(kin.ChassisSpeeds(*twist))
        beta = np.array([s.angle.radians() + np.pi / 2 for s in states])
        q = _no_slip_rates(robot, twist, beta)
        expected = [s.speed / w.r for s, w in zip(states, robot.wheels, strict=True)]
        np.testing.assert_allclose(q[3:], expected, rtol=1e-10, atol=1e-10)


def test_docs_list_every_robot_with_its_drawing():
    """docs/catalog.md has a row and a drawing (made by docs/figures/make_figures.py) for every catalog robot."""
    docs = Path(__file__).resolve().parents[1] / "docs"
    text = (docs / "catalog.md").read_text(encoding="utf-8")
    for name in NAMES:
        assert f"| `{name}` |" in text, name
        assert f'<img src="figures/catalog/{name}.png"' in text, name
        assert (docs / "figures" / "catalog" / f"{name}.png").read_bytes().startswith(b"\x89PNG")


def test_docs_table_gives_each_robot_its_degree_of_mobility():
    """The m column of docs/catalog.md is the body's mobility (the classification's, `wmrkit analyze`); where
    k - rank A (`wmrkit kinematics`) is larger, the row says so: agv-drive-unit's read 1 while k - rank A = 2."""
    text = (Path(__file__).resolve().parents[1] / "docs" / "catalog.md").read_text(encoding="utf-8")
    rows = {m[1]: m[2] for m in re.finditer(r"^\| `([^`]+)` \|[^|]*\|[^|]*\| ([^|]+) \| <img", text, re.M)}
    assert set(rows) == set(NAMES)
    for name, cell in rows.items():
        body = classify(catalog.load(name)).mobility
        assert cell.split()[0] == str(body), name
        if MOBILITY[name] != body:
            assert f"({MOBILITY[name]} with the" in cell, name


def test_a_folder_named_like_a_catalog_robot_does_not_hide_it(tmp_path, monkeypatch):
    """A folder 'forklift/' of logs in the working folder made every 'wmrkit ... forklift' answer "forklift: a
    folder; a description is a file"; a file of that name is still a description, as documented."""
    monkeypatch.chdir(tmp_path)
    (tmp_path / "forklift").mkdir()
    assert catalog.resolve("forklift") == catalog.load("forklift")
    (tmp_path / "logs").mkdir()
    with pytest.raises(ValueError, match=r"^logs: a folder; a description is a file$"):
        catalog.resolve("logs")
    (tmp_path / "bicycle").write_text(catalog.source_text("diff-drive"), encoding="utf-8")
    assert catalog.resolve("bicycle") == catalog.load("diff-drive")


def test_a_name_of_the_wrong_type_is_a_clear_type_error(tmp_path, monkeypatch):
    """catalog.load(None) or load(Path('forklift')) answered "'NoneType' object is not iterable" from difflib, and
    resolve(Path('forklift')) "unsupported operand type(s) for +"; a path-like names a robot like its str."""
    for bad in (None, 3, ["forklift"], b"forklift", Path("forklift")):
        with pytest.raises(TypeError, match=r"^a catalog robot's name is a str, got "):
            catalog.load(bad)
        with pytest.raises(TypeError, match=r"^a catalog robot's name is a str, got "):
            catalog.source_text(bad)
    for bad in (None, 3, ["forklift"], b"forklift"):
        with pytest.raises(TypeError, match=r"^a robot is a catalog name or a description file's path, got "):
            catalog.resolve(bad)
    monkeypatch.chdir(tmp_path)
    assert catalog.resolve(Path("forklift")) == catalog.load("forklift")
    (tmp_path / "mine.yaml").write_text(catalog.source_text("bicycle"), encoding="utf-8")
    assert catalog.resolve(tmp_path / "mine.yaml") == catalog.load("bicycle")


def test_unknown_names_point_to_the_catalog_robot(tmp_path, monkeypatch):
    """'FORKLIFT' got no suggestion (difflib is case-sensitive) and 'forklift.yaml', the catalog file's name, only
    "no such file"."""
    monkeypatch.chdir(tmp_path)
    with pytest.raises(UnknownNameError, match=r"^no robot 'FORKLIFT' in the catalog \(did you mean 'forklift'\?\)"):
        catalog.resolve("FORKLIFT")
    with pytest.raises(UnknownNameError, match=r"^forklift.yaml: no such file \(the catalog's robot is 'forklift', "
                                         r"without '.yaml'\)$"):
        catalog.resolve("forklift.yaml")
    with pytest.raises(UnknownNameError, match=r"^robot.yaml: no such file$"):
        catalog.resolve("robot.yaml")
