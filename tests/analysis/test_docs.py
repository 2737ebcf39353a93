"""The Python example of docs/analysis.md prints what its comments say (its other block is a sketch of calls,
not a program)."""

from __future__ import annotations

from doc_examples import check_python_examples


def test_the_vehicle_type_example_prints_what_its_comments_say():
    """It was checked by no test: its `print(...)` comments, `...` standing for the elided text."""
    check_python_examples("analysis.md", 1)
