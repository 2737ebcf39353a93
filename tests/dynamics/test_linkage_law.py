"""A linkage's ``law`` (``ackermann`` | ``parallel``), stated in the description or defaulted only where the wheels
decide it: ``ackermann`` with fixed wheels on one axle line, ``parallel`` over every steerable wheel of a robot
without one (a synchro drive). A four-wheel-steer car's front and rear linkages have no default: not held, warned,
until the description states the law. Checked against closed forms (a steering torque on a wheel at rest turns
``tau t^2 / (2 I)``, ``I`` the inertia of the wheels it steers) and the Ackermann geometry, never the code's output."""

from __future__ import annotations

import dataclasses
import json
import math

import numpy as np
import pytest
from dynamics_robots import linked_car

from wmrkit import Robot
from wmrkit.cli.main import main
from wmrkit.couplings import Coupling, CouplingError
from wmrkit.dynamics.linkages import LinkageWarning
from wmrkit.dynamics.model import DynamicModel
from wmrkit.errors import WmrkitError

I_STEER, TAU, DURATION = 0.05, 0.02, 1.0
STEERS = ("fl", "fr", "rl", "rr")


def four_wheel_steer(law: str | None = None, linkages=(("fl", "fr"), ("rl", "rr"))) -> dict:
    """A 4WS car (wheelbase 0.6 m, track 0.4 m, no fixed wheel) whose `linkages` each steer a pair."""
    wheel = {"type": "steerable", "r": 0.1, "actuated": ["spin", "steer"], "inertia": {"spin": 0.01, "steer": I_STEER},
             "tyre": "dugoff"}
    where = {"fl": (0.3, 0.2), "fr": (0.3, -0.2), "rl": (-0.3, 0.2), "rr": (-0.3, -0.2)}
    couplings = [{"kind": "linkage", "joints": [f"{w}.steer" for w in pair]} | ({"law": law} if law else {})
                 for pair in linkages]
    return {"name": "car4ws", "body": {"mass": 30, "inertia": 1.5, "com": [0, 0], "com_height": 0.2},
            "wheels": [{**wheel, "name": n, "position": list(where[n])} for n in STEERS], "couplings": couplings}


def _simulate(tmp_path, capsys, data: dict) -> tuple[dict, str, dict]:
    """``wmrkit simulate --json`` with a steering torque TAU on fl alone from rest: (answer, stderr, the last
    sample's heading of each wheel)."""
    path, torques, out = tmp_path / "car.json", tmp_path / "t.csv", tmp_path / "run.csv"
    path.write_text(json.dumps(data))
    torques.write_text(f"time,fl.steer\n0,{TAU}\n")
    assert main(["simulate", str(path), "--torques", str(torques), "--duration", str(DURATION), "--out", str(out),
                 "--json"]) == 0
    answer, err = json.loads(capsys.readouterr().out), capsys.readouterr().err
    header = out.read_text().splitlines()[0].split(",")
    run = np.genfromtxt(out, delimiter=",", skip_header=1)
    return answer, err, {w: run[:, header.index(f"{w}.steer [rad]")] for w in STEERS}


def test_a_four_wheel_steer_car_without_a_law_is_warned_and_not_held(tmp_path, capsys):
    """Before, the dynamics held each pair parallel without a word (fr turned with fl, at half fl's angle). No fixed
    wheel and a linkage over some steerable wheels: no law to default to, so each angle keeps its own servo, and
    simulate says so once per linkage, naming the field to state. fl alone turns ``tau t^2 / (2 I)``."""
    answer, _, heading = _simulate(tmp_path, capsys, four_wheel_steer())
    said = [w for w in answer["warnings"] if "not held" in w]
    assert len(said) == 2 and all("law: parallel" in w and "law field" in w for w in said)
    assert said[0].startswith("the steering linkage of wheels 'fl' and 'fr' is not held by the dynamics")
    assert heading["fl"][-1] == pytest.approx(TAU * DURATION ** 2 / (2 * I_STEER), rel=2e-3)
    assert np.abs(heading["fr"]).max() < 1e-3 * heading["fl"][-1]
    with pytest.warns(LinkageWarning, match="not held"):
        model = DynamicModel.of(Robot.from_dict(four_wheel_steer()))
    assert model.pack[17].shape == (0, 10)
    assert model.steering_inertia() == pytest.approx([I_STEER] * 4, rel=1e-12)  # each wheel its own


def test_the_warning_is_one_stderr_line_per_linkage(tmp_path, capsys):
    path = tmp_path / "car.json"
    path.write_text(json.dumps(four_wheel_steer()))
    assert main(["simulate", str(path), "--path", "straight", "--speed", "0.5"]) == 0
    lines = [x for x in capsys.readouterr().err.splitlines() if "not held" in x]
    assert [x.split(" is not held")[0] for x in lines] == [
        "wmrkit: warning: the steering linkage of wheels 'fl' and 'fr'",
        "wmrkit: warning: the steering linkage of wheels 'rl' and 'rr'"]


def test_law_parallel_holds_each_pair_parallel(tmp_path, capsys):
    """Stated, the law holds: fr turns with fl in every sample, the torque moving both (``tau t^2 / (2 * 2 I)``),
    no warning; the rear pair stays put."""
    answer, _, heading = _simulate(tmp_path, capsys, four_wheel_steer("parallel"))
    assert not any("linkage" in w for w in answer["warnings"])
    np.testing.assert_allclose(heading["fr"], heading["fl"], atol=1e-8)  # the CSV's 9 digits
    assert heading["fl"][-1] == pytest.approx(TAU * DURATION ** 2 / (2 * 2 * I_STEER), rel=2e-3)
    assert np.abs(heading["rl"]).max() < 1e-3 * heading["fl"][-1]
    model = DynamicModel.of(Robot.from_dict(four_wheel_steer("parallel")))
    assert model.steering_inertia() == pytest.approx([2 * I_STEER] * 4, rel=1e-12)


def test_a_synchro_drive_holds_parallel_by_default_and_not_over_some_of_its_wheels():
    """One linkage over every steerable wheel (no fixed wheel): a synchro drive, parallel without a word; the same
    robot with one wheel outside the linkage has no default (the pair may be an Ackermann linkage)."""
    every = four_wheel_steer(linkages=[STEERS])
    model = DynamicModel.of(Robot.from_dict(every))
    assert model.steering_inertia() == pytest.approx([4 * I_STEER] * 4, rel=1e-12)
    assert model.pack[17].shape == (3, 10) and not model.pack[17][:, 3].any()  # law 0: parallel
    some = four_wheel_steer(linkages=[STEERS[:3]])
    with pytest.warns(LinkageWarning, match=r"the steering linkage of wheels 'fl', 'fr' and 'rl' is not held"):
        model = DynamicModel.of(Robot.from_dict(some))
    assert model.pack[17].shape == (0, 10)
    assert model.steering_inertia() == pytest.approx([I_STEER] * 4, rel=1e-12)


def test_law_parallel_on_a_car_with_fixed_wheels_turns_the_pair_together():
    """A stated law wins over the Ackermann default: the front pair turns together, not on the rear axle's ICR."""
    data = linked_car().to_dict()
    data["couplings"][0]["law"] = "parallel"
    model = DynamicModel.of(Robot.from_dict(data))
    i, j = (model.names.index(f"{w}.steer") for w in ("fl", "fr"))
    beta = model.robot.beta_of_heading([0.3, 0.3])
    nu = np.zeros(model.n)
    nu[i] = nu[j] = 0.7
    model.accelerations(beta, nu, forces=np.zeros(8))  # held: accepted
    ackermann = model.robot.beta_of_heading([0.3, math.atan2(0.6, 0.6 / math.tan(0.3) + 0.4)])
    with pytest.raises(WmrkitError, match=r"the steering linkage of wheels 'fl' and 'fr' sets fr at heading "
                                          r"0.3 rad with fl at 0.3 rad, not 0.2"):
        model.accelerations(ackermann, nu, forces=np.zeros(8))
    data["couplings"][0]["law"] = "ackermann"  # stated as the default is: the same model
    assert np.array_equal(DynamicModel.of(Robot.from_dict(data)).pack[17], DynamicModel.of(linked_car()).pack[17])


@pytest.mark.parametrize(("law", "expected"), [
    ("ackerman", "couplings[0].law: 'ackerman': a linkage's law is one of ackermann, parallel (did you mean "
                 "'ackermann'?)"),
    (3, "couplings[0].law: must be a non-empty string, got 3"),
    ("ackermann", "couplings[0].law: linkage(fl.steer, fr.steer): law ackermann: its wheels' axles would meet on the "
                  "fixed wheels' axle line, and the robot has no fixed wheel"),
])
def test_a_bad_law_is_refused_in_one_line(tmp_path, capsys, law, expected):
    data = four_wheel_steer()
    data["couplings"][0]["law"] = law
    path = tmp_path / "car.yaml"
    path.write_text(json.dumps(data))
    assert main(["simulate", str(path), "--path", "straight"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith(f"wmrkit: error: {path}:") and expected in err
    assert main(["show", str(path), "--json"]) == 2
    answer = json.loads(capsys.readouterr().err)
    assert answer["field"] == "couplings.0.law" and expected.split(": ", 1)[1] in answer["error"]


def test_a_law_on_a_gear_or_ackermann_off_one_axle_is_refused(tmp_path, capsys):
    data = four_wheel_steer()
    data["couplings"].append({"kind": "gear", "joints": ["fl.spin", "fr.spin"], "law": "parallel"})
    path = tmp_path / "car.yaml"
    path.write_text(json.dumps(data))
    assert main(["show", str(path)]) == 2
    assert "couplings[2].law: 'parallel': only a linkage has a law" in capsys.readouterr().err
    car = linked_car().to_dict()
    car["wheels"][1]["position"] = [0.1, -0.2]  # the rear axles no longer one line
    car["couplings"][0]["law"] = "ackermann"
    path.write_text(json.dumps(car))
    assert main(["show", str(path)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "couplings[0].law: linkage(fl.steer, fr.steer): law ackermann: the fixed " \
                                     "wheels' axles (rl, rr) are not one line" in err
    robot = Robot.from_dict(four_wheel_steer())
    with pytest.raises(CouplingError, match=r"law 'ackerman': a linkage's law is one of ackermann, parallel"):
        Coupling("linkage", ("fl.steer", "fr.steer"), (1, 1), "ackerman")
    with pytest.raises(CouplingError, match=r"couplings\[0\] linkage\(fl.steer, fr.steer\): law ackermann: .*no fixed"):
        dataclasses.replace(robot, couplings=(Coupling("linkage", ("fl.steer", "fr.steer"), (1, 1), "ackermann"),))


@pytest.mark.parametrize("suffix", [".yaml", ".json"])
def test_the_law_is_written_back(tmp_path, capsys, suffix):
    """to_file / from_file keep the law (and write none where none is stated); show prints it."""
    robot = Robot.from_dict(four_wheel_steer("parallel"))
    path = tmp_path / f"car{suffix}"
    robot.to_file(path)
    again = Robot.from_file(path)
    assert again.couplings == robot.couplings and [c.law for c in again.couplings] == ["parallel", "parallel"]
    assert "law" not in Robot.from_dict(four_wheel_steer()).to_dict()["couplings"][0]
    assert main(["show", str(path)]) == 0
    assert "coupling: linkage of fl.steer, fr.steer (ratios 1, 1; law parallel)" in capsys.readouterr().out
