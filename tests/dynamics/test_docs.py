"""The Python examples of docs/dynamics.md run and print what the page says."""

from __future__ import annotations

import contextlib
import io
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def test_python_examples_of_the_dynamics_page_print_what_it_says():
    text = (ROOT / "docs" / "dynamics.md").read_text()
    blocks = re.findall(r"```python\n(.*?)```", text, flags=re.S)
    assert len(blocks) == 2
    for block in blocks:
        expected = [m.strip() for m in re.findall(r"print\(.*\)\s+#\s*(.*)$", block, flags=re.M)]
        out = io.StringIO()
        with contextlib.redirect_stdout(out):
            exec(compile(block, "docs/dynamics.md", "exec"), {})  # our own documentation, not user text
        assert out.getvalue().split("\n")[:-1] == expected


def test_figures_of_the_page_exist():
    text = (ROOT / "docs" / "dynamics.md").read_text()
    for path in re.findall(r"\]\((figures/dynamics/[\w.-]+)\)", text):
        assert (ROOT / "docs" / path).exists(), path
