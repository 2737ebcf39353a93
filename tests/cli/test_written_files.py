"""Every option that writes a file says so: one stderr line ``wmrkit: WHAT written to PATH`` (cli._shown.written).

Before, --plot, --out, --animate and --report wrote their files in silence, but for three commands that each said it
their own way on stdout (``drawing written to``, ``report written to``, ``; camera file``, ``; animation``,
``; table``), and never under --json. Now one line on stderr, with or without --json, whose stdout stays the JSON
answer alone."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from cli_options import options
from wmrkit.cli.main import main

ROOT = Path(__file__).parents[2]
LOG = str(ROOT / "examples" / "logs" / "mecanum-4.csv")
CALIBRATE = ["vision", "calibrate", "--rows", "100", "--half-separation", "0.1", "--row-distance", "0.5",
             "--x1", "200", "--x2", "150"]

#: (argv with {f} a file and {d} a folder in tmp_path, exit code, [(what, the path named)]); every case run with
#: and without --json.
CASES = [
    (["show", "diff-drive", "--plot", "{f}.png"], 0, [("drawing", "{f}.png")]),
    (["feasibility", "forklift", "--reference", "square", "--plot", "{f}.png"], 1, [("plot", "{f}.png")]),
    (["track", "diff-drive", "--reference", "line", "--duration", "1", "--plot", "{f}.png"], 0,
     [("plot", "{f}.png")]),
    (["tyre", "linear", "--load", "1000", "--slip-ratio", "0.1", "--plot", "{f}.svg"], 0, [("plot", "{f}.svg")]),
    ([*CALIBRATE, "--out", "{f}.yaml"], 0, [("camera file", "{f}.yaml")]),
    (["park", "thesis-9.1", "--plot", "{f}.png"], 0, [("plot", "{f}.png")]),
    (["analyze", "thesis-tricycle", "--resolution", "8", "--report", "{d}"], 0, [("report", "{d}/index.html")]),
    (["odometry", "mecanum-4", LOG, "--out", "{f}.csv", "--plot", "{f}.png"], 0,
     [("trajectory", "{f}.csv"), ("plot", "{f}.png")]),
    (["kinematics", "diff-drive", "--codegen", "c", "{d}"], 0,
     [("code", "{d}/diff_drive_kinematics.h"), ("code", "{d}/diff_drive_kinematics.c")]),
]

#: The output options not run here (seconds each), and the test that checks their line.
ELSEWHERE = {
    ("batch odometry", "--out"): "tests/batch/test_fleet_imu.py (table)",
    ("batch odometry", "--trajectories"): "cli/batch.py: said with the table",
    ("batch montecarlo", "--plot"): "cli/batch.py",
    ("sweep", "--out"): "cli/batch.py", ("sweep", "--plot"): "cli/batch.py",
    ("simulate", "--out"): "tests/cli/test_shown_numbers.py", ("simulate", "--plot"): "cli/dynamics.py",
    ("park", "--animate"): "tests/parking/test_cli_park.py", ("track", "--animate"): "cli/control.py",
    ("follow-line", "--animate"): "cli/vision.py", ("slip-study", "--report"): "cli/slip.py (each figure)",
}


def _filled(items, tmp_path: Path):
    return [s.format(f=tmp_path / "out", d=tmp_path / "dir") for s in items]


@pytest.mark.parametrize("as_json", [False, True])
@pytest.mark.parametrize(("argv", "code", "said"), CASES, ids=[" ".join(c[0][:2]) for c in CASES])
def test_a_written_file_is_named_on_stderr(argv, code, said, as_json, tmp_path, capsys):
    argv = _filled(argv, tmp_path) + (["--json"] if as_json else [])
    assert main(argv) == code
    out = capsys.readouterr()
    lines = [f"wmrkit: {what} written to {path}" for what, path in ((w, _filled([p], tmp_path)[0]) for w, p in said)]
    assert [ln for ln in out.err.splitlines() if " written to " in ln] == lines, out.err
    for what, path in said:
        assert Path(_filled([path], tmp_path)[0]).is_file(), what
    assert " written to " not in out.out and "; camera file" not in out.out
    if as_json:
        json.loads(out.out)  # stdout: the JSON answer alone


def test_every_output_option_is_checked_somewhere():
    """A new --out/--plot/--animate/--report option is added to CASES (or to ELSEWHERE, naming its check)."""
    found = {(" ".join(words), o) for words, action in options() for o in action.option_strings
             if o in ("--out", "--plot", "--animate", "--report", "--trajectories", "--codegen")}
    run = {(" ".join(argv[:2]) if argv[0] == "vision" else argv[0], o) for argv, _, _ in CASES
           for o in argv if o.startswith("--") and o in ("--out", "--plot", "--animate", "--report", "--codegen")}
    assert found == run | set(ELSEWHERE), (found - run - set(ELSEWHERE), (run | set(ELSEWHERE)) - found)
