"""``wmrkit track`` records the warnings of its run and says them: it said only the four classes it listed
(sampling, gate, arrival, linkage), so any other raised in the run (a kinematics GearWarning, numpy's
RuntimeWarning) was silently dropped, on stderr and in the JSON "warnings"."""

from __future__ import annotations

import importlib
import json
import warnings

import numpy as np
import pytest

from wmrkit.cli.main import main
from wmrkit.couplings import GearWarning
from wmrkit.errors import WmrkitError

GEAR = "the test's gear warning"
track_module = importlib.import_module("wmrkit.control.track")  # the package's `track` is the function


@pytest.fixture
def warning_run(monkeypatch):
    """``track`` with a run that raises a GearWarning twice and numpy's divide-by-zero RuntimeWarning; `fail`:
    then an error."""
    real = track_module.track
    state = {"fail": False}

    def run(*args, **kwargs):
        for _ in range(2):  # said once
            warnings.warn(GEAR, GearWarning, stacklevel=1)
        np.array(1.0) / np.array(0.0)
        if state["fail"]:
            raise WmrkitError("the run's error")
        return real(*args, **kwargs)

    monkeypatch.setattr(track_module, "track", run)
    return state


def test_track_says_every_warning_of_its_run(warning_run, capsys):
    argv = ["track", "diff-drive", "--reference", "line", "--duration", "1"]
    with pytest.warns(RuntimeWarning, match="divide by zero"):  # passed on as numpy raised it
        assert main(argv) == 0
    err = capsys.readouterr().err
    assert err.count(f"wmrkit: warning: {GEAR}\n") == 1
    with pytest.warns(RuntimeWarning, match="divide by zero"):
        assert main([*argv, "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["warnings"] == [GEAR]


def test_track_says_them_before_its_error(warning_run, capsys):
    warning_run["fail"] = True
    with pytest.warns(RuntimeWarning, match="divide by zero"):
        assert main(["track", "diff-drive", "--reference", "line", "--duration", "1"]) == 2
    err = capsys.readouterr().err
    assert err == f"wmrkit: warning: {GEAR}\nwmrkit: error: the run's error\n"
