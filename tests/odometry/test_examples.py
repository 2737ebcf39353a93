"""The odometry examples run and print what their docstrings promise."""

from __future__ import annotations

import runpy
import sys
from pathlib import Path

import pytest

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


def test_square_example(capsys):
    runpy.run_path(str(EXAMPLES / "odometry_square.py"), run_name="__main__")
    out = capsys.readouterr().out
    assert "exact: " in out and "calibrated  cw: return error" in out
    errors = [float(line.split()[-2]) for line in out.splitlines() if line.startswith("calibrated")]
    assert max(errors) < 2e-3  # after calibration the squares close to encoder resolution


def test_forklift_log_example(capsys, tmp_path, monkeypatch):
    monkeypatch.setattr(sys, "argv", ["odometry_forklift_log.py", str(tmp_path)])
    runpy.run_path(str(EXAMPLES / "odometry_forklift_log.py"), run_name="__main__")
    out = capsys.readouterr().out
    assert (tmp_path / "forklift.tum").exists() and (tmp_path / "forklift_weighted.png").exists()
    weighted = next(line for line in out.splitlines() if line.startswith("weights {'steer'"))
    assert float(weighted.split("error ")[1].split(" m")[0]) < 0.01


@pytest.mark.parametrize("name", ["odometry_square.py", "odometry_forklift_log.py"])
def test_examples_have_a_docstring_that_says_how_to_run_them(name):
    text = (EXAMPLES / name).read_text()
    assert text.startswith('"""') and f"python examples/{name}" in text
