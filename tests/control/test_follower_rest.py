"""The path followers on a reference at rest (a constant pose: its path has zero length, its start is its end).
Before, Stanley's default run from the reference's pose integrated with an absolute tolerance of 0 (relative to
the top speed, 0) and ``wmrkit track diff-drive --reference rest.csv --controller stanley`` ended in a traceback
(``ValueError: attempt to get argmin of an empty sequence``, the integrator's first step at t = NaN), as did pure
pursuit started off it (``--from 0 2 0``); Stanley started off it warned "it passed the path's end beside it". Now a
follower on a path of zero length is done at once, and one that starts away from it says why it stays there."""

from __future__ import annotations

import json
import warnings

import numpy as np
import pytest

from wmrkit import catalog
from wmrkit.cli.main import main
from wmrkit.control.references import reference_from_samples
from wmrkit.control.track import track
from wmrkit.control.trackers import ArrivalWarning

REST = (1.0, 2.0, 0.5)  # x [m], y [m], theta [rad]


def _rest():
    return reference_from_samples("rest", np.array([0.0, 1.0, 2.0]), np.tile(REST, (3, 1)))


@pytest.mark.parametrize("controller", ["stanley", "pure-pursuit"])
@pytest.mark.parametrize("robot_name", ["diff-drive", "mecanum-4", "ackermann"])
def test_a_follower_on_a_reference_at_rest_is_done_at_once(robot_name, controller):
    """From the default start (its tracked point on the reference's pose) the run ends at t = 0, no warning, the
    tracked point on the rest pose (the end of a path of zero length)."""
    with warnings.catch_warnings():
        warnings.simplefilter("error", ArrivalWarning)
        run = track(catalog.load(robot_name), _rest(), controller=controller)
    assert run.t[-1] == 0.0
    np.testing.assert_allclose(run.tracked[-1, :2], REST[:2], rtol=0, atol=1e-12)


@pytest.mark.parametrize("period", [None, 0.1])
@pytest.mark.parametrize("controller", ["stanley", "pure-pursuit"])
def test_a_follower_away_from_a_reference_at_rest_says_why_it_stays(controller, period):
    """From (0, 2, 0), 1 m behind the rest point along x: the run ends at once where it starts, and the warning names
    the cause (the reference is at rest), not a pass beside the end."""
    with pytest.warns(ArrivalWarning, match=r"the reference is at rest \(its path has zero length\)") as caught:
        run = track(catalog.load("diff-drive"), _rest(), controller=controller, initial_pose=[0.0, 2.0, 0.0],
                    period=period)
    assert run.t[-1] == 0.0 and not any("beside" in str(w.message) for w in caught)
    np.testing.assert_array_equal(run.pose[-1], [0.0, 2.0, 0.0])


@pytest.mark.parametrize("start", [[], ["--from", "0", "2", "0"]])
@pytest.mark.parametrize("controller", ["stanley", "pure-pursuit"])
def test_cli_track_on_a_reference_at_rest(tmp_path, capsys, controller, start):
    """The CLI answers at once, exit 0 (a traceback before), warning only when started away from it."""
    path = tmp_path / "rest.csv"
    path.write_text("t,x,y,theta\n" + "".join(f"{t},{REST[0]},{REST[1]},{REST[2]}\n" for t in range(3)))
    assert main(["track", "diff-drive", "--reference", str(path), "--controller", controller, "--json", *start]) == 0
    data = json.loads(capsys.readouterr().out)
    assert len(data["warnings"]) == (1 if start else 0)
    assert all("the reference is at rest" in w for w in data["warnings"])


@pytest.mark.parametrize("start", [[], ["--from", "0", "2", "0"]])
@pytest.mark.parametrize("controller", ["stanley", "pure-pursuit"])
def test_cli_track_on_a_reference_at_rest_for_a_given_duration(tmp_path, capsys, controller, start):
    """With --duration the run is integrated to it: its tolerance was the reference's top speed (0) times a time, the
    integrator's first step at t = NaN and a traceback ('attempt to get argmin of an empty sequence'); now the robot's
    size per second sets it. The robot stays where it is (the path has zero length): its error is its distance."""
    path = tmp_path / "rest.csv"
    path.write_text("t,x,y,theta\n" + "".join(f"{t},{REST[0]},{REST[1]},{REST[2]}\n" for t in range(3)))
    argv = ["track", "diff-drive", "--reference", str(path), "--controller", controller, "--duration", "3", "--json"]
    assert main([*argv, *start]) == 0
    data = json.loads(capsys.readouterr().out)
    pose = np.array(data["pose"])
    assert data["t"][-1] == pytest.approx(3.0) and np.all(pose == pose[0])
