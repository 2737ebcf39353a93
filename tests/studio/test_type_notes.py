"""What `wmrkit analyze` says about the type beyond m and d, the studio says too: the m gear couplings leave, and
what held steering linkages leave of the wheels' ICRs. The page showed 'm = 3, s = 0' for omni-3 with two wheels on
a gear (analyze: 'its gear couplings leave m = 2') and 'm = 1, s = 2' for two steered wheels on a parallel linkage
(analyze: 'only 2 ICRs ...; the type is of the wheels alone')."""

from __future__ import annotations

import contextlib
import io
import json

import pytest

from wmrkit import catalog
from wmrkit.cli.main import main as cli_main
from wmrkit.studio import api


def with_couplings(name: str, couplings: list[dict]) -> dict:
    d = catalog.load(name).to_dict()
    d["couplings"] = couplings
    return d


GEARED = with_couplings("omni-3", [{"kind": "gear", "joints": ["front_left.spin", "back.spin"], "ratios": [1, 2]}])
LINKED = with_couplings("thesis-two-steer-castor", [{"kind": "linkage", "joints": ["o1.steer", "o2.steer"],
                                                     "ratios": [1, 1], "law": "parallel"}])


def analyze_cli(description: dict, tmp_path) -> tuple[str, dict]:
    """`wmrkit analyze FILE` as text and as --json."""
    path = tmp_path / "robot.json"
    path.write_text(json.dumps(description))
    answers = []
    for extra in ([], ["--json"]):
        out = io.StringIO()
        with contextlib.redirect_stdout(out):
            assert cli_main(["analyze", str(path), *extra]) == 0
        answers.append(out.getvalue())
    return answers[0], json.loads(answers[1])


@pytest.mark.parametrize(("description", "said"), [
    (GEARED, "its gear couplings leave m = 2 (couplings)"),
    (LINKED, "with its steering linkages held: m = 1, d = 0: only 2 ICRs"),
])
def test_the_type_notes_are_the_lines_analyze_prints(tmp_path, description, said):
    text, data = analyze_cli(description, tmp_path)
    live = api.analyze_live({"description": description})["analysis"]
    assert len(live["type_notes"]) == 1 and live["type_notes"][0].startswith(said), live["type_notes"]
    assert live["type_notes"][0] in text  # the sentence analyze prints, word for word
    assert live["linkages"] == data["linkages"]


def test_no_type_notes_where_analyze_prints_none():
    for name in ("omni-3", "ackermann", "thesis-two-steer-castor"):  # ackermann's linkage allows every ICR
        live = api.analyze_live({"description": catalog.load(name).to_dict()})["analysis"]
        assert live["type_notes"] == [], name

