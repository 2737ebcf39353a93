"""``fk`` judges a given ``omega`` (a gyro's rate) by the speed it gives the wheels, omega times the robot's size
(:func:`~wmrkit.kinematics.linalg.robot_size`), not as 1 m/s per rad/s: the same contradiction between the wheels
and the gyro gets the same verdict on the robot scaled by 1e-3 and by 1e3."""

from __future__ import annotations

import json
from dataclasses import replace

import numpy as np
import pytest

from wmrkit import Robot
from wmrkit.catalog import load
from wmrkit.cli.main import main
from wmrkit.description import robot_to_dict
from wmrkit.kinematics.linalg import LENGTH_FIELDS


def _scaled_file(tmp_path, factor: float) -> str:
    """diff-drive with every length multiplied by `factor` (fields, not the library), written as a description."""
    robot = load("diff-drive")
    scaled = replace(robot, wheels=tuple(replace(w, **{f: getattr(w, f) * factor for f in LENGTH_FIELDS})
                                         for w in robot.wheels))
    path = tmp_path / f"dd_{factor:g}.json"
    path.write_text(json.dumps(robot_to_dict(scaled)))
    return str(path)


def _fk(path: str, capsys, *rates: str) -> dict:
    args = [a for r in rates for a in ("--spin", r)]
    assert main(["fk", path, *args, "--json"]) == 0
    return json.loads(capsys.readouterr().out)


@pytest.mark.parametrize("factor", [1e-3, 1.0, 1e3])
def test_a_gyro_rate_the_wheels_contradict_is_inconsistent_at_any_scale(tmp_path, capsys, factor):
    path = _scaled_file(tmp_path, factor)
    robot = Robot.from_file(path)
    # Brute force: the wheels alone (equal spins) fix omega = 0; the gyro says 0.5 rad/s. The least-squares twist
    # leaves slip on both wheels of about omega * half-track each, a fixed fraction of the wheels' speeds.
    out = _fk(path, capsys, "left=10", "right=10", "omega=0.5")
    half_track = robot.wheel("left").l
    assert out["residual"] > 0.1 * 0.5 * half_track  # a sizeable share of the wheels' speed from the rotation
    assert out["consistent"] is False  # at 1e-3 was True: tolerance 0.02 * 0.5 "m/s" from omega alone
    assert set(out["slipping"]) == {"left", "right"}


@pytest.mark.parametrize("factor", [1e-3, 1.0, 1e3])
def test_a_gyro_rate_that_agrees_with_the_wheels_stays_consistent(tmp_path, capsys, factor):
    path = _scaled_file(tmp_path, factor)
    robot = Robot.from_file(path)
    r, b = robot.wheel("left").r, robot.wheel("left").l
    omega = r * (12 - 10) / (2 * b)  # closed form of a differential drive: r (right - left) = 2 b omega
    out = _fk(path, capsys, "left=10", "right=12", f"omega={omega:.17g}")
    assert out["consistent"] is True and out["slipping"] == []
    assert np.allclose(out["twist"], [r * 11, 0.0, omega], rtol=1e-9, atol=1e-12 * factor)
