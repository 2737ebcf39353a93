"""The examples of examples/ run and their numbers hold against an independent reference (a closed form, a check
computed another way, the documented values), not just "it ran". The odometry examples are tested in
tests/odometry/test_examples.py."""

from __future__ import annotations

import math
import re
import runpy
import sys
from pathlib import Path

import numpy as np
import pytest

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def run_example(name: str, folder: Path, monkeypatch, capsys) -> tuple[dict, str]:
    """The example's globals and what it printed, run as a script with `folder` as its argument."""
    monkeypatch.setattr(sys, "argv", [name, str(folder)])
    scope = runpy.run_path(str(EXAMPLES / name), run_name="__main__")
    return scope, capsys.readouterr().out


def numbers(line: str) -> list[float]:
    return [float(x) for x in re.findall(r"[-+]?\d+\.?\d*(?:e[-+]?\d+)?", line)]


def test_slip_skid_steer(tmp_path, monkeypatch, capsys):
    scope, out = run_example("slip_skid_steer.py", tmp_path, monkeypatch, capsys)
    fit, a, b = scope["fit"], scope["a"], scope["b"]
    assert 0.6 < fit.ratio < 0.9  # docs/slip.md: k = 0.77 on the quasi-static model
    assert fit.multiplier == pytest.approx(1 + fit.ratio * (a / b) ** 2, abs=1e-6)  # one model on a symmetric skid
    rows = {line[:24].strip(): numbers(line[24:]) for line in out.splitlines()
            if line.startswith(("calibration run", "tight loop", "slalom"))}
    assert len(rows) == 3
    for no_slip, track, wls, gap in rows.values():
        assert wls < no_slip / 2.5 and wls == pytest.approx(track, abs=1e-4) and gap < 1e-6
    assert len(list(tmp_path.glob("skid-*.png"))) == 3


def test_track_forklift(tmp_path, monkeypatch, capsys):
    scope, out = run_example("track_forklift.py", tmp_path, monkeypatch, capsys)
    run, pi, dyn, a = scope["run"], scope["pi"], scope["dyn"], scope["GAIN"]
    e0 = math.hypot(0.0, 0.5)
    assert run.error[0] == pytest.approx(e0)  # recomputed here, not read from the example
    assert np.max(np.abs(run.error - e0 * np.exp(-a * run.t))) < 2e-7  # docs/control.md: to 2e-7 m
    assert np.max(np.abs(pi.error - np.abs(e0 * (1 - a * pi.t / 2) * np.exp(-a * pi.t / 2)))) < 2e-7
    assert dyn.error[-1] < 5e-3 and np.max(dyn.error[dyn.t >= 10]) < 5e-3  # docs: about 1.3 mm of tyre slip
    assert "P law:  error 0.50 m" in out and (tmp_path / "track-dynamics.png").exists()


def test_park_car(tmp_path, monkeypatch, capsys):
    pytest.importorskip("shapely")
    scope, out = run_example("park_car.py", tmp_path, monkeypatch, capsys)
    lines = out.splitlines()
    assert re.findall(r"slot: (\d+) manoeuvres", out) == ["2", "4"]  # Tables 9.1 and 9.2
    assert sum("parked corners inside the slot: True" in line for line in lines) == 2
    asked = [float(x) for x in re.findall(r"asked: below (\S+) cm", out)]
    gaps = [numbers(line.split("from the corners")[1])[0] for line in lines if "from the corners" in line]
    assert asked == [7, 17] and len(gaps) == 2  # Tables 9.1 and 9.2
    assert all(0 < gap < limit for gap, limit in zip(gaps, asked, strict=True))
    assert gaps == [float(x) for x in re.findall(r"final gap to the curb (\S+) cm", out)]  # the planner's own
    assert sum(line.endswith("collision-free True") for line in lines) == 2
    driven, plan = scope["driven"], scope["plan"]  # thesis-9.1 with the P law
    assert driven.deviation.max() < 0.02  # docs/parking.md: within 2 cm
    assert np.hypot(*(driven.pose[-1, :2] - np.array(plan.final_pose[:2]))) < 0.01
    assert "shortest slot that works: 2.642 m" in out  # docs/parking.md
    assert len(list(tmp_path.glob("park-*.png"))) == 2


def test_follow_line(tmp_path, monkeypatch, capsys):
    pytest.importorskip("cv2")
    scope, out = run_example("follow_line.py", tmp_path, monkeypatch, capsys)
    runs = [line for line in out.splitlines() if line.startswith("line-follower")]
    assert len(runs) == 2
    for line, overshoots in zip(runs, (False, True), strict=True):
        assert "images lost 0" in line
        final = float(line.split("->")[1].split(" cm")[0])
        overshoot = float(line.split("overshoot ")[1].split(" cm")[0])
        agree = float(line.split("give h within ")[1].split(" mm")[0])
        # a one-period delay: real roots of z^2 - z + aT for aT <= 1/4 (a = 0.3), complex for a = 0.8
        assert abs(final) < 0.5 and (overshoot > 1.0 if overshoots else overshoot == 0.0) and agree < 1.0
    h, recursion = scope["h"], np.array(scope["recursion"])
    assert np.max(np.abs(h - recursion)) < 5e-4  # the camera path against the exact delayed recursion
    assert abs(h[0]) == pytest.approx(0.3) and abs(h[-1]) < 1e-3
    assert (tmp_path / "follow-line-first-image.png").exists()


def test_design_sweep(tmp_path, monkeypatch, capsys):
    scope, out = run_example("design_sweep.py", tmp_path, monkeypatch, capsys)
    best = scope["result"].best[0]
    assert best[scope["ALPHA"]] == pytest.approx(math.radians(60)) and best[scope["BACK_L"]] == pytest.approx(0.2)
    assert best["kappa_mean"] == pytest.approx(1.0, abs=1e-6)  # the symmetric kiwi drive is isotropic
    assert best["length"] == pytest.approx(math.sqrt(2) * 0.2, rel=1e-6)  # D = sqrt(2) L (docs/analysis.md)
    rebuilt = [line for line in out.splitlines() if line.strip().startswith("rebuilt")]
    assert len(rebuilt) == 4
    for line in rebuilt:
        assert abs(numbers(line.split("the sweep's:")[1])[0]) < 1e-6
    assert numbers(rebuilt[-1].split("kappa")[1])[0] > 1.5  # the worst design of the grid
    assert (tmp_path / "sweep-omni-3.png").exists()


@pytest.mark.parametrize("path", sorted(EXAMPLES.glob("*.py")), ids=lambda p: p.name)
def test_every_example_has_a_docstring_that_says_how_to_run_it(path):
    text = path.read_text()
    assert text.startswith('"""') and f"python examples/{path.name}" in text
    assert len(text.splitlines()) <= 90


def test_the_readme_lists_every_example_with_a_command_that_runs_it():
    """The README's Examples block: one `python examples/NAME.py [DIR]` per example (each is run by the tests above
    or by tests/odometry/test_examples.py with such an argument)."""
    readme = (EXAMPLES.parent / "README.md").read_text()
    block = readme.split("## Examples", 1)[1].split("```", 2)[1]
    commands = [re.sub(r"\s+#.*$", "", line).split() for line in block.splitlines() if line.strip()]
    assert all(words[0] == "python" and len(words) <= 3 for words in commands)
    assert sorted(words[1] for words in commands) == sorted(f"examples/{p.name}" for p in EXAMPLES.glob("*.py"))
