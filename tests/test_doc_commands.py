"""Every ``$ wmrkit ...`` example of the documentation prints what its page shows (``...`` elides lines)."""

from __future__ import annotations

import pytest

from doc_examples import ROOT, check_command_examples, command_examples

PAGES = sorted(p.name for p in (ROOT / "docs").glob("*.md") if command_examples(p.name))


def test_the_pages_with_command_examples_are_found():
    assert {"control.md", "vision.md", "wheel-ik.md", "slip-control.md", "limits.md", "parking.md"} <= set(PAGES)


@pytest.mark.parametrize("page", PAGES)
def test_command_examples_print_what_the_page_shows(page, tmp_path, capsys):
    assert check_command_examples(page, tmp_path, capsys) > 0
