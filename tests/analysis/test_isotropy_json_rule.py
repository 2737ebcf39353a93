"""One rule for the condition number of ``wmrkit analyze --json``: where the text says "isotropy: does not apply"
(m <= 1, of the wheels or left by gear couplings), ``condition_number`` is null and ``isotropy_note`` is the text's
note; elsewhere it is kappa and the note null. Before: ackermann and swerve-4 (m = 1) gave 1.0, a diff-drive
whose wheels are on one gear (m = 1 left) gave null, while the text said "does not apply" for both."""

from __future__ import annotations

import json

import pytest

from wmrkit import catalog
from wmrkit.cli.main import main

PREFIX = "  isotropy: "


def _solid_axle(tmp_path) -> str:
    d = catalog.load("diff-drive").to_dict()
    d["couplings"] = [{"kind": "gear", "joints": ["left.spin", "right.spin"], "ratios": [1.0, 1.0]}]
    path = tmp_path / "solid-axle.json"
    path.write_text(json.dumps(d), encoding="utf-8")
    return str(path)


def _answers(capsys, robot: str, *extra: str) -> tuple[str | None, dict]:
    assert main(["analyze", robot, "--resolution", "8", *extra]) == 0
    lines = capsys.readouterr().out.splitlines()
    note = next((x.removeprefix(PREFIX) for x in lines if x.startswith(PREFIX)), None)
    assert main(["analyze", robot, "--resolution", "8", "--json", *extra]) == 0
    return note, json.loads(capsys.readouterr().out)


@pytest.mark.parametrize("robot", ["ackermann", "swerve-4", "forklift", "diff-drive", "omni-3", "mecanum-4",
                                   "solid-axle"])
@pytest.mark.parametrize("length", [[], ["--length", "300 mm"]])
def test_the_json_condition_number_follows_the_text(tmp_path, capsys, robot, length):
    spec = _solid_axle(tmp_path) if robot == "solid-axle" else robot
    note, out = _answers(capsys, spec, *length)
    m = min(out["mobility"], out["coupled_mobility"])
    assert (note is not None) == (m <= 1)  # no two motions to balance: the thesis's §5.5.4-5.5.5
    assert out["isotropy_note"] == note
    if note is not None:
        assert out["condition_number"] is None
    else:
        assert out["condition_number"] >= 1.0  # sigma_max / sigma_min
    # a given length is said back, the natural one only where isotropy applies
    assert out["characteristic_length"] == (0.3 if length else (None if note is not None else
                                                                 out["characteristic_length"]))
    assert out["natural_length"] is (not length)
