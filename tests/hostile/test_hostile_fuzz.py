"""Issue 9: a seeded fuzzer of descriptions, in-process through ``wmrkit.cli.main.main``.

Mutated catalog descriptions (extreme numbers, units, duplicated, deleted or re-indented lines, stray characters)
go through ``show``, ``kinematics``, ``ik``, ``fk`` and ``analyze``: every run must exit 0 with finite numbers or
exit 2 with one line, and never raise. Cases it found are kept in ``fuzz/`` and replayed by test_hostile_cli.py.
Run longer with ``WMRKIT_FUZZ_SECONDS=300 pytest tests/hostile/test_hostile_fuzz.py``.
"""

from __future__ import annotations

import contextlib
import io
import os
import random
import re
import time

from wmrkit import catalog
from wmrkit.cli.main import main

SECONDS = float(os.environ.get("WMRKIT_FUZZ_SECONDS", "120"))  # a few minutes of the CI run (issue 9)
SEED = int(os.environ.get("WMRKIT_FUZZ_SEED", "20260909"))

NUMBERS = ["1e308", "-1e308", "1e-320", "0", "-0.0", ".nan", ".inf", "-.inf", "1e400", "'1e300 km'", "'2e-9'",
           "123456789012345678901234567890", "'89.9999 deg'", "'90 deg'", "1e-9", "3.14159265358979", "'0.5 turn'",
           "-1", "'1e-7 mm'", "'999 m'", "'1001 m'"]
TOKENS = ["\t", "\x07", "\\ud800", "\u2028", "&a", "*a", "<<: *a", "{", "[", "]", "}", ":", "- ", "!!python/object",
          "'", '"', "#", "\x00", "é", "r: 0.07", "name: x", "type: castor", "type: swedish", "gamma: 1e-3"]
_NUMBER = re.compile(r"(?<![\w.])-?\d+(?:\.\d+)?(?:e-?\d+)?(?![\w.])")
_BAD_VALUE = re.compile(r"(?:^|[\s=(,\[])[-+]?(?:nan|inf)\b", re.IGNORECASE)  # a number, not in a name


def mutate(text: str, rng: random.Random) -> str:
    """One to three random edits of a description's text."""
    for _ in range(rng.randint(1, 3)):
        lines = text.split("\n")
        k = rng.randrange(len(lines))
        op = rng.randrange(6)
        if op == 0:
            numbers = list(_NUMBER.finditer(text))
            if numbers:
                m = rng.choice(numbers)
                text = text[:m.start()] + rng.choice(NUMBERS) + text[m.end():]
        elif op == 1:
            text = "\n".join(lines[:k + 1] + lines[k:])
        elif op == 2:
            text = "\n".join(lines[:k] + lines[k + 1:])
        elif op == 3:
            i = rng.randrange(len(text) + 1)
            text = text[:i] + rng.choice(TOKENS) + text[i:]
        elif op == 4:
            text = "\n".join([*lines[:k], "\t" + lines[k], *lines[k + 1:]])
        else:
            j = rng.randrange(len(lines))
            lines[k], lines[j] = lines[j], lines[k]
            text = "\n".join(lines)
    return text


def run(argv: list[str]) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main(argv)
    return code, out.getvalue(), err.getvalue()


def check(path: str) -> None:
    """Every command on the description at `path`: exit 0 and finite output (1 too for an infeasible twist: an answer
    that is no), or exit 2 and one line."""
    for argv in (["show", path], ["kinematics", path], ["ik", path, "--twist", "1", "0", "0"],
                 ["fk", path, "--spin", "w=1"], ["analyze", path]):
        code, out, err = run(argv)
        assert code in (0, 2) or (code == 1 and argv[0] == "ik" and out), (argv, code)
        if code == 2:
            assert err.count("\n") == 1 and err.startswith("wmrkit: error: "), (argv, err)
        elif argv[0] in ("kinematics", "analyze"):
            assert not _BAD_VALUE.search(out), (argv, out)
        if code == 2 and argv[0] == "show":
            return  # loading fails: the other commands fail the same way (test_hostile_cli checks them all)


def test_fuzzed_descriptions_give_an_answer_or_one_line(tmp_path):
    rng = random.Random(SEED)
    sources = [catalog.source_text(n) for n in ("diff-drive", "omni-3", "thesis-omni-castor", "swerve-4",
                                                "thesis-tricycle", "mecanum-4")]
    deadline, cases = time.monotonic() + SECONDS, 0
    while time.monotonic() < deadline:
        text = mutate(rng.choice(sources), rng)
        path = tmp_path / f"case{cases}.{rng.choice(['yaml', 'json'])}"
        path.write_text(text, encoding="utf-8", errors="surrogateescape")
        try:
            check(str(path))
        except BaseException:
            (tmp_path.parent / "fuzz-failure.yaml").write_text(text, encoding="utf-8", errors="surrogateescape")
            raise
        cases += 1
    assert cases > 10
