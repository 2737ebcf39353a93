"""Run the Python examples of a documentation page and compare what they print with the page's ``# comments``."""

from __future__ import annotations

import contextlib
import io
import os
import re
import shlex
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def check_python_examples(page: str, count: int) -> None:
    """Each ```python block of ``docs/<page>`` runs (from the repository root) and prints, line by line, the
    comments after its ``print(...)`` calls (a ``...`` in a comment stands for any text there; the rest of the line
    exactly); the page has `count` blocks."""
    text = (ROOT / "docs" / page).read_text()
    blocks = re.findall(r"```python\n(.*?)```", text, flags=re.S)
    assert len(blocks) == count
    cwd = os.getcwd()
    os.chdir(ROOT)
    try:
        for block in blocks:
            expected = [m.strip() for m in re.findall(r"print\(.*\)\s+#\s*(.*)$", block, flags=re.M)]
            out = io.StringIO()
            with contextlib.redirect_stdout(out):
                exec(compile(block, f"docs/{page}", "exec"), {})  # our own documentation, not user text
            printed = out.getvalue().split("\n")[:-1]
            assert len(printed) == len(expected), (printed, expected)
            assert all(p == e or ("..." in e and same_line(e, p)) for p, e in zip(printed, expected, strict=True)), \
                (printed, expected)
    finally:
        os.chdir(cwd)


#: Options whose value is a file the command writes: redirected into the test's temporary folder.
OUTPUT_OPTIONS = ("--out", "--report", "--plot", "--animate")


def command_examples(page: str) -> list[tuple[str, list[str]]]:
    """Each ``$ wmrkit ...`` command of the ``` blocks of ``docs/<page>`` (continued by a trailing backslash, with
    its ``  # comment``) with the lines shown after it, up to the next command or the block's end."""
    examples: list[tuple[str, list[str]]] = []
    inside, shown = False, None  # shown: the lines after the command being read, None when none is
    for line in (ROOT / "docs" / page).read_text().splitlines():
        if line.startswith("```"):
            inside, shown = not inside, None
        elif not inside:
            continue
        elif line.startswith("$ wmrkit "):
            shown = []
            examples.append((line[2:], shown))
        elif shown == [] and examples[-1][0].endswith("\\"):
            examples[-1] = (examples[-1][0][:-1].rstrip() + " " + line.strip(), shown)
        elif line.startswith("$ "):
            shown = None  # another program's command: its lines are not checked
        elif shown is not None:
            shown.append(line.rstrip())
    return [(cmd.strip(), _trim(lines)) for cmd, lines in examples]


def _trim(lines: list[str]) -> list[str]:
    while lines and not lines[-1]:
        lines = lines[:-1]
    return lines


NUMBER = re.compile(r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?")


def same_line(shown: str, out: str, rtol: float = 1e-3) -> bool:
    """The same text, numbers equal within `rtol` relative or 1e-9 absolute: round-off (a residual of 2e-16 or
    5e-16, the last printed digit) differs between machines, a stale number does not pass. A ``...`` inside a line
    stands for any text there (a time measured on the run)."""
    if "..." in shown:
        return re.fullmatch(".*?".join(map(re.escape, shown.split("..."))), out) is not None
    if NUMBER.split(shown) != NUMBER.split(out):
        return False
    a, b = NUMBER.findall(shown), NUMBER.findall(out)
    pairs = zip(map(float, a), map(float, b), strict=True)  # as many: the text between them is the same
    return all(abs(x - y) <= 1e-9 + rtol * abs(x) for x, y in pairs)


def fits(shown: list[str], out: list[str], rtol: float = 1e-3) -> bool:
    """Whether `out` reads line by line as `shown` (:func:`same_line`), where a line ``...`` (indented or not) stands
    for any number of lines."""
    if not shown:
        return not out
    if shown[0].strip() == "...":
        return any(fits(shown[1:], out[k:], rtol) for k in range(len(out) + 1))
    return bool(out) and same_line(shown[0], out[0], rtol) and fits(shown[1:], out[1:], rtol)


def check_command_examples(page: str, tmp_path: Path, capsys) -> int:
    """Run every command example of ``docs/<page>`` (from the repository root, files it writes into `tmp_path`) and
    compare: lines shown starting ``wmrkit: `` are its standard error, the others its standard output; exit code 2
    when an error is shown, else 0, or N when a comment ``# exit N`` on the command says so. A comment ``# numbers
    within N %`` widens the numbers' tolerance (a closed loop that amplifies round-off, which differs with how the
    kernels were compiled). Returns the number of examples."""
    from wmrkit.cli.main import main

    examples = command_examples(page)
    cwd = os.getcwd()
    os.chdir(ROOT)
    try:
        for line, shown in examples:
            command, _, comment = line.partition("  #")
            within = re.search(r"numbers within (\d+) %", comment)
            rtol = int(within[1]) / 100 if within else 1e-3
            argv = shlex.split(command)[1:]
            for k in range(1, len(argv)):
                if argv[k - 1] in OUTPUT_OPTIONS:
                    shown = [s.replace(argv[k], str(tmp_path / argv[k])) for s in shown]
                    argv[k] = str(tmp_path / argv[k])
            code = main(argv)
            captured = capsys.readouterr()
            err = [ln for ln in captured.err.splitlines() if not ln.startswith("wmrkit: compiling")]
            out = [ln.rstrip() for ln in _trim(captured.out.splitlines())]
            failed = any(s.startswith("wmrkit: error:") for s in shown)
            said = re.search(r"exit (\d)", comment)  # '# exit 1': an answer that is no (park without a plan)
            assert code == (int(said[1]) if said else 2 if failed else 0), (page, command, code, captured.err)
            assert fits([s for s in shown if not s.startswith("wmrkit: ")], out, rtol), (page, command, out)
            assert fits([s for s in shown if s.startswith("wmrkit: ")], err, rtol), (page, command, err)
    finally:
        os.chdir(cwd)
    return len(examples)
