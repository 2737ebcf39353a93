"""Sweep 7 of the chapter 7-9 doors (session 30): hostile numbers and texts given to `track`, `simulate`, `park`,
`odometry --method wls`, `vision locate` and `follow-line`. Each case printed a traceback, a Python warning line or an
internal message, or printed a problem's text raw; each now answers with one located line (exit 2) or its answer."""

from __future__ import annotations

import json
import warnings

import pytest

from wmrkit import catalog
from wmrkit.cli.main import main
from wmrkit.errors import WmrkitError


def _one_line_error(argv: list[str], capsys) -> str:
    """Run `argv`: exit 2, nothing on stdout, one line on stderr (no Python warning before it); return it."""
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # a RuntimeWarning would print its own lines on stderr
        assert main(argv) == 2
    out, err = capsys.readouterr()
    assert out == ""
    assert len(err.splitlines()) == 1, err
    assert err.startswith("wmrkit: error: ")
    return err


@pytest.mark.parametrize("lookahead", ["1e308", "1e10"])
def test_track_refuses_a_lookahead_beyond_the_coordinates_it_handles(lookahead, capsys):
    # 1e308: OverflowError traceback in pure pursuit's goal test, (1e-3 * aim) ** 2 (exit 1)
    err = _one_line_error(["track", "diff-drive", "--reference", "circle", "--controller", "pure-pursuit",
                           "--lookahead", lookahead], capsys)
    assert "--lookahead: expected a distance in (0, 1e+09] m along the path" in err


def test_pure_pursuit_refuses_the_same_lookahead_from_python():
    from wmrkit.control import builtin_reference
    from wmrkit.control.points import control_point
    from wmrkit.control.trackers import pure_pursuit

    robot = catalog.load("diff-drive")
    with pytest.raises(WmrkitError, match=r"^lookahead: expected a distance in \(0, 1e\+09\] m along the path"):
        pure_pursuit(control_point(robot), builtin_reference("circle", speed=0.5, size=3.0), lookahead=1e308)


def test_a_lookahead_at_the_bound_still_runs(capsys):
    # the largest lookahead accepted: aimed at the path's end, the diff drive follows the circle (its cross-track
    # error is a fraction of a millimetre), as with any lookahead longer than the path
    assert main(["track", "diff-drive", "--reference", "circle", "--controller", "pure-pursuit", "--lookahead",
                 "1e9", "--json"]) == 0
    answer = json.loads(capsys.readouterr().out)
    assert answer["summary"]["max_cross_track"] < 1e-3
