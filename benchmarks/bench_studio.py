"""Studio benchmarks: server time per edit (the live analysis of an 8-wheel robot) and one drive request.

Target (issue 14): at most 20 ms median per edit on the server; the browser side (edit -> numbers shown, at most
50 ms) is measured by tests/studio/test_browser.py and printed there. Each edit is a new robot (a wheel moved by
0.1 mm), so no per-robot cache helps, as in the page. The peer is the library's full :func:`wmrkit.analysis.analyze`
(which adds the singular sets over the whole steering space) on the same edits; "HTTP" is the whole ASGI request
(JSON in and out) through Starlette's test client.
"""

from __future__ import annotations

import math
import statistics
import time

from wmrkit.analysis.summary import analyze
from wmrkit.description import robot_from_dict

from ._harness import Result


def ring(kind: str, n: int = 8, shift: float = 0.0) -> dict:
    """An 8-wheel robot description: wheels on a circle of radius 0.4 m (+ `shift`), all driven and sensed."""
    wheels = []
    for i in range(n):
        w = {"name": f"w{i}", "type": kind, "l": 0.4 + shift, "alpha": 2 * math.pi * i / n, "r": 0.05,
             "beta": math.pi / 2, "actuated": ["spin"], "sensed": ["spin"]}
        if kind == "swedish":
            w.update(gamma=math.pi / 4 * (1 if i % 2 else -1), r_r=0.01)
        elif kind == "castor":
            w.update(d=0.05)
        elif kind == "steerable":
            w.update(actuated=["spin", "steer"], sensed=["spin", "steer"])
        wheels.append(w)
    return {"name": f"{kind}-8", "wheels": wheels}


ROBOTS = {"mecanum-8 (m = 3)": "swedish", "castor-8 (8 steering angles)": "castor",
          "swerve-8 (coordinated)": "steerable", "fixed-8 (skid)": "fixed"}


def _median(fn, descriptions: list[dict]) -> float:
    times = []
    for d in descriptions:
        t0 = time.perf_counter()
        fn(d)
        times.append(time.perf_counter() - t0)
    return statistics.median(times)


def run(quick: bool) -> list[Result]:
    """Median server time per edit for four 8-wheel robots, vs the full analysis; one HTTP round per robot."""
    from wmrkit.studio import api

    edits = 7 if quick else 25
    results = []
    for label, kind in ROBOTS.items():
        descriptions = [ring(kind, shift=1e-4 * k) for k in range(edits)]
        api.analyze_live({"description": ring(kind, shift=-1e-4)})  # warm compiled kernels, not this robot
        ours = _median(lambda d: api.analyze_live({"description": d}), descriptions)
        peer = _median(lambda d: analyze(robot_from_dict(d)), [ring(kind, shift=2e-4 * k + 5e-5)
                                                                for k in range(max(3, edits // 3))])
        results.append(Result(f"studio edit: {label}", 1, ours, "analyze() full", peer, "< 20 ms median"))
    try:
        from starlette.testclient import TestClient

        from wmrkit.studio.app import create_app
    except ImportError:
        return results
    client = TestClient(create_app("."))
    for label, kind in (("mecanum-8", "swedish"), ("castor-8", "castor")):
        descriptions = [ring(kind, shift=0.01 + 1e-4 * k) for k in range(edits)]
        ours = _median(lambda d: client.post("/api/analyze", json={"description": d}).raise_for_status(),
                       descriptions)
        results.append(Result(f"studio HTTP /api/analyze: {label}", 1, ours, "analyze() full", None,
                              "< 20 ms median"))
        drive = _median(lambda d: client.post("/api/drive", json={"description": d, "twist": [0.3, 0.1, 0.2]})
                        .raise_for_status(), descriptions)
        results.append(Result(f"studio HTTP /api/drive: {label}", 1, drive, "-", None, ""))
    return results
