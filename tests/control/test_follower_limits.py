"""A path follower's longer default run (the reference's duration plus its extra time) never turns an answer into a
refusal: the extra time shrinks to what the loop's limits allow, and a run that then ends on its way says which
limit cut it. The limits are lowered here so that the runs are short; the arithmetic is the loops' own."""

from __future__ import annotations

import importlib
import json
import math

import numpy as np
import pytest

from wmrkit import catalog
from wmrkit.cli.main import main
from wmrkit.control.points import control_point
from wmrkit.control.trackers import APPROACH_FLOOR, ARRIVAL_FRACTION, default_lookahead

LOOP = importlib.import_module("wmrkit.control.loop")
TRACK = importlib.import_module("wmrkit.control.track")
LINE = ["--reference", "line", "--controller", "pure-pursuit", "--json"]  # 10 m along +x at 0.5 m/s: 20 s


def _sampled_limit(monkeypatch, evaluations: int) -> None:
    monkeypatch.setattr(LOOP, "MAX_SAMPLED_EVALUATIONS", evaluations)
    monkeypatch.setattr(TRACK, "MAX_SAMPLED_EVALUATIONS", evaluations)


def _line_follower(samples: int, period: float, length: float) -> np.ndarray:
    """The axle point's arc length on the 10 m line at each period: the path's 0.5 m/s held a period, scaled by
    sqrt(d / L) within L of the end (the car starts on the line, aligned: pure pursuit drives straight)."""
    s = [0.0]
    for _ in range(samples - 1):
        d = 10.0 - s[-1]
        s.append(s[-1] + period * 0.5 * (max(APPROACH_FLOOR, math.sqrt(d / length)) if d < length else 1.0))
    return np.array(s)


def test_a_sampled_follower_whose_extra_time_passes_the_limit_answers(monkeypatch, capsys):
    """With a sampled loop allowed 215 evaluations (the ideal plant: one a period), the line's 20 s at 0.1 s (201
    periods) fit, its follower's 30 s (301) do not: 'wmrkit track ackermann --reference line --controller
    pure-pursuit --period 0.1' was refused (exit 2, '301 periods, more than 215 evaluations'). Now the extra time is
    cut to 1.4 s (214 periods after the first: 215 evaluations), the car is still braking 0.361 m before the end, as
    the held-speed recurrence says, beyond its tolerance (0.27 m: 0.1 of its 2.7 m lookahead), and the warning
    names the limit."""
    _sampled_limit(monkeypatch, 215)
    assert main(["track", "ackermann", *LINE, "--period", "0.1"]) == 0
    out = json.loads(capsys.readouterr().out)
    t, x = np.array(out["t"]), np.array(out["pose"])[:, 0]
    assert len(t) == 215 and t[-1] == pytest.approx(21.4)
    robot = catalog.load("ackermann")
    lookahead = default_lookahead(control_point(robot, None), 0.5)
    expected = _line_follower(len(t), 0.1, lookahead)
    np.testing.assert_allclose(x - x[0], expected, atol=1e-9)  # the axle point is R's offset: the same motion
    gap = 10.0 - expected[-1]
    assert gap > ARRIVAL_FRACTION * lookahead
    [said] = [w for w in out["warnings"] if "did not reach the path's end" in w]
    assert f"ended {gap:.4g} m from it" in said
    assert ("the followers' extra time after the reference's 20 s was cut to 1.4 s by the sampled loop's limit of "
            "215 evaluations; give a longer period (--period)") in said


def test_only_the_extra_time_is_cut(monkeypatch, capsys):
    """Where the cut leaves time enough (280 evaluations: 27.9 s), the follower arrives as without a limit (before:
    refused) and nothing is said; where the reference's own duration does not fit (150 evaluations), the run is
    refused as before, for the reference's duration, not the follower's longer one."""
    _sampled_limit(monkeypatch, 280)
    assert main(["track", "ackermann", *LINE, "--period", "0.1"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert 20.0 < out["t"][-1] < 27.9 and not out["warnings"]
    x = np.array(out["pose"])[:, 0]
    assert 10.0 - (x[-1] - x[0]) < 0.1  # the axle point (R's offset, aligned) at the end
    _sampled_limit(monkeypatch, 150)
    assert main(["track", "ackermann", *LINE, "--period", "0.1"]) == 2
    err = json.loads(capsys.readouterr().err)["error"]
    assert err.startswith("duration 20 s at a period of 0.1 s: 201 periods, more than 150 evaluations"), err


def test_a_follower_through_the_dynamics_whose_extra_time_passes_the_limit_answers(monkeypatch, capsys):
    """Through the dynamics (1 ms steps) with 21,000 steps allowed, the line's 20 s fit and the follower's 30 s did
    not: refused (exit 2). Now the run lasts 21 s and says the dynamics' limit cut it."""
    monkeypatch.setattr(importlib.import_module("wmrkit.dynamics.simulate"), "MAX_STEPS", 21_000)
    assert main(["track", "forklift", *LINE, "--dynamics"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["t"][-1] == pytest.approx(21.0)
    [said] = [w for w in out["warnings"] if "did not reach the path's end" in w]
    assert "was cut to 1 s by the dynamics' limit of" in said and "integration steps" in said
