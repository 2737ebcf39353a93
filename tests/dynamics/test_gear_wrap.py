"""Heading set-points of a ``gear`` are judged modulo a turn (``wheels.wrap_angle``, as the servos and the linkage
law take them): a 1:1 pair written at 179 deg and -181 deg is one heading, not a breach of the gear. Before, the
difference was taken as written, 360 deg, and the set-points were refused as fighting the gear."""

from __future__ import annotations

import math

import numpy as np
import pytest
from test_linked_servos import _geared_units

from wmrkit.dynamics.linkages import first_breach, first_ik_breach, gear_breach

DEG = math.pi / 180


@pytest.mark.parametrize(("front", "rear"), [(179.0, -181.0), (-179.0, 181.0), (170.0, 530.0)])
def test_headings_a_whole_turn_apart_keep_a_one_to_one_gear(front, rear):
    model = _geared_units((1.0, 1.0))
    headings = np.array([front, rear]) * DEG
    assert gear_breach(model, headings, {0, 1}) is None
    assert first_breach(model, headings[None], {0, 1}) is None
    assert first_ik_breach(model, headings[None], {0, 1}) is None


def test_a_breach_across_the_turn_is_still_found_at_its_wrapped_size():
    """179 deg against -179 deg is 2 deg off the 1:1 gear (not 358): refused, naming the heading the gear gives."""
    model = _geared_units((1.0, 1.0))
    headings = np.array([179.0, -179.0]) * DEG
    j, ref, want, gear = gear_breach(model, headings, {0, 1})
    assert (j, ref, gear.channel_name) == (1, 0, "gear(front.steer, rear.steer)")
    assert want == pytest.approx(179.0 * DEG)
    assert first_breach(model, np.vstack([[0.0, 0.0], headings]), {0, 1}) == 1
