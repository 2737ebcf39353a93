"""Property tests of the studio's endpoints: random robots give the library's analysis, random JSON never a 5xx."""

from __future__ import annotations

import math

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from strategies import robots

pytest.importorskip("starlette")
pytest.importorskip("httpx2")  # starlette.testclient's transport (plain httpx is deprecated there)

from starlette.testclient import TestClient

from wmrkit.analysis.summary import analyze
from wmrkit.errors import WmrkitError
from wmrkit.studio import api
from wmrkit.studio.app import create_app

CLIENT = TestClient(create_app("."))  # read-only here: no endpoint that writes is called
FUZZ = st.recursive(
    st.none() | st.booleans() | st.integers(-10**6, 10**6) | st.floats(allow_nan=False, allow_infinity=False)
    | st.text(max_size=12) | st.sampled_from(["fixed", "castor", "swedish", "90 deg", "5 mm", "pi/2", "wheels"]),
    lambda inner: st.lists(inner, max_size=4) | st.dictionaries(
        st.sampled_from(["name", "type", "wheels", "r", "beta", "heading", "position", "l", "alpha", "d", "gamma",
                         "r_r", "b", "delta", "actuated", "sensed", "twist"]), inner, max_size=6),
    max_leaves=25,
)


@settings(max_examples=100, suppress_health_check=[HealthCheck.too_slow])
@given(robots(max_wheels=3))
def test_live_analysis_equals_library(robot):
    try:
        live = api.live_summary(robot)
    except WmrkitError:
        with pytest.raises(WmrkitError):
            analyze(robot)
        return
    full = analyze(robot).to_dict()
    for key in ("mobility", "steerability", "type", "degenerate", "reasons", "instantaneous_mobility"):
        assert live[key] == full[key]
    assert live["icr"]["text"] == full["icr"]
    k, want = live["condition_number"], full["condition_number"]
    assert (k is None and (want is None or not math.isfinite(want))) or k == pytest.approx(want, rel=1e-9)


@settings(max_examples=200, suppress_health_check=[HealthCheck.too_slow])
@given(st.sampled_from(["/api/analyze", "/api/drive", "/api/kappa", "/api/configurations", "/api/open"]),
       st.dictionaries(st.sampled_from(["description", "twist", "heading", "wheels", "resolution", "catalog",
                                        "samples", "duration"]), FUZZ, max_size=4))
def test_random_json_is_answered_without_a_server_error(endpoint, body):
    r = CLIENT.post(endpoint, json=body)
    assert r.status_code < 500, r.text
    if r.status_code >= 400:
        assert r.json()["error"]
