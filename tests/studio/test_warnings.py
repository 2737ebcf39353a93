"""The studio says a description's warnings (``DescriptionWarning``: a ``mecanum`` wheel whose ``gamma`` is not
+-45 deg) in its answers' ``warnings``, the lines ``wmrkit analyze --json`` gives, and not on the server's stderr.
Before: /api/analyze, /api/open and /api/meta had no ``warnings``; Python's warning went to the server's stderr."""

from __future__ import annotations

import json
import warnings

import pytest

from wmrkit import catalog
from wmrkit.cli.main import main
from wmrkit.description import DescriptionWarning

pytest.importorskip("starlette")
from starlette.testclient import TestClient

from wmrkit.studio import api
from wmrkit.studio.app import create_app

CORNERS = {"fl": (0.2, 0.15), "fr": (0.2, -0.15), "rl": (-0.2, 0.15), "rr": (-0.2, -0.15)}


def _mecanum(gamma: str | None) -> dict:
    """mecanum-4's layout, the first wheel's gamma as given (None: from its quadrant, the standard +45 deg)."""
    wheels = [{"name": n, "type": "mecanum", "position": [x, y], "r": 0.05, "actuated": ["spin"]}
              for n, (x, y) in CORNERS.items()]
    if gamma is not None:
        wheels[0]["gamma"] = gamma
    return {"name": "mg", "wheels": wheels}


def _cli_warnings(tmp_path, capsys, description: dict, name: str = "mg.json") -> tuple[str, list[str]]:
    """The file's path and the warnings `wmrkit analyze FILE --json` gives (the reference; one JSON line: line 1)."""
    path = tmp_path / name
    path.write_text(json.dumps(description), encoding="utf-8")
    assert main(["analyze", str(path), "--json"]) == 0
    return str(path), json.loads(capsys.readouterr().out)["warnings"]


@pytest.mark.parametrize(("gamma", "said"), [("90 deg", True), ("30 deg", True), (None, False),
                                             ("-45 deg", False), ("135 deg", False)])
def test_analyze_answers_the_description_warnings(tmp_path, capsys, gamma, said):
    _, want = _cli_warnings(tmp_path, capsys, _mecanum(gamma))
    assert bool(want) == said
    client = TestClient(create_app(tmp_path))
    with warnings.catch_warnings():
        warnings.simplefilter("error", DescriptionWarning)  # a warning escaping the answer would be a 500
        r = client.post("/api/analyze", json={"description": _mecanum(gamma)})
    assert r.status_code == 200, r.text
    got = r.json()["warnings"]
    # the same line as the CLI's, the source being the studio's rather than the file's
    assert got == [w.replace(f"{tmp_path / 'mg.json'}:1: ", "studio: ") for w in want], (got, want)
    if said:
        assert got[0].startswith("studio: wheels[0].gamma: wheel 'fl' is of type mecanum with gamma ")
    assert capsys.readouterr().err == ""  # nothing on the server's stderr


@pytest.mark.parametrize("name", ["diff-drive", "mecanum-4", "swerve-4", "omni-3"])
def test_a_normal_robot_has_no_warnings(tmp_path, name):
    client = TestClient(create_app(tmp_path))
    r = client.post("/api/analyze", json={"description": catalog.load(name).to_dict()})
    assert r.status_code == 200 and r.json()["warnings"] == []
    r = client.post("/api/open", json={"catalog": name})
    assert r.status_code == 200 and r.json()["warnings"] == []


def test_open_and_start_file_answer_the_file_warnings(tmp_path, capsys):
    path, want = _cli_warnings(tmp_path, capsys, _mecanum("90 deg"))
    assert len(want) == 1 and want[0].startswith(f"{path}:1: wheels[0].gamma: ")
    client = TestClient(create_app(tmp_path, robot_spec="mg.json"))
    with warnings.catch_warnings():
        warnings.simplefilter("error", DescriptionWarning)
        opened = client.post("/api/open", json={"path": "mg.json"})
        start = client.get("/api/meta").json()["start"]
    assert opened.status_code == 200 and opened.json()["warnings"] == want
    assert start["warnings"] == want and "error" not in start
    # the description answered is written back as a swedish wheel: nothing more to say about it
    assert client.post("/api/analyze", json={"description": opened.json()["description"]}).json()["warnings"] == []
    assert capsys.readouterr().err == ""


def test_other_endpoints_keep_the_warning_off_stderr(tmp_path, capsys):
    """/api/configurations, /api/kappa, /api/drive and /api/save read the same description: silently (the page
    shows the warning from /api/analyze)."""
    client = TestClient(create_app(tmp_path))
    body = {"description": _mecanum("90 deg")}
    with warnings.catch_warnings():
        warnings.simplefilter("error", DescriptionWarning)
        assert client.post("/api/configurations", json=body).status_code == 200
        assert client.post("/api/drive", json=body | {"twist": [0.1, 0, 0]}).status_code == 200
        assert client.post("/api/save", json=body | {"path": "out.yaml"}).status_code == 200
    assert capsys.readouterr().err == ""


def test_with_warnings_passes_other_warnings_on():
    def read():
        warnings.warn("not a description's", UserWarning, stacklevel=1)
        return 1

    with pytest.warns(UserWarning, match="not a description's"):
        assert api.with_warnings(read) == (1, [])
