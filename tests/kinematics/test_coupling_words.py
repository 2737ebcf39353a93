"""Text names a coupling in the description's terms (wmrkit.couplings.coupling_words): the channel name
``differential(rear_left.spin, rear_right.spin)`` is the library's, kept in JSON. Before, coupling_words knew only
steering couplings (a differential raised IndexError: no '.steer' joint), and every text door printed channel names."""

from __future__ import annotations

import json
import math
import warnings

import numpy as np

from wmrkit import catalog
from wmrkit.cli.main import main
from wmrkit.couplings import Coupling, GearBreach, coupling_words
from wmrkit.kinematics.extended import extended_solution
from wmrkit.kinematics.linkage_check import LinkageAngleWarning

CAR = catalog.load("ackermann")
DIFF, LINK = (c.channel_name for c in CAR.couplings)  # the JSON's names


def test_long_and_short_forms_by_wheel():
    assert coupling_words(CAR.couplings, LINK) == "the steering linkage of wheels 'front_left' and 'front_right'"
    assert coupling_words(CAR.couplings, DIFF) == "the differential of wheels 'rear_left' and 'rear_right'"
    assert coupling_words(CAR.couplings, LINK, short=True) == "linkage of front_left and front_right"
    assert coupling_words(CAR.couplings, DIFF, short=True) == "differential of rear_left and rear_right"


def test_other_joints_are_named_by_joint_and_a_joint_as_is():
    gear = Coupling("gear", ("unit.spin1", "unit.spin2", "rear.spin"), (1.0, -1.0, 2.0))
    couplings = (gear,)
    long = "the gear of joints 'unit.spin1', 'unit.spin2' and 'rear.spin'"
    assert coupling_words(couplings, gear.channel_name) == long
    assert coupling_words(couplings, gear.channel_name, short=True) == "gear of unit.spin1, unit.spin2 and rear.spin"
    assert coupling_words(couplings, "rear.spin") == "rear.spin"  # not a channel: a joint's own name


def test_the_joints_of_a_coupling_read_by_wheel_or_by_joint():
    """Sentences about a coupling's joints ('do not turn together', 'out of its ratios') said 'the joints of the
    gear of joints 'd.spin1' and 'd.spin2''; named by joint, the joints are now the gear's: a gear of one double
    wheel's spins, a mixed one (two wheels, one of them twice), a gear and a linkage by wheel."""
    double = Coupling("gear", ("d.spin1", "d.spin2"), (1.0, 2.0))
    mixed = Coupling("gear", ("unit.spin1", "unit.spin2", "rear.spin"), (1.0, -1.0, 2.0))
    axle = Coupling("gear", ("left.spin", "right.spin"), (1.0, 1.0))
    link = Coupling("linkage", ("fl.steer", "fr.steer"), (1.0, 1.0))
    assert double.joints_words() == "the gear's joints 'd.spin1' and 'd.spin2'"
    assert mixed.joints_words() == "the gear's joints 'unit.spin1', 'unit.spin2' and 'rear.spin'"
    assert axle.joints_words() == "the joints of the gear of wheels 'left' and 'right'"
    assert link.joints_words() == "the joints of the steering linkage of wheels 'fl' and 'fr'"
    assert double.words() == "the gear of joints 'd.spin1' and 'd.spin2'"  # alone, as before
    breach = GearBreach(double, (0, 1), 0.5)
    assert breach.head == "the gear's joints 'd.spin1' and 'd.spin2' (ratios 1, 2) do not turn together"
    assert GearBreach(axle, (0, 1), 0.5).head.startswith("the joints of the gear of wheels 'left' and 'right' (")


def test_fk_warns_of_a_double_wheel_s_gear_by_its_joints(tmp_path, capsys):
    """The whole warning of `fk` on a double wheel whose two spins are geared 1:1 and given apart."""
    data = {"name": "geared-unit", "wheels": [
        {"name": "d", "type": "double", "position": [0.3, 0.0], "heading": 0, "b": 0.06, "r": 0.08,
         "actuated": ["spin1", "spin2"], "sensed": ["steer", "spin1", "spin2"]},
        {"name": "left", "type": "castor", "position": [-0.3, 0.2], "beta": "90 deg", "d": 0.05, "r": 0.05},
        {"name": "right", "type": "castor", "position": [-0.3, -0.2], "beta": "90 deg", "d": 0.05, "r": 0.05}],
        "couplings": [{"kind": "gear", "joints": ["d.spin1", "d.spin2"], "ratios": [1, 1]}]}
    path = tmp_path / "unit.json"
    path.write_text(json.dumps(data))
    assert main(["fk", str(path), "--spin", "d.spin1=10", "--spin", "d.spin2=5", "--steer", "d=0"]) == 0
    err = capsys.readouterr().err
    assert ("\nwmrkit: warning: the gear's joints 'd.spin1' and 'd.spin2' (ratios 1, 1) do not turn together "
            "(d.spin1 10, d.spin2 5 rad/s; 50% apart): the rates contradict") in err
    assert "joints of the gear of joints" not in err


def test_kinematics_text_names_the_couplings_json_keeps_channels(capsys):
    assert main(["kinematics", "ackermann"]) == 0
    line = next(x for x in capsys.readouterr().out.splitlines() if x.startswith("  actuation ["))
    assert line.startswith("  actuation [differential of rear_left and rear_right, linkage of front_left and "
                           "front_right]: ")
    assert main(["kinematics", "ackermann", "--json"]) == 0
    act = json.loads(capsys.readouterr().out)["actuation"]
    assert act["actuated"] + act["steering_actuators"] == [DIFF, LINK]


def test_analyze_text_names_the_couplings_json_keeps_channels(capsys):
    assert main(["analyze", "ackermann"]) == 0
    out = capsys.readouterr().out
    assert "(differential of rear_left and rear_right, linkage of front_left and front_right)" in out
    assert "singular (actuated: differential of rear_left and rear_right): " in out
    assert "linkage(" not in out and "differential(" not in out
    assert main(["analyze", "ackermann", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["singular"]["actuated"]["channels"] == [DIFF]


def test_fk_text_names_the_linkage_by_its_wheels(capsys):
    """Before: 'the headings break a steering linkage: linkage(front_left.steer, front_right.steer) (law ackermann)
    sets front_right ...'. front_right's Ackermann heading is found here from the ICR on the rear axle line (the
    catalog car: wheelbase 2.70 m, track 1.55 m), not from the law's formula."""
    args = ["fk", "ackermann", "--spin", "rear_left=1", "--spin", "rear_right=1", "--steer", "front_left=0.3",
            "--steer", "front_right=-0.1"]
    assert main(args) == 0
    err = capsys.readouterr().err
    icr = 0.775 + 2.70 / math.tan(0.3)
    want = math.degrees(math.atan(2.70 / (icr + 0.775)))
    assert (f"wmrkit: warning: the headings break a steering linkage: the steering linkage of wheels 'front_left' and "
            f"'front_right' (law ackermann) sets front_right at heading {want:.6g} deg with front_left at "
            f"{math.degrees(0.3):.6g} deg, not {math.degrees(-0.1):.6g} deg: it cannot set them") in err
    assert "linkage(" not in err
    assert main([*args, "--json"]) == 0  # its warnings are the text's
    assert json.loads(capsys.readouterr().out)["warnings"][0] == err.splitlines()[0].removeprefix("wmrkit: warning: ")


def test_extended_solution_warns_in_the_terms_of_the_angles_given():
    """Given beta (the thesis's angles), the warning says so, not 'headings' (the headings it shows are users');
    given headings, headings. Before: 'the steering angles break a steering linkage: linkage(...) ...; check the
    angles' either way."""
    rear = ["rear_left.spin", "rear_right.spin"]
    heading = np.radians([20.0, 0.0])
    for kw, words in (({"heading": heading}, "the headings"),
                      ({"beta": CAR.beta_of_heading(heading)}, "the angles beta")):
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            extended_solution(CAR, rear, [0.0, 0.0], **kw)
        said = [str(w.message) for w in caught if issubclass(w.category, LinkageAngleWarning)]
        assert len(said) == 1 and said[0].startswith(
            f"{words} break a steering linkage: the steering linkage of wheels 'front_left' and 'front_right' (law "
            "ackermann) sets front_right at heading ") and said[0].endswith(f"; check {words}")
