"""Steering ranges of wheels whose steering the dynamics hold together: a ``linkage`` (:mod:`wmrkit.dynamics.
linkages`, its law :func:`wmrkit.kinematics.linkage_law.law`) or a ``gear`` between steering joints (``h_j - h_j0 =
k_j u`` from the described headings, :func:`wmrkit.dynamics.linkages.gear_breach`). The range of the leader's
heading that keeps every wheel held with it within its own ``steer_range``, and the followers' headings set from the
leader's by the law or the ratios.

Clipping each linked wheel to its range on its own breaks the linkage: a car with +-0.5 rad front wheels on a
corner had its left wheel clipped at -0.5 and its right one at +0.5, 1.2 rad off the Ackermann law, the servos
fighting the linkage. Keeping the leader in the range where every follower fits, and setting the followers by the
law, holds the ICR on the linkage's geometry.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from ..kinematics.linkage_law import law, leader_of, linkage_table
from ..robot import Robot
from ..wheels import heading_from_beta, heading_in_range, wrap_angle

TWO_PI = 2.0 * math.pi
#: Turns of a gear's first wheel tried either way in :meth:`LinkedRanges.settle`.
GEAR_TURNS = 2
#: Refits of a gear's least-squares turn from its current one at most (:func:`_local_fit`; one or two in practice).
LOCAL_REFITS = 16
#: Misses [rad] of a linkage's two ends within this of each other tie (:meth:`LinkedRanges.held_end`): round-off.
TIE = 1e-9


@dataclass(frozen=True)
class _Link:
    """A steered wheel (``robot.steer_names`` index) held by a leader: its heading from the leader's, the leader's
    from its own (the inverse), whether that increases, whether headings are angles (mod 2 pi: a linkage's law) or
    plain numbers (a gear's ratios), and whether the follower is free of the leader (on the axle line)."""

    follower: int
    leader: int
    to_follower: Callable[[float], float]
    to_leader: Callable[[float], float]
    increasing: bool
    angular: bool
    fixed: bool = False
    ratio: float | None = None  # the follower's turn per turn of the leader, when its law is one (gear, parallel)


@dataclass(frozen=True)
class LinkedRanges:
    """The steering couplings of a robot the dynamics hold, over its steered wheels (``robot.steer_names``
    indices): ``links``, ``leaders`` and ``followers`` their indices, ``ranges (n_steer, 2)`` each wheel's heading
    range with each leader's narrowed to the arc where its followers fit their own ranges."""

    links: tuple[_Link, ...]
    leaders: np.ndarray
    followers: np.ndarray
    ranges: np.ndarray
    gears: tuple[tuple[list[int], np.ndarray], ...] = ()  # each gear's steered wheels and ratios

    @classmethod
    def of(cls, robot: Robot, ranges: np.ndarray) -> LinkedRanges | None:
        """The held linkages and steering gears of `robot` with the wheels' heading `ranges` ``(n_steer, 2)``
        (:func:`.steering.steer_ranges`), or None without one. Every wheel's rest heading is within its range (the
        description's rule) and on the law and the ratios (the dynamics refuse others), so the arcs share the
        leader's rest heading: the part of them kept."""
        gears = _gears(robot)
        links = _linkage_links(robot) + [link for idx, k in gears for link in _gear_links(robot, idx, k)]
        if not links:
            return None
        narrowed = np.array(ranges, dtype=float)
        leaders = np.array(sorted({k.leader for k in links}), dtype=int)
        for lead in leaders:
            arc = None if not np.isfinite(ranges[lead]).all() else (float(ranges[lead, 0]), float(ranges[lead, 1]))
            for link in (k for k in links if k.leader == lead):
                arc = _meet(arc, _leader_arc(link, ranges[link.follower]), float(robot.heading[lead]))
            if arc is not None:
                narrowed[lead] = arc
        return cls(tuple(links), leaders, np.array([k.follower for k in links], dtype=int), narrowed, tuple(gears))

    def settle(self, heading: np.ndarray, rest: np.ndarray, current: np.ndarray | None = None,
               hold: bool = False) -> None:
        """Set, in place, each gear's leader in `heading` ``(n_steer,)`` [rad] at a least-squares turn ``u = k . d /
        k . k`` of the headings asked of its wheels, ``d`` their turns from the `rest` headings (the least-squares fit
        :func:`wmrkit.couplings.gear_fill` makes of given rates): the gear's motion nearest to them. A heading is an
        orientation, so the miss ``sum((k u - d) mod 2 pi)^2`` has a fit per whole turn of each wheel: the best one
        (:func:`_best_fit`), or, with the `current` headings (on the gear), the fit reached from the gear's turn there
        (:func:`_local_fit`, continuous along a run) when it misses as little, or always when `hold` (the gear turns
        continuously: it leaves its fit only where that fit ends, a wheel half a turn from the heading asked).

        Before, the best fit was taken at every call: where two fits miss alike (1:2 units whose rear is asked half a
        turn off twice the front: ``u = d0 +- 2 pi / 5``) it jumped 144 deg back and forth, and the continuous loop of
        ``track examples/robots/geared.json --reference circle --size 3`` slid along that tie (steps of 1e-6 s at
        t = 3.76 s) until 'too stiff' after 2 min of computing."""
        for idx, k in self.gears:
            d = np.remainder(heading[idx] - rest[idx] + math.pi, TWO_PI) - math.pi
            best, miss = _best_fit(k, d)
            if current is not None:
                local = _local_fit(k, d, float(current[idx[0]] - rest[idx[0]]) / float(k[0]))
                if hold or _miss(k, local, d) <= miss + 1e-12:
                    best = local
            heading[idx[0]] = rest[idx[0]] + k[0] * best

    def held_end(self, lead: int, asked: np.ndarray, current: float, forward: float, margin: float) -> float:
        """The end of leader `lead`'s kept arc to hold it at, when no root of the heading `asked` of it fits: the one
        at which the axles of its wheels (itself and its followers, set by the law or the ratios) are nearest those
        `asked` ``(n_steer,)`` of them (the sum of their misses, mod pi). A car's inner wheel asked a turn sharper
        than its stop, near 90 deg, is nearly as far from both, but the outer wheel is not: the leader alone chose
        the wrong stop, and the catalog car turned away from its reference for over 9 s at a corner. The end the
        leader is `current` ly held at stays unless the other end is nearer by more than `margin` (for a car the
        ends tie where the twist asked stops and reverses). Held at neither, a tie (within :data:`TIE`, round-off)
        takes the end nearer the root of (8.9) at which the leader rolls forward, the heading `forward`: a car
        asked to turn on the spot drives forward into the turn. Before, the end held stayed only when the leader
        alone chose it too, and a tie took the leader's own choice: the car at its left stop on the corner of
        ``track ackermann --reference corner``, asked to turn on the spot (its inner wheel at 106 deg, whose other
        root -74 deg is nearer the right stop), swapped to the right stop at the first round-off of a reversal and
        back 0.1 s later; sampled (``--period 0.05``) it took the right stop at the corner itself, by the sign of
        a speed of 3e-17 m/s."""
        wheels = [lead, *(k.follower for k in self.links if k.leader == lead)]
        ends = [float(e) for e in self.ranges[lead]]
        miss = []
        for end in ends:
            h = np.array(asked, dtype=float)
            h[lead] = end
            self.follow(h)
            miss.append(sum(abs(math.remainder(float(h[w] - asked[w]), math.pi)) for w in wheels))
        at = [abs(math.remainder(current - end, TWO_PI)) <= 1e-9 for end in ends]
        if any(at) and abs(miss[0] - miss[1]) <= margin:
            return ends[0] if at[0] else ends[1]
        if abs(miss[0] - miss[1]) <= TIE:
            return min(ends, key=lambda end: abs(math.remainder(forward - end, TWO_PI)))
        return ends[0] if miss[0] < miss[1] else ends[1]

    def follow(self, heading: np.ndarray) -> np.ndarray:
        """Set, in place, each follower's heading in `heading` ``(n_steer,)`` [rad] from its leader's; returns which
        followers turned half round from the heading they had (their spins to negate)."""
        reverse = np.zeros(len(heading), dtype=bool)
        for link in self.links:
            f = link.to_follower(float(heading[link.leader]))
            reverse[link.follower] = abs(math.remainder(f - heading[link.follower], TWO_PI)) > 0.5 * math.pi
            heading[link.follower] = f
        return reverse


def _miss(k: np.ndarray, u: float, d: np.ndarray) -> float:
    """The squared misses [rad^2] of a gear's headings at turn `u` from the turns `d` asked (each mod 2 pi)."""
    return float(np.sum((np.remainder(k * u - d + math.pi, TWO_PI) - math.pi) ** 2))


def _best_fit(k: np.ndarray, d: np.ndarray) -> tuple[float, float]:
    """The least-squares turn of ratios `k` to the turns `d` asked whose headings miss them least, and that miss: each
    wheel's turn by the whole turns nearest the gear's at a turn that puts its first wheel at its heading
    (:data:`GEAR_TURNS` of those tried either way; ties: the smallest turn). Before, each turn was wrapped to (-pi,
    pi] on its own: 1:2 units asked on the gear at u = 2 rad (the rear at 4 rad, read -2.28) were fitted at -0.51."""
    best, miss = 0.0, math.inf
    for m in range(-GEAR_TURNS, GEAR_TURNS + 1):
        u = _refit(k, d, (d[0] + TWO_PI * m) / k[0])
        off = _miss(k, u, d)
        if off < miss - 1e-12 or (off <= miss + 1e-12 and abs(u) < abs(best)):
            best, miss = u, min(off, miss)
    return best, miss


def _refit(k: np.ndarray, d: np.ndarray, u: float) -> float:
    """The least-squares turn of ratios `k` to the turns `d` asked, each wheel's turn taken by the whole turns
    nearest the gear's at turn `u` [rad]."""
    return float(k @ (d + TWO_PI * np.round((k * u - d) / TWO_PI))) / float(k @ k)


def _local_fit(k: np.ndarray, d: np.ndarray, u: float) -> float:
    """The least-squares turn of ratios `k` to the turns `d` asked reached from turn `u` [rad]: each wheel's turn by
    the whole turns nearest the gear's at `u`, refitted until they hold (the miss decreases at each refit, so it
    stops, at most :data:`LOCAL_REFITS` times). It moves continuously with `d` while that fit exists: the gear's
    branch along a run."""
    for _ in range(LOCAL_REFITS):
        fitted = _refit(k, d, u)
        if fitted == u:
            break
        u = fitted
    return u


def _linkage_links(robot: Robot) -> list[_Link]:
    """The followers of the held linkages (the rows of :func:`~wmrkit.kinematics.linkage_law.linkage_table`)."""
    table = linkage_table(robot, tuple(f"{n}.steer" for n in robot.steer_names))
    delta = [robot.wheel(n).delta for n in robot.steer_names]
    out = []
    for row in table:
        j, i = int(row[0]), int(row[1])
        to_j = (lambda h, row=row, i=i, j=j:  # noqa: E731  (one per row)
                float(heading_from_beta(law(row, h - delta[i] + 0.5 * math.pi)[0], delta[j])))
        to_i = (lambda h, row=row, i=i, j=j:  # noqa: E731
                float(heading_from_beta(leader_of(row, h - delta[j] + 0.5 * math.pi), delta[i])))
        out.append(_Link(j, i, to_j, to_i, not (row[3] == 1.0 and row[4] * row[5] < 0), True,
                         row[3] == 1.0 and row[5] == 0.0, 1.0 if row[3] == 0.0 else None))
    return out


def _gears(robot: Robot) -> list[tuple[list[int], np.ndarray]]:
    """The ``gear`` couplings turning two or more steered wheels: their indices and ratios."""
    names, out = robot.steer_names, []
    for c in (c for c in robot.couplings if c.kind == "gear"):
        steered = [(names.index(j[:-6]), k) for j, k in zip(c.joints, c.ratios, strict=True)
                   if j.endswith(".steer") and j[:-6] in names]
        if len(steered) > 1:
            out.append(([i for i, _ in steered], np.array([k for _, k in steered], dtype=float)))
    return out


def _gear_links(robot: Robot, idx: list[int], k: np.ndarray) -> list[_Link]:
    """The steered wheels a gear turns with its first one: ``h_j = h_j0 + k_j / k_i (h_i - h_i0)``."""
    rest, i, out = robot.heading, idx[0], []
    for j, r in zip(idx[1:], k[1:] / k[0], strict=True):
        out.append(_Link(j, i, lambda h, j=j, r=r: float(rest[j] + r * (h - rest[i])),
                         lambda h, j=j, r=r: float(rest[i] + (h - rest[j]) / r), r > 0, False, ratio=float(r)))
    return out


def _leader_arc(link: _Link, rng: np.ndarray) -> tuple[float, float] | None:
    """The arc ``(lo, hi)`` of leader headings (counter-clockwise from lo) at which `link`'s follower is within its
    heading range `rng`; None: any (no range, or a follower on the axle line: it keeps its rest angle, within its
    range, whatever the leader does)."""
    if not np.isfinite(rng).all() or link.fixed:
        return None
    ends = [link.to_leader(float(h)) for h in rng]
    if not link.increasing:  # the range's ends swap
        ends.reverse()
    return ends[0], ends[0] + (float(np.mod(ends[1] - ends[0], TWO_PI)) if link.angular else ends[1] - ends[0])


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
