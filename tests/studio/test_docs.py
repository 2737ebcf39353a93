"""docs/studio.md's Python example prints what its comments say."""

from __future__ import annotations

from doc_examples import check_python_examples


def test_python_example_prints_what_the_page_shows():
    """The page showed `2 1.0` for diff-drive's condition number, the call printed `2 1.0000000000000004` (round-off
    of kappa = 1: at D = the half track 0.2 m the spins are (vx -+ D omega) / r, rows (1, -+1) / r, orthogonal)."""
    check_python_examples("studio.md", 1)
