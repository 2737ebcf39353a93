"""Refusals that name many rates stay readable: the first few and a count of the rest, on one line.

``wmrkit kinematics d64.yaml --codegen c DIR`` (64 double wheels, two spins sensed) refused with a line of 2,177
characters naming 186 undetermined rates, cut by the CLI mid-name ('... d61.steer,... (2177 characters)')."""

from __future__ import annotations

import math
import re

import numpy as np
import pytest
from scipy.linalg import null_space

from wmrkit import Robot
from wmrkit.errors import MAX_LISTED, SingularError, name_list
from wmrkit.kinematics.codegen import write_code


def _doubles(n: int, sensed: tuple[int, ...]) -> Robot:
    return Robot.from_dict({"name": f"d{n}", "wheels": [
        {"name": f"d{i}", "type": "double", "b": 0.05, "r": 0.03,
         "position": [0.5 * math.cos(2 * math.pi * i / n), 0.5 * math.sin(2 * math.pi * i / n)],
         **({"sensed": ["spin1"]} if i in sensed else {})} for i in range(n)]})


def _undetermined(robot: Robot) -> list[str]:
    """Brute force: an unknown rate is free when some motion with the sensed rates at 0 moves it (a null vector of
    the unknowns' columns of A, at a random steering, with a non-zero entry there)."""
    beta = np.random.default_rng(3).uniform(-math.pi, math.pi, len(robot.steer_names))
    a = np.asarray(robot.constraint_matrix(beta))
    unknown = [j for j, n in enumerate(robot.velocity_names) if n not in robot.sensed]
    basis = null_space(a[:, unknown])
    return [robot.velocity_names[j] for j, row in zip(unknown, basis, strict=True) if np.abs(row).max() > 1e-8]


@pytest.mark.parametrize("n", [3, 8])
def test_a_codegen_refusal_names_the_first_rates_and_counts_the_rest(tmp_path, n):
    robot = _doubles(n, (0, n // 2))
    free = _undetermined(robot)
    with pytest.raises(SingularError) as err:
        write_code(robot, "c", tmp_path)
    listed = re.search(r"do not determine \(([^)]*)\)", str(err.value)).group(1)
    if len(free) <= MAX_LISTED:
        assert listed == ", ".join(free)
    else:  # before: every one of them
        assert listed == f"{', '.join(free[:MAX_LISTED])} and {len(free) - MAX_LISTED} more"
    assert "\n" not in str(err.value) and len(str(err.value)) < 400


def test_name_list():
    assert name_list([]) == "" and name_list(["a"]) == "a"
    names = [f"n{i}" for i in range(MAX_LISTED + 5)]
    assert name_list(names[:MAX_LISTED]) == ", ".join(names[:MAX_LISTED])
    assert name_list(names) == ", ".join(names[:MAX_LISTED]) + " and 5 more"
