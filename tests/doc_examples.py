"""Run the Python examples of a documentation page and compare what they print with the page's ``# comments``."""

from __future__ import annotations

import contextlib
import io
import os
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def check_python_examples(page: str, count: int) -> None:
    """Each ```python block of ``docs/<page>`` runs (from the repository root) and prints, line by line, the
    comments after its ``print(...)`` calls; the page has `count` blocks."""
    text = (ROOT / "docs" / page).read_text()
    blocks = re.findall(r"```python\n(.*?)```", text, flags=re.S)
    assert len(blocks) == count
    cwd = os.getcwd()
    os.chdir(ROOT)
    try:
        for block in blocks:
            expected = [m.strip() for m in re.findall(r"print\(.*\)\s+#\s*(.*)$", block, flags=re.M)]
            out = io.StringIO()
            with contextlib.redirect_stdout(out):
                exec(compile(block, f"docs/{page}", "exec"), {})  # our own documentation, not user text
            assert out.getvalue().split("\n")[:-1] == expected
    finally:
        os.chdir(cwd)
