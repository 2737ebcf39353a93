"""The README's examples work as written: its Python block runs, and every command of "What you get" exits 0 from
a fresh directory (the studio, a server that runs until stopped, is left to tests/studio)."""

from __future__ import annotations

import os
import re
import shlex
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
README = (ROOT / "README.md").read_text()


def test_the_python_example_runs(tmp_path, monkeypatch):
    blocks = re.findall(r"```python\n(.*?)```", README, flags=re.S)
    assert blocks
    monkeypatch.chdir(tmp_path)
    for block in blocks:
        exec(compile(block, "README.md", "exec"), {})  # our own README, not user text


def what_you_get() -> list[tuple[str, int]]:
    """The commands of the README's "What you get" block, without their comments, each with its exit code (0, or N
    where its comment says 'exit N': an answer that is no)."""
    section = README.split("## What you get", 1)[1].split("```", 2)[1]
    lines = [line.strip() for line in section.splitlines() if line.startswith(("wmrkit ", "python "))]
    said = [re.search(r"#.*\bexit (\d)", line) for line in lines]
    commands = [re.sub(r"\s+#.*$", "", line) for line in lines]
    return [(c, int(s[1]) if s else 0) for c, s in zip(commands, said, strict=True)]


def test_every_command_of_what_you_get_exits_0(tmp_path):
    """Or 1 where its comment says so (docs/limits.md, Exit codes)."""
    commands = [(c, code) for c, code in what_you_get() if not c.startswith("wmrkit studio")]
    assert len(commands) >= 15
    for folder in ("examples", "docs"):  # commands name files of the repository by relative path
        (tmp_path / folder).symlink_to(ROOT / folder)
    env = {**os.environ, "MPLBACKEND": "Agg"}
    failed = []
    for command, code in commands:  # in order: the odometry commands read the log the example script writes
        words = shlex.split(command)
        argv = [sys.executable, "-m", "wmrkit", *words[1:]] if words[0] == "wmrkit" else [sys.executable, *words[1:]]
        out = subprocess.run(argv, cwd=tmp_path, env=env, capture_output=True, text=True, timeout=600)
        if out.returncode != code:
            failed.append(f"{command}: exit {out.returncode}: {out.stderr.strip()[-300:]}")
    assert failed == []


def test_a_wheel_written_as_the_readme_writes_it_without_its_heading_is_told_heading(tmp_path):
    """The README writes wheels with `position` and `heading`; forgetting the heading was reported as a missing
    'beta', a field that file never used."""
    from wmrkit import DescriptionError, Robot

    path = tmp_path / "rover.yaml"
    path.write_text("name: rover\nwheels:\n  - {name: left, type: fixed, position: [0, 0.3], r: 0.1}\n")
    with pytest.raises(DescriptionError) as err:
        Robot.from_file(path)
    assert str(err.value).endswith("rover.yaml:3: wheels[0]: missing field 'heading' (rolling direction, "
                                   "0 = straight ahead; or the thesis's 'beta')")


def test_the_described_robot_is_rated_as_the_readme_says(tmp_path, capsys):
    """'Describing a robot': its YAML, saved as tricycle.yaml, is what the sentence after it says: 'wmrkit analyze
    tricycle.yaml rates it a type-4 vehicle (m = 1, d = 1) with sufficient, consistent actuators'."""
    import json

    from wmrkit.cli.main import main

    section = README.split("## Describing a robot", 1)[1]
    (tmp_path / "tricycle.yaml").write_text(re.findall(r"```yaml\n(.*?)```", section, flags=re.S)[0])
    assert "`wmrkit analyze tricycle.yaml` rates it a type-4 vehicle (m = 1, d = 1) with sufficient, consistent" \
           in " ".join(section.split())
    assert main(["analyze", str(tmp_path / "tricycle.yaml"), "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert (report["type"], report["mobility"], report["steerability"]) == (4, 1, 1)
    assert report["actuation"]["sufficient"] and report["actuation"]["consistent"]


def test_what_you_get_names_every_command():
    """Each command of `wmrkit --help` has a line (or, needing files of one's own, a comment) in "What you get":
    `sweep`, `slip-study`, `vision` and `calibrate` had none, and `batch ...  # also sweep, montecarlo` sent a
    reader to a `wmrkit batch sweep` that does not exist."""
    import argparse

    from wmrkit.cli.main import build_parser

    block = README.split("## What you get", 1)[1].split("```", 2)[1]
    parser = build_parser()
    commands = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction)).choices
    assert [c for c in commands if f"wmrkit {c} " not in block + " "] == []
    for group in ("batch", "vision"):
        said = {m for line in block.splitlines() if line.startswith(f"wmrkit {group} ")
                for m in re.findall(r"[\w-]+", line.split()[2] + " " + line.partition("# ")[2])}
        assert said & set(commands[group]._subparsers._group_actions[0].choices)  # a real subcommand
        assert not re.search(rf"wmrkit {group}\b.*#.*\balso\b.*\bsweep\b", block)
