"""twist_program judges the wheel-IK steering of every knot against the held linkages and steering gears at once
(linkages.first_ik_breach), naming the first knot that breaks one as before. Before, it looped over the knots in
Python, a linkage_breach and a gear_breach call each (5 s for a 1e5-knot program, about 50 us a knot); the per-knot
judges now run once, for the message."""

from __future__ import annotations

import math

import numpy as np
import pytest
from test_linkages import _synchro
from test_linked_servos import _geared_units

from wmrkit.dynamics import programs
from wmrkit.dynamics.model import DynamicModel
from wmrkit.errors import WmrkitError

K, LATE = 3001, 2400


def _counted(monkeypatch) -> dict[str, int]:
    """Calls of the per-knot judges from twist_program's check, counted."""
    calls = {"linkage_breach": 0, "gear_breach": 0}
    for name in calls:
        judge = getattr(programs, name)

        def counting(*args, _judge=judge, _name=name):
            calls[_name] += 1
            return _judge(*args)
        monkeypatch.setattr(programs, name, counting)
    return calls


def _late(twist) -> tuple[np.ndarray, np.ndarray]:
    """K knots translating diagonally, the knot LATE and those after it `twist`."""
    t = np.arange(K) * 0.01
    twists = np.tile([0.2, 0.2, 0.0], (K, 1))
    twists[LATE:] = twist
    return t, twists


def test_a_chain_turned_at_a_late_knot_is_refused_there_judged_at_once(monkeypatch):
    model = DynamicModel.of(_synchro())
    calls = _counted(monkeypatch)
    with pytest.raises(WmrkitError, match=rf"^twist \(0.3, 0.0, 0.5\) at t = {LATE * 0.01:g} s has no no-slip "
                                          r"motion for 'synchro': its wheels' steering breaks a linkage "
                                          r"\(the steering linkage of wheels 'a', 'b' and 'c' sets b at heading "):
        programs.twist_program(model, *_late((0.3, 0.0, 0.5)))
    assert calls["linkage_breach"] <= 1 and calls["gear_breach"] <= 1
    assert programs.twist_program(model, *_late((0.3, 0.0, 0.5)), allow_slip=True).fight_linkages
    assert not programs.twist_program(model, *_late((0.2, -0.1, 0.0))).fight_linkages  # translations hold it
    assert calls["linkage_breach"] <= 1 and calls["gear_breach"] <= 1


def test_geared_units_crabbing_at_a_late_knot_are_refused_there_judged_at_once(monkeypatch):
    model = _geared_units((1.0, 2.0))
    calls = _counted(monkeypatch)
    t, twists = _late((math.cos(0.1), math.sin(0.1), 0.0))
    twists[:LATE] = (1.0, 0.0, 0.0)
    with pytest.raises(WmrkitError, match=rf"^twist .* at t = {LATE * 0.01:g} s .* breaks the ratios of "
                                          r"the steering gear of wheels 'front' and 'rear' \(it sets rear at heading "
                                          r"0.2 rad with front's at 0.1 rad, the wheel IK 0.1 rad\)"):
        programs.twist_program(model, t, twists)
    assert calls["linkage_breach"] <= 1 and calls["gear_breach"] <= 1
