"""The report's sample motions are titled with their ICR and headings: no negative zero ('turn about (0.00, -0.00)
m', 'front -0°' were drawn), each ICR on the steered wheel's axle at the heading shown (checked here by geometry)."""

from __future__ import annotations

import math
import re

from wmrkit import Robot
from wmrkit.analysis import classify
from wmrkit.analysis.figures import motions_figure

TRICYCLE = {"name": "tri", "wheels": [
    {"name": "front", "type": "steerable", "position": [0.9, 0], "heading": "20 deg", "r": 0.15},
    {"name": "rear_left", "type": "fixed", "position": [0, 0.3], "heading": 0, "r": 0.15},
    {"name": "rear_right", "type": "fixed", "position": [0, -0.3], "heading": 0, "r": 0.15}]}


def _titles(robot):
    return [ax.get_title() for ax in motions_figure(robot, classify(robot)).axes]


def test_titles_have_no_negative_zero_and_the_icr_on_the_axle():
    titles = _titles(Robot.from_dict(TRICYCLE))
    assert titles and not any(re.search(r"-0(\.0*)?\b(?![.\d])", t) for t in titles), titles
    turns = 0
    for t in titles:
        m = re.match(r"turn about \((-?[\d.]+), (-?[\d.]+)\) m.*\nheadings: front (-?\d+)°", t, flags=re.S)
        if m:
            turns += 1
            x, y, h = float(m[1]), float(m[2]), math.radians(float(m[3]))
            along = (x - 0.9) * math.cos(h) + y * math.sin(h)  # the ICR's offset along the rolling direction
            assert abs(along) <= 0.01 + math.hypot(x - 0.9, y) * math.radians(0.5), t  # 2 decimals, 1 deg shown
    assert turns >= 2
