"""Results as the commands show them (cli._shown): round-off printed as 0, a genuinely small value as computed, no
negative zero in text, CSV or JSON; a Table 8.1 jump with its unit.

Before: a straight diff-drive log printed ``y = -0.000000 m, theta = -0.000000 rad (-0.000 deg)`` and ``rotation
3.53884e-16 rad``; ``fk`` zeroed every value below an absolute 1e-12 (``--spin left=1e-12 --spin right=1e-12``:
``vx = 0 m/s``, where it is 7.5e-14 m/s) yet printed ``vy = -4.34251e-12 m/s`` and ``ik`` a roller at
``-1.77636e-08`` rad/s at 1e6 rad/s; ``simulate --out`` wrote ``-0`` cells; ``feasibility`` printed ``jump 1.57``
with no unit. The rule: a value within 1e-12 of its quantity's scale (the magnitudes it is computed from) is
round-off. Every expected number below is computed here from the robots' dimensions, not taken from the code."""

from __future__ import annotations

import csv
import json
import math
import re

import pytest

from wmrkit.cli._common import print_json
from wmrkit.cli._shown import fixed, tidy, tidy_pose, tidy_twist
from wmrkit.cli.main import main

R_DIFF, TRACK_DIFF = 0.075, 0.40  # diff-drive: wheel radius, track [m] (its catalog description)
R_MECANUM = 0.0762


def _log(path, left, right):
    """A diff-drive joint log over 1 s at 100 Hz, the spins [rad] given as functions of time."""
    rows = ["time [s],left.spin [rad],right.spin [rad]"]
    rows += [f"{k / 100!r},{left(k / 100)!r},{right(k / 100)!r}" for k in range(101)]
    path.write_text("\n".join(rows) + "\n", encoding="utf-8")
    return str(path)


def _out(capsys, argv, code=0):
    assert main(argv) == code
    return capsys.readouterr().out


def test_tidy_zeroes_roundoff_of_its_scale_only():
    assert tidy(3e-13, 1.0) == 0.0 and tidy(-3e-13, 1.0) == 0.0
    assert tidy(1e-9, 1.0) == 1e-9 and tidy(-1e-9, 1.0) == -1e-9  # a slip of 1e-9 m on a 1 m step is a slip
    assert tidy(1e-20, 1e-9) == 1e-20  # small, but not small for its scale
    assert math.copysign(1.0, tidy(-0.0, 0.0)) == 1.0  # never -0
    assert tidy_pose((1.0, -1e-18, -1e-18), 1.0, 0.2) == (1.0, 0.0, 0.0)
    assert tidy_pose((1.0, 1e-9, 1e-9), 1.0, 0.2) == (1.0, 1e-9, 1e-9)
    assert tidy_twist((2.0, -4e-17, 1e-15), 0.5) == (2.0, 0.0, 0.0)
    assert tidy_twist((2.0, 4e-9, 1e-9), 0.5) == (2.0, 4e-9, 1e-9)
    assert [fixed(v, 6) for v in (-1e-9, -0.0, -4e-7, -6e-7)] == ["0.000000", "0.000000", "0.000000", "-0.000001"]


def test_a_straight_odometry_run_prints_no_roundoff(tmp_path, capsys):
    """Both wheels at 10 rad/s for 1 s: x = r 10 = 0.75 m, the rest exactly 0."""
    out = _out(capsys, ["odometry", "diff-drive", _log(tmp_path / "s.csv", lambda t: 10 * t, lambda t: 10 * t)])
    lines = out.splitlines()
    assert lines[1] == f"final pose: x = {R_DIFF * 10:.6f} m, y = 0.000000 m, theta = 0.000000 rad (0.000 deg)"
    assert lines[2].startswith("path length 0.75 m, rotation 0 rad,")
    assert lines[3] == "slip indicator: max 0 m, rms 0 m per interval"


def test_a_small_genuine_rotation_is_printed(tmp_path, capsys):
    """The right wheel turning 5.33e-9 rad more over the run turns the robot by r d / track = 1e-9 rad."""
    extra = 1e-9 * TRACK_DIFF / R_DIFF
    out = _out(capsys, ["odometry", "diff-drive", _log(tmp_path / "s.csv", lambda t: 10 * t,
                                                       lambda t: 10 * t + extra * t)])
    rotation = float(re.search(r"rotation (\S+) rad", out)[1])
    assert rotation == pytest.approx(1e-9, rel=1e-4)


def test_fk_prints_a_tiny_twist_and_no_roundoff(capsys):
    out = _out(capsys, ["fk", "diff-drive", "--spin", "left=1e-12", "--spin", "right=1e-12"])
    assert out.splitlines() == [f"twist (robot frame): vx = {R_DIFF * 1e-12:.6g} m/s, vy = 0 m/s, omega = 0 rad/s",
                                "residual (slip norm): 0 m/s (consistent)"]
    spins = [a for w in ("front_left", "front_right", "rear_left", "rear_right") for a in ("--spin", f"{w}=1e6")]
    out = _out(capsys, ["fk", "mecanum-4", *spins])
    assert out.splitlines() == [f"twist (robot frame): vx = {R_MECANUM * 1e6:.6g} m/s, vy = 0 m/s, omega = 0 rad/s",
                                "residual (slip norm): 0 m/s (consistent)"]


def test_ik_prints_tiny_rates_and_no_roundoff(capsys):
    out = _out(capsys, ["ik", "diff-drive", "--twist", "1e-14", "0", "0"])
    assert [ln.split()[3] for ln in out.splitlines()[1:3]] == [f"{1e-14 / R_DIFF:.6g}"] * 2
    out = _out(capsys, ["ik", "mecanum-4", "--twist", "1e6", "0", "0"])
    rows = out.splitlines()[1:5]
    assert all(row.split()[3] == f"{1e6 / R_MECANUM:.6g}" and row.endswith("roller 0") for row in rows), out


def test_simulate_writes_no_negative_zero(tmp_path, capsys):
    """The first sample's forces are computed as -0.0 (a product with the zero slip): written as 0."""
    out = tmp_path / "sim.csv"
    _out(capsys, ["simulate", "forklift", "--path", "straight", "--duration", "0.02", "--out", str(out)])
    with open(out, encoding="utf-8") as f:
        cells = [c for row in list(csv.reader(f))[1:] for c in row]
    assert cells and not [c for c in cells if c.startswith("-") and float(c) == 0.0]
    out = tmp_path / "sim.json"
    _out(capsys, ["simulate", "forklift", "--path", "straight", "--duration", "0.02", "--out", str(out)])
    assert not re.search(r"-0\.0(?![0-9])", out.read_text())


def test_a_json_answer_has_no_negative_zero(capsys):
    print_json({"a": -0.0, "b": [1.0, -0.0, (-0.0,)], "c": -1e-300})
    data = json.loads(capsys.readouterr().out)
    assert "-0.0" not in json.dumps(data) and data["c"] == -1e-300


def test_a_feasibility_jump_has_its_unit(capsys):
    """The square's corners turn the tangent by a quarter turn: pi/2 rad, 90 deg."""
    out = _out(capsys, ["feasibility", "forklift", "--reference", "square"], 1)
    jumps = re.findall(r"tangent-angle jump \(chi not C0\), jump (\S+) rad \((\S+) deg\):", out)
    assert len(jumps) == 3 and all(float(r) == pytest.approx(math.pi / 2, rel=1e-2)
                                   and float(d) == pytest.approx(90, rel=1e-2) for r, d in jumps), out


def test_track_prints_a_tiny_error_and_no_roundoff(capsys):
    """The p law makes the error e0 exp(-a t) (a = 1/s). From on the 3 m circle it is 0 (the solver's 1.8e-12 m,
    on positions up to 6 m, was printed). From 1e-9 m off: max 1e-9 m, rms e0 / sqrt(2 T) over the circle's
    T = 2 pi 3 / 0.5 = 12 pi s (sampled every 0.05 s: 2.5 % more), and 1e-9 exp(-37.7) at the end, round-off. The
    diff drive tracks a point 0.25 m ahead of its axle (its origin)."""
    out = _out(capsys, ["track", "diff-drive", "--reference", "circle"])
    assert "tracking error [m]: rms 0, max 0, final 0\ncross-track error [m]: rms 0, max 0\n" in out
    out = _out(capsys, ["track", "diff-drive", "--reference", "circle", "--from", "-0.25", "1e-9", "0"])
    rms, top, final = (float(v) for v in re.search(r"tracking error \[m\]: rms (\S+), max (\S+), final (\S+)\n",
                                                   out).groups())
    assert top == pytest.approx(1e-9, rel=1e-3) and final == 0.0
    assert rms == pytest.approx(1e-9 / math.sqrt(2 * 12 * math.pi), rel=0.05)


@pytest.mark.parametrize("suffix", [".csv", ".tum"])
def test_odometry_writes_no_negative_zero(suffix, tmp_path, capsys):
    """A start pose given as '-0' was written as '-0' cells (and the TUM quaternion's sin(-0 / 2) as -0)."""
    out = tmp_path / f"o{suffix}"
    log = _log(tmp_path / "b.csv", lambda t: -10 * t, lambda t: -10 * t)
    _out(capsys, ["odometry", "diff-drive", log, "--pose", "0", "-0", "-0", "--out", str(out)])
    cells = [c for line in out.read_text().splitlines() if not line.startswith(("#", "time"))
             for c in re.split(r"[, ]", line)]
    assert cells and not [c for c in cells if c.startswith("-") and float(c) == 0.0]


def test_simulate_prints_no_roundoff_heading_off_its_path_and_keeps_a_real_one(capsys):
    """A straight run ended '-1.03e-18 rad' off its programmed path: 0 at the end; the figure-eight's real offset
    is printed as computed."""
    out = _out(capsys, ["simulate", "skid-steer-4", "--path", "straight", "--duration", "0.5", "--json"])
    heading = json.loads(out)["deviation"]["end_heading"]
    assert heading != 0 and abs(heading) < 1e-14  # the round-off the text hides
    text = _out(capsys, ["simulate", "skid-steer-4", "--path", "straight", "--duration", "0.5"])
    assert re.search(r"m and 0 rad at the end", text)


@pytest.mark.parametrize(("argv", "option", "si"), [
    (["simulate", "skid-steer-4", "--path", "straight", "--duration", "0.2"], "--speed", "1"),
    (["tyre", "pacejka", "--load", "5000", "--slip-ratio", "0.05"], "--speed", "10"),
])
def test_speed_options_take_speed_units(capsys, argv, option, si):
    """'--speed "3.6 km/h"' is 1 m/s, '36 km/h' 10 m/s: the same output as the SI number (it was refused)."""
    with_unit = f"{float(si) * 3.6:g} km/h"
    assert _out(capsys, [*argv, option, with_unit]) == _out(capsys, [*argv, option, si])


def test_an_initial_twist_component_of_the_wrong_kind_is_refused_by_name(capsys):
    assert main(["simulate", "skid-steer-4", "--path", "straight", "--initial-twist", "1 m/s", "0", "1 mm/s"]) == 2
    assert capsys.readouterr().err == ("wmrkit: error: --initial-twist OMEGA: '1 mm/s' is a speed, expected an "
                                       "angular rate\n")
