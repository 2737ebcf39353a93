"""The examples of docs/slip.md run and print what the page says (doctest over the markdown)."""

from __future__ import annotations

import doctest
from pathlib import Path

DOC = Path(__file__).resolve().parents[2] / "docs" / "slip.md"


def test_slip_page_examples_run():
    result = doctest.testfile(str(DOC), module_relative=False, optionflags=doctest.NORMALIZE_WHITESPACE, verbose=False)
    assert result.attempted >= 8
    assert result.failed == 0
