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


@pytest.mark.parametrize("path", sorted(EXAMPLES.glob("*.py")), ids=lambda p: p.name)
def test_every_example_has_a_docstring_that_says_how_to_run_it(path):
    text = path.read_text()
    assert text.startswith('"""') and f"python examples/{path.name}" in text
    assert len(text.splitlines()) <= 90
