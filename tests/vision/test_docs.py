"""The Python examples of docs/vision.md run and print what the page says."""

from __future__ import annotations

import os
import re
from pathlib import Path

from doc_examples import check_python_examples

ROOT = Path(__file__).resolve().parents[2]


def test_python_examples_of_the_vision_page_print_what_it_says():
    check_python_examples("vision.md", 2)


def test_command_examples_of_the_vision_page_print_what_it_says(tmp_path, capsys):
    import shlex

    from wmrkit.cli.main import main

    text = (ROOT / "docs" / "vision.md").read_text()
    blocks, current = [], None
    for line in text.splitlines():
        if line.startswith("```"):
            if current is None:
                current = [] if line == "```" else ["#skip"]
            else:
                if current[:1] != ["#skip"]:
                    blocks.append("\n".join(current) + "\n")
                current = None
        elif current is not None:
            current.append(line)
    examples = []
    for block in blocks:
        for chunk in re.split(r"^\$ ", block, flags=re.M)[1:]:
            lines = chunk.replace("\\\n", " ").splitlines()
            examples.append((shlex.split(lines[0]), [ln for ln in lines[1:] if ln.strip() and ln != "..."]))
    assert len(examples) == 6
    cwd = os.getcwd()
    os.chdir(ROOT)
    try:
        for argv, shown in examples:
            argv = [str(tmp_path / a) if a == "camera.yaml" else a for a in argv]
            assert argv[0] == "wmrkit" and main(argv[1:]) == 0
            out = capsys.readouterr().out.splitlines()
            for line in shown:
                assert line.replace("camera file camera.yaml", f"camera file {tmp_path / 'camera.yaml'}") in out
    finally:
        os.chdir(cwd)
