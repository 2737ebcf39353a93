"""track and feasibility say that they do not model a gear coupling (``couplings:``) when it matters: both
answered a solid-axle car's circle without a word (feasible; tracked as if its rear wheels turned apart)."""

from __future__ import annotations

import dataclasses

from wmrkit import catalog
from wmrkit.cli.main import main
from wmrkit.couplings import Coupling

GEAR = "gear(rear_left.spin, rear_right.spin)"
WORDS = "the gear of wheels 'rear_left' and 'rear_right'"


def kart(tmp_path, ratios=(1.0, 1.0)):
    car = catalog.load("ackermann")
    car = dataclasses.replace(car, couplings=(car.couplings[1], Coupling("gear", GEAR[5:-1].split(", "), ratios)))
    path = tmp_path / "kart.yaml"
    car.to_file(path)
    return str(path)


def test_feasibility_says_a_gear_is_not_considered(tmp_path, capsys):
    assert main(["feasibility", kart(tmp_path), "--reference", "circle"]) == 0
    out, err = capsys.readouterr()
    assert "feasible: yes" in out and ("wmrkit: warning: the gear of wheels 'rear_left' and 'rear_right' is not "
                                       "considered: Table 8.1 judges") in err
    assert main(["feasibility", "ackermann", "--reference", "circle"]) == 0
    assert capsys.readouterr().err == ""  # a differential forbids no twist


def test_track_warns_when_its_commands_break_a_gear(tmp_path, capsys):
    path = kart(tmp_path)
    assert main(["track", path, "--reference", "circle", "--duration", "3"]) == 0
    err = capsys.readouterr().err
    assert f"the commands turn the joints of {WORDS} out of its ratios (ratios 1, 1)" in err
    # the kinematic loop holds a steering gear's ratios (control.linked_ranges), not a gear of spins
    assert "the kinematic loop holds the ratios of steering joints only, not these (it drives each on its own)" in err
    assert main(["track", path, "--reference", "line", "--duration", "3"]) == 0  # straight: the axle turns as one
    assert "out of its ratios" not in capsys.readouterr().err


def test_track_dynamics_holds_the_gear_and_says_its_servos_fight(tmp_path, capsys):
    """Through the dynamics the gear holds (the forklift's drive wheels on a solid axle), so the warning no longer
    says that the simulation does not model it."""
    fork = catalog.load("forklift")
    drives = ("right_drive.spin", "left_drive.spin")
    path = tmp_path / "fork.yaml"
    dataclasses.replace(fork, couplings=(Coupling("gear", drives, (1.0, 1.0)),)).to_file(path)
    assert main(["track", str(path), "--reference", "circle", "--duration", "2", "--dynamics"]) == 0
    err = capsys.readouterr().err
    assert ("the commands turn the joints of the gear of wheels 'right_drive' and 'left_drive' out of its ratios "
            "(ratios 1, 1); the dynamics hold the gear") in err
    assert "does not model" not in err
