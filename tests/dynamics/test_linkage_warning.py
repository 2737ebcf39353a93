"""A linkage the dynamics do not hold (no ``law``, none to default to: a four-wheel-steer car's pairs) is said
wherever a dynamic model is built: a :class:`LinkageWarning` from ``DynamicModel.of`` (so from ``simulate``,
``Stepper`` and the loops through the dynamics), one ``wmrkit: warning:`` line and one JSON item per linkage from
``simulate`` and ``track --dynamics``, never a Python warning's text on stderr."""

from __future__ import annotations

import json
import warnings

import pytest
from test_linkage_law import four_wheel_steer

from wmrkit import Robot
from wmrkit.cli.main import main
from wmrkit.dynamics.linkages import LinkageWarning
from wmrkit.dynamics.model import DynamicModel
from wmrkit.dynamics.simulate import Inputs, Stepper, simulate

HEADS = ["the steering linkage of wheels 'fl' and 'fr' is not held by the dynamics",
         "the steering linkage of wheels 'rl' and 'rr' is not held by the dynamics"]


def _said(run) -> tuple[object, list[warnings.WarningMessage]]:
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        out = run()
    return out, [w for w in caught if issubclass(w.category, LinkageWarning)]


def test_the_python_api_warns_where_the_model_is_built():
    """Before, ``DynamicModel.of``, ``simulate`` and ``Stepper`` said nothing (only the CLI's simulate did)."""
    robot = Robot.from_dict(four_wheel_steer())
    model, said = _said(lambda: DynamicModel.of(robot))
    assert [str(w.message).split(":")[0] for w in said] == HEADS
    assert all("law field" in str(w.message) for w in said)
    assert said[0].filename == __file__  # at the caller's line
    inputs = Inputs.torques_only(model, [0.0, 0.01], {"fl.steer": [0.02, 0.02]})
    assert len(_said(lambda: simulate(robot, inputs, 0.01, step=1e-3))[1]) == 2  # simulate builds it: warns
    assert len(_said(lambda: Stepper(robot))[1]) == 2
    assert _said(lambda: simulate(model, inputs, 0.01, step=1e-3))[1] == []  # given the model: already said
    assert _said(lambda: Stepper(model))[1] == []


def test_a_held_linkage_does_not_warn():
    assert _said(lambda: DynamicModel.of(Robot.from_dict(four_wheel_steer("parallel"))))[1] == []


def _cli(tmp_path, capsys, *args: str) -> tuple[dict, list[str], list]:
    path = tmp_path / "car.json"
    path.write_text(json.dumps(four_wheel_steer()))
    code, leaked = _said(lambda: main([args[0], str(path), *args[1:], "--json"]))
    assert code == 0
    captured = capsys.readouterr()
    return json.loads(captured.out), captured.err.splitlines(), leaked


@pytest.mark.parametrize("args", [("simulate", "--path", "straight", "--speed", "0.5"),
                                  ("track", "--reference", "line", "--duration", "0.2", "--dynamics")])
def test_the_cli_says_it_once_per_linkage(tmp_path, capsys, args):
    """``track --dynamics`` said nothing before; ``simulate`` says it once (not again as a Python warning)."""
    answer, err, leaked = _cli(tmp_path, capsys, *args)
    assert leaked == []
    assert [x.split(":")[0] for x in answer["warnings"] if "not held" in x] == HEADS
    lines = [x for x in err if "not held" in x]
    assert [x.split(" is not held")[0] for x in lines] == [f"wmrkit: warning: {h.split(' is')[0]}" for h in HEADS]
    assert not any("LinkageWarning" in x for x in err)

