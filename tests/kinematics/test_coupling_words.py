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
from wmrkit.couplings import Coupling, coupling_words
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
