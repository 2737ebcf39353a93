"""A path follower's default run through the dynamics stops at the control period where it has arrived, instead of
being simulated to its whole bound (the reference's duration and the followers' extra time) and trimmed there: the
same samples, bit for bit, as the whole run trimmed by :func:`.follower_run.ended`, in fewer periods."""

from __future__ import annotations

import importlib

import numpy as np
import pytest

from wmrkit import catalog
from wmrkit.cli.control import min_turning_radius
from wmrkit.control.follower_run import ended
from wmrkit.control.references import builtin_reference, default_size
from wmrkit.control.track import track

PLANT = importlib.import_module("wmrkit.control.dynamic_plant")
SLIP = importlib.import_module("wmrkit.control.slip_loop")


def _spy(monkeypatch, module, name: str) -> list:
    """Replace the loop `module.name` by one that also runs it whole (until=None) and keeps both answers."""
    real, calls = getattr(module, name), []

    def loop(*args, until=None, **kwargs):
        whole = real(*args, **kwargs)
        stopped = real(*args, until=until, **kwargs)
        calls.append((whole, stopped, until))
        return stopped

    monkeypatch.setattr(module, name, loop)
    return calls


def _check_same_as_trimmed(calls: list, run) -> None:
    (whole, stopped, until), = calls
    assert until is not None  # the follower's arrival reaches the loop
    trimmed = ended(whole, until)
    assert trimmed.keys() == stopped.keys()
    for key, value in trimmed.items():
        if isinstance(value, np.ndarray):
            assert value.dtype == stopped[key].dtype and np.array_equal(value, stopped[key]), key
    assert len(stopped["t"]) < len(whole["t"])  # fewer periods simulated than the whole bound
    hits = [until(float(t), p) for t, p in zip(stopped["t"], stopped["pose"], strict=True)]  # a run's samples
    assert hits[-1] and not any(hits[:-1])
    assert np.array_equal(run.t, stopped["t"]) and np.array_equal(run.pose, stopped["pose"])


@pytest.mark.parametrize(("name", "ref_name", "controller"), [("forklift", "circle", "pure-pursuit"),
                                                              ("forklift", "line", "stanley"),
                                                              ("skid-steer-4", "line", "pure-pursuit")])
def test_a_follower_through_the_dynamics_stops_where_the_whole_run_is_trimmed(monkeypatch, name, ref_name,
                                                                              controller):
    robot = catalog.load(name)
    ref = builtin_reference(ref_name, size=default_size(ref_name, min_turning_radius(robot)))
    calls = _spy(monkeypatch, PLANT, "simulate_dynamics")
    _check_same_as_trimmed(calls, track(robot, ref, controller=controller, dynamics=True))


def test_a_follower_through_the_slip_loop_stops_where_the_whole_run_is_trimmed(monkeypatch):
    robot, ref = catalog.load("forklift"), builtin_reference("line")
    calls = _spy(monkeypatch, SLIP, "simulate_slip_control")
    _check_same_as_trimmed(calls, track(robot, ref, controller="pure-pursuit", dynamics=True, slip_model="mqe"))
