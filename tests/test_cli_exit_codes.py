"""One exit-code contract for every command (docs/limits.md, Exit codes): 0 an answer, 1 an answer that is no (the
verdict the command was asked for: a twist or a reference not feasible, no parking manoeuvre, a batch with failed
logs), 2 no answer (bad input, or a run that stopped at a bound or diverged: one error line, a JSON error object
under --json, nothing on stdout). Warnings and flagged data do not change it. 'wmrkit ik' and 'wmrkit feasibility'
exited 0 on a 'feasible: no' while 'wmrkit park' exited 1 on its no."""

from __future__ import annotations

import json

import pytest

from cli_options import options
from wmrkit.cli.main import main

#: Every command's words, and the leaves (the commands that run).
COMMANDS = {cmd for cmd, a in options() if a.dest == "help"}
LEAVES = sorted(cmd for cmd in COMMANDS if cmd and not any(c[:len(cmd)] == cmd and c != cmd for c in COMMANDS))
SHORT = ("vehicle: {a1: 150 cm, b1: 50 cm, c1: 140 cm, h1: 105 cm, d1: 50 cm, phi_max: 46 deg}\n"
         "space: {H: 230 cm, J: 200 cm, MS: 20 cm, dx2: 90 cm, final_gap: 7 cm}\n")
VISION = "docs/figures/vision"

#: Representative command lines of each command and their exit code ({d}: a folder of files; from the repository's
#: root). Every verdict command has its yes (0) and its no (1).
CASES: dict[tuple[str, ...], list[tuple[str, int]]] = {
    ("robots",): [("robots", 0)],
    ("show",): [("show no-such-robot", 2)],
    ("kinematics",): [("kinematics diff-drive", 0)],
    ("ik",): [("ik diff-drive --twist 1 0 0.5", 0), ("ik diff-drive --twist 1 0.2 0", 1),
              ("ik diff-drive --twist 1e9 0 0", 2)],
    ("fk",): [("fk mecanum-4 --spin front_left=10 --spin front_right=12 --spin rear_left=-3 --spin rear_right=40",
               0)],  # rates that contradict each other: flagged ("consistent": false), answered
    ("analyze",): [("analyze diff-drive", 0)],
    ("odometry",): [("odometry diff-drive {d}/turning-yaw.csv --heading-column yaw", 0),  # flagged, answered
                    ("odometry diff-drive {d}/bad.csv", 2)],
    ("feasibility",): [("feasibility ackermann --reference circle", 0), ("feasibility forklift --reference square", 1)],
    ("track",): [("track mecanum-4 --reference line --duration 2", 0),
                 ("track diff-drive --reference circle --duration 2 --gain 1e308 --period 0.1", 2)],  # diverged
    ("tyre",): [("tyre pacejka --load 3000 --slip-ratio 0.1", 0)],
    ("simulate",): [("simulate skid-steer-4 --path straight --duration 1e9", 2)],  # a bound
    ("park",): [("park thesis-9.1", 0), ("park {d}/short.yaml", 1), ("park {d}/no-such.yaml", 2)],
    ("follow-line",): [(f"follow-line line-follower --camera {VISION}/follower-camera.yaml --duration 1e9", 2)],
    ("vision", "locate"): [(f"vision locate --points {VISION}/chufa-points.json --camera {VISION}/chufa-camera.yaml",
                            2)],  # its lines need --spacing
    ("vision", "calibrate"): [(f"vision calibrate {VISION}/calibration.png --rows 60 --half-separation 3.5cm "
                               "--row-distance 10.22cm", 0)],
    ("calibrate",): [("calibrate diff-drive {d}/no-such.csv --reference {d}/no-such.tum", 2)],
    ("slip-study",): [("slip-study no-such-robot", 2)],
    ("sweep",): [("sweep omni-3 --vary wheels.back.l=150mm:250mm:3 --workers 0", 0)],
    ("batch", "odometry"): [("batch odometry diff-drive {d}/yaw.csv --workers 0", 0),
                            ("batch odometry diff-drive {d}/yaw.csv {d}/bad.csv --workers 0", 1)],  # a log failed
    ("batch", "calibrate"): [("batch calibrate diff-drive {d}/no-such --closed --workers 0", 2)],
    ("batch", "montecarlo"): [("batch montecarlo diff-drive --path arc -n 3 --workers 0", 0)],
    ("studio",): [("studio --port 70000", 2)],  # a server: no --json
}


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    import numpy as np

    from wmrkit.odometry.logs import write_csv

    d = tmp_path_factory.mktemp("exit")
    t = np.arange(21) * 0.1
    for name, yaw in (("turning-yaw.csv", 0.5 * t), ("yaw.csv", 0 * t)):
        write_csv(d / name, ("time", "left.spin", "right.spin", "yaw"), np.column_stack([t, 10 * t, 10 * t, yaw]))
    (d / "bad.csv").write_text("time,left.spin,right.spin\n0,0,0\n0.1,x,0\n")
    (d / "short.yaml").write_text(SHORT)
    return d


def test_every_command_has_its_cases():
    assert sorted(CASES) == LEAVES


@pytest.mark.parametrize(("command", "line", "code"), [(c, line, code) for c, cases in CASES.items()
                                                       for line, code in cases], ids=lambda x: str(x)[:60])
def test_the_exit_code_says_answer_no_or_no_answer(command, line, code, files, capsys, monkeypatch):
    from doc_examples import ROOT

    monkeypatch.chdir(ROOT)
    json_flag = [] if command == ("studio",) else ["--json"]
    assert main([*line.format(d=files).split(), *json_flag]) == code
    out, err = capsys.readouterr()
    if code == 2:  # no answer: nothing on stdout, one error line (a JSON error object under --json)
        assert out == "" and len(err.splitlines()) >= 1 and "Traceback" not in err
        last = err.splitlines()[-1]
        assert json.loads(last)["error"] if json_flag else last.startswith("wmrkit: error: ")
    else:  # an answer, yes or no: printed on stdout
        answer = json.loads(out)
        verdict = answer.get("feasible") if isinstance(answer, dict) else None
        if verdict is not None:  # the exit code is the answer's verdict
            assert code == (0 if verdict else 1)


@pytest.mark.parametrize("json_flag", [[], ["--json"]])
def test_running_out_of_memory_is_no_answer_not_a_no(json_flag, capsys, monkeypatch):
    """A MemoryError (a 1e7-sample feasibility beside other work on a machine without swap) exited 1, an uncaught
    exception's status, which says 'the reference is not feasible', after a traceback: now one line and 2."""
    import importlib

    def exhausted(*args, **kwargs):
        raise MemoryError

    module = importlib.import_module("wmrkit.control.feasibility")  # the module: wmrkit.control's name is its function
    monkeypatch.setattr(module, "feasibility", exhausted)  # the CLI imports it from there when it runs
    assert main(["feasibility", "diff-drive", "--reference", "circle", *json_flag]) == 2
    out, err = capsys.readouterr()
    assert out == "" and "Traceback" not in err and len(err.splitlines()) == 1
    message = json.loads(err)["error"] if json_flag else err.removeprefix("wmrkit: error: ")
    assert message.startswith("out of memory") and "'feasibility'" in message
