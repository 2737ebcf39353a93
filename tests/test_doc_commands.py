"""Every ``$ wmrkit ...`` example of the documentation prints what its page shows (``...`` elides lines)."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from doc_examples import ROOT, check_command_examples, command_examples

PAGES = sorted(p.name for p in (ROOT / "docs").glob("*.md") if command_examples(p.name))


def test_the_pages_with_command_examples_are_found():
    assert {"control.md", "vision.md", "wheel-ik.md", "slip-control.md", "limits.md", "parking.md",
            "batch.md"} <= set(PAGES)


@pytest.mark.parametrize("page", PAGES)
def test_command_examples_print_what_the_page_shows(page, tmp_path, capsys):
    assert check_command_examples(page, tmp_path, capsys) > 0


def test_control_one_call_example_summary_is_what_its_comment_says(tmp_path, monkeypatch):
    """docs/control.md's first example: the numbers of its `run.summary()` comment are the run's (`~` an order of
    magnitude, within a factor 3). Its final error read ~1e-11 while the run ends at 2e-9."""
    block = re.findall(r"```python\n(.*?)```", (ROOT / "docs" / "control.md").read_text(), flags=re.S)[0]
    comment = re.search(r"run\.summary\(\)\s+# \{(.*)\}", block)[1]
    monkeypatch.chdir(tmp_path)  # the example writes track.png
    scope: dict = {}
    exec(compile(block, "docs/control.md", "exec"), scope)  # our own documentation, not user text
    summary = scope["run"].summary()
    shown = dict(re.findall(r"'(\w+)': (~?[-+]?\d[-+.\deE]*)", comment))
    assert set(shown) == {"max_error", "final_error"}
    for key, value in shown.items():
        if value.startswith("~"):
            assert float(value[1:]) / 3 <= summary[key] <= 3 * float(value[1:]), (key, summary[key])
        else:
            assert summary[key] == pytest.approx(float(value), rel=1e-3), (key, summary[key])


def test_every_command_line_option_is_named_in_the_documentation():
    """Each option of each command (its long or short form) appears in the README or a page of docs/: `odometry
    --pose`, `kinematics --all`, `batch montecarlo --runs/--rate`, `batch odometry --trajectory-format` and
    `follow-line --blur/--clutter` were in --help only."""
    import argparse

    from cli_options import options

    text = "\n".join(p.read_text() for p in [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))])
    missing = []
    for words, action in options():
        if words and not isinstance(action, argparse._HelpAction):
            if not any(re.search(re.escape(o) + r"(?![\w-])", text) for o in action.option_strings):
                missing.append(f"{' '.join(words)} {'/'.join(action.option_strings)}")
    assert missing == []


def test_no_command_of_the_documentation_has_an_unquoted_glob():
    """A command as the pages write it runs as pasted into any shell: `wheels[0].alpha` unquoted is a glob, which
    zsh (macOS's shell) refuses ('no matches found') and bash replaces by a file of that pattern if one exists;
    `'logs/*.csv'` is quoted for wmrkit to expand. batch.md's sweep wrote `--vary wheels[0].alpha,...` bare."""
    unquoted = []
    for page in [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]:
        inside = False
        for number, line in enumerate(page.read_text().splitlines(), 1):
            if line.startswith("```"):
                inside = not inside
            command = line.strip().removeprefix("$ ")
            if inside and command.startswith(("wmrkit ", "python ", "pip ")):
                words = re.sub(r"'[^']*'|\"[^\"]*\"", "''", re.split(r"\s+#\s", command)[0])
                if re.search(r"[*?]|\w\[", words):  # '[--from X Y THETA]' is a synopsis, not a word
                    unquoted.append(f"{page.name}:{number}: {command}")
    assert unquoted == []


def _anchors(page: Path) -> set[str]:
    """GitHub's anchors of a page's headings: lower case, punctuation dropped, spaces as hyphens."""
    return {re.sub(r"[^\w\- ]", "", h.strip().lower()).replace(" ", "-")
            for h in re.findall(r"^#+ (.*)$", page.read_text(), flags=re.M)}


def test_every_file_and_link_the_documentation_names_exists():
    """What README.md and docs/ point a reader to is in the repository: relative links (and their #anchors), paths
    written in backticks (from the root, the page or the package: `slip/skid.py`) and `tests/...py::test_name`
    citations. Paths of the examples' outputs and placeholders (`DIR/NAME.tum`) are not files; the thesis digests
    (`spec/...`) and the style guide (`shared/STYLE.md`) are cited sources of the project, not in the repository."""
    outside = ("logs/", "refs/", "out/", "report/", "traj/", "squares/", "spec/", "shared/")
    missing = []
    for page in [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]:
        text = page.read_text()
        for target, anchor in re.findall(r"\]\(([^)#:\s]+)(#[\w-]+)?\)", text):
            path = page.parent / target
            if not path.exists() or (anchor and path.suffix == ".md" and anchor[1:] not in _anchors(path)):
                missing.append(f"{page.name}: link {target}{anchor}")
        for path, name in re.findall(r"`((?:[\w.-]+/)+[\w.-]+\.\w+)(?:::(\w+))?`", text):
            found = [p for p in (ROOT / path, page.parent / path, ROOT / "src" / "wmrkit" / path) if p.exists()]
            if not found and not path.startswith(outside) and not path.split("/")[0].isupper():
                missing.append(f"{page.name}: {path}")
            elif name and not re.search(rf"^def {name}\b", found[0].read_text(), flags=re.M):
                missing.append(f"{page.name}: {path}::{name}")
    assert missing == []


def test_signatures_the_documentation_writes_with_beta_name_heading_too():
    """A signature of the pages (`mobility(robot, beta=None)`, `icr(robot, beta)`) of a function that takes the users'
    `heading=` says so on its line: docs/kinematics.md, docs/wheel-ik.md and docs/analysis.md gave every function
    with the thesis's `beta` only, the axle angle, 90 deg off the heading a reader of the conventions page passes."""
    import importlib
    import inspect
    import pkgutil

    import wmrkit

    functions = {}
    for info in pkgutil.walk_packages(wmrkit.__path__, "wmrkit."):
        if info.name.split(".")[1] in ("kinematics", "analysis"):
            module = importlib.import_module(info.name)
            functions |= {n: f for n, f in vars(module).items() if inspect.isfunction(f)}
    unsaid = []
    for page in sorted((ROOT / "docs").glob("*.md")):
        for number, line in enumerate(page.read_text().splitlines(), 1):
            for name in re.findall(r"\b(\w+)\(robot\b[^()]*\bbeta\b[^()]*\)", line):
                if name in functions and "heading" in inspect.signature(functions[name]).parameters \
                        and "heading=" not in line:
                    unsaid.append(f"{page.name}:{number}: {name}")
    assert unsaid == []


def test_commands_that_say_what_they_write_run_as_written_and_write_it(tmp_path, monkeypatch, capsys):
    """A `wmrkit` command of a page's block whose comment says `# writes PATH` (`and .c`: the same name with that
    suffix) exits 0 from a fresh folder and leaves those files. docs/symbolic-and-codegen.md's `--codegen` lines
    ran on `robot.yaml`, a file no one has ('no such file', exit 2)."""
    from wmrkit.cli.main import main

    found = []
    for page in sorted((ROOT / "docs").glob("*.md")):
        for line in page.read_text().splitlines():
            command, _, comment = line.partition("  #")
            said = re.match(r"\s*writes (\S+)(?: and (\.\w+))?", comment)
            if command.startswith("wmrkit ") and said:
                found.append((page.name, command.strip(), said[1], said[2]))
    assert found
    monkeypatch.chdir(tmp_path)
    for page, command, path, other in found:
        assert main(command.split()[1:]) == 0, (page, command, capsys.readouterr().err)
        written = [Path(path)] + ([Path(path).with_suffix(other)] if other else [])
        assert all(p.is_file() for p in written), (page, command, written)


def test_files_the_commands_read_are_in_the_repository_or_made_on_the_page():
    """A file a `wmrkit` command of these pages reads (`LOG.csv`, `--torques`, `--slip-weights`, a description) is in
    the repository, or a line of the page writes it first (`--out`, `> FILE`, `# writes FILE`, `write_log("FILE"`,
    `savetxt('FILE'`). slip.md read log.csv and calib.json, dynamics.md torques.csv, kinematics.md robot.yaml and
    odometry.md log.csv and counts.csv that no one had. UPPER-case names (`LOG`, `TRAJ.tum`) are placeholders."""
    import itertools
    import shlex

    outputs = ("--out", "--plot", "--report", "--animate", "--trajectories")
    unmade = []
    for name in ("dynamics.md", "kinematics.md", "odometry.md", "slip.md"):
        text, written, inside = (ROOT / "docs" / name).read_text(), set(), False
        for number, line in enumerate(text.splitlines(), 1):
            written |= set(re.findall(r"(?:--out|--plot|>|# writes)\s+([\w./-]+\.\w+)", line))
            written |= set(re.findall(r"""(?:write_\w+|savetxt)\(["']([\w./-]+)["']""", line))
            if line.startswith("```"):
                inside = not inside
            command = re.split(r"\s+#\s", line.strip().removeprefix("$ "))[0]
            if not inside or not command.startswith("wmrkit "):
                continue
            words = shlex.split(command)
            for before, word in itertools.pairwise(words):
                if before not in outputs and re.fullmatch(r"[\w./-]+\.(csv|json|ya?ml|tum|txt)", word) \
                        and not Path(word).stem.isupper() and word not in written and not (ROOT / word).exists():
                    unmade.append(f"{name}:{number}: {word}")
    assert unmade == []
