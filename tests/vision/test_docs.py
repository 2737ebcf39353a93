"""The Python examples of docs/vision.md run and print what the page says (its commands: tests/test_doc_commands.py)."""

from __future__ import annotations

from doc_examples import check_python_examples


def test_python_examples_of_the_vision_page_print_what_it_says():
    check_python_examples("vision.md", 2)
