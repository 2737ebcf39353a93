"""The examples of docs/parking.md run and print what the page says (doctest over the markdown), and its table
against Reeds-Shepp is what docs/figures/make_parking.py computes today."""

from __future__ import annotations

import doctest
import importlib.util
import re
from pathlib import Path

import pytest

DOC = Path(__file__).resolve().parents[2] / "docs" / "parking.md"


def test_parking_page_examples_run():
    result = doctest.testfile(str(DOC), module_relative=False, optionflags=doctest.NORMALIZE_WHITESPACE, verbose=False)
    assert result.attempted >= 10
    assert result.failed == 0


def test_the_reeds_shepp_table_is_what_the_code_gives():
    """Every row of the page's comparison table but its planning time (one run's, on some machine) is recomputed:
    the rows of 9.1 at H = 6 m (past its roomy length: 6.84 m then 4.27 m, parked in 3.2 m of the slot) and 9.2 at
    H = 4 m (13.46 m then 17.21 m; Reeds-Shepp through 1327 then 2028 poses) had been left from before the planner
    changed."""
    pytest.importorskip("rsplan")
    pytest.importorskip("shapely")
    spec = importlib.util.spec_from_file_location("make_parking", DOC.parent / "figures" / "make_parking.py")
    script = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(script)

    def untimed(lines: list[str]) -> list[list[str]]:
        return [row[:5] + row[6:] for row in (line.split(" | ") for line in lines)]

    shown = [line for line in DOC.read_text().splitlines() if re.match(r"\| (Table |9\.\d, H)", line)]
    assert len(shown) == 12
    assert untimed(shown) == untimed(script.comparison(repeat=1).splitlines()[2:])
