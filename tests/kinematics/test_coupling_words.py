"""Text names a coupling in the description's terms (wmrkit.couplings.coupling_words): the channel name
``differential(rear_left.spin, rear_right.spin)`` is the library's, kept in JSON. Before, coupling_words knew only
steering couplings (a differential raised IndexError: no '.steer' joint), and every text door printed channel names."""

from __future__ import annotations

import json

from wmrkit import catalog
from wmrkit.cli.main import main
from wmrkit.couplings import Coupling, coupling_words

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
