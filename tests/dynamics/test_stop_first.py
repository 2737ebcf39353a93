"""A run that fails says why first and fast: a wheel that lifts off before the state diverges is reported as the
lift-off (not as a divergence blamed on the step), and the adaptive integrator stops where its state leaves the
physical range instead of grinding through its budget of evaluations."""

from __future__ import annotations

import numpy as np
import pytest

from wmrkit import Robot
from wmrkit.cli.main import main
from wmrkit.dynamics.inputs import Inputs, compiled_inputs
from wmrkit.dynamics.model import DynamicModel
from wmrkit.dynamics.runs import LiftOffError
from wmrkit.dynamics.simulate import simulate
from wmrkit.errors import WmrkitError

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


def _counted(monkeypatch) -> list:
    """Count the evaluations of the model (the adaptive run's right-hand side and its records)."""
    from wmrkit.dynamics import _integrate

    calls, derivative = [], _integrate.derivative
    monkeypatch.setattr(_integrate, "derivative", lambda *a: calls.append(a[0]) or derivative(*a))
    return calls


def test_the_adaptive_run_stops_where_its_state_leaves_the_physical_range(monkeypatch):
    """Before: with linear tyres (the loads do not act) and the lift-off allowed, LSODA ground through its 1e7
    evaluations (3 min) to "needed more than 1e+07 evaluations of the model by t = 0.0008 s": the robot spins at
    2.3e6 rad/s where round-off in the forces outgrows the tolerance, and the steps fall to 1e-9 s. It stops at the
    first accepted state past limits.MAX_SPEED now, in a few hundred evaluations (the budget here: 1e5)."""
    from wmrkit.dynamics import runs
    from wmrkit.limits import MAX_SPEED

    monkeypatch.setattr(runs, "MAX_EVALUATIONS", 100_000)
    calls = _counted(monkeypatch)
    model, inputs = _light("linear")
    with pytest.raises(WmrkitError) as err:
        simulate(model, inputs, 1.0, method="adaptive", allow_lift_off=True)
    message = str(err.value)
    assert message.startswith("the adaptive integration left the physical range at t = ") and len(calls) < 5000
    assert "use smaller torques or speeds" in message and "\n" not in message
    # independently: the same solver, unstopped, is past 1e3 m/s there (a wheel's rim: its rate times its radius)
    t_stop = float(message.split("t = ")[1].split(" s")[0])
    from scipy.integrate import solve_ivp

    from wmrkit.dynamics._integrate import derivative, model_work_arrays
    from wmrkit.dynamics.simulate import initial_state

    w, acc, pack, inp = model_work_arrays(model), np.zeros(model.n), model.pack, compiled_inputs(model, inputs)
    s0 = initial_state(model, (0, 0, 0), (0, 0, 0))
    sol = solve_ivp(lambda t, s: derivative(t, s, acc, pack, inp, w), (0, t_stop), s0, method="LSODA", rtol=1e-6,
                    atol=1e-9)
    rim = np.abs(sol.y[model.n + 3:model.n + 5, -1]) * 0.075
    assert rim.max() > MAX_SPEED


def test_an_adaptive_lift_off_is_reported_first_and_fast(monkeypatch):
    """Before (the CLI's case, the lift-off not allowed): the same 3 min to the same budget error, though a wheel
    lifted off at once (the 1e9 N m accelerate it at t = 0, which empties the load); now the first accepted
    state that lifts a wheel off stops it."""
    calls = _counted(monkeypatch)
    model, inputs = _light("linear")
    with pytest.raises(LiftOffError) as err:
        simulate(model, inputs, 1.0, method="adaptive")
    assert len(calls) < 5000 and 0 <= err.value.t < 1e-3
    # independently: a 1 us fixed-step run lifts the same contact off by then
    with pytest.raises(LiftOffError) as fixed:
        simulate(model, inputs, 2e-4, step=1e-6)
    assert fixed.value.contact == err.value.contact
