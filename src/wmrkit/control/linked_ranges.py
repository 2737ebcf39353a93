"""Steering ranges of the wheels a ``linkage`` holds (:mod:`wmrkit.dynamics.linkages`): the range of the leader's
heading that keeps every linked wheel within its own ``steer_range``, and the followers' headings set from the
leader's by the linkage's law (:func:`wmrkit.kinematics.linkage_law.law`, the one the dynamics hold).

Clipping each linked wheel to its range on its own breaks the linkage: a car with +-0.5 rad front wheels asked for a
tight left turn had its left wheel clipped at 0.5 and its right one at 0.5 too, 0.1 rad off the Ackermann law, the
servos fighting the linkage (and a right turn the other way round). Keeping the leader in the range where every
follower fits, and setting the followers by the law, holds the ICR on the linkage's geometry.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..kinematics.linkage_law import law, leader_of, linkage_table
from ..robot import Robot
from ..wheels import heading_from_beta, heading_in_range, wrap_angle

TWO_PI = 2.0 * math.pi


@dataclass(frozen=True)
class LinkedRanges:
    """The held linkages of a robot over its steered wheels (``robot.steer_names`` indices): ``table`` the rows of
    :func:`~wmrkit.kinematics.linkage_law.linkage_table` (columns: steered-wheel indices), ``leaders`` and
    ``followers`` their indices, ``ranges (n_steer, 2)`` each wheel's heading range with each leader's narrowed to
    the arc where its followers fit their own ranges, ``delta`` the wheels' steering offsets."""

    table: np.ndarray
    leaders: np.ndarray
    followers: np.ndarray
    ranges: np.ndarray
    delta: np.ndarray

    @classmethod
    def of(cls, robot: Robot, ranges: np.ndarray) -> LinkedRanges | None:
        """The linkages of `robot` the dynamics hold with the wheels' heading `ranges` ``(n_steer, 2)``
        (:func:`.steering.steer_ranges`), or None without one. Every wheel's rest heading is within its range (the
        description's rule) and the rest headings are on the law (:func:`~wmrkit.kinematics.linkage_law.
        linkage_table` refuses others), so the arcs share the leader's rest heading: the part of them kept."""
        names = tuple(f"{n}.steer" for n in robot.steer_names)
        table = linkage_table(robot, names)
        if not len(table):
            return None
        delta = np.array([robot.wheel(n).delta for n in robot.steer_names], dtype=float)
        narrowed = np.array(ranges, dtype=float)
        leaders = np.unique(table[:, 1].astype(int))
        for lead in leaders:
            arc = None if not np.isfinite(ranges[lead]).all() else (float(ranges[lead, 0]), float(ranges[lead, 1]))
            for row in table[table[:, 1] == lead]:
                arc = _meet(arc, _leader_arc(row, ranges[int(row[0])], delta[lead], delta[int(row[0])]),
                            float(robot.heading[lead]))
            if arc is not None:
                narrowed[lead] = arc
        return cls(table, leaders, table[:, 0].astype(int), narrowed, delta)

    def follow(self, heading: np.ndarray) -> np.ndarray:
        """Set, in place, each follower's heading in `heading` ``(n_steer,)`` [rad] from its leader's by the law;
        returns which followers turned half round from the heading they had (their spins to negate)."""
        reverse = np.zeros(len(heading), dtype=bool)
        for row in self.table:
            j, i = int(row[0]), int(row[1])
            f = float(heading_from_beta(law(row, float(heading[i]) - self.delta[i] + 0.5 * math.pi)[0],
                                        self.delta[j]))
            reverse[j] = abs(math.remainder(f - heading[j], TWO_PI)) > 0.5 * math.pi
            heading[j] = f
        return reverse


def _leader_arc(row: np.ndarray, rng: np.ndarray, lead_delta: float, delta: float) -> tuple[float, float] | None:
    """The arc ``(lo, hi)`` of leader headings (counter-clockwise from lo) at which the follower of linkage row
    `row` is within its heading range `rng`; None: any (no range, or a follower on the axle line: it keeps its rest
    angle, within its range, whatever the leader does)."""
    if not np.isfinite(rng).all() or (row[3] == 1.0 and row[5] == 0.0):
        return None
    to_beta = 0.5 * math.pi - delta
    ends = [float(heading_from_beta(leader_of(row, float(h) + to_beta), lead_delta)) for h in rng]
    if row[3] == 1.0 and row[4] * row[5] < 0:  # the law decreases: the range's ends swap
        ends.reverse()
    return ends[0], ends[0] + float(np.mod(ends[1] - ends[0], TWO_PI))


def _meet(a: tuple[float, float] | None, b: tuple[float, float] | None, rest: float) -> tuple[float, float] | None:
    """The common part of two arcs (None: the whole circle) that holds the `rest` heading (both do)."""
    if a is None or b is None:
        return b if a is None else a
    shift = a[0] + float(wrap_angle(b[0] - a[0])) - b[0]
    for k in (-1, 0, 1):
        lo, hi = max(a[0], b[0] + shift + k * TWO_PI), min(a[1], b[1] + shift + k * TWO_PI)
        if lo <= hi and heading_in_range(rest, lo, hi, tol=1e-9):
            return lo, hi
    raise AssertionError(f"steering arcs {a} and {b} do not share the rest heading {rest}")  # pragma: no cover
