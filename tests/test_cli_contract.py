"""One CLI, one contract: every command (walked from the parser tree, ``tests/cli_options.py``) answers a command line
it cannot parse as every other error: exit code 2 and one line, a JSON object of one shape under ``--json`` (however
the option is spelt), and nothing on stdout."""

from __future__ import annotations

import json

import pytest

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
