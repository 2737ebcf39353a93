"""Shared helpers of the slip tests: the forklift in the thesis's chapter-7 layout."""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from wmrkit import catalog
from wmrkit.robot import Robot

L12, L3, R = 0.45, 1.35, 0.23


def forklift_at_axle() -> Robot:
    """The catalog forklift with its origin moved to the drive-axle mid-point (the chapter-7 origin, (7.60))."""
    fk = catalog.load("forklift")
    wheels = []
    for w in fk.wheels:
        x, y = w.position
        x += 1.0
        wheels.append(replace(w, l=float(np.hypot(x, y)), alpha=float(np.arctan2(y, x))))
    return replace(fk, wheels=tuple(wheels))


def thesis_twist_to_rep(v):
    """(vx, vy, omega) in the thesis frame (x right, y forward) -> REP-103 (x forward, y left)."""
    v = np.asarray(v, dtype=float)
    return np.stack([v[..., 1], -v[..., 0], v[..., 2]], axis=-1)
