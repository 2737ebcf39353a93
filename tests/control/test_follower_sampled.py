"""A sampled loop's pure pursuit arrives at the path's end where it passes it: it moves ``v T`` between its decisions
and sees its pose ``delay`` periods late, so its point passes the end between two samples, and a test of one sample
against its aim radius (``AIM_FRACTION`` of its lookahead: 1.35 mm for the forklift) was met only by luck: it
turned round and ended far from the end."""

from __future__ import annotations

import itertools
import re
import warnings

import numpy as np
import pytest

from wmrkit import catalog
from wmrkit.control.points import control_point
from wmrkit.control.references import builtin_reference
from wmrkit.control.track import track
from wmrkit.control.trackers import AIM_FRACTION, ArrivalWarning, default_lookahead, top_speed

#: Starts near the line's end (10, 0): facing back past it, beside it before it, across it, on it, behind it.
STARTS = ((10.05, 0.2, 3.0), (9.5, 0.3, 0.0), (9.8, -0.2, 0.5), (9.0, 0.0, 0.0), (10.3, -0.3, 2.5))


def _closest(a: np.ndarray, b: np.ndarray, p: np.ndarray) -> float:
    """Distance from `p` to the segment `a`-`b`, by brute force (4001 points along it), less its resolution."""
    u = np.linspace(0.0, 1.0, 4001)[:, None]
    return float(np.hypot(*(a + u * (b - a) - p).T).min()) - float(np.hypot(*(b - a))) / 8000


def _aim(robot, ref) -> float:
    """Pure pursuit's aim radius [m] at its default lookahead."""
    return AIM_FRACTION * default_lookahead(control_point(robot), top_speed(ref))


@pytest.mark.parametrize("name", ["forklift", "diff-drive"])
def test_a_sampled_run_stops_where_its_point_passes_the_end(name):
    """Periods 0.05-0.5 s, delays 0-3, five starts: the run ends within one step ``v T`` (``v`` the line's 0.5 m/s,
    which pure pursuit's point never exceeds) of a point where its last step passed within ``(1 + delay) v T`` (at
    least the aim radius) of the end, and from the first step that came within the aim radius of it every sample
    stays that near (it never turns round once it was there). Before: the forklift facing back past the end,
    period 0.1 s, 1 late, passed 3 um from it between two samples 2.4 mm and 1.3 mm from it, turned round and
    ended 1.44 m away."""
    robot, ref = catalog.load(name), builtin_reference("line")
    end, aim = ref.pose[-1, :2], _aim(robot, ref)
    for period, delay, start in itertools.product((0.05, 0.1, 0.2, 0.5), (0, 1, 3), STARTS):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", ArrivalWarning)  # 0.5 s, 3 late: its step ends beyond 0.1 m
            run = track(robot, ref, controller="pure-pursuit", initial_pose=list(start), period=period, delay=delay)
        p, step = run.tracked[:, :2], 0.5 * period
        case = (period, delay, start)
        bound = max(aim, (1 + delay) * step) + step
        assert float(np.hypot(*(p[-1] - end))) <= bound, case
        near = [k for k in range(len(p) - 1) if _closest(p[k], p[k + 1], end) < aim]
        if near:  # once within the aim radius of the end, it stays within the bound (it never turns round)
            assert float(np.hypot(*(p[near[0]:] - end).T).max()) <= bound, case


def test_the_brief_case_ends_at_the_end():
    """``wmrkit track forklift --reference line --controller pure-pursuit --from 10.05 0.2 3 --period 0.1
    --delay 1`` ended 1.44 m from the end with an ArrivalWarning; now at the sample after it passed it."""
    robot, ref = catalog.load("forklift"), builtin_reference("line")
    with warnings.catch_warnings():
        warnings.simplefilter("error", ArrivalWarning)
        run = track(robot, ref, controller="pure-pursuit", initial_pose=[10.05, 0.2, 3.0], period=0.1, delay=1)
    p, end = run.tracked[:, :2], ref.pose[-1, :2]
    assert _closest(p[-2], p[-1], end) < _aim(robot, ref)
    assert float(np.hypot(*(p[-1] - end))) <= float(np.hypot(*(p[-1] - p[-2])))  # within its last step


def test_a_sampled_run_that_ends_beyond_the_tolerance_says_it_was_its_step():
    """At a period of 0.5 s, 3 samples late, the forklift's last step passed the end and ended 0.14 m from it: the
    warning said it "passed the path's end beside it ... the end was behind it"; it now names the step."""
    robot, ref = catalog.load("forklift"), builtin_reference("line")
    with pytest.warns(ArrivalWarning) as caught:
        run = track(robot, ref, controller="pure-pursuit", initial_pose=[9.0, 0.0, 0.0], period=0.5, delay=3)
    p, end = run.tracked[:, :2], ref.pose[-1, :2]
    assert _closest(p[-2], p[-1], end) < 4 * float(np.hypot(*(p[-1] - p[-2])))  # passed within (1 + 3) steps
    message = str(caught[0].message)
    assert "between its last two samples" in message and "3 period(s) late" in message, message
    shown = float(re.search(r"samples, ([0-9.]+) m apart", message).group(1))
    assert shown == pytest.approx(float(np.hypot(*(p[-1] - p[-2]))), rel=2e-3)
