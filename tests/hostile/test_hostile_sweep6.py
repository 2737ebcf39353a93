"""Sweep 6 of the command-line doors, found by a fuzzer of every command's options (hostile values put into the
documented commands): outputs that cannot be written, a simulation's initial twist, the size of a local cluster.
Each case printed a traceback or started work it could not finish; each now answers with one located line and
exit 2 before any work."""

from __future__ import annotations

import argparse
import errno

import numpy as np
import pytest

from wmrkit import catalog
from wmrkit.cli._common import OUTPUT_FILES, OUTPUT_FOLDERS
from wmrkit.cli.main import build_parser, main
from wmrkit.errors import WmrkitError

#: A command line of every command that writes files, with the option under test last but its value: each parses
#: (its inputs need not exist: outputs are checked before anything is read).
WRITERS = [
    ["show", "forklift", "--plot"],
    ["analyze", "forklift", "--report"],
    ["kinematics", "forklift", "--codegen", "c"],
    ["odometry", "diff-drive", "log.csv", "--out"],
    ["odometry", "diff-drive", "log.csv", "--plot"],
    ["batch", "odometry", "diff-drive", "log.csv", "--workers", "0", "--out"],
    ["batch", "odometry", "diff-drive", "log.csv", "--workers", "0", "--trajectories"],
    ["batch", "montecarlo", "diff-drive", "--path", "square", "--workers", "0", "--plot"],
    ["sweep", "omni-3", "--vary", "wheels.back.l=0.1:0.2:3", "--workers", "0", "--out"],
    ["sweep", "omni-3", "--vary", "wheels.back.l=0.1:0.2:3", "--workers", "0", "--plot"],
    ["slip-study", "skid-steer-4", "--report"],
    ["vision", "calibrate", "image.png", "--rows", "60", "--half-separation", "0.035", "--row-distance", "0.1",
     "--out"],
    ["follow-line", "line-follower", "--camera", "camera.yaml", "--animate"],
    ["park", "thesis-9.1", "--plot"],
    ["park", "thesis-9.1", "--animate"],
    ["tyre", "pacejka", "--load", "1000", "--plot"],
    ["simulate", "forklift", "--path", "turn", "--out"],
    ["simulate", "forklift", "--path", "turn", "--plot"],
    ["track", "diff-drive", "--reference", "circle", "--plot"],
    ["track", "diff-drive", "--reference", "circle", "--animate"],
    ["feasibility", "forklift", "--reference", "square", "--plot"],
]
FOLDER_OPTIONS = {f"--{d}" for d in OUTPUT_FOLDERS} | {"--codegen"}


def _commands(parser: argparse.ArgumentParser, prefix: tuple[str, ...] = ()):
    """Every (command words, option string) of the parser whose option names a file or folder written."""
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for name, sub in action.choices.items():
                yield from _commands(sub, (*prefix, name))
        elif action.option_strings and (action.dest in OUTPUT_FILES + OUTPUT_FOLDERS or action.dest == "codegen"):
            yield prefix, action.option_strings[-1]


def _option(argv: list[str]) -> str:
    return argv[-2] if argv[-2] == "--codegen" else argv[-1]


def _words(argv: list[str]) -> tuple[str, ...]:
    """The command words that begin `argv` (``batch odometry``, ``show``)."""
    parser, words = build_parser(), []
    for word in argv:
        subs = [a for a in parser._actions if isinstance(a, argparse._SubParsersAction)]
        if not subs or word not in subs[0].choices:
            break
        parser = subs[0].choices[word]
        words.append(word)
    return tuple(words)


def test_every_output_option_of_every_command_is_covered_here():
    assert set(_commands(build_parser())) == {(_words(argv), _option(argv)) for argv in WRITERS}


def _one_line(argv: list[str], capsys) -> str:
    code = main(argv)
    captured = capsys.readouterr()
    assert code == 2, (argv, captured.err[-500:])
    assert captured.err.count("\n") == 1 and captured.err.startswith("wmrkit: error: "), (argv, captured.err)
    return captured.err


@pytest.mark.parametrize("argv", WRITERS, ids=lambda a: " ".join(a[:2] + a[-1:]))
def test_an_output_that_cannot_be_written_is_refused_before_any_work(argv, tmp_path, capsys):
    option = _option(argv)
    folder = option in FOLDER_OPTIONS
    name = "out" if folder else {"--plot": "x.png", "--animate": "x.gif"}.get(option, "x.csv")
    a_file = tmp_path / "file.txt"
    a_file.write_text("")
    (tmp_path / name).mkdir()
    cases = [(str(tmp_path / "missing" / name), "no such folder"),  # savefig's FileNotFoundError before
             (str(a_file / name), "is not a folder")]  # NotADirectoryError
    cases.append((str(a_file), "is a file, not a folder") if folder else (str(tmp_path / name), "is a folder"))
    for path, expected in cases:
        if folder and "missing" in path:
            continue  # a missing folder is created with its parents
        message = _one_line([*argv, path], capsys)
        assert f"{option} {path}: " in message and expected in message, message


def test_a_write_that_fails_midway_is_one_line_naming_the_file(monkeypatch, tmp_path, capsys):
    from matplotlib.figure import Figure

    def full_disk(self, path, **kwargs):
        raise OSError(errno.ENOSPC, "No space left on device", str(path))

    monkeypatch.setattr(Figure, "savefig", full_disk)  # the checks before the work pass: the disk fills later
    for argv in (["show", "forklift"], ["park", "thesis-9.1"]):  # a message of its own, the one of main()
        path = str(tmp_path / "drawing.png")
        message = _one_line([*argv, "--plot", path], capsys)
        assert message.startswith(f"wmrkit: error: {path}: ") and "No space left on device" in message


@pytest.mark.parametrize("twist", [["10", "2", "1e308"], ["10", "1e6", "0"], ["0", "0", "1000.1"]])
def test_simulate_refuses_an_initial_twist_outside_the_envelope(twist, capsys):
    # 1e308 rad/s and 1e6 m/s raised ZeroDivisionError in the compiled observer
    message = _one_line(["simulate", "forklift", "--path", "turn", "--initial-twist", *twist], capsys)
    assert "initial twist" in message and "within 1000 m/s" in message


def test_initial_state_checks_the_pose_and_twist_from_python():
    from wmrkit.dynamics.model import DynamicModel
    from wmrkit.dynamics.simulate import initial_state

    model = DynamicModel.of(catalog.load("forklift"))
    assert np.all(np.isfinite(initial_state(model, (1000.0, 0.0, 0.0))))  # the envelope's edge is accepted
    for twist, pose in [((1000.001, 0, 0), (0, 0, 0)), ((0, 0, 0), (1e10, 0, 0)), ((0, 0, 0), (0, 0, np.nan))]:
        with pytest.raises(WmrkitError, match=r"initial (twist|pose)"):
            initial_state(model, twist, pose)


def test_a_local_cluster_is_at_most_four_workers_per_cpu(monkeypatch, capsys):
    import os

    monkeypatch.setattr(os, "cpu_count", lambda: 2)
    # 1000000 started a million worker processes (the fuzzer's run hung)
    message = _one_line(["batch", "montecarlo", "diff-drive", "--path", "square", "--workers", "9"], capsys)
    assert "--workers must be in [0, 8]" in message and "--scheduler" in message


@pytest.mark.parametrize("model", ["none", "mqe"])
def test_a_loop_through_the_dynamics_that_diverges_is_stopped_at_once(model, capsys):
    # --gain 2147483648 commanded 7e7 m/s: the MQE commands ran 80 s for 5 s of loop, the IK commands ended in a
    # lift-off 4.3 s later
    message = _one_line(["track", "skid-steer-4", "--reference", "circle", "--size", "2", "--dynamics", "--period",
                         "0.05", "--slip-model", model, "--duration", "5", "--gain", "2147483648"], capsys)
    assert "the loop diverged: at t = 0.05 s" in message and "beyond 1000 m/s" in message
