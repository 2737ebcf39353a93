"""The Python examples of docs/control.md run as written."""

from __future__ import annotations

import re
from pathlib import Path

DOC = Path(__file__).resolve().parents[2] / "docs" / "control.md"


def test_python_examples_run():
    blocks = re.findall(r"```python\n(.*?)```", DOC.read_text(encoding="utf-8"), re.S)
    assert blocks
    spaces = []
    for block in blocks:
        namespace: dict = {}
        exec(compile(block, str(DOC), "exec"), namespace)
        spaces.append(namespace)
    run = spaces[0]["run"]
    assert run.summary()["final_error"] < 1e-6 and run.summary()["max_error"] == 0.5
    assert spaces[1]["feasible"] and spaces[1]["twist"].any()


def test_every_figure_exists():
    for name in re.findall(r"\(figures/control/([\w.-]+\.png)\)", DOC.read_text(encoding="utf-8")):
        assert (DOC.parent / "figures" / "control" / name).exists(), name


def test_the_lookahead_paragraph_s_sampled_figure_eight_is_what_the_code_gives():
    """'the car's figure-eight at 5 m/s, --period 0.1 --delay 1, N mm RMS (M mm max) at 1 m, passing the path's end
    E m beside it (...), against N' mm (M' mm) at 2.7 m, ending E' m from it': the page said 138 mm RMS (605 mm max)
    at 1 m, from earlier code; the code gives 133 (574) and ends 0.315 m from the end with a warning."""
    import warnings

    import numpy as np

    from wmrkit import catalog
    from wmrkit.control import builtin_reference, track
    from wmrkit.control.trackers import ArrivalWarning

    text = " ".join(DOC.read_text(encoding="utf-8").split())
    said = re.search(r"`--period 0\.1 --delay 1`, (\d+) mm RMS \((\d+) mm max\) at 1 m, passing the path's end "
                     r"([\d.]+) m beside it \([^)]*\), against (\d+) mm \((\d+) mm\) at 2\.7 m, ending ([\d.]+) m from "
                     r"it", text)
    assert said, "the sentence on the sampled figure-eight"
    car, ref = catalog.load("ackermann"), builtin_reference("figure-eight", speed=5.0, size=29.0)
    for lookahead, (rms, top, end), warns in ((1.0, said.groups()[:3], True), (2.7, said.groups()[3:], False)):
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always", ArrivalWarning)
            run = track(car, ref, controller="pure-pursuit", period=0.1, delay=1, lookahead=lookahead)
        s = run.summary()
        assert round(1e3 * s["rms_cross_track"]) == int(rms) and round(1e3 * s["max_cross_track"]) == int(top)
        ended = float(np.hypot(*(run.tracked[-1, :2] - ref.pose[-1, :2])))
        assert abs(ended - float(end)) <= 0.5 * 10.0 ** -len(end.split(".")[1]), (lookahead, ended)
        assert any(issubclass(w.category, ArrivalWarning) for w in caught) == warns
