"""Sweep 6 of the command-line doors, found by a fuzzer of every command's options (hostile values put into the
documented commands): outputs that cannot be written, a simulation's initial twist, the size of a local cluster.
Each case printed a traceback or started work it could not finish; each now answers with one located line and
exit 2 before any work."""

from __future__ import annotations

import argparse
import errno
import json
from pathlib import Path

import numpy as np
import pytest

from cli_options import options
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
VISION = Path(__file__).parents[2] / "docs" / "figures" / "vision"
FOLDER_OPTIONS = {f"--{d}" for d in OUTPUT_FOLDERS} | {"--codegen"}


def _commands(parser: argparse.ArgumentParser):
    """Every (command words, option string) of the parser whose option names a file or folder written."""
    for words, action in options(parser):
        if action.dest in OUTPUT_FILES + OUTPUT_FOLDERS or action.dest == "codegen":
            yield words, action.option_strings[-1]


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
        named = path if argv[0] == "show" else f"--plot {path}"  # main() names the option too
        assert message.startswith(f"wmrkit: error: {named}: ") and "No space left on device" in message


def test_a_report_folder_that_cannot_be_made_late_names_the_option(monkeypatch, tmp_path, capsys):
    """mkdir failing after the checks (as root, /proc passes the permission check) named the folder alone; the text
    names the option too, the JSON keeps the file."""
    import os

    folder = str(tmp_path / "figures")
    makedirs = os.makedirs

    def refuse(name, *args, **kwargs):  # the report's folder only: numba's cache keeps its own (tests/test_jit.py)
        if str(name).startswith(folder):
            raise OSError(errno.ENOENT, "No such file or directory", str(name))
        return makedirs(name, *args, **kwargs)

    monkeypatch.setattr(os, "makedirs", refuse)
    argv = ["slip-study", "skid-steer-4", "--source", "quasi-static", "--report", folder]
    assert _one_line(argv, capsys).startswith(f"wmrkit: error: --report {folder}")
    assert main([*argv, "--json"]) == 2
    assert json.loads(capsys.readouterr().err)["file"].startswith(folder)


@pytest.mark.parametrize("twist", [["10", "2", "1e308"], ["10", "1e6", "0"], ["0", "0", "1000.1"]])
def test_simulate_refuses_an_initial_twist_outside_the_envelope(twist, capsys):
    # 1e308 rad/s and 1e6 m/s raised ZeroDivisionError in the compiled observer
    message = _one_line(["simulate", "forklift", "--path", "turn", "--initial-twist", *twist], capsys)
    assert message.startswith("wmrkit: error: --initial-twist [") and "within 1000 m/s" in message  # names the option


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


@pytest.mark.parametrize("loop", [["--period", "0.05"], ["--dynamics", "--period", "0.05"],
                                  ["--dynamics", "--period", "0.05", "--slip-model", "mqe"]])
def test_a_negative_delay_is_refused_by_every_loop(loop, capsys):
    # the loop with slip-model commands indexed its history with it (a traceback)
    message = _one_line(["track", "skid-steer-4", "--reference", "circle", "--duration", "1", *loop, "--delay", "-1"],
                        capsys)
    assert "delay: expected a number of samples >= 0, got -1" in message


@pytest.mark.parametrize("argv, expected", [
    # a traceback from islice before
    (["odometry", "diff-drive", "log.csv", "--chunk-size", "99999999999999999999999"],
     "--chunk-size must be in [1, 4194304] samples"),
    # ran forever before (1e23 bootstrap refits)
    (["batch", "calibrate", "diff-drive", "log.csv", "--closed", "--workers", "0", "--ci", "bootstrap", "--bootstrap",
      "99999999999999999999999"], "--bootstrap must be in [2, 10000] replicates"),
    (["slip-study", "skid-steer-4", "--seed", "3"], "--seed applies to the forklift study"),  # ignored before
    (["slip-study", "skid-steer-4", "--quick"], "--quick applies to the forklift study"),
    (["slip-study", "forklift", "--source", "md"], "--source applies to the skid-steer-4 study"),
    (["vision", "calibrate", "image.png", "--rows", "60", "--half-separation", "0.035", "--row-distance", "0.1",
      "--size", "0", "0"], "--size applies to --x1/--x2"),  # ignored before
    (["vision", "locate", "--points", f"{VISION}/chufa-points.json", "--camera", f"{VISION}/chufa-camera.yaml",
      "--lines", "2"], "--lines applies to an IMAGE"),  # ignored before
    (["vision", "locate", "--points", f"{VISION}/chufa-points.json", "--camera", f"{VISION}/chufa-camera.yaml",
      "--mode", "gradient"], "--mode applies to an IMAGE"),  # ignored before
    (["vision", "locate", "--points", "", "--camera", f"{VISION}/chufa-camera.yaml"], "--points: empty value"),
    # LinAlgError from the eigenvalues of kappa at D = 5e-324 m; analyze printed "condition number infinite (these
    # joints do not determine the twist)" at D = 1e-9 m
    (["sweep", "omni-3", "--vary", "wheels.back.l=0.1:0.2:3", "--workers", "0", "--length", "5e-324"],
     "--length: 4.94066e-324 m is outside the lengths wmrkit handles"),
    (["analyze", "thesis-steer-castor", "--length", "1e-9"], "--length: 1e-09 m is outside the lengths"),
    # 18849 s of loop at 1 mm/s: about an hour of slip-model solves before
    (["track", "skid-steer-4", "--reference", "circle", "--dynamics", "--slip-model", "mqe", "--speed", "1e-3"],
     "more than 50000 control periods with slip-model commands"),
    (["track", "skid-steer-4", "--reference", "circle", "--dynamics", "--period", "0.1", "--duration", "60000"],
     "more than 5e+07 integration steps"),
    # 285,665 samples: 940 MB and 8 s; 1e5 Hz raised numpy's MemoryError after a minute (3.6 GiB for one array)
    (["batch", "montecarlo", "diff-drive", "--path", "square", "-n", "2", "--workers", "0", "--rate", "10000"],
     "a run at most 134217728 (1 GiB): a rate of at most 9035 Hz"),
])
def test_options_that_ran_unbounded_or_were_ignored_are_refused(argv, expected, capsys):
    assert expected in _one_line(argv, capsys)


def test_library_checks_of_the_same_limits():
    from wmrkit.batch.calibrate import fleet_calibrate
    from wmrkit.odometry.logs import read_csv

    with pytest.raises(WmrkitError, match="chunk_size must be in"):
        next(read_csv("log.csv", ("left.spin",), chunk_size=0))
    with pytest.raises(WmrkitError, match="n_boot must be in"):
        fleet_calibrate(catalog.load("diff-drive"), [object()], [], ci="bootstrap", n_boot=10**9)


def test_a_noise_bound_of_minus_zero_is_zero(capsys):
    # numpy's uniform(0.0, -0.0) raised "high - low < 0" (found by the options fuzzer, seed 11)
    camera = str(VISION / "follower-camera.yaml")
    argv = ["follow-line", "line-follower", "--camera", camera, "--duration", "3", "--json"]
    assert main([*argv, "--noise", "0", "-0"]) == 0
    with_minus_zero = capsys.readouterr().out
    assert main([*argv, "--noise", "0", "0"]) == 0
    assert capsys.readouterr().out == with_minus_zero


def test_a_closed_pipe_still_ends_quietly_with_exit_0(monkeypatch):
    # BrokenPipeError is an OSError without a file: the handler of OSErrors naming a file must not take it
    class ClosedPipe:
        def write(self, text):
            raise BrokenPipeError(errno.EPIPE, "Broken pipe")

        def flush(self):
            pass

    monkeypatch.setattr("sys.stdout", ClosedPipe())
    assert main(["robots"]) == 0


BLANKS = [  # an argument given as empty text, and the name the one line gives it
    (["analyze", ""], "ROBOT"),
    (["odometry", "diff-drive", " "], "LOG"),
    (["vision", "locate", "--points", "", "--camera", "camera.yaml"], "--points"),
    (["vision", "locate", "image.png", "--camera", ""], "--camera"),
    (["track", "forklift", "--reference", ""], "--reference"),
    (["tyre", "dugoff", "--load", "1000", "--param", "mu=0.5", "--param", ""], "--param"),
]


@pytest.mark.parametrize("argv, name", BLANKS, ids=lambda a: " ".join(a) if isinstance(a, list) else a)
def test_an_empty_argument_is_refused_by_name(argv, name, capsys):
    """Read as a path, '' is the current folder: 'analyze ""' said '.: cannot read the file (IsADirectoryError)',
    'odometry diff-drive ""' said ': not a ROS 2 bag' (the options fuzzer's empty values)."""
    assert _one_line(argv, capsys) == f"wmrkit: error: {name}: empty value\n"


@pytest.mark.parametrize("argv", WRITERS, ids=lambda a: " ".join(a[:2] + a[-1:]))
def test_an_empty_output_name_is_refused_by_name(argv, capsys):
    option = _option(argv)
    assert _one_line([*argv, ""], capsys) == f"wmrkit: error: {option}: empty value\n"


@pytest.mark.parametrize(("robot", "vary", "field", "value"), [
    ("omni-3", "wheels.back.l=150mm:250mm:3", "l", 0.25),  # the fuzzer's ground and docs/batch.md's sweep
    ("omni-3", "wheels[0].alpha,wheels[0].beta=30deg:90deg:3", "beta", np.pi / 2),
    ("mecanum-4", "wheels[0].gamma=30deg:60deg:3", "gamma", np.pi / 3),
])
def test_a_sweep_varies_wheels_saved_in_the_users_form(robot, vary, field, value):
    """Descriptions are saved with position, heading and type mecanum: a sweep of l, alpha, beta or gamma set the
    thesis's field beside them and every design was refused ("give either 'position' or 'l' and 'alpha'")."""
    from wmrkit.batch.sweep_kernel import parse_vary, variant

    base = catalog.load(robot)
    axis = parse_vary(vary, base)
    design = variant(base, {t: axis.values[-1] for t in axis.targets})
    i = axis.targets[0][0]
    assert getattr(design.wheels[i], field) == pytest.approx(value)
    for j, w in enumerate(base.wheels):
        if j != i:
            assert design.wheels[j] == w


def test_a_synthetic_run_holds_at_most_a_gib_of_fine_arrays():
    """simulate's fine arrays grew with rate x duration x the robot's size: 1e7 samples (its documented limit) of the
    diff-drive would have taken 27 GB. The bound is in numbers, so a larger robot gets a lower rate."""
    from wmrkit.odometry.synthetic import MAX_FINE_VALUES, TwistProfile, fine_step_values, simulate

    profile = TwistProfile(np.array([0.01]), np.array([[0.5, 0.0, 0.0]]))
    for name in ("diff-drive", "swerve-4"):
        robot = catalog.load(name)
        top = MAX_FINE_VALUES / (fine_step_values(robot) * 8 * 0.01)
        assert len(simulate(robot, profile, 0.01 * top).log) > 100  # just inside: 'batch montecarlo --rate 9000'
        with pytest.raises(WmrkitError, match=rf"'{name}' holds up to \d+ numbers a fine step .* a rate of at most"):
            simulate(robot, profile, 1.01 * top)


def test_a_monte_carlo_study_is_bounded_in_memory_and_work():
    """A LOG of 3e6 samples took 850 MB for two runs, and 10^6 runs of it would have run for days."""
    from wmrkit.batch.engine import BatchError
    from wmrkit.batch.montecarlo import MAX_LOG_VALUES, MAX_RUNS, MAX_WORK, RUN_COST, monte_carlo
    from wmrkit.odometry.logs import JointLog

    robot = catalog.load("diff-drive")

    def log(n):
        t = np.arange(n) * 0.01
        return JointLog(t, ("left.spin", "right.spin"), np.column_stack([t, 1.001 * t]))

    n = MAX_LOG_VALUES // 5 + 1
    with pytest.raises(BatchError, match=rf"log: {n} samples of 2 joints: a Monte Carlo log holds at most"):
        monte_carlo(robot, log(n), 2)
    n = int((MAX_WORK / MAX_RUNS - RUN_COST) // 5) + 1  # the shortest log of which MAX_RUNS runs are too many
    most = int(MAX_WORK // (5 * n + RUN_COST))
    assert most < MAX_RUNS
    with pytest.raises(BatchError, match=rf"runs: at most {most} runs of this log \({n} samples of 2 joints\) on 1 "
                                         rf"worker, got {MAX_RUNS}: .* more workers \(--workers up to the CPUs, "
                                         r"--scheduler\)"):
        monte_carlo(robot, log(n), MAX_RUNS)
    assert monte_carlo(robot, log(n), 3).runs == 3
