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
