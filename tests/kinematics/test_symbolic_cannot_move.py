"""``kinematics --symbolic`` on a robot that cannot move (m = 0 at every steering): the exact answer, every velocity
zero, as the numeric models say, never a least-squares fit; a robot with m = 0 only at uncoordinated steering keeps
its least-squares (extended) forms."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import yaml

from wmrkit import Robot, Wheel, catalog
from wmrkit.cli.main import main
from wmrkit.kinematics.symbolic import cannot_move, format_symbolic


def _fixed(name: str, x: float, y: float, heading_deg: float) -> Wheel:
    """A fixed wheel at (x, y) [m] rolling along `heading_deg` (its axle at heading + 90 deg)."""
    return Wheel(name=name, type="fixed", l=math.hypot(x, y), alpha=math.atan2(y, x),
                 beta=math.radians(heading_deg + 90.0), r=0.1, actuated=("spin",), sensed=("spin",))


#: Three fixed wheels whose axles do not meet at one point: no twist rolls them all.
STUCK = (_fixed("a", 0.5, 0.0, 0.0), _fixed("b", -0.5, 0.3, 60.0), _fixed("c", -0.5, -0.3, -60.0))


def _nullity(robot: Robot, beta: np.ndarray) -> np.ndarray:
    """Brute force: the null space of the no-slip matrix (3.22) by SVD, at each configuration ``(n, n_steer)``."""
    a = robot.constraint_matrix(beta)
    s = np.linalg.svd(a, compute_uv=False)
    return a.shape[-1] - np.sum(s > 1e-9 * s[..., :1], axis=-1)


def test_three_fixed_wheels_on_axles_that_do_not_meet_print_every_velocity_zero_exactly(tmp_path: Path, capsys):
    """The no-slip matrix has full column rank (brute-force SVD): only q = 0 rolls. Before, both closed forms were
    least squares ("least squares (4.11)/(4.82): 3 assigned for mobility m = 0", vx = 1/30*a.spin + ...)."""
    robot = Robot(name="stuck", wheels=STUCK)
    assert _nullity(robot, np.zeros((1, 0)))[0] == 0
    assert cannot_move(robot)
    text = format_symbolic(robot)
    assert "least squares" not in text
    assert text.count("the robot cannot move (m = 0 at every steering") == 2
    assert text.count("assigned: nothing") == 2
    for name in robot.velocity_names:
        assert text.count(f"    {name} = 0\n") + text.endswith(f"    {name} = 0") == 2, name
    path = tmp_path / "stuck.yaml"
    path.write_text(yaml.safe_dump({"name": "stuck", "wheels": [
        {"name": "a", "type": "fixed", "position": [0.5, 0.0], "heading": 0.0, "r": 0.1, "actuated": ["spin"]},
        {"name": "b", "type": "fixed", "position": [-0.5, 0.3], "heading": "60 deg", "r": 0.1, "actuated": ["spin"]},
        {"name": "c", "type": "fixed", "position": [-0.5, -0.3], "heading": "-60 deg", "r": 0.1,
         "actuated": ["spin"]}]}))
    assert main(["kinematics", str(path), "--symbolic"]) == 0
    out = capsys.readouterr().out
    assert "least squares" not in out and out.count("the robot cannot move") == 4  # numeric and closed forms


def test_a_steered_wheel_does_not_free_a_stuck_robot():
    """The three fixed wheels and a steerable one: nullity 0 at 200 random steering angles (brute force)."""
    robot = Robot(name="stuck", wheels=(*STUCK, Wheel(name="s", type="steerable", l=0.8, alpha=2.0, beta=0.3, r=0.2)))
    beta = np.random.default_rng(1).uniform(-math.pi, math.pi, (200, 1))
    assert not _nullity(robot, beta).any()
    assert cannot_move(robot)
    assert "least squares" not in format_symbolic(robot)


def test_robots_that_move_at_some_steering_keep_their_least_squares_forms():
    """m = 0 at generic steering, m >= 1 where the axles meet: Ackermann and swerve (described straight ahead), and
    two fixed wheels whose axles cross at (0, 0) with a steered wheel aimed there. Their forms stay least squares."""
    crossing = Robot(name="x", wheels=(_fixed("a", 0.0, 0.5, 0.0), _fixed("b", 0.5, 0.0, 90.0),
                                       Wheel(name="s", type="steerable", l=0.7, alpha=2.5, beta=2.5, r=0.2)))
    for robot in (catalog.load("ackermann"), catalog.load("swerve-4"), crossing):
        assert _nullity(robot, robot.beta[None])[0] >= 1, robot.name  # it moves at this steering
        assert not cannot_move(robot), robot.name
    assert "least squares" in format_symbolic(crossing)
