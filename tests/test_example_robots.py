"""The example robots the documentation's prose runs commands on (examples/robots/): the geared steering units,
the cart on a solid axle and the synchro drive. Before, docs/wheel-ik.md and docs/control.md named geared.json,
cart.yaml and synchro.yaml, which no command made and the repository did not hold; each is checked here against
what the pages say of it (closed forms, not the code's own numbers), and every inline ``wmrkit`` command of docs/
that names one runs and says what the page quotes."""

from __future__ import annotations

import math
import re
import shlex

import pytest

from doc_examples import ROOT
from wmrkit import Robot
from wmrkit.analysis.summary import analyze
from wmrkit.cli.main import main

ROBOTS = ("geared.json", "cart.yaml", "synchro.yaml")


def _inline_commands() -> list[tuple[str, str]]:
    """``(page, command)`` of each inline `` `wmrkit ...` `` of docs/*.md naming an example robot (a span may break
    across lines)."""
    found = []
    for page in sorted((ROOT / "docs").glob("*.md")):
        for span in re.findall(r"`(wmrkit [^`]*examples/robots/[^`]*)`", page.read_text()):
            found.append((page.name, " ".join(span.split())))
    return found


COMMANDS = _inline_commands()


def test_each_example_robot_has_a_documented_command():
    named = {word.rpartition("/")[2] for _, command in COMMANDS for word in command.split()}
    assert set(ROBOTS) <= named
    for name in ROBOTS:
        assert (ROOT / "examples" / "robots" / name).is_file()


#: What the pages say each command answers: its exit code and a piece of its output or warning they quote.
SAYS = {("ik", "geared.json"): (1, "feasible: NO (a steering gear cannot set these headings)"),
        ("ik", "synchro.yaml"): (1, "the steering linkage of wheels 'a', 'b' and 'c' (law parallel) sets a at heading "
                                    "-2.63485 deg with c at -2.63485 deg, not 5.71059 deg"),
        ("fk", "cart.yaml"): (0, "do not turn together"),
        ("fk", "synchro.yaml"): (0, "the headings break a steering linkage: the steering linkage of wheels 'a', 'b' "
                                    "and 'c' (law parallel) sets b at heading 0 deg with a at 0 deg, not 10 deg"),
        ("track", "geared.json"): (0, "robot geared-units, reference circle of radius 3 m, controller p")}


@pytest.mark.parametrize(("page", "command"), COMMANDS, ids=[c for _, c in COMMANDS])
def test_a_documented_command_on_an_example_robot_runs(page, command, capsys, monkeypatch):
    """Each answers as its page says (an answer that is no, 1, for ik's 'feasible: NO'), never an error, and says
    what the page quotes of it."""
    argv = shlex.split(command)[1:]
    code, said = SAYS[argv[0], argv[1].rpartition("/")[2]]
    monkeypatch.chdir(ROOT)
    assert main(argv) == code, (page, command, capsys.readouterr().err)
    out, err = capsys.readouterr()
    assert "wmrkit: error" not in err and said in out + err, (page, command, out, err)


def _robot(name: str) -> Robot:
    return Robot.from_file(ROOT / "examples" / "robots" / name)


def _heading(px: float, py: float, vx: float, vy: float, omega: float) -> float:
    """Heading [deg] of a wheel at (px, py) rolling with the twist: its contact point's velocity direction."""
    return math.degrees(math.atan2(vy + omega * px, vx - omega * py))


def test_the_geared_units_turn_their_steering_1_to_2_and_ik_holds_them_to_it(capsys, monkeypatch):
    """docs/wheel-ik.md: units at (0.3, 0.2) and (-0.3, -0.2) m whose steering a gear turns 1:2; asked (1, 0, 1) the
    twist needs each unit's own heading (closed form) and the gear sets the front at half the rear's."""
    robot = _robot("geared.json")
    assert [(w.name, w.type) for w in robot.wheels] == [("front", "double"), ("rear", "double")]
    (gear,) = robot.couplings
    assert (gear.kind, tuple(gear.joints), tuple(gear.ratios)) == ("gear", ("front.steer", "rear.steer"), (1.0, 2.0))
    front, rear = _heading(0.3, 0.2, 1, 0, 1), _heading(-0.3, -0.2, 1, 0, 1)
    monkeypatch.chdir(ROOT)
    assert main(["ik", "examples/robots/geared.json", "--twist", "1", "0", "1"]) == 1
    out, err = capsys.readouterr()
    assert out.rstrip().endswith("feasible: NO (a steering gear cannot set these headings)")
    assert (f"the steering gear of wheels 'front' and 'rear' (ratios 1, 2) sets front at heading {rear / 2:.6g} deg "
            "with rear at "
            f"{rear:.6g} deg, not {front:.6g} deg, which the twist needs") in err
    assert main(["ik", "examples/robots/geared.json", "--twist", "1", "0", "0"]) == 0  # both straight: 0 = 2 * 0
    assert "feasible: yes" in capsys.readouterr().out


def test_the_cart_s_solid_axle_leaves_it_one_degree_of_mobility(capsys, monkeypatch):
    """docs/analysis.md: a solid axle (a gear of both spins of a differential drive, 1:1) has coupled mobility 1
    where m is 2; docs/wheel-ik.md: fk with the two spins apart warns, 10 and 5 rad/s being 50 % apart."""
    found = analyze(_robot("cart.yaml")).to_dict()
    assert (found["mobility"], found["steerability"], found["coupled_mobility"]) == (2, 0, 1)
    monkeypatch.chdir(ROOT)
    assert main(["fk", "examples/robots/cart.yaml", "--spin", "left=10", "--spin", "right=5"]) == 0
    assert ("the joints of the gear of wheels 'left' and 'right' (ratios 1, 1) do not turn together (left.spin 10, "
            "right.spin 5 rad/s; 50% apart)") in capsys.readouterr().err


def test_the_synchro_drive_has_two_degrees_of_steerability_and_commands_one():
    """docs/analysis.md: a synchro drive, one linkage of its three steered wheels: m = 1, d = 2, commanded 1 (thesis
    type 5 by its wheels alone); it only translates."""
    found = analyze(_robot("synchro.yaml")).to_dict()
    assert (found["mobility"], found["steerability"], found["commanded_steerability"], found["type"]) == (1, 2, 1, 5)
    assert found["icr"].startswith("ICR at infinity: translation only")


def test_the_cart_is_the_coupling_tests_cart():
    """The same robot as tests/geared.py's ``cart_yaml(1.0)``, which the coupling tests check at length."""
    import yaml

    from geared import cart_yaml

    assert _robot("cart.yaml") == Robot.from_dict(yaml.safe_load(cart_yaml(1.0)))
