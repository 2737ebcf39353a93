"""Hostile request bodies at the studio's door: a huge integer, a quantity with a unit, a misspelt field or wheel
name answer 4xx with one short line naming the field (never a 500), and the twist reads units as `wmrkit ik`."""

from __future__ import annotations

import contextlib
import io
import json
import math
from pathlib import Path

import pytest

pytest.importorskip("starlette")
pytest.importorskip("httpx2")  # starlette.testclient's transport

from starlette.testclient import TestClient

from wmrkit import catalog
from wmrkit.cli.main import main as cli_main
from wmrkit.studio.app import create_app


@pytest.fixture()
def client(tmp_path: Path):
    return TestClient(create_app(tmp_path), raise_server_exceptions=False)


def desc(name: str) -> dict:
    return catalog.load(name).to_dict()


@pytest.mark.parametrize(("body", "field"), [
    ({"twist": [10**400, 0, 0]}, "twist.vx"), ({"twist": [0, 0, 0], "duration": 10**400}, "duration"),
])
def test_an_integer_too_large_for_a_float_is_a_400(client, body, field):
    """JSON integers have no bound: 1e400 written as digits was an OverflowError (500) in the twist's check."""
    r = client.post("/api/drive", json={"description": desc("diff-drive"), **body})
    assert r.status_code == 400, r.text
    assert r.json()["error"].startswith(f"{field}: ") and "too large" in r.json()["error"]


def _ik_json(*args: str) -> dict:
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        assert cli_main(["ik", *args, "--json"]) == 0
    return json.loads(out.getvalue())


def test_twist_takes_units_as_wmrkit_ik(client):
    """'500 mm/s' and '30 deg/s' were refused ('is a speed, expected a number') where `wmrkit ik --twist` reads
    them: the studio and the CLI give the same spins for the same twist written with units."""
    twist = ["500 mm/s", "0.36 km/h", "30 deg/s"]
    r = client.post("/api/drive", json={"description": desc("mecanum-4"), "twist": twist})
    assert r.status_code == 200, r.json()
    assert r.json()["twist"] == pytest.approx([0.5, 0.1, math.pi / 6], rel=1e-15)
    ik = _ik_json("mecanum-4", "--twist", *twist)
    for name, wheel in ik["wheels"].items():
        assert r.json()["wheels"][name]["spin"] == pytest.approx(wheel["spin"], rel=1e-12)


@pytest.mark.parametrize(("twist", "words"), [
    (["1 deg", 0, 0], "twist.vx: '1 deg' is an angle, expected a speed"),
    ([0, 0, "1 m/s"], "twist.omega: '1 m/s' is a speed, expected an angular rate"),
    ([0, None, 0], "twist.vy: expected a speed, got no value (null)"),
    ([0, 0, 2e6], "twist.omega: beyond 1e+06"),
])
def test_twist_errors_name_the_component(client, twist, words):
    r = client.post("/api/drive", json={"description": desc("diff-drive"), "twist": twist})
    assert r.status_code == 400 and r.json()["error"].startswith(words), r.json()


def test_duration_takes_a_time_unit(client):
    body = {"description": desc("diff-drive"), "twist": [0.2, 0, 0.5], "samples": 5}
    ms = client.post("/api/drive", json={**body, "duration": "1500 ms"})
    assert ms.status_code == 200, ms.json()
    assert ms.json() == client.post("/api/drive", json={**body, "duration": 1.5}).json()
    r = client.post("/api/drive", json={**body, "duration": "3 m"})
    assert r.status_code == 400 and r.json()["error"].startswith("duration: '3 m' is a length, expected a time")


@pytest.mark.parametrize(("endpoint", "body", "hint"), [
    ("/api/drive", {"twist": [1, 0, 0], "sample": 5}, "samples"),
    ("/api/drive", {"twist": [1, 0, 0], "twists": [1, 0, 0]}, "twist"),
    ("/api/kappa", {"resoluton": 24}, "resolution"),
    ("/api/save", {"path": "a.yaml", "overwrit": True}, "overwrite"),
    ("/api/analyze", {"descripton": {}}, "description"),
    ("/api/drive", {"twist": [0, 0, 0], "heading": {"front_lef": 0}}, "front_left"),
    ("/api/kappa", {"wheels": ["front_lef"]}, "front_left"),
])
def test_a_misspelt_field_or_wheel_says_did_you_mean(client, endpoint, body, hint):
    """A misspelt request field or wheel listed every choice but named none; the description's fields say
    "(did you mean 'r'?)", and so do the request's now."""
    full = {"description": desc("swerve-4"), **body} if "descripton" not in body else body
    r = client.post(endpoint, json=full)
    assert r.status_code == 400, r.json()
    assert f"(did you mean '{hint}'?)" in r.json()["error"], r.json()


@pytest.mark.parametrize(("endpoint", "body"), [
    ("/api/drive", {"twist": [0, 0, 0], "samples": "9" * 100_000}),
    ("/api/drive", {"twist": [0, 0, 0], "samples": 10**4000}),
    ("/api/kappa", {"resolution": "9" * 100_000}),
])
def test_a_huge_value_is_quoted_short(client, endpoint, body):
    """samples of 100,000 digits was quoted whole in the error line."""
    r = client.post(endpoint, json={"description": desc("swerve-4"), **body})
    assert r.status_code == 400 and len(r.json()["error"]) < 200, r.json()["error"][:300]


def test_another_host_name_is_refused_in_json(tmp_path):
    """The DNS-rebinding refusal was Starlette's plain text 'Invalid host header', not the studio's JSON error
    naming the host and the names it answers; the security headers stay."""
    from wmrkit.studio.app import LOCAL_HOSTS

    app = create_app(tmp_path, allowed_hosts=LOCAL_HOSTS)
    r = TestClient(app, base_url="http://evil.example:8765").get("/api/meta")
    assert r.status_code == 400 and r.headers["content-type"] == "application/json", r.text
    assert r.json()["error"].startswith("host 'evil.example:8765' refused: the studio answers only 127.0.0.1,")
    assert r.headers["x-frame-options"] == "DENY"
    for base in ("http://127.0.0.1:8765", "http://[::1]:8765", "http://LOCALHOST"):
        assert TestClient(app, base_url=base).get("/api/files").status_code == 200, base
