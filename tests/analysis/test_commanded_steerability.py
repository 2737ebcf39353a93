"""analyze keeps the thesis's type (the wheel geometry, Table 5.1) and says how much of the steerability d the
robot's steering linkages command: a synchro drive (three steered wheels on one steering chain, their spins on
one drive chain) is type 5 with d = 2 by its wheels, and its one steering mechanism commands d = 1."""

from __future__ import annotations

import json

import pytest

from geared import SYNCHRO
from wmrkit import Robot, catalog
from wmrkit.analysis.classification import classify
from wmrkit.analysis.summary import analyze
from wmrkit.cli.main import main
from wmrkit.couplings import Coupling, steering_mechanisms


def test_a_synchro_drive_commands_one_degree_of_steerability(tmp_path, capsys):
    """Before: 'type 5 ... steerability d = 2', with nothing saying that one chain steers all three wheels."""
    path = tmp_path / "synchro.yaml"
    path.write_text(SYNCHRO)
    robot = Robot.from_file(path)
    c = classify(robot)
    assert (c.type, c.mobility, c.steerability, c.commanded_steerability) == (5, 1, 2, 1)
    assert c.describe().endswith("; its steering linkages command d = 1 (couplings)")
    assert main(["analyze", str(path), "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert (out["steerability"], out["commanded_steerability"]) == (2, 1)


@pytest.mark.parametrize(("name", "commanded"), [("swerve-4", 2), ("ackermann", 1), ("thesis-two-steer-castor", 2),
                                                 ("diff-drive", 0), ("omni-3", 0)])
def test_without_a_linkage_below_d_nothing_changes(name, commanded):
    """Independent steering motors command all of d; the car's linkage steers the wheels d counts as one."""
    a = analyze(catalog.load(name), resolution=8)
    c = a.classification
    assert c.commanded_steerability == c.steerability == commanded
    assert "linkages command" not in a.format_text() and a.to_dict()["commanded_steerability"] == commanded


def test_steering_mechanisms_merges_chained_linkages():
    """Two linkages of two wheels each and a fifth wheel: three mechanisms."""
    links = (Coupling("linkage", ("a.steer", "b.steer"), (1, 1)), Coupling("linkage", ("c.steer", "d.steer"), (1, 1)))
    assert steering_mechanisms(links, ["a", "b", "c", "d", "e"]) == 3
    assert steering_mechanisms((), ["a", "b"]) == 2
    assert steering_mechanisms(links, ["a", "c"]) == 2
