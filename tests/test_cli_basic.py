"""The ``wmrkit`` command: user mistakes give one line on stderr and exit 2; --json output parses."""

from __future__ import annotations

import json
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from wmrkit import Robot, catalog
from wmrkit.cli.main import main

BROKEN = {
    "malformed.yaml": "name: x\nwheels:\n  - name: a\n    type: fixed: x\n",
    "typo.yaml": "name: x\nwheels:\n  - {name: a, type: fixed, l: 0, alpah: 0, beta: 0, r: 0.1}\n",
    "date.yaml": "name: x\nwheels:\n  - {name: a, type: fixed, position: [0, 0], beta: 0, r: 2020-13-45}\n",
    "newline-name.yaml": 'name: x\nwheels:\n  - {name: "a\\nb", type: fixed, position: [0, 0], beta: 0, r: -1}\n',
    "bad.json": '{"name": "x", "wheels": [{"name": "a", "type": "fixed", "position": [0, 0], "beta": 0, "r": NaN}]}',
}


def _wmrkit(*args: str, module: str = "wmrkit.cli.main", cwd: Path | None = None) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", module, *args], capture_output=True, text=True, cwd=cwd,
                          timeout=120)


def _one_error_line(out: subprocess.CompletedProcess) -> str:
    assert out.returncode == 2, out.stderr
    assert "Traceback" not in out.stderr
    lines = out.stderr.splitlines()
    assert len(lines) == 1 and lines[0].startswith("wmrkit: error: "), out.stderr
    assert out.stdout == ""
    return lines[0]


def test_show_broken_file_exits_2_with_one_line(tmp_path):
    (tmp_path / "broken.yaml").write_text(BROKEN["malformed.yaml"])
    line = _one_error_line(_wmrkit("show", "broken.yaml", cwd=tmp_path))
    assert line == "wmrkit: error: broken.yaml:4: malformed YAML: mapping values are not allowed here"


@pytest.mark.parametrize("name", sorted(BROKEN))
def test_every_broken_file_is_one_line_in_process(name, tmp_path, capsys):
    path = tmp_path / name
    path.write_text(BROKEN[name])
    assert main(["show", str(path)]) == 2
    captured = capsys.readouterr()
    assert captured.out == ""
    lines = captured.err.splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"wmrkit: error: {path}:")


def test_undecodable_file_is_one_line(tmp_path):
    (tmp_path / "bin.yaml").write_bytes(b"\xff\xfe\x00name")
    assert "cannot read the file (UnicodeDecodeError" in _one_error_line(_wmrkit("show", "bin.yaml", cwd=tmp_path))


def test_show_json_parses():
    out = _wmrkit("show", "forklift", "--json")
    assert out.returncode == 0, out.stderr
    data = json.loads(out.stdout)
    robot = catalog.load("forklift")
    assert data["name"] == "forklift"
    assert data["velocity_names"] == list(robot.velocity_names)
    assert data["steer_names"] == ["steer"]
    assert [w["name"] for w in data["wheels"]] == ["right_drive", "left_drive", "steer"]
    assert data["actuated_joints"] == ["right_drive.spin", "left_drive.spin", "steer.steer"]


@pytest.mark.parametrize("module", ["wmrkit", "wmrkit.cli.main"])
def test_a_command_run_as_a_module_says_nothing_on_stderr(module):
    """``python -m wmrkit.cli.main`` ran main() before the module had defined the compile notice's helper, so any
    command lasting longer than the notice's first poll (0.25 s) printed a NameError traceback from its thread."""
    out = _wmrkit("analyze", "forklift", module=module)
    assert out.returncode == 0 and out.stderr == "", out.stderr


def test_robots_json_parses_and_lists_the_catalog():
    out = _wmrkit("robots", "--json", module="wmrkit")  # python -m wmrkit works too
    assert out.returncode == 0, out.stderr
    data = json.loads(out.stdout)
    assert [d["name"] for d in data] == list(catalog.names())
    assert {d["name"]: d["wheels"] for d in data}["forklift"] == 3


def test_unknown_robot_exits_2_with_a_suggestion():
    line = _one_error_line(_wmrkit("show", "forklfit"))
    assert line == ("wmrkit: error: no robot 'forklfit' in the catalog (did you mean 'forklift'?); "
                    "'wmrkit robots' lists them")


def test_missing_file_and_text_summary(tmp_path, capsys):
    assert main(["show", str(tmp_path / "none.yaml")]) == 2
    assert capsys.readouterr().err == f"wmrkit: error: {tmp_path / 'none.yaml'}: no such file\n"
    good = tmp_path / "good.json"
    catalog.load("forklift").to_file(good)
    assert main(["show", str(good)]) == 0
    text = capsys.readouterr().out
    assert text.startswith("robot forklift: 3 wheels")
    assert "velocity vector q_dot (6): vx, vy, omega, right_drive.spin, left_drive.spin, steer.spin" in text


def test_a_long_first_compilation_is_announced_once(monkeypatch, capsys):
    """While another thread holds numba's compiler lock past the threshold the CLI says why it is quiet (a first
    run compiles kernels for seconds); with the lock free it says nothing."""
    import threading

    from numba.core.compiler_lock import global_compiler_lock

    import wmrkit.cli.main as cli

    monkeypatch.setattr(cli, "COMPILE_NOTICE_AFTER", 0.2)
    done = threading.Event()
    watcher = threading.Thread(target=cli._compile_notice, args=(done, 0.02))
    watcher.start()
    watcher.join(0.4)
    assert watcher.is_alive() and capsys.readouterr().err == ""  # the lock is free: silence
    held, release = threading.Event(), threading.Event()

    def compile_for_a_while():
        with global_compiler_lock:
            held.set()
            release.wait(5)

    compiler = threading.Thread(target=compile_for_a_while)
    compiler.start()
    held.wait(5)
    watcher.join(5)
    release.set()
    compiler.join(5)
    done.set()
    err = capsys.readouterr().err
    assert not watcher.is_alive() and err.count("compiling numerical kernels") == 1



@pytest.mark.parametrize("first", [True, False])
def test_the_dynamics_first_compile_is_announced_at_once_with_its_duration(monkeypatch, capsys, first):
    """The dynamics kernels not yet cached (about 20 s to compile) are announced as soon as they compile, once, with
    how long they take; cached (or another command's kernels), the notice waits for its threshold as before."""
    import threading

    import wmrkit._jit as jit
    import wmrkit.cli.main as cli

    monkeypatch.setattr(cli, "COMPILE_NOTICE_AFTER", 0.5)
    monkeypatch.setattr(cli, "DYNAMICS_NOTICE_AFTER", 0.02)
    monkeypatch.setattr(cli, "_compiling", lambda: True)
    monkeypatch.setattr(cli, "_first_dynamics_compile", lambda: first)
    monkeypatch.setattr(jit, "UNCACHED", set())  # not another test's uncached kernel (that notice is test_jit's)
    watcher = threading.Thread(target=cli._compile_notice, args=(threading.Event(), 0.01))
    start = time.perf_counter()
    watcher.start()
    watcher.join(5)
    elapsed, err = time.perf_counter() - start, capsys.readouterr().err
    assert not watcher.is_alive()
    if first:
        assert err == cli.DYNAMICS_NOTICE + "\n" and "about 20 s" in err and elapsed < 0.5
    else:
        assert err == cli.COMPILE_NOTICE + "\n" and elapsed >= 0.5

@pytest.mark.parametrize("value, expected", [("-5deg", -np.radians(5)), ("-0.5rad", -0.5), ("-1e-2", -0.01),
                                             ("-.25", -0.25), ("-5 deg", -np.radians(5))])
def test_a_negative_value_with_a_unit_is_a_value_not_an_option(value, expected, capsys):
    """argparse reads a word starting with '-' as an option unless it is '-90' or '-0.5': '--slip-angle -5deg'
    failed with 'expected one argument' although units are accepted everywhere (docs/conventions.md)."""
    assert main(["tyre", "dugoff", "--load", "1000", "--slip-ratio", "0", "--slip-angle", value, "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["slip_angle"] == pytest.approx(expected, rel=1e-15)
    assert out["Fy"] > 0  # a negative slip angle: the force of the ground pushes to +y (independent of the parse)


@pytest.mark.parametrize("name", catalog.names())
def test_show_json_reads_back_as_the_same_robot(name, tmp_path, capsys):
    """docs/catalog.md: copy `wmrkit show NAME --json` and change the numbers. The copy was refused with
    "unknown field 'velocity_names'" (the derived names show adds)."""
    assert main(["show", name, "--json"]) == 0
    path = tmp_path / "copy.json"
    path.write_text(capsys.readouterr().out, encoding="utf-8")
    assert Robot.from_file(path) == catalog.load(name)


def test_show_json_copy_with_stale_derived_names_is_refused(tmp_path, capsys):
    assert main(["show", "diff-drive", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    data["wheels"][0]["name"] = "port"  # renamed, but velocity_names still says left.spin
    path = tmp_path / "copy.json"
    path.write_text(json.dumps(data), encoding="utf-8")
    assert main(["show", str(path)]) == 2
    line = capsys.readouterr().err.strip()
    assert "copy.json" in line and "velocity_names: derived from the wheels" in line and "port.spin" in line


@pytest.mark.parametrize("args", [
    ["show", "{robot}", "--plot", "{robot}"],  # the description was replaced by the drawing (exit 0)
    ["odometry", "diff-drive", "{log}", "--out", "{log}"],
    ["odometry", "diff-drive", "{log}", "--out", "{dir}/./{log_name}"],  # the same file by another name
    ["odometry", "diff-drive", "{log}", "--out", "{dir}/p.svg", "--plot", "{dir}/p.svg"],  # two outputs in one file
    ["kinematics", "{robot}", "--codegen", "c", "{dir}/gen", "--json"],  # an output folder is not compared: runs
])
def test_an_output_that_is_an_input_or_another_output_is_refused(args, tmp_path, capsys):
    """Before any work, one line naming both; the input is left as it was."""
    robot, log = tmp_path / "q.png", tmp_path / "run.csv"
    robot.write_text(json.dumps(catalog.load("diff-drive").to_dict()))
    log.write_text("time,left.spin,right.spin\n0,0,0\n1,1,1\n")
    before = robot.read_text(), log.read_text()
    names = {"robot": robot, "log": log, "dir": tmp_path, "log_name": log.name}
    code = main([a.format(**names) for a in args])
    err = capsys.readouterr().err
    if "--codegen" in args:
        assert code == 0, err
        return
    assert code == 2 and len(err.strip().splitlines()) == 1 and "is also " in err, err
    assert "(the output would replace it)" in err and (robot.read_text(), log.read_text()) == before
    assert not (tmp_path / "p.svg").exists()


def test_every_option_has_help_and_says_its_default():
    """`--help` documents every option, and an option that takes a value it does not require says the value it
    takes when not given: `simulate --method` and `batch montecarlo --seed` had no help at all; `follow-line
    --period` (0.5 s), `tyre --speed` (2 m/s), `track --controller`/`--steering`/`--delay` and `feasibility
    --framework`, among others, left their defaults unsaid."""
    import argparse

    from cli_options import options

    silent = []
    for words, action in options():
        if not isinstance(action, argparse._HelpAction | argparse._VersionAction):
            takes_value = action.nargs != 0 and not action.required
            default = not (action.default is None or action.default is False or action.default == [])
            if not action.help or (takes_value and default and "default" not in action.help):
                silent.append(f"{' '.join(words)} {action.option_strings[-1]} (default {action.default!r})")
    assert silent == []


def test_options_choosing_an_integration_scheme_explain_every_choice():
    """`--method`/`--scheme` offered `paper002` (and `slip-study --source` `md`) with no word of what they are: the
    paper's number in the project's bibliography. Every such option now names each of its choices in its help."""
    import re

    from cli_options import options

    unexplained = []
    for words, action in options():
        if action.choices and {"paper002", "md"} & set(action.choices):
            for choice in action.choices:
                if not re.search(rf"(?<![\w-]){re.escape(choice)}(?![\w-])", action.help or ""):
                    unexplained.append(f"{' '.join(words)} {action.option_strings[-1]} {choice}")
    assert unexplained == []


def test_odometry_options_a_description_may_default_say_so():
    """A description's `odometry:` block (method, scheme, slip, noise) and a wheel's `slip:` give the defaults of
    `wmrkit odometry`'s options (docs/description-format.md): `--kf-noise` said '(default 1 1 1)' and `--mu`
    'default 1,1' while a described noise or friction coefficient was used in their place; `--mu-default` and
    `--kf-wheel` said nothing of their defaults."""
    from cli_options import options

    described = ("--method", "--scheme", "--mu", "--mu-default", "--kf-noise", "--kf-period", "--kf-wheel")
    helps = {a.option_strings[-1]: a.help for words, a in options() if words == ("odometry",)}
    assert [o for o in described if "description" not in helps[o]] == []


def test_show_and_ik_name_a_mecanum_wheel_as_its_description_does(tmp_path, capsys):
    """`type: mecanum` (a Swedish wheel with the standard rollers of its quadrant) was shown as 'swedish' by the
    `show` and `ik` tables, while `show --json` wrote 'mecanum'; a Swedish wheel with other rollers stays 'swedish'."""
    assert main(["show", "mecanum-4"]) == 0
    rows = [line.split() for line in capsys.readouterr().out.splitlines()[2:6]]
    assert [r[1] for r in rows] == ["mecanum"] * 4
    assert main(["ik", "mecanum-4", "--twist", "0.5", "0.3", "0"]) == 0
    assert [line.split()[1] for line in capsys.readouterr().out.splitlines()[1:5]] == ["mecanum"] * 4
    odd = tmp_path / "odd.yaml"
    odd.write_text("name: odd\nwheels:\n"
                   "  - {name: a, type: swedish, position: [0.2, 0.2], heading: 0, r: 0.05, gamma: 30 deg, r_r: 0.01}\n"
                   "  - {name: b, type: mecanum, position: [-0.2, -0.2], r: 0.05}\n")
    assert main(["show", str(odd)]) == 0
    assert [line.split()[1] for line in capsys.readouterr().out.splitlines()[2:4]] == ["swedish", "mecanum"]
