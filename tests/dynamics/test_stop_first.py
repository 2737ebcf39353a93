"""A run that fails says why first and fast: a wheel that lifts off before the state diverges is reported as the
lift-off (not as a divergence blamed on the step), and the adaptive integrator stops where its state leaves the
physical range instead of grinding through its budget of evaluations."""

from __future__ import annotations

import pytest

from wmrkit import Robot
from wmrkit.cli.main import main
from wmrkit.dynamics.inputs import Inputs
from wmrkit.dynamics.model import DynamicModel
from wmrkit.dynamics.runs import LiftOffError
from wmrkit.dynamics.simulate import simulate

LIGHT = {"name": "light", "body": {"mass": 0.1, "inertia": 0.001, "com": [-0.05, 0], "com_height": 0.05},
         "wheels": [{"name": "left", "type": "fixed", "position": [0, 0.2], "heading": 0, "r": 0.075,
                     "actuated": ["spin"], "inertia": {"spin": 1e-4}},
                    {"name": "right", "type": "fixed", "position": [0, -0.2], "heading": 0, "r": 0.075,
                     "actuated": ["spin"], "inertia": {"spin": 1e-4}},
                    {"name": "caster", "type": "castor", "position": [-0.25, 0], "heading": 0, "d": 0.04,
                     "r": 0.025, "inertia": {"spin": 1e-5, "steer": 1e-5}}]}
BIG = 1e9  # N m: within MAX_TORQUE (1e10), absurd on a 0.1 kg robot


def _light(tyre: str | None = None) -> tuple[DynamicModel, Inputs]:
    model = DynamicModel.of(Robot.from_dict(LIGHT), tyre)
    return model, Inputs.torques_only(model, [0.0, 1.0], {"left.spin": [BIG, BIG], "right.spin": [BIG, BIG]})


def test_a_lift_off_before_the_divergence_is_reported_first(tmp_path, capsys):
    """Before: "the simulation diverged before t = 1 s; use a smaller step (--step) or the adaptive method (or
    smaller torques or speeds)", though a wheel lifted off in the first steps (and a shorter step diverged too)."""
    model, inputs = _light()
    with pytest.raises(LiftOffError) as short:  # a run too short to diverge: the lift-off alone
        simulate(model, inputs, 0.001)
    with pytest.raises(LiftOffError) as full:
        simulate(model, inputs, 1.0)
    assert (full.value.t, full.value.contact) == (short.value.t, short.value.contact)
    assert str(full.value) == str(short.value) and str(full.value).endswith("use smaller torques or speeds")
    robot, torques = tmp_path / "light.yaml", tmp_path / "big.csv"
    robot.write_text(str(LIGHT).replace("'", '"'))  # JSON is YAML
    torques.write_text(f"time,left.spin,right.spin\n0,{BIG:g},{BIG:g}\n1,{BIG:g},{BIG:g}\n")
    assert main(["simulate", str(robot), "--torques", str(torques)]) == 2
    out, err = capsys.readouterr()
    assert out == "" and err == f"wmrkit: error: {short.value}\n"
