"""``odometry``'s slip rule counts a turn on the spot as motion (the rotation at the wheels' distance): a cart on a
1 : -1 geared axle, whose only motion is that turn, gives a consistent log; a castor column out of scale still warns."""

from __future__ import annotations

import json

import numpy as np
import pytest

from geared import CASTOR, cart_yaml
from wmrkit import Robot
from wmrkit.cli.main import main
from wmrkit.odometry.synthetic import TwistProfile, simulate


def _log(tmp_path, scale: float):
    path = tmp_path / "cart.yaml"
    castor = CASTOR.replace("r: 0.025}", "r: 0.025, sensed: [spin, steer]}")  # sensed: the joints are redundant
    path.write_text(cart_yaml(-1.0, castor))  # the spins always opposite: it can only turn about the axle's middle
    robot = Robot.from_file(path)
    run = simulate(robot, TwistProfile.from_segments([(2.0, 0.0, 0.0, 0.5)]), 50.0)
    positions = run.log.heading_positions(robot).copy()
    positions[:, run.log.joints.index("caster.spin")] *= scale
    log = tmp_path / "spin.csv"
    rows = [",".join(["time", *run.log.joints])]
    rows += [",".join(f"{float(v):.17g}" for v in (t, *row)) for t, row in zip(run.log.time, positions, strict=True)]
    log.write_text("\n".join(rows) + "\n")
    return path, log, run.truth[-1]


def test_a_turn_on_the_spot_of_a_reversed_axle_is_consistent(tmp_path, capsys):
    path, log, truth = _log(tmp_path, 1.0)
    assert np.allclose(truth, [0.0, 0.0, 1.0])  # 2 s at 0.5 rad/s about the origin
    assert main(["odometry", str(path), str(log), "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert np.allclose(out["final_pose"], truth, atol=1e-4)  # the joints agree: the pose is right
    assert out["consistent"] is True and out["warnings"] == []  # was: "larger than the motion itself" (5e-8 m)


@pytest.mark.parametrize("scale", [2.0, -1.0])
def test_a_castor_column_out_of_scale_on_the_spot_still_warns(tmp_path, capsys, scale):
    path, log, _ = _log(tmp_path, scale)
    main(["odometry", str(path), str(log), "--json"])
    out = json.loads(capsys.readouterr().out)
    assert out["consistent"] is False
    assert any("the sensed joints contradict each other" in w for w in out["warnings"])
