"""The kinematics tables at the size limits: least-squares round-off is printed as 0, real entries are kept.

On 64 castors on a 0.5 m ring (MAX_WHEELS), ``wmrkit kinematics`` printed entries such as ``-1.00095e-12`` in the
direct model where the value is 0 (the absolute 1e-12 of the text table lies below that round-off, which grows with
the matrix's scale), and ran them into the previous column (``-74.9149-1.00095e-12``). Checked against the closed form
of a pure translation: with every castor heading h, c0.spin alone (c0.steer, c1.steer held at 0) moves the robot
along h at r per rad, every spin turning at 1 and no castor steering."""

from __future__ import annotations

import math

import numpy as np
import pytest

from wmrkit import Robot
from wmrkit.cli.main import main
from wmrkit.kinematics.linalg import characteristic_length
from wmrkit.kinematics.models import direct_model


def _ring(n: int, scale: float, heading: float) -> Robot:
    """`n` castors (d = 0.05, r = 0.03 times `scale`) on a ring of radius 0.5 `scale`, three spins sensed."""
    robot = Robot.from_dict({"name": f"ring{n}", "wheels": [
        {"name": f"c{i}", "type": "castor", "d": 0.05 * scale, "r": 0.03 * scale,
         "position": [0.5 * scale * math.cos(2 * math.pi * i / n), 0.5 * scale * math.sin(2 * math.pi * i / n)],
         **({"sensed": ["spin"]} if i in (0, n // 4, n // 2) else {})} for i in range(n)]})
    return robot.with_steering({w.name: heading for w in robot.wheels})


def _translation(model, r: float, heading: float) -> np.ndarray:
    """The closed-form column of c0.spin: vx, vy = r (cos h, sin h), omega 0, spins 1, steering rates 0."""
    exact = {"vx": r * math.cos(heading), "vy": r * math.sin(heading), "omega": 0.0}
    return np.array([exact.get(n, 1.0 if n.endswith(".spin") else 0.0) for n in model.solved])


@pytest.mark.parametrize("n", [32, 64])
@pytest.mark.parametrize("scale", [1e-5, 1.0, 999.0])
@pytest.mark.parametrize("heading", [0.0, 0.3, 2.5, -1.2])
def test_the_printed_direct_model_is_the_closed_form_to_the_last_zero(n, scale, heading):
    from wmrkit.kinematics.summary import printed_matrix  # the rule of the text tables

    robot = _ring(n, scale, heading)
    model = direct_model(robot)
    assert model.assigned == ("c0.steer", "c0.spin", "c1.steer")
    column = model.assigned.index("c0.spin")
    exact = _translation(model, 0.03 * scale, heading)
    printed = printed_matrix(model.as_dict(), characteristic_length(robot))
    zero = exact == 0.0
    assert np.all(printed[zero, column] == 0.0)  # round-off is 0
    np.testing.assert_allclose(printed[~zero, column], exact[~zero], rtol=1e-9)  # a value is kept, even 3e-7 m
    np.testing.assert_array_equal(printed[printed != 0.0], model.matrix[printed != 0.0])  # and as computed


def test_kinematics_prints_no_round_off_for_64_castors(tmp_path, capsys):
    """Before: 'c9.steer  =     -74.9149-1.00095e-12     75.9149' (and 47 more such rows)."""
    path = tmp_path / "c64.yaml"
    path.write_text("name: c64\nwheels:\n" + "".join(
        f"  - {{name: c{i}, type: castor, position: [{0.5 * math.cos(2 * math.pi * i / 64)!r}, "
        f"{0.5 * math.sin(2 * math.pi * i / 64)!r}], d: 0.05, r: 0.03"
        f"{', actuated: [spin]' if i in (0, 32) else ''}{', sensed: [spin]' if i in (0, 16, 32) else ''}}}\n"
        for i in range(64)))
    assert main(["kinematics", str(path)]) == 0
    out = capsys.readouterr().out
    table = [line for line in out[out.index("direct model"):out.index("inverse model")].splitlines()[2:] if "=" in line]
    rows = {line.split("=")[0].strip(): line.split("=")[1].split() for line in table}
    assert len(rows) == 64 * 2 + 3 - 3 and all(len(v) == 3 for v in rows.values())  # three columns, apart
    for name, (_, spin, _) in rows.items():
        assert spin == {"vx": "0.03"}.get(name, "1" if name.endswith(".spin") else "0"), (name, spin)
