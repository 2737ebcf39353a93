"""The Python examples of docs/slip-control.md run and print what the page says; its figures exist."""

from __future__ import annotations

import re

from doc_examples import ROOT, check_python_examples


def test_python_examples_print_what_the_page_says():
    check_python_examples("slip-control.md", 2)


def test_every_figure_exists():
    text = (ROOT / "docs" / "slip-control.md").read_text()
    names = re.findall(r"\(figures/control/([\w.-]+\.png)\)", text)
    assert names
    for name in names:
        assert (ROOT / "docs" / "figures" / "control" / name).exists(), name
