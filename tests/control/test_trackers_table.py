"""docs/control.md's table of the path followers on the catalog robots is what the code gives (some of its rows,
recomputed: docs/figures/control/make_trackers_table.py writes it all)."""

from __future__ import annotations

import importlib.util
import re

import pytest

from doc_examples import ROOT

SCRIPT = ROOT / "docs" / "figures" / "control" / "make_trackers_table.py"


def _script():
    spec = importlib.util.spec_from_file_location("make_trackers_table", SCRIPT)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _doc_rows() -> list[str]:
    text = (ROOT / "docs" / "control.md").read_text()
    return [line for line in text.splitlines() if re.match(r"\| [\w-]+ \| [\w-]+ \| (pure-pursuit|stanley) \| [\d.]+ \|"
                                                            r" [\d.]+ \| [\d.]+ \| [\d.]+ \|$", line)]


def test_the_table_has_every_row_and_no_steering_held_at_a_stop():
    """Every robot x reference x controller of the script is in the page, once; no steered wheel was held beyond
    its range on any of them (the trackers ask a car for no turn tighter than its steering allows)."""
    script, rows = _script(), _doc_rows()
    keys = [tuple(r.split(" | ")[:3]) for r in rows]
    assert sorted(keys) == sorted((f"| {a}", b, c) for a in script.ROBOTS for b in script.REFERENCES
                                  for c in script.CONTROLLERS)
    assert all(r.split(" | ")[5] == "0.0" for r in rows)


def test_every_row_on_a_smooth_reference_ends_at_the_path_s_end():
    """Every row on a reference Table 8.1 lets the robots follow (no tangent jump) ends within 0.1 m of the path's
    end (the tolerance of a follower of length 1 m, the shortest here: ``ARRIVAL_FRACTION``; that it ends on the
    path, not short of it, test_follower_arrival checks on these runs)."""
    smooth = [r for r in _doc_rows() if r.split(" | ")[1] in ("line", "circle", "figure-eight", "arc-line")]
    assert len(smooth) == 6 * 4 * 2
    assert all(float(r.split(" | ")[6].rstrip(" |")) < 100.0 for r in smooth), smooth


@pytest.mark.parametrize(("robot", "reference", "controller"), [("ackermann", "square", "pure-pursuit"),
                                                                ("ackermann", "figure-eight", "pure-pursuit"),
                                                                ("forklift", "arc-line", "stanley")])
def test_rows_of_the_table_are_what_the_code_gives(robot, reference, controller):
    assert _script().row(robot, reference, controller) in _doc_rows()


def test_the_page_s_bounds_on_the_last_column_are_the_table_s():
    """The sentence under the table bounds its last column per follower ("Stanley's every row within 19 mm (...),
    pure pursuit's within 0.3 mm, and no row warns") by the table's own largest values: it said three rows ended
    beside the end and warned (339, 515, 108.5 mm) while those rows read 0.0 since pure pursuit holds its goal
    point at the end."""
    text = " ".join((ROOT / "docs" / "control.md").read_text().split())
    said = re.search(r"Stanley's every row within ([\d.]+) mm \([^)]*\), pure pursuit's within ([\d.]+) mm, and no row "
                     r"warns", text)
    assert said, "the sentence bounding the table's last column"
    for controller, bound in (("stanley", float(said[1])), ("pure-pursuit", float(said[2]))):
        largest = max(float(r.split(" | ")[6].rstrip(" |")) for r in _doc_rows() if r.split(" | ")[2] == controller)
        assert largest <= bound < largest + 1, (controller, largest, bound)
