"""The Python examples of docs/dynamics.md run and print what the page says."""

from __future__ import annotations

import re
from pathlib import Path

from doc_examples import check_python_examples

ROOT = Path(__file__).resolve().parents[2]


def test_python_examples_of_the_dynamics_page_print_what_it_says():
    check_python_examples("dynamics.md", 3)


def test_figures_of_the_page_exist():
    text = (ROOT / "docs" / "dynamics.md").read_text()
    for path in re.findall(r"\]\((figures/dynamics/[\w.-]+)\)", text):
        assert (ROOT / "docs" / path).exists(), path
