"""Every option that takes a number reads it with the house reader (``wmrkit.parse_quantity``, docs/conventions.md
"Units"): a time with its unit ('50ms', '2 s', '1e3 us') where the option is a time, the same run as the bare
number of seconds; a unit of another kind and text that is no number refused with one line naming the option, exit
2 (JSON under --json). Before session 41 the time options of track and simulate refused '2s' ("is a time, expected a
number"), and the options parsed by argparse's ``float`` (odometry --max-gap, follow-line --period, --kf-noise, ...)
printed argparse's usage and "invalid float value"."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from wmrkit.cli.main import main

ROOT = Path(__file__).parents[2]
LOG = str(ROOT / "examples" / "logs" / "mecanum-4.csv")
FOLLOWER = str(ROOT / "docs" / "figures" / "vision" / "follower-camera.yaml")
TRACK = ["track", "diff-drive", "--reference", "circle"]
SIMULATE = ["simulate", "forklift", "--path", "turn"]
ODOMETRY = ["odometry", "mecanum-4", LOG, "--quiet"]
FOLLOW = ["follow-line", "line-follower", "--camera", FOLLOWER]
MONTECARLO = ["batch", "montecarlo", "diff-drive", "--path", "arc", "--workers", "0"]
STRIPES = ["vision", "calibrate", "--rows", "100", "--half-separation", "0.1", "--row-distance", "1"]

#: (command line, option, how many values it takes) of every option whose value is a time.
TIMES = [(TRACK, "--duration", 1), (TRACK, "--period", 1), (SIMULATE, "--duration", 1), (SIMULATE, "--step", 1),
         (ODOMETRY, "--max-gap", 1), (FOLLOW, "--period", 1), (FOLLOW, "--duration", 1),
         (["odometry", "mecanum-4", LOG, "--method", "fk1"], "--kf-period", 1)]
#: ... of those whose value is a frequency [Hz, or 'kHz'] ...
FREQUENCIES = [(MONTECARLO, "--rate", 1)]
#: ... and of those whose value is a bare number (counts, gains, pixels, probabilities, noise coefficients).
NUMBERS = [([*ODOMETRY, "--covariance"], "--crowley", 3), (ODOMETRY, "--cpr", 1), (ODOMETRY, "--gear", 1),
           (["odometry", "mecanum-4", LOG, "--method", "fk1"], "--kf-noise", 3),
           (["batch", "calibrate", "mecanum-4", LOG, "--workers", "0"], "--level", 1), (MONTECARLO, "--noise", 1),
           (MONTECARLO, "--slip", 1), (STRIPES, "--rows", 1), (STRIPES, "--x1", 1),
           (STRIPES, "--x2", 1), (FOLLOW, "--gain", 1), (FOLLOW, "--image-noise", 1), (FOLLOW, "--blur", 1)]


def _run(argv: list[str], capsys) -> tuple[int, str, str]:
    code = main(argv)
    out, err = capsys.readouterr()
    return code, out, err


def _ids(case: tuple) -> str:
    return f"{case[0][0]} {case[1]}"


def _given(option: str, count: int, value: str) -> list[str]:
    """`option` with `value` last among its `count` values (the others 1)."""
    return [option, *["1"] * (count - 1), value]


def _kind(case: tuple) -> str:
    return "a time" if case in TIMES else "a frequency" if case in FREQUENCIES else "a number"


@pytest.mark.parametrize("case", [(*c, k) for c in TIMES for k in ("2 deg", "0.5 m")] +
                         [(*c, k) for c in NUMBERS + FREQUENCIES for k in ("2 s", "2 deg")],
                         ids=lambda c: f"{_ids(c)} {c[3]}")
def test_a_unit_of_another_kind_is_refused_in_one_line_naming_the_option(case, capsys):
    argv, option, count, value = case
    kind = _kind((argv, option, count))
    code, out, err = _run([*argv, *_given(option, count, value)], capsys)
    assert (code, out) == (2, ""), err
    assert err.count("\n") == 1 and err.startswith(f"wmrkit: error: {option}: '{value}' is "), err
    assert err.endswith(f", expected {kind}\n"), err


@pytest.mark.parametrize("case", TIMES + NUMBERS + FREQUENCIES, ids=_ids)
def test_text_that_is_no_number_is_refused_with_the_house_message_under_json_too(case, capsys):
    argv, option, count = case
    kind = _kind(case)
    for text in ("abc", "nan"):
        code, out, err = _run([*argv, *_given(option, count, text), "--json"], capsys)
        assert (code, out, err.count("\n")) == (2, "", 1), err
        error = json.loads(err)
        assert error["error"].startswith(f"{option}: cannot read '{text}' as {kind} (write e.g. "), error
        assert error["field"] == option, error


@pytest.mark.parametrize(("argv", "with_unit", "bare"), [
    ([*TRACK, "--json"], ["--duration", "2s"], ["--duration", "2"]),
    ([*TRACK, "--duration", "1", "--json"], ["--period", "50ms"], ["--period", "0.05"]),
    ([*SIMULATE, "--json"], ["--duration", "20 ms", "--step", "1e3 us"], ["--duration", "0.02", "--step", "0.001"]),
    ([*ODOMETRY, "--json"], ["--max-gap", "500 ms"], ["--max-gap", "0.5"]),
    ([*ODOMETRY, "--json"], ["--max-gap", "1ms"], ["--max-gap", "0.001"]),  # refused: the log's steps are longer
    ([*FOLLOW, "--json"], ["--period", "500ms", "--duration", "1 s"], ["--period", "0.5", "--duration", "1"]),
    ([*MONTECARLO, "-n", "2", "--quiet", "--json"], ["--rate", "0.05 kHz"], ["--rate", "50"]),
], ids=["track --duration", "track --period", "simulate", "odometry --max-gap", "odometry --max-gap refused",
        "follow-line", "montecarlo --rate"])
def test_a_time_with_its_unit_gives_the_run_of_the_bare_seconds(argv, with_unit, bare, capsys):
    bare_run = _run([*argv, *bare], capsys)
    assert bare_run[0] in (0, 2) and (bare_run[1] or bare_run[2]), bare_run  # an answer, or a refusal of the log
    assert _run([*argv, *with_unit], capsys) == bare_run
