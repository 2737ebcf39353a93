"""Steering in the loop (§8.4): 4- and 2-quadrant angles within each wheel's range, swerve motion modes, skew-free
discretisation of a twist over a period.

Headings throughout (the rolling direction, 0 = straight ahead along +x, counter-clockwise positive). For a wheel
whose steering axis moves with velocity ``u`` the lateral constraint (8.9) has two roots, ``atan2(u)`` with a
positive spin and that plus pi with a negative one:

- ``"4-quadrant"``: the thesis's choice, the spin keeps its sign (ours >= 0: always rolling forward); the wheel turns
  half round when the robot reverses (the pi jump of §8.6.2).
- ``"2-quadrant"``: heading in (-90, 90] deg, spin times ``sign`` (8.51), the usual +-90 deg steering range.
- ``"closest"``: the root closest to the current heading (WPILib ``optimize``; :func:`wheel_commands`' policy).

A wheel's ``steer_range`` (description field, headings) restricts the roots; when neither fits, the heading is
clamped to the range and flagged: the vehicle must stop and re-orient the wheel (Table 8.1 remedies).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from .._shapes import as_vectors, readonly
from ..limits import MAX_QUERY_RATE
from ..robot import Robot, check_robot
from ..wheels import heading_in_range, wrap_angle
from .linked_ranges import LinkedRanges
from .points import ControlError

__all__ = ["POLICIES", "SteeringChoice", "ackermann_twist", "check_policy", "choose_steering", "crab_twist",
           "discretize_twist", "icr_twist", "steer_ranges"]

POLICIES = ("closest", "4-quadrant", "2-quadrant")


def _finite(named: dict[str, ArrayLike]) -> list[np.ndarray]:
    """The named arrays broadcast together, as floats; a :class:`ControlError` naming the argument for a NaN or an
    infinity, or naming both for shapes that do not broadcast (instead of numpy's message, or NaN results)."""
    arrays = {name: np.asarray(value, dtype=float) for name, value in named.items()}
    for name, a in arrays.items():
        if not np.isfinite(a).all():
            raise ControlError(f"{name}: expected finite numbers, got {a.ravel()[~np.isfinite(a.ravel())][0]}")
    try:
        return list(np.broadcast_arrays(*arrays.values()))
    except ValueError:
        shapes = ", ".join(f"{name} {a.shape}" for name, a in arrays.items())
        raise ControlError(f"shapes that do not broadcast together: {shapes}") from None


def steer_ranges(robot: Robot) -> np.ndarray:
    """``(n_steer, 2)`` heading ranges [rad] of the steering wheels; ``(-inf, inf)`` where none is described."""
    check_robot(robot)
    out = np.tile([-np.inf, np.inf], (len(robot.steer_names), 1))
    for k, name in enumerate(robot.steer_names):
        rng = getattr(robot.wheel(name), "steer_range", None)
        if rng is not None:
            out[k] = rng
    return out


def _nearest_end(h: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The end of the range ``[lo, hi]`` nearest to heading `h`, and how far it is [rad]."""
    to_lo, to_hi = np.abs(wrap_angle(h - lo)), np.abs(wrap_angle(h - hi))
    return np.where(to_lo < to_hi, lo, hi), np.minimum(to_lo, to_hi)


@dataclass(frozen=True, eq=False)
class SteeringChoice:
    """Chosen headings ``(..., n_steer)`` [rad], their spins ``(..., n_steer)`` [rad/s], ``in_range`` flags, and
    ``reversed``: the root taken is the other one, ``heading + pi`` (the spin negated; a double wheel's sub-wheels
    also change sides, :func:`reverse_spins`)."""

    heading: np.ndarray
    spin: np.ndarray
    in_range: np.ndarray
    reversed: np.ndarray


def check_policy(policy: str) -> None:
    """Refuse a steering policy that is not one of :data:`POLICIES`."""
    if policy not in POLICIES:
        raise ControlError(f"unknown steering policy '{policy}' (policies: {', '.join(POLICIES)})")


def choose_steering(heading: ArrayLike, spin: ArrayLike, current: ArrayLike, *, policy: str = "closest",
                    ranges: ArrayLike | None = None, hold_margin: float = 0.0) -> SteeringChoice:
    """Pick, per wheel, the root of (8.9) allowed by `policy` and the heading range.

    `heading`, `spin`: one root and its spin ``(..., n)``; the other root is ``heading + pi`` with ``-spin``.
    `current` ``(..., n)``: current headings (for ``"closest"`` and for ties). `ranges` ``(n, 2)`` heading ranges.
    When neither root fits, the wheel is held at the end of its range nearest to either root, with that root's spin
    (a car asked for 70 deg left by a +-40 deg rack turns 40 deg left, not 40 deg right with its wheel reversed).
    `hold_margin` [rad]: a wheel held at an end (`current` there) stays there unless the other end is nearer by more
    than this (hysteresis: a heading asked back and forth across the tie, 90 deg for a +-40 deg rack, does not swap
    ends at each crossing).
    """
    check_policy(policy)
    if isinstance(hold_margin, bool) or not isinstance(hold_margin, int | float) or not hold_margin >= 0:
        raise ControlError(f"hold_margin: expected an angle >= 0 [rad] (inf: never change ends), got {hold_margin!r}")
    h0, s0, cur = _finite({"heading": heading, "spin": spin, "current": current})
    r = None if ranges is None else np.asarray(ranges, dtype=float)
    h, s, fits, reverse = checked_steering(h0, s0, cur, policy, r, hold_margin)
    return SteeringChoice(readonly(h), readonly(s), readonly(fits), readonly(reverse))


def checked_steering(h0: np.ndarray, s0: np.ndarray, cur: np.ndarray, policy: str, r: np.ndarray | None,
                     hold_margin: float) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """:func:`choose_steering` of arguments it has checked (float arrays of one shape, a policy, a margin), as
    ``(heading, spin, in_range, reversed)``: for a loop calling it thousands of times (the continuous loop)."""
    h0 = wrap_angle(h0)
    h1, s1 = wrap_angle(h0 + math.pi), -s0
    if policy == "4-quadrant":
        pref0 = s0 >= 0
    elif policy == "2-quadrant":
        pref0 = (h0 > -math.pi / 2 + 1e-12) & (h0 <= math.pi / 2 + 1e-12)
    else:  # a tie (both 90 deg away): the root rolling forward, as the IK and WPILib's optimize
        d0, d1 = np.abs(wrap_angle(h0 - cur)), np.abs(wrap_angle(h1 - cur))
        pref0 = (d0 < d1 - 1e-12) | ((np.abs(d0 - d1) <= 1e-12) & (s0 >= 0))
    if r is None:
        ok0 = ok1 = np.ones(h0.shape, dtype=bool)
        lo = hi = None
    else:
        lo, hi = r[..., 0], r[..., 1]
        ok0, ok1 = heading_in_range(h0, lo, hi), heading_in_range(h1, lo, hi)
    take0 = np.where(ok0 & ok1, pref0, ok0)
    h = np.where(take0, h0, h1)
    fits = ok0 | ok1
    if lo is not None and not np.all(fits):  # neither root fits: the end of the range nearest to either root
        with np.errstate(invalid="ignore"):
            end0, miss0 = _nearest_end(h0, lo, hi)
            end1, miss1 = _nearest_end(h1, lo, hi)
            near0 = (miss0 < miss1) | ((miss0 == miss1) & pref0)
            if hold_margin > 0:  # within the margin of a tie, the end the wheel is held at
                at0 = np.abs(wrap_angle(cur - end0)) <= 1e-9
                at1 = np.abs(wrap_angle(cur - end1)) <= 1e-9
                near0 = np.where((np.abs(miss0 - miss1) <= hold_margin) & (at0 != at1), at0, near0)
        h = np.where(fits, h, np.where(near0, end0, end1))
        take0 = np.where(fits, take0, near0)
    s = np.where(take0, s0, s1)
    return np.asarray(h), np.asarray(s), np.asarray(fits), ~np.asarray(take0)


def spin_columns(robot: Robot) -> np.ndarray:
    """``(n_steer, 2)`` columns in ``robot.rate_names`` of each steering wheel's spins: ``(spin, -1)`` for a
    steerable wheel, ``(spin1, spin2)`` for a double wheel, ``(-1, -1)`` for the passive ones (castors)."""
    out = np.full((len(robot.steer_names), 2), -1, dtype=int)
    for k, name in enumerate(robot.steer_names):
        kind = robot.wheel(name).type
        joints = ("spin",) if kind == "steerable" else ("spin1", "spin2") if kind == "double" else ()
        for i, joint in enumerate(joints):
            out[k, i] = robot.rate_names.index(f"{name}.{joint}")
    return out


def unit_spin(rates: np.ndarray, columns: np.ndarray) -> np.ndarray:
    """The spin of each steered unit of `columns` (:func:`spin_columns`): its wheel's, the mean of a double's two."""
    one = rates[..., columns[:, 0]]
    return np.where(columns[:, 1] >= 0, 0.5 * (one + rates[..., columns[:, 1]]), one)


def reverse_spins(rates: np.ndarray, columns: np.ndarray, reverse: np.ndarray) -> None:
    """Joint `rates` (``robot.rate_names`` order) in place for the other root of each unit of `columns` where
    `reverse`: a wheel turned half round rolls backwards (spin negated), and a double wheel's sub-wheels change
    sides (``spin1, spin2 -> -spin2, -spin1``, from the rolling rows (3.24))."""
    for c1, c2 in columns[np.asarray(reverse, dtype=bool)]:
        if c2 < 0:
            rates[..., c1] = -rates[..., c1]
        else:
            rates[..., [c1, c2]] = -rates[..., [c2, c1]]


def check_steering_driven(robot: Robot) -> None:
    """The loops through the dynamics steer a wheel through its steering servo: a steerable or double wheel whose
    steering is not actuated would not follow the commands (nothing turns it, no stop holds it in its range)."""
    for name in robot.steer_names:
        w = robot.wheel(name)
        if w.type in ("steerable", "double") and "steer" not in w.actuated:
            raise ControlError(f"wheel '{name}': its steering is not actuated, so through the dynamics nothing would "
                               f"steer it ({w.type} wheel, actuated: {', '.join(w.actuated) or 'none'}); add 'steer' "
                               "to its 'actuated', or track without the dynamics (ideal joints)")


def range_keeper(robot: Robot, policy: str = "closest") -> Callable[..., np.ndarray]:
    """``(headings, rates, current, hold_margin=0) -> in_range`` for the loops (the kinematic plant's commands,
    :mod:`._loop_plant`, and those through the dynamics): moves, in place, each steered wheel's heading to the root
    of (8.9) that `policy` picks from the `current` headings, within its ``steer_range`` (its spins for that root,
    :func:`reverse_spins`), or to the end of the range nearest to either root when neither fits (`hold_margin`:
    :func:`choose_steering`'s, whose checks are the caller's: the IK's finite headings); returns which fitted. With
    ``"closest"`` and no range it does nothing to a wheel on its own: the IK has picked the root closest to
    `current` already.

    The wheels of a ``linkage``, or of a ``gear`` between steering joints, are not kept one by
    one (that breaks it): its leader is kept within the arc where every wheel held with it fits its range, and the
    followers are set from it by the linkage's law or the gear's ratios (:class:`.linked_ranges.LinkedRanges`; a
    gear's leader first at the gear's least-squares turn to the headings asked: the one reached from the
    `current` turn, always with a `hold_margin`, else when no other misses less),
    their spins negated where they turn half round; when the leader is held at an end of that arc, none of those
    wheels fitted, and the end is the one nearer the headings asked of them all
    (:meth:`.linked_ranges.LinkedRanges.held_end`)."""
    check_policy(policy)
    ranges, columns = steer_ranges(robot), spin_columns(robot)
    links = LinkedRanges.of(robot, ranges)
    chosen = (np.isfinite(ranges).any(axis=1) | (policy != "closest")) & (columns[:, 0] >= 0)
    if links is not None:
        ranges = links.ranges
        chosen[links.leaders] |= np.isfinite(ranges[links.leaders]).any(axis=1) & (columns[links.leaders, 0] >= 0)
        chosen[links.followers] = False
    steered, rest = columns[chosen], robot.heading

    def keep(heading: np.ndarray, rates: np.ndarray, current: np.ndarray, hold_margin: float = 0.0) -> np.ndarray:
        fits, reversed_ = np.ones(len(heading), dtype=bool), np.zeros(len(heading), dtype=bool)
        if links is not None:
            links.settle(heading, rest, current, hold_margin > 0)
        asked, spin = heading.copy(), unit_spin(rates, columns)  # the IK's roots and spins
        if chosen.any():  # the IK's headings and spins (finite), the policy checked above
            heading[chosen], _, fits[chosen], reversed_[chosen] = checked_steering(
                heading[chosen], unit_spin(rates, steered), np.asarray(current, dtype=float)[chosen], policy,
                ranges[chosen], hold_margin)
            reverse_spins(rates, steered, reversed_[chosen])
        if links is not None:
            for lead in links.leaders[~fits[links.leaders] & chosen[links.leaders]].tolist():
                forward = float(asked[lead]) + (0.0 if spin[lead] >= 0 else math.pi)  # the root rolling forward
                heading[lead] = links.held_end(lead, asked, float(current[lead]), forward, hold_margin)
                if (abs(float(wrap_angle(asked[lead] - heading[lead]))) > 0.5 * math.pi) != reversed_[lead]:
                    reverse_spins(rates, columns[[lead]], np.ones(1, dtype=bool))  # the other root's spin
            reverse_spins(rates, columns, links.follow(heading) & (columns[:, 0] >= 0))
            for link in links.links:
                fits[link.follower] = fits[link.leader]
        return fits

    return keep


# ---- swerve motion modes ------------------------------------------------------------------------------------
def crab_twist(speed: ArrayLike, direction: ArrayLike) -> np.ndarray:
    """Crab (translation only): every wheel at heading `direction` [rad]. ``(...), (...) -> (..., 3)``."""
    v, d = _finite({"speed": speed, "direction": direction})
    return np.stack([v * np.cos(d), v * np.sin(d), np.zeros_like(v)], axis=-1)


def icr_twist(icr_xy: ArrayLike, omega: ArrayLike) -> np.ndarray:
    """Rotation at rate `omega` [rad/s] about an arbitrary ICR ``(x, y)`` [m, robot frame] (§5.4, ros2_controllers
    #2000): the origin's velocity is ``omega z x (0 - c) = omega (c_y, -c_x)``. ``(..., 2), (...) -> (..., 3)``."""
    c = as_vectors(icr_xy, 2, "icr_xy")
    cx, cy, w = _finite({"icr_xy[..., 0]": c[..., 0], "icr_xy[..., 1]": c[..., 1], "omega": omega})
    return np.stack([w * cy, -w * cx, w], axis=-1)


def ackermann_twist(speed: ArrayLike, curvature: ArrayLike, axle_x: float = 0.0) -> np.ndarray:
    """Ackermann mode: ICR on the line ``x = axle_x`` (a virtual rear axle), `speed` [m/s] of the point
    ``(axle_x, 0)``, `curvature` [1/m]; finite for curvature 0. ``(...), (...) -> (..., 3)``."""
    v, k, x = _finite({"speed": speed, "curvature": curvature, "axle_x": axle_x})
    return np.stack([v, -v * k * x, v * k], axis=-1)


def discretize_twist(twist_robot: ArrayLike, dt: float) -> np.ndarray:
    """Second-order (skew-free) discretisation: the constant body twist that, held for `dt`, ends at the pose
    ``(vx dt, vy dt, omega dt)`` of the body frame: the SE(2) logarithm of that pose over `dt` (WPILib
    ``ChassisSpeeds.discretize``, #5349/#7332). Inverse of :func:`wmrkit.odometry.integrate_exact`'s chord form:
    ``(vx, vy)' = Rot(-h) (vx, vy) / sinc(h)`` with ``h = omega dt / 2``. ``(..., 3) -> (..., 3)``.

    Refused where the result would exceed ``limits.MAX_QUERY_RATE``: a period turning (nearly) a whole number of
    turns ends where it started, so no constant twist with that omega moves it along the step (``sinc(h) = 0``;
    ``omega dt = 2 pi`` gave ``vx = -2.6e16`` m/s)."""
    from ..odometry.integrators import sinc

    t = as_vectors(twist_robot, 3, "twist_robot")
    if not (0 < dt < math.inf) or not np.isfinite(t).all():  # NaN included
        raise ControlError(f"discretize_twist: expected a finite twist and a period dt > 0 s, got dt = {dt}")
    h = 0.5 * t[..., 2] * dt
    c, s, k = np.cos(h), np.sin(h), 1.0 / sinc(h)
    vx = k * (c * t[..., 0] + s * t[..., 1])
    vy = k * (-s * t[..., 0] + c * t[..., 1])
    out = np.stack([vx, vy, t[..., 2]], axis=-1)
    if not (np.abs(out) <= MAX_QUERY_RATE).all():  # inf and NaN included
        worst = np.unravel_index(np.argmin(np.abs(sinc(h))), h.shape)
        raise ControlError(f"discretize_twist: omega dt = {2 * float(h[worst]):.6g} rad is (nearly) a whole number of "
                           f"turns per period, where no constant twist reaches the step (the discretised twist would "
                           f"exceed {MAX_QUERY_RATE:g} m/s); give a shorter period")
    return out
