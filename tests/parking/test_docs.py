"""The examples of docs/parking.md run and print what the page says (doctest over the markdown)."""

from __future__ import annotations

import doctest
from pathlib import Path

DOC = Path(__file__).resolve().parents[2] / "docs" / "parking.md"


def test_parking_page_examples_run():
    result = doctest.testfile(str(DOC), module_relative=False, optionflags=doctest.NORMALIZE_WHITESPACE, verbose=False)
    assert result.attempted >= 10
    assert result.failed == 0
