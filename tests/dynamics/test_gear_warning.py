"""wmrkit simulate says that the dynamics do not model a gear coupling (``couplings:``)."""

from __future__ import annotations

import dataclasses
import json

from wmrkit import catalog
from wmrkit.cli.main import main
from wmrkit.couplings import Coupling


def test_simulate_says_a_gear_is_not_modelled(tmp_path, capsys):
    """The dynamics drive a differential as one servo but each joint of a gear on its own; it said nothing."""
    fork = catalog.load("forklift")
    fork = dataclasses.replace(fork, couplings=(Coupling("gear", ("right_drive.spin", "left_drive.spin"), (1, 1)),))
    path = tmp_path / "fork.yaml"
    fork.to_file(path)
    assert main(["simulate", str(path), "--path", "straight", "--duration", "0.2", "--step", "0.01", "--json"]) == 0
    warnings = json.loads(capsys.readouterr().out)["warnings"]
    assert "gear(right_drive.spin, left_drive.spin) is not modelled: each of its joints is driven on its own" in (
        " ".join(warnings))
    assert main(["simulate", "forklift", "--path", "straight", "--duration", "0.2", "--step", "0.01", "--json"]) == 0
    assert not any("not modelled" in w for w in json.loads(capsys.readouterr().out)["warnings"])
