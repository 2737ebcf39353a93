"""``analyze``'s ``coupled_mobility`` is the twist's m with the gears held, comparable with ``mobility`` (the type's):
a double wheel's joints also move with the body at rest, which k - rank A counts and the twist's m does not."""

from __future__ import annotations

import json

import numpy as np
import pytest
import scipy.linalg

from geared import held_constraints
from wmrkit import Robot
from wmrkit.cli.main import main

_WHEELS = """name: dbl
wheels:
  - {name: d1, type: TYPE, position: [0.3, 0], heading: 0, b: 0.1, r: 0.05, EXTRA
     actuated: [spin1, spin2], sensed: [spin1, spin2, steer]}
  - {name: d2, type: TYPE, position: [-0.3, 0], heading: 0, b: 0.1, r: 0.05, EXTRA sensed: [spin1]}
"""
_GEAR = "couplings:\n  - {kind: gear, joints: [d1.spin1, d1.spin2], ratios: [1, RATIO]}\n"


def _twist_mobility(robot: Robot) -> int:
    """Brute force: the rank of the twist part of the null space of (3.22) with a row q_i / k_i - q_0 / k_0 = 0 per
    further joint of each gear."""
    basis = scipy.linalg.null_space(held_constraints(robot))
    return int(np.linalg.matrix_rank(basis[:3], tol=1e-9)) if basis.size else 0


@pytest.mark.parametrize("kind, extra", [("double", ""), ("double_castor", "d: 0.04,")])
@pytest.mark.parametrize("gear", [None, -1.0, 1.0])
def test_coupled_mobility_is_the_twist_s_m_with_the_gears(tmp_path, capsys, kind, extra, gear):
    text = _WHEELS.replace("TYPE", kind).replace("EXTRA", extra)
    if gear is not None:  # -1: the sub-wheels spin against each other, d1 turns on the spot and pins the body
        text += _GEAR.replace("RATIO", repr(gear))
    path = tmp_path / "dbl.yaml"
    path.write_text(text)
    assert main(["analyze", str(path), "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    want = _twist_mobility(Robot.from_file(path))
    assert out["coupled_mobility"] == want  # was 3 (no gear) and 2 (gear): k - rank A, above the type's m = 1
    assert out["coupled_mobility"] <= out["instantaneous_mobility"]
    assert main(["analyze", str(path)]) == 0
    first = capsys.readouterr().out.splitlines()[0]
    assert first.endswith(f"; its gear couplings leave m = {want} (couplings)") == (want < out["mobility"])
