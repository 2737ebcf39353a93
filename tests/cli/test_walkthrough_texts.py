"""What a first-time user reads in the text of `kinematics`, `ik` and `show` (session 40's walkthrough): counts that
match the description, every slipping wheel named, every length with its unit. Expected values are counted from
the descriptions here, not taken from the code's output."""

from __future__ import annotations

import math
import re

import pytest

from wmrkit import catalog
from wmrkit.cli.main import main


def _out(capsys, argv, code=0):
    assert main(argv) == code
    return capsys.readouterr()


@pytest.mark.parametrize("name", ["swerve-4", "ackermann", "thesis-two-steer-castor", "thesis-tricycle"])
def test_the_extended_count_names_every_steered_wheel(name, capsys):
    """The extended solution (§4.5) may assign m + n_o velocities, n_o the centred steerable wheels. Before, the
    line counted n_o as extended_dof minus the m *at this steering*: a car steered straight (m = 1 there, 0 at generic
    steering) read "with its 1 steering rate", swerve-4 "its 3 steering rates", for 2 and 4 steered wheels."""
    robot = catalog.load(name)
    n_o = sum(w.type == "steerable" for w in robot.wheels)
    out = _out(capsys, ["kinematics", name]).out
    line = next(x for x in out.splitlines() if "(extended solutions, §4.5)" in x)
    assert re.match(rf"  with its {n_o} steering angles? \(extended solutions", line), line
    generic = int(re.search(r"m = (\d+) at generic steering", out)[1]) if "generic steering" in out else \
        int(re.search(r"mobility m = (\d+)", out)[1])
    assert f", {generic + n_o} velocit" in line


def test_ik_names_every_fixed_wheel_that_would_slip(tmp_path, capsys):
    """A diff drive asked for vy = 0.2 m/s: both wheels slip sideways at 0.2 m/s (vy + omega x, x = 0), and the
    warning named only 'left', as if the other rolled. Six wheels on one axle asked for vy = 1: four named, the rest
    counted."""
    err = _out(capsys, ["ik", "diff-drive", "--twist", "1", "0.2", "0.5"], code=1).err
    assert "wheel 'left' slips at +0.2 m/s, wheel 'right' at +0.2 m/s (fixed wheels" in err
    path = tmp_path / "six.yaml"
    path.write_text("name: six\nwheels:\n" + "".join(
        f"  - {{name: w{i}, type: fixed, position: [0.{i}, 0.2], heading: 0, r: 0.1}}\n" for i in range(6)))
    err = _out(capsys, ["ik", str(path), "--twist", "0", "1", "0", "--json"], code=1).out
    assert "wheel 'w0' slips at +1 m/s, wheel 'w1' at +1 m/s, wheel 'w2' at +1 m/s, wheel 'w3' at +1 m/s and 2 more" \
        in err


def test_show_gives_every_length_its_unit(tmp_path, capsys):
    """`show`'s columns say [m] and [deg]; the extras after the joints printed `d=0.04 delta=0deg`, `b=0.06` and
    `r_r=0.0125` with no unit (a user who wrote `d: 40 mm` could not tell). Values from the file: 40 mm, 60 mm, and a
    mecanum wheel's default roller radius r/4."""
    path = tmp_path / "mixed.yaml"
    path.write_text("name: mixed\nwheels:\n"
                    "  - {name: c, type: castor, position: [-0.3, 0], d: 40 mm, r: 0.025}\n"
                    "  - {name: u, type: double, position: [0.3, 0], b: 60 mm, r: 0.08}\n"
                    "  - {name: m, type: mecanum, position: [0.3, 0.2], r: 0.05}\n")
    rows = {line.split()[0]: line for line in _out(capsys, ["show", str(path)]).out.splitlines()[2:5]}
    assert rows["c"].endswith("  d=0.04 m delta=0 deg")
    assert rows["u"].endswith("  b=0.06 m")
    assert rows["m"].endswith(f"  gamma=45 deg r_r={0.05 / 4:g} m")


def test_kinematics_says_the_units_of_its_tables(capsys):
    """The model tables print `vx = 0.0375 left.spin` with no unit anywhere in the text: the velocities line now says
    them. diff-drive's direct model: vx = r/2 per wheel spin (r = 0.075 m), in m/s per rad/s."""
    out = _out(capsys, ["kinematics", "diff-drive"]).out
    assert "  velocities (vx, vy [m/s]; omega, joint rates [rad/s]): vx, vy, omega, left.spin" in out
    row = next(x for x in out.splitlines() if x.strip().startswith("vx ") and "=" in x)
    assert [float(v) for v in row.split("=")[1].split()] == [0.075 / 2, 0.075 / 2]


def _numbers(text):
    return [float(v) for v in re.findall(r"-?\d+\.\d+", text)]


def test_analyze_shows_a_small_robots_icr_to_its_scale(tmp_path, capsys):
    """ICR coordinates were printed to 3 decimals of a metre at any scale: a 2 mm diff drive's axle at x = 0.4 mm read
    `line through (0.000, 0.000) m`, a 3 mm tricycle's ICR at (0.4, 7.14) mm `(0.000, 0.007) m`. Now to 1 % of the
    robot's size. The expected points are the axle intersections computed here."""
    path = tmp_path / "micro.yaml"
    diff = ("name: micro\nwheels:\n  - {name: l, type: fixed, position: [0.4 mm, 1 mm], heading: 0, r: 0.2 mm}\n"
            "  - {name: r, type: fixed, position: [0.4 mm, -1 mm], heading: 0, r: 0.2 mm}\n")
    path.write_text(diff)
    line = _out(capsys, ["analyze", str(path)]).out.splitlines()[1]
    assert line.startswith("  ICR anywhere on the line through (")
    x, y, ux, uy = _numbers(line)
    assert abs(x - 0.0004) < 1e-5 and y == 0 and (ux, uy) == (0, 1)  # 1 % of its 1 mm size
    path.write_text(diff + "  - {name: f, type: steerable, position: [3 mm, 0], heading: 20 deg, r: 0.2 mm}\n")
    line = _out(capsys, ["analyze", str(path)]).out.splitlines()[1]
    t = 0.0026 / math.sin(math.radians(20))  # along the front axle from (3 mm, 0) to x = 0.4 mm
    (x, y), size = _numbers(line), 0.0026  # the wheels' spread about their centroid is below 2.6 mm
    assert abs(x - 0.0004) < 0.01 * size and abs(y - t * math.cos(math.radians(20))) < 0.01 * size, line


def test_a_robot_of_metres_keeps_its_icr_in_millimetres(capsys):
    """A robot of metres (the §4.6 tricycle): 3 decimals, as before."""
    line = _out(capsys, ["analyze", "thesis-tricycle-ch4"]).out.splitlines()[1]
    assert re.fullmatch(r"  ICR at \(-?\d+\.\d{3}, -?\d+\.\d{3}\) m", line), line
