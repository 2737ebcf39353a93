"""Issue 9: every CLI command on every hostile input answers with exit 2 and one line, in bounded time and memory.

The corpus lives beside this file (descriptions/, logs/, bags/, and fuzz/ for the cases the fuzzer found); large
inputs are generated at test time. Most cases run in-process through ``wmrkit.cli.main.main``; the cases about
hangs and memory run as subprocesses under a time limit and an address-space limit (``RLIMIT_AS``).
"""

from __future__ import annotations

import json
import math
import re
import resource
import subprocess
import sys
import time
from pathlib import Path

import pytest

from wmrkit.cli.main import main

HERE = Path(__file__).parent
DESCRIPTIONS = sorted((HERE / "descriptions").iterdir()) + sorted((HERE / "fuzz").glob("*.yaml"))
LOGS = sorted((HERE / "logs").iterdir())
BAGS = sorted((HERE / "bags").iterdir())
#: Seconds one in-process command may take on a hostile input (they are refused while loading).
FAST = 5.0


def _ok_log(tmp_path: Path) -> str:
    path = tmp_path / "ok.csv"
    path.write_text("time,left.spin,right.spin\n0,0,0\n0.01,0.1,0.1\n")
    return str(path)


def _commands(robot: str, log: str) -> list[list[str]]:
    return [["show", robot], ["kinematics", robot], ["ik", robot, "--twist", "1", "0", "0"],
            ["fk", robot, "--spin", "left=1"], ["analyze", robot], ["odometry", robot, log, "--quiet"]]


def _refused(argv: list[str], capsys) -> str:
    start = time.perf_counter()
    code = main(argv)
    elapsed = time.perf_counter() - start
    captured = capsys.readouterr()
    assert code == 2, (argv, captured.err, captured.out[-300:])
    assert captured.err.count("\n") == 1 and captured.err.endswith("\n"), (argv, captured.err)
    if "--json" in argv:  # errors as one JSON object
        assert json.loads(captured.err)["error"], (argv, captured.err)
    else:
        assert captured.err.startswith("wmrkit: error: "), (argv, captured.err)
    captured.err.encode("utf-8")  # printable: no lone surrogate
    assert elapsed < FAST, (argv, elapsed)
    return captured.err


@pytest.mark.parametrize("path", DESCRIPTIONS, ids=lambda p: p.name)
def test_every_command_refuses_a_hostile_description_with_one_located_line(path, tmp_path, capsys):
    log = _ok_log(tmp_path)
    for argv in _commands(str(path), log):
        message = _refused(argv, capsys)
        assert path.name in message


@pytest.mark.parametrize("path", LOGS, ids=lambda p: p.name)
def test_odometry_refuses_a_broken_log_with_one_line_naming_it(path, capsys):
    extra = ["--spin", "counts", "--cpr", "1000", "--counter-bits", "32"] if "encoder" in path.name else []
    message = _refused(["odometry", "diff-drive", str(path), "--quiet", *extra], capsys)
    assert path.name in message
    assert path.name in _refused(["odometry", "diff-drive", str(path), "--quiet", "--json", *extra], capsys)


def test_the_issue_s_log_messages_name_the_row_and_the_reason(capsys):
    logs = HERE / "logs"
    cases = {"extra-field-middle.csv": r"extra-field-middle.csv:3: expected 3 fields, got 4",
             "overflow.csv": r"overflow.csv:3: left.spin: turns",
             "truncated-last-line.csv": r"truncated-last-line.csv:3: the last line has no line end",
             "non-utf8.csv": r"non-utf8.csv:3: bytes that are not UTF-8",
             "time-overflow.csv": r"time-overflow.csv:3: time 1e\+308 s: the time step overflows"}
    for name, pattern in cases.items():
        assert re.search(pattern, _refused(["odometry", "diff-drive", str(logs / name), "--quiet"], capsys)), name
    message = _refused(["odometry", "diff-drive", str(logs / "encoder-jump.csv"), "--quiet", "--spin", "counts",
                        "--cpr", "1000"], capsys)  # no counter width: the jump is still an error
    assert "encoder-jump.csv:4: left.spin" in message and "implausible" in message


@pytest.mark.parametrize("path", BAGS, ids=lambda p: p.name)
def test_odometry_refuses_a_broken_bag_with_one_line_naming_it(path, capsys):
    assert path.name in _refused(["odometry", "diff-drive", str(path), "--quiet"], capsys)


@pytest.mark.parametrize(("option", "said"), [
    (["--covariance", "--crowley", "nan", "1", "1"], "--crowley: cannot read 'nan' as a number"),  # the reader's
    (["--covariance", "--crowley", "1", "-1", "1"], "--crowley: coefficients must be finite and >= 0"),
    (["--covariance", "--crowley", "1", "1", "1e999"], "--crowley: must be finite, got '1e999'")])
def test_noise_coefficients_must_be_finite_and_non_negative(option, said, tmp_path, capsys):
    message = _refused(["odometry", "diff-drive", _ok_log(tmp_path), "--quiet", *option], capsys)
    assert said in message


# ---- hangs and memory: subprocesses under limits ----------------------------------------------------------

#: Address-space limit of a subprocess: numpy, scipy and numba reserve ~1 GB of virtual memory at start.
MEMORY = 3 << 30


def _limited() -> None:
    resource.setrlimit(resource.RLIMIT_AS, (MEMORY, MEMORY))


def _run(argv: list[str], timeout: float) -> subprocess.CompletedProcess:
    start = time.perf_counter()
    result = subprocess.run([sys.executable, "-m", "wmrkit", *argv], capture_output=True, text=True,
                            timeout=timeout, preexec_fn=_limited)
    result.elapsed = time.perf_counter() - start  # type: ignore[attr-defined]
    return result


def _wheels(n: int, kind: str = "fixed", name: str = "w") -> str:
    rows = []
    for i in range(n):
        a = 2 * math.pi * i / n
        geometry = {"fixed": f"beta: {a:.6f}", "castor": "d: 0.05"}[kind]
        rows.append(f"  - {{name: {name}{i}, type: {kind}, l: 0.3, alpha: {a:.6f}, {geometry}, r: 0.05, "
                    "sensed: [spin]}\n")
    return "".join(rows)


def test_size_limits_refuse_huge_descriptions_quickly_in_bounded_memory(tmp_path):
    many = tmp_path / "wheels-1000.yaml"
    many.write_text("name: many\nwheels:\n" + _wheels(1000))
    big = tmp_path / "big.yaml"
    big.write_text("name: big\n" + "# padding\n" * 120_000 + "wheels:\n" + _wheels(2))
    long_name = tmp_path / "long-name.yaml"
    long_name.write_text("name: x\nwheels:\n" + _wheels(1, name="w" * 200_000))  # below the size limit
    report = tmp_path / "report"
    for argv, expected in ((["kinematics", str(many)], "1000 wheels: wmrkit analyses at most"),
                           (["show", str(big)], "a description holds at most"),
                           (["analyze", str(long_name), "--report", str(report)], "at most 64 characters")):
        result = _run(argv, timeout=30)
        assert result.returncode == 2, result.stderr[-500:]
        assert result.stderr.count("\n") == 1 and expected in result.stderr
        assert result.elapsed < 15


def test_a_robot_of_many_castors_gets_a_bounded_answer(tmp_path):
    robot = tmp_path / "castors-32.yaml"
    robot.write_text("name: castors\nwheels:\n" + _wheels(32, "castor"))
    result = _run(["kinematics", str(robot)], timeout=60)
    assert result.returncode == 0, result.stderr[-500:]
    assert "mobility m = 3" in result.stdout
    assert "note: minimal actuator sets: more than 24" in result.stdout  # a bounded search says so


def test_a_yaml_bomb_in_a_bag_s_metadata_is_refused_in_bounded_memory():
    result = _run(["odometry", "diff-drive", str(HERE / "bags" / "yaml-bomb"), "--quiet"], timeout=30)
    assert result.returncode == 2 and result.stderr.count("\n") == 1 and "YAML anchors" in result.stderr


def _laughs(levels: int = 9) -> str:
    """A YAML "billion laughs" list: 9 aliases of the level below, `levels` deep (9**9 items once expanded)."""
    expr, prev = '&a ["x", "x", "x", "x", "x", "x", "x", "x", "x"]', "a"
    for anchor in "bcdefghijk"[:levels - 1]:
        expr, prev = f"&{anchor} [{expr}, " + ", ".join([f"*{prev}"] * 8) + "]", anchor
    return expr


@pytest.mark.parametrize("field", ["name", "notes", "wheel name", "wheel type", "coupling kind", "velocity_names"])
def test_an_alias_bomb_where_text_is_expected_is_refused_quickly(field, tmp_path):
    """A billion-laughs list given as a name, a type or a coupling kind: the error quoted the value with repr(),
    expanding its 4e8 items, and the command ran out of time and memory instead of refusing it."""
    bomb = _laughs()
    wheel = {"name": "a", "type": "fixed"} | ({"name": bomb} if field == "wheel name" else {}) | (
        {"type": bomb} if field == "wheel type" else {})
    text = ("name: " + (bomb if field == "name" else "x") + "\n" + (f"notes: {bomb}\n" if field == "notes" else "")
            + (f"velocity_names: {bomb}\n" if field == "velocity_names" else "")
            + f"wheels:\n  - {{name: {wheel['name']}, type: {wheel['type']}, position: [0, 0.2], heading: 0, "
            "r: 0.05}\n"
            + (f"couplings:\n  - {{kind: {bomb}, joints: [a.spin, b.spin]}}\n" if field == "coupling kind" else ""))
    path = tmp_path / "bomb.yaml"
    path.write_text(text)
    result = _run(["show", str(path)], timeout=30)
    assert result.returncode == 2 and result.stdout == "", result.stderr[-300:]
    (line,) = result.stderr.splitlines()
    assert line.startswith(f"wmrkit: error: {path}:") and len(line) < 400 and result.elapsed < 10, line


@pytest.mark.skipif(not hasattr(__import__("os"), "mkfifo"), reason="needs named pipes")
def test_named_pipes_and_devices_given_as_input_files_are_refused_not_read(tmp_path):
    """A FIFO given as a description, reference, torque file, parking problem, camera file, slip-weights file or
    trajectory waited for a writer forever (the open blocks), and /dev/zero as a description never ended; each is one
    line naming the file, exit 2. The commands run in one child process with a time limit."""
    import os

    pipe = tmp_path / "pipe.yaml"
    os.mkfifo(pipe)
    log = _ok_log(tmp_path)
    commands = [["show", str(pipe)], ["show", "/dev/zero"], ["track", "diff-drive", "--reference", str(pipe)],
                ["feasibility", "diff-drive", "--reference", str(pipe)],
                ["simulate", "skid-steer-4", "--torques", str(pipe)], ["park", str(pipe)],
                ["follow-line", "line-follower", "--camera", str(pipe)],
                ["odometry", "diff-drive", log, "--method", "wls", "--slip-weights", str(pipe)],
                ["calibrate", "diff-drive", log, "--reference", str(pipe)]]
    script = ("import json, sys\nfrom wmrkit.cli.main import main\nfor argv in json.loads(sys.argv[1]):\n"
              "    print(main(argv), flush=True)\n")
    out = subprocess.run([sys.executable, "-c", script, json.dumps(commands)], capture_output=True, text=True,
                         timeout=300)
    assert out.stdout.split() == ["2"] * len(commands), out.stderr
    lines = out.stderr.strip().splitlines()
    assert len(lines) == len(commands)
    for line, argv in zip(lines, commands, strict=True):
        named = "/dev/zero" if "/dev/zero" in argv else str(pipe)
        assert line.startswith(f"wmrkit: error: {named}: not a regular file") or (
            argv[0] == "calibrate" and line == f"wmrkit: error: {named}: not a file"), (argv, line)
