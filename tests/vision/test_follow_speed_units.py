"""``wmrkit follow-line --speed`` reads a speed with its unit (kind ``speed``, docs/conventions.md): the run of
``"50 cm/s"`` is the run of ``0.5`` (m/s, SI), bit for bit; a quantity of another kind is refused in one line."""

from __future__ import annotations

import json
import math

import pytest

from wmrkit.cli.main import main
from wmrkit.vision.camera import Camera


@pytest.fixture
def argv(tmp_path):
    Camera(150.0, math.radians(60), 0.3, 160, 120).to_file(tmp_path / "cam.yaml")
    return ["follow-line", "line-follower", "--camera", str(tmp_path / "cam.yaml"), "--duration", "2", "--json"]


def _run(capsys, argv, code=0):
    assert main(argv) == code
    out, err = capsys.readouterr()
    return json.loads(out if code == 0 else err), err.splitlines()


def test_a_speed_with_its_unit_is_the_si_number(capsys, argv):
    si, _ = _run(capsys, [*argv, "--speed", "0.5"])
    assert si["speed"] == 0.5
    for text in ("50 cm/s", "0.5 m/s", "500mm/s", "1.8 km/h"):
        assert _run(capsys, [*argv, "--speed", text])[0] == si, text
    other, _ = _run(capsys, [*argv, "--speed", "0.3"])  # the speed shapes the run (a unit dropped would show)
    assert other["speed"] == 0.3 and other["trace"] != si["trace"]
    assert _run(capsys, [*argv, "--speed", "30 cm/s"])[0] == other


@pytest.mark.parametrize(("text", "said"), [
    ("3 deg/s", "--speed: '3 deg/s' is an angular rate, expected a speed"),
    ("0.5 m", "--speed: '0.5 m' is a length, expected a speed"),
    ("fast", "--speed: cannot read 'fast' as a speed"),
])
def test_a_speed_of_another_kind_is_refused_in_one_line(capsys, argv, text, said):
    error, lines = _run(capsys, [*argv, "--speed", text], 2)
    assert error["error"].startswith(said) and len(lines) == 1
    assert main([a for a in argv if a != "--json"] + ["--speed", text]) == 2
    out, err = capsys.readouterr()
    assert out == "" and err.startswith(f"wmrkit: error: {said}") and err.count("\n") == 1
