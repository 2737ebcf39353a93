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


def test_a_row_of_the_table_is_what_the_script_gives():
    """The forklift's circle with FK2 feedback and no-slip commands (a loop that does not amplify round-off), as
    docs/figures/control/make_slip_control.py computes it: the page had 257.8 / 303.3 mm, from earlier code (table of
    2026-11-25); the script gives 258.4 / 303.9 mm."""
    import importlib.util

    from wmrkit import catalog
    from wmrkit.control import track

    spec = importlib.util.spec_from_file_location(
        "make_slip_control", ROOT / "docs" / "figures" / "control" / "make_slip_control.py")
    script = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(script)
    (robot_name, ref_name, speed, size, duration) = script.CASES[0]
    weights, noise = script.estimators(robot_name)
    run = track(catalog.load(robot_name), script.ramped(ref_name, speed, size, duration), dynamics=True,
                period=script.PERIOD, slip_model="none", feedback="fk2", weights=weights, noise=noise,
                ramp=script.HOLD_RAMP)
    s = run.summary(script.SETTLE)
    row = next(line for line in (ROOT / "docs" / "slip-control.md").read_text().splitlines()
               if line.startswith(f"| {robot_name} | {ref_name} (") and "| fk2 |" in line)
    cells = row.split(" | ")
    assert (cells[3], cells[5]) == (f"{1e3 * s['rms_error']:.1f}", f"{1e3 * s['max_error']:.1f}"), row
