"""A seeded fuzzer of every command's options: hostile values (NaN, infinities, 1e308, huge integers, empty text,
units, paths that cannot be written) put into valid command lines, or added as options the parser offers.

Each case must exit 0 (or 1 where that is an answer, :data:`ANSWER_NO`; JSON without NaN or infinities under
``--json``, nor a null that stands for a number that was not finite, outside the fields :data:`UNDEFINED`
documents) or exit 2 with one error line (a JSON object under
``--json``), never let an exception escape, and answer within :data:`HANG` seconds. The cases run in a worker
process (``options_worker.py``) that is killed and restarted on a hang. Its first run (issue 9's rules on the newer
commands) found the cases of test_hostile_sweep6.py. Run longer with
``WMRKIT_FUZZ_SECONDS=600 pytest tests/hostile/test_hostile_options.py``.
"""

from __future__ import annotations

import argparse
import json
import os
import random
import re
import select
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

from wmrkit import catalog
from wmrkit.cli.main import build_parser
from wmrkit.odometry.logs import write_csv
from wmrkit.odometry.synthetic import simulate, square_path

HERE = Path(__file__).parent
SECONDS = float(os.environ.get("WMRKIT_FUZZ_SECONDS", "45"))
SEED = int(os.environ.get("WMRKIT_FUZZ_SEED", "20261125"))
#: Seconds after which a case counts as a hang: the slowest cases within the documented limits here, a Monte Carlo
#: study of the most work one worker takes (``batch.montecarlo.MAX_WORK``), take about 45-60 s on one core.
HANG = 200.0
VALUES = ["nan", "inf", "-inf", "1e308", "-1e308", "0", "-0", "-1", "1e-308", "5e-324", "1e20", "-1e20",
          "99999999999999999999999", "", " ", "abc", "1e400", "1e308deg", "nan deg", "0.5", "2", "1000000", "1e9",
          "-1e-9", "0x10", "1_000", "\uff13", "1,5", "=", "a=b", "front=", "=3", "1e-3", "360deg", "-1e5deg",
          "1e308 m", "10 km", "3 rad", "1 turn", "1e-300", "4e9", "2147483648", "-2147483649"]
PATHS = ["missing/x.png", "file.txt/x.png", "folder", "file.txt", "x.weird", "x.gif", "x.svg", "x.csv"]
OUTPUTS = ("--out", "--plot", "--animate", "--report", "--trajectories")
#: JSON fields whose null documents "not defined" (docs/wheel-ik.md: the heading of a wheel that does not steer, the
#: steering rate no twist defines); any other NaN or infinity printed as null is a silent wrong answer.
UNDEFINED = re.compile(r"^\$\.wheels\.[^.\[]+\.(heading|steer_rate)$")
_BAD_VALUE = re.compile(r"(?:^|[\s=(,\[])[-+]?(?:nan|inf)\b", re.IGNORECASE)  # a printed number, not a name


def bases(log: str) -> list[list[str]]:
    """Valid command lines of every command that answers in about a second."""
    vision = "docs/figures/vision/"
    return [
        ["show", "forklift"], ["kinematics", "forklift", "--steer", "steer=30deg"],
        ["ik", "swerve-4", "--twist", "1", "0.5", "0.3"],
        ["fk", "diff-drive", "--spin", "left=10", "--spin", "right=12"],
        ["analyze", "forklift"], ["odometry", "diff-drive", log], ["odometry", "diff-drive", log, "--method", "wls"],
        ["odometry", "diff-drive", log, "--method", "fk2"],
        ["odometry", "diff-drive", log, "--method", "fk2", "--kf-noise", "1e100", "1e100", "1e100", "--json"],
        ["tyre", "pacejka", "--load", "8175", "--slip-ratio", "0.1", "--slip-angle", "0.05"],
        ["simulate", "forklift", "--path", "turn", "--duration", "1"],
        ["track", "diff-drive", "--reference", "circle", "--duration", "2"],
        ["track", "diff-drive", "--reference", "circle", "--period", "0.1", "--duration", "2"],
        ["feasibility", "forklift", "--reference", "square"], ["park", "thesis-9.1"],
        ["vision", "locate", "--points", vision + "chufa-points.json", "--camera", vision + "chufa-camera.yaml",
         "--spacing", "60cm"],
        ["follow-line", "line-follower", "--camera", vision + "follower-camera.yaml", "--duration", "3"],
        ["batch", "montecarlo", "diff-drive", "--path", "square", "-n", "20", "--workers", "0"],
        ["sweep", "omni-3", "--vary", "wheels.back.l=0.1:0.2:3", "--workers", "0"],
    ]


def _parser_of(argv: list[str]) -> argparse.ArgumentParser:
    parser = build_parser(argv[0])
    for word in argv:
        subs = [a for a in parser._actions if isinstance(a, argparse._SubParsersAction)]
        if subs and word in subs[0].choices:
            parser = subs[0].choices[word]
    return parser


def mutate(base: list[str], parser: argparse.ArgumentParser, rng: random.Random) -> list[str]:
    """`base` with one value replaced by a hostile one, or with an option of `parser` added."""
    argv = list(base)
    values = [k for k in range(1, len(argv)) if not argv[k].startswith("--")]
    if values and rng.random() < 0.45:
        k = rng.choice(values)
        if argv[k - 1] in OUTPUTS:
            argv[k] = rng.choice(PATHS)
        elif "=" in argv[k] and rng.random() < 0.6:
            argv[k] = argv[k].split("=", 1)[0] + "=" + rng.choice(VALUES)
        else:
            argv[k] = rng.choice(VALUES)
    else:
        options = [a for a in parser._actions if a.option_strings and a.dest not in ("help", "version")]
        option = rng.choice(options)
        name = option.option_strings[-1]
        argv.append(name)
        count = 0 if option.nargs == 0 else option.nargs if isinstance(option.nargs, int) else 1
        for _ in range(count):
            if name in OUTPUTS:
                argv.append(rng.choice(PATHS))
            elif option.choices and rng.random() < 0.5:
                argv.append(str(rng.choice(list(option.choices))))
            else:
                argv.append(rng.choice([*VALUES, "1", "0.5", "left=1", "front=10deg"]))
    if "--json" not in argv and rng.random() < 0.3:
        argv.append("--json")
    return argv


class Worker:
    """``options_worker.py`` in a process of its own, restarted after a hang."""

    def __init__(self, cwd: Path) -> None:
        self.cwd = cwd
        self._start()

    def _start(self) -> None:
        self.process = subprocess.Popen([sys.executable, str(HERE / "options_worker.py")], cwd=self.cwd,
                                        stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True,
                                        env={**os.environ, "MPLBACKEND": "Agg"})

    def run(self, argv: list[str]) -> dict | None:
        """The worker's answer, or None when it took longer than :data:`HANG` seconds (then restarted)."""
        self.process.stdin.write(json.dumps(argv) + "\n")
        self.process.stdin.flush()
        ready, _, _ = select.select([self.process.stdout], [], [], HANG)
        line = self.process.stdout.readline() if ready else ""
        if not line:
            self.close()
            self._start()
            return None
        return json.loads(line)

    def close(self) -> None:
        self.process.kill()
        self.process.wait()


#: Commands whose exit code 1 is an answer that is no, printed like any other (park: no plan, or a collision).
ANSWER_NO = {"park", "ik", "feasibility"}


def problem(argv: list[str], answer: dict | None) -> str | None:
    """What is wrong with `answer` to `argv`, or None."""
    if answer is None:
        return f"no answer within {HANG:g} s"
    code, out, err = answer["code"], answer["out"], answer["err"]
    if answer["escaped"]:
        return "an exception escaped: " + answer["escaped"]
    if code not in (0, 2) and not (code == 1 and argv[0] in ANSWER_NO and out.strip()):
        return f"exit code {code}"
    if code == 2:
        if "--json" in argv:
            try:
                assert "error" in json.loads(err.strip().splitlines()[-1])
            except (AssertionError, IndexError, ValueError):
                return "the error is not a JSON object: " + err[-300:]
            return None
        lines = [ln for ln in err.splitlines() if ln.startswith("wmrkit: error: ")]
        return None if len(lines) == 1 and err.endswith(lines[0] + "\n") else "not one error line: " + err[-300:]
    if answer["json"]:
        return "bad JSON output: " + answer["json"]
    unexplained = [p for p in answer["nulls"] if not UNDEFINED.match(p)]
    if unexplained:  # print_json writes NaN and infinities as null: a silent NaN unless the field may be undefined
        return "a NaN or infinity printed as null at " + ", ".join(unexplained[:5])
    if "--json" not in argv and _BAD_VALUE.search(out):
        return "a NaN or infinity printed: " + out[-300:]
    return None


def _fixture(folder: Path) -> str:
    (folder / "docs").symlink_to(HERE.parents[1] / "docs")
    (folder / "file.txt").write_text("")
    (folder / "folder").mkdir()
    run = simulate(catalog.load("diff-drive"), square_path(1.0), 10.0, spin_noise_per_rad=1e-5, seed=1)
    write_csv(folder / "log.csv", ("time", *run.log.joints), np.column_stack([run.log.time, run.log.positions]))
    return "log.csv"


def test_hostile_option_values_get_an_answer_or_one_line(tmp_path):
    rng = random.Random(SEED)
    lines = bases(_fixture(tmp_path))
    parsers = [_parser_of(b) for b in lines]
    worker = Worker(tmp_path)
    found, cases, end = [], 0, time.monotonic() + SECONDS
    try:
        for base in lines:  # every base is valid: the fuzzer's ground (an answer: 0, or 1 where it is no)
            answer = worker.run(base)
            assert answer is not None and answer["code"] != 2 and problem(base, answer) is None, (base, answer)
        while time.monotonic() < end and len(found) < 5:
            i = rng.randrange(len(lines))
            argv = mutate(lines[i], parsers[i], rng)
            cases += 1
            trouble = problem(argv, worker.run(argv))
            if trouble:
                found.append((argv, trouble))
    finally:
        worker.close()
    assert found == [], f"{len(found)} of {cases} cases: {found}"
