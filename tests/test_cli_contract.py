"""One CLI, one contract: every command (walked from the parser tree, ``tests/cli_options.py``) answers a command line
it cannot parse as every other error: exit code 2 and one line, a JSON object of one shape under ``--json`` (however
the option is spelt), and nothing on stdout."""

from __future__ import annotations

import json

import pytest

import test_cli_json_answers as answers
from cli_options import options
from wmrkit.cli.main import main

#: Every command's words (``('batch', 'odometry')``) and whether it offers --json.
COMMANDS = {cmd: any(a.dest == "json" for c, a in options() if c == cmd) for cmd, a in options() if a.dest == "help"}
LEAVES = sorted(cmd for cmd in COMMANDS if cmd and not any(c[:len(cmd)] == cmd and c != cmd for c in COMMANDS))
#: The keys of every error object (docs/limits.md).
ERROR_KEYS = ["error", "file", "wheel", "field", "line"]


def test_the_walk_finds_every_command():
    assert len(LEAVES) >= 20 and ("batch", "montecarlo") in LEAVES and ("vision", "locate") in LEAVES
    assert [cmd for cmd in LEAVES if not COMMANDS[cmd]] == [("studio",)]  # a server: no answer to print


@pytest.mark.parametrize("spelling", ["--json", "--js"])
@pytest.mark.parametrize("command", [cmd for cmd in LEAVES if COMMANDS[cmd]], ids=" ".join)
def test_a_usage_error_under_json_is_one_error_object(command, spelling, capsys):
    """'--js' is --json to argparse (an abbreviation): the answer was JSON but an error was a text line."""
    assert main([*command, spelling, "--no-such-option"]) == 2
    out, err = capsys.readouterr()
    assert out == "" and len(err.splitlines()) == 1, err
    error = json.loads(err)
    assert list(error) == ERROR_KEYS and error["error"].startswith(f"{' '.join(command)}: "), error


@pytest.mark.parametrize("command", LEAVES, ids=" ".join)
def test_a_usage_error_is_the_usage_and_one_error_line(command, capsys):
    """The command's usage: an unknown option was answered with wmrkit's ('usage: wmrkit [-h] [--version] COMMAND
    ...') and a message naming no command."""
    assert main([*command, "--no-such-option"]) == 2
    out, err = capsys.readouterr()
    lines = err.splitlines()
    assert out == "" and lines[0].startswith(f"usage: wmrkit {' '.join(command)}"), err
    assert [ln for ln in lines if ln.startswith("wmrkit: error: ")] == [lines[-1]] and "Traceback" not in err


@pytest.mark.parametrize("argv", [
    ["robots"], ["ik", "diff-drive", "--twist", "1", "0", "0"], ["studio", "--port", "0"],
    ["batch", "montecarlo", "diff-drive", "--path", "square"], ["vision", "locate", "x.png", "--camera", "c.yaml"],
    ["odometry", "diff-drive", "log.csv", "extra.csv"]])
def test_an_unknown_argument_is_named_with_the_command_and_its_usage(argv, capsys):
    """Not wmrkit's usage and a bare 'unrecognized arguments' (the commands' other usage errors name them)."""
    command = [w for w in argv if w in {"batch", "montecarlo", "vision", "locate"}] or argv[:1]
    unknown = "extra.csv" if argv[0] == "odometry" else "--bogus"
    assert main([*argv, "--bogus"] if unknown == "--bogus" else argv) == 2
    lines = capsys.readouterr().err.splitlines()
    assert lines[0].startswith(f"usage: wmrkit {' '.join(command)} ")
    assert lines[-1] == f"wmrkit: error: {' '.join(command)}: unrecognized arguments: {unknown}"


def test_an_abbreviated_json_answers_its_error_in_json(capsys):
    assert main(["show", "no-such-robot", "--js"]) == 2
    assert json.loads(capsys.readouterr().err)["error"].startswith("no robot 'no-such-robot'")


#: A complete command line of each command with a --seed (the walk below finds them all).
SEEDED = {("batch", "montecarlo"): ["diff-drive", "--path", "square"], ("slip-study",): ["forklift"],
          ("follow-line",): ["line-follower", "--camera", "docs/figures/vision/follower-camera.yaml"]}


@pytest.mark.parametrize("value", ["-1", "1e3", "x"])
def test_every_seed_option_takes_one_rule_and_names_itself(value, capsys):
    """--seed -1 was refused after the parsing as 'seed must be an integer >= 0, got -1' (batch montecarlo,
    slip-study) or 'follow-line: seed must ...', naming no option, while '1e3' was argparse's 'invalid int value'."""
    assert sorted(cmd for cmd, a in options() if "--seed" in a.option_strings) == sorted(SEEDED)
    for command, rest in SEEDED.items():
        assert main([*command, *rest, "--seed", value]) == 2
        assert capsys.readouterr().err.splitlines()[-1] == (
            f"wmrkit: error: {' '.join(command)}: argument --seed: expected a whole number >= 0, got '{value}'")


#: The answers about no robot: a tyre model, an image, a camera, and the catalog (a list, one object a robot).
NO_ROBOT = {("tyre",), ("vision", "locate"), ("vision", "calibrate"), ("robots",)}
#: Answers about a robot their command line names otherwise than as ROBOT: the study's robot, a parking problem's
#: (the short slot's vehicle is given by its numbers: no robot).
OTHER_ROBOTS = {("slip-study",): "skid-steer-4", ("park",): None}


@pytest.fixture(scope="module")
def case_files(tmp_path_factory):
    from test_cli_json_answers import write_case_files

    return write_case_files(tmp_path_factory.mktemp("contract"))


def _strict(token: str):
    raise ValueError(f"{token} is not JSON")


@pytest.mark.parametrize("command", sorted(answers.CASES), ids=" ".join)
def test_every_json_answer_names_its_robot_lists_its_warnings_and_is_strict(command, case_files, capsys,
                                                                             monkeypatch):
    """docs/limits.md, JSON answers: an object whose first key is ``robot`` when it is about a robot, with a
    ``warnings`` list of the stderr's warning lines ([] when none), and no NaN/Infinity token. 'show forklift
    --json' had neither key (``name`` first), slip-study no ``robot``, and analyze, calibrate, follow-line,
    slip-study, sweep and vision's answers no ``warnings``. A new command needs its case in
    ``test_cli_json_answers.CASES`` (checked there), so it cannot drift."""
    from doc_examples import ROOT

    monkeypatch.chdir(ROOT)
    line, code = answers.CASES[command]
    argv = line.format(d=case_files).split()
    assert main([*argv, "--json"]) == code
    out, err = capsys.readouterr()
    answer = json.loads(out, parse_constant=_strict)
    if command == ("robots",):
        assert isinstance(answer, list) and answer and all("name" in row for row in answer)
        return
    said = [ln.removeprefix("wmrkit: warning: ") for ln in err.splitlines() if ln.startswith("wmrkit: warning: ")]
    assert isinstance(answer["warnings"], list) and all(isinstance(w, str) for w in answer["warnings"])
    if said:
        assert answer["warnings"][-len(said):] == said  # the command's, after a parking plan's own
    elif command != ("park",):
        assert answer["warnings"] == []
    if command in NO_ROBOT:
        assert "robot" not in answer
    else:
        robot = OTHER_ROBOTS.get(command, argv[len(command)])
        assert next(iter(answer)) == "robot" and answer["robot"] == robot


def test_show_json_still_names_the_robot_and_loads_back(tmp_path, capsys):
    """``show``'s answer is the description (``name`` kept) and the contract's keys: a copy with them reads back;
    a copy whose ``name`` was edited and not its ``robot`` is refused naming the field."""
    from wmrkit import catalog
    from wmrkit.robot import Robot

    assert main(["show", "forklift", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["robot"] == data["name"] == "forklift" and data["warnings"] == []
    (tmp_path / "copy.json").write_text(json.dumps(data))
    assert Robot.from_file(tmp_path / "copy.json") == catalog.load("forklift")
    (tmp_path / "copy.json").write_text(json.dumps({**data, "name": "truck"}))
    assert main(["show", str(tmp_path / "copy.json")]) == 2
    line = capsys.readouterr().err.strip()
    assert "robot: the robot's name" in line and "'truck'" in line


def test_a_park_problem_of_a_catalog_robot_names_it(tmp_path, capsys):
    (tmp_path / "p.yaml").write_text("vehicle: {robot: ackermann, a1: 3.6 m, b1: 1.0 m, c1: 1.8 m, phi_max: 34 deg}\n"
                                     "space: {H: 7 m, J: 3 m, MS: 0.3 m, dx2: 1.5 m, final_gap: 0.1 m}\n")
    assert main(["park", str(tmp_path / "p.yaml"), "--json"]) in (0, 1)
    answer = json.loads(capsys.readouterr().out)
    assert next(iter(answer)) == "robot" and answer["robot"] == "ackermann" and isinstance(answer["warnings"], list)
