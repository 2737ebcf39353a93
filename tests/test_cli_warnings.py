"""One contract for warnings: under ``--json`` every command that can warn lists its warnings in a top-level
``"warnings"`` (the words of its ``wmrkit: warning:`` lines, which stay on stderr for people; [] when none). ``ik``,
``fk``, ``odometry``, ``track``, ``batch odometry`` and ``batch montecarlo`` said them on stderr only, where a script
reading the JSON could not see them."""

from __future__ import annotations

import json

import numpy as np
import pytest

from cli_options import options
from wmrkit.cli.main import main

#: Every command offering --json, as its words.
JSON_COMMANDS = {cmd for cmd, action in options() if action.dest == "json"}
#: The commands that cannot warn (their JSON has no "warnings"); a new command is put here or in CASES.
SILENT = {("robots",), ("show",), ("analyze",), ("sweep",), ("calibrate",), ("slip-study",),
          ("vision", "locate"), ("vision", "calibrate"), ("follow-line",)}
PREFIX = "wmrkit: warning: "


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    """Logs for odometry (a yaw column that turns where the wheels do not, and one that agrees), batch odometry (a
    log of one sample) and batch calibrate (closed squares, and the same cut short before their last turn ends),
    zero torques for simulate, a car with a solid rear axle (a gear coupling)."""
    import dataclasses

    from wmrkit import catalog
    from wmrkit.batch.calibrate import default_parameters
    from wmrkit.couplings import Coupling
    from wmrkit.odometry.calibration import apply_parameters
    from wmrkit.odometry.logs import write_csv
    from wmrkit.odometry.synthetic import simulate, square_path

    d = tmp_path_factory.mktemp("warnings")
    car = catalog.load("ackermann")  # a solid rear axle: its spins on a gear, which some commands do not model
    dataclasses.replace(car, couplings=(Coupling("gear", ("rear_left.spin", "rear_right.spin"), (1.0, 1.0)),)
                        ).to_file(d / "kart.yaml")
    t = np.arange(21) * 0.1
    for name, yaw in (("turning-yaw.csv", 0.5 * t), ("yaw.csv", 0 * t)):
        write_csv(d / name, ("time", "left.spin", "right.spin", "yaw"), np.column_stack([t, 10 * t, 10 * t, yaw]))
    (d / "one.csv").write_text("time,left.spin,right.spin\n0,0,0\n")
    (d / "short.yaml").write_text("vehicle: {a1: 150 cm, b1: 50 cm, c1: 140 cm, h1: 105 cm, d1: 50 cm, phi_max: 46 deg}"
                                  "\nspace: {H: 230 cm, J: 200 cm, MS: 20 cm, dx2: 90 cm, final_gap: 7 cm}\n")
    (d / "zero.csv").write_text("time,front_left.spin,front_right.spin,rear_left.spin,rear_right.spin\n"
                                "0,0,0,0,0\n0.1,0,0,0,0\n")
    diff = catalog.load("diff-drive")
    true = apply_parameters(diff, default_parameters(diff, closed=True), [0.01, 0.03])
    for i in range(4):
        log = simulate(true, square_path(1.5, clockwise=i % 2 == 1, pause=0.5), 10.0).log
        for folder, n in (("squares", len(log)), ("short", len(log) - 6)):  # cut short: 24.5 s, the turn ends later
            (d / folder).mkdir(exist_ok=True)
            write_csv(d / folder / f"sq{i}.csv", ("time", *log.joints),
                      np.column_stack([log.time, log.positions])[:n])
    return d


#: Each command that can warn: a command line that warns (or several, each warning its own way) and one that does not
#: ({d}: the files' folder).
CASES = {
    ("ik",): ("ik diff-drive --twist 1 0.2 0", "ik diff-drive --twist 1 0 0.5"),
    ("fk",): ("fk diff-drive --spin left=10", "fk diff-drive --spin left=10 --spin right=12"),
    ("odometry",): ("odometry diff-drive {d}/turning-yaw.csv --heading-column yaw",
                    "odometry diff-drive {d}/yaw.csv --heading-column yaw"),
    ("track",): (("track mecanum-4 --reference line --period 0.5 --delay 1 --gain 0.8 --duration 2",
                  "track forklift --reference square --duration 13"),  # a corner: Table 8.1's stop and re-orient
                 "track mecanum-4 --reference line --duration 2"),
    ("tyre",): ("tyre pacejka --load 3000 --slip-ratio 0.1 --speed 30", "tyre pacejka --load 3000 --slip-ratio 0.1"),
    ("simulate",): ("simulate skid-steer-4 --torques {d}/zero.csv --initial-twist 20 0 0 --duration 0.02 --tyre "
                    "pacejka", "simulate skid-steer-4 --torques {d}/zero.csv --initial-twist 5 0 0 --duration 0.02 "
                    "--tyre pacejka"),
    ("park",): ("park thesis-9.2", "park thesis-9.1"),
    # its own warning: an impossible slot (the answer, exit 1) draws no animation; it was a 'wmrkit: note:' line
    ("park", "--animate"): ("park {d}/short.yaml --animate {d}/no.gif", "park thesis-9.1 --check"),
    ("kinematics",): ("kinematics {d}/kart.yaml --symbolic", "kinematics ackermann --symbolic"),
    ("feasibility",): ("feasibility {d}/kart.yaml --reference circle", "feasibility ackermann --reference circle"),
    ("batch", "odometry"): ("batch odometry diff-drive {d}/one.csv {d}/yaw.csv --workers 0",
                            "batch odometry diff-drive {d}/yaw.csv --workers 0"),
    ("batch", "calibrate"): ("batch calibrate diff-drive {d}/short --closed --workers 0",
                             "batch calibrate diff-drive {d}/squares --closed --workers 0"),
    ("batch", "montecarlo"): ("batch montecarlo thesis-omni-castor --path arc -n 3 --workers 0",
                              "batch montecarlo diff-drive --path arc -n 3 --workers 0"),
}


#: The exit code of a case that warns when it is not 0: an answer that is no (docs/limits.md, Exit codes).
NO = {"ik diff-drive --twist 1 0.2 0": 1, "park {d}/short.yaml --animate {d}/no.gif": 1}


def test_every_command_with_json_is_one_that_can_warn_or_one_that_cannot():
    assert {c for c in CASES if not c[-1].startswith("--")} | SILENT == JSON_COMMANDS and not set(CASES) & SILENT


def _run(capsys, line: str, files, *extra: str) -> tuple[str, str]:
    assert main([*line.format(d=files).split(), *extra]) == NO.get(line, 0)
    out, err = capsys.readouterr()
    return out, err


def _said(text: str, prefix: str = PREFIX) -> list[str]:
    return [line.removeprefix(prefix) for line in text.splitlines() if line.startswith(prefix)]


@pytest.mark.parametrize("command", sorted(CASES), ids=" ".join)
def test_the_json_lists_the_warnings_that_stderr_says(command, files, capsys):
    warnings, quiet = CASES[command]
    for warns in (warnings,) if isinstance(warnings, str) else warnings:
        out, err = _run(capsys, warns, files, "--json")
        text_out, text_err = _run(capsys, warns, files)
        said = _said(text_err)  # park's plan's warnings too (they were 'warning: ...' lines on stdout)
        assert said and json.loads(out)["warnings"] == said and "warning:" not in text_out
        assert _said(err) == _said(text_err)  # on stderr under --json too, for people
    out, err = _run(capsys, quiet, files, "--json")
    assert json.loads(out)["warnings"] == [] and PREFIX not in err


def test_a_warning_said_outside_a_command_run_is_printed_only(capsys):
    from wmrkit.cli._common import print_json, warn

    warn("no run collects this")
    print_json({"a": 1})
    out, err = capsys.readouterr()
    assert err == f"{PREFIX}no run collects this\n" and json.loads(out) == {"a": 1, "warnings": []}


def test_every_warning_line_of_the_cli_is_said_through_one_function():
    """A command printing its own 'wmrkit: warning:' line would miss the JSON's list."""
    from pathlib import Path

    import wmrkit.cli

    folder = Path(wmrkit.cli.__file__).parent
    assert [p.name for p in folder.glob("*.py") if "wmrkit: warning:" in p.read_text()] == ["_common.py"]
