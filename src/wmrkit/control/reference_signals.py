"""The sampled signals of a reference that Table 8.1 judges (for :mod:`.feasibility`): position, tangent angle
``chi`` (8.29) and its rate ``omega_g`` (8.31), curvature ``kappa`` (8.33) and its rate, heading ``theta``, velocity
and acceleration; and, for a densely sampled reference, a sparser copy on which rounding does not dominate the
curvature signals.
"""

from __future__ import annotations

import math

import numpy as np

from ..wheels import wrap_angle
from .references import Reference, reference_from_samples


def signals(reference: Reference, *, speed_tol: float = 1e-6, slow: float = 0.05) -> dict[str, np.ndarray]:
    """The sampled signals of `reference` ``(n,)`` each, and ``at_rest`` ``(n,)`` (speed at most `speed_tol`).

    ``chi`` and its rate, ``kappa`` and its rate are NaN at rest, where they are undefined, and the last three
    where the speed changes by more than `slow` (5 %) of itself in one sample step (``dt |v . a| / |v|^2``), ``chi``
    where by more than itself: a reference starting or stopping, where they come from ``v`` and ``a`` near zero
    and, for a sampled reference, from finite differences of positions that hardly move (a 3 m circle from rest at
    100 Hz had a curvature of 0 to 1.6 1/m over its first 0.15 s, and a tangent pointing backwards at its first
    sample). A constant-speed reference, or
    one with exact derivatives at a steady speed, has none of them undefined but the curvature rate at its first and
    last :data:`_EDGE` samples (one-sided differences)."""
    p, v, a = reference.pose, reference.velocity, reference.acceleration
    speed = np.hypot(v[:, 0], v[:, 1])
    t = reference.t
    at_rest = ~(speed > speed_tol)
    with np.errstate(invalid="ignore", divide="ignore"):
        change = np.gradient(t) * np.abs(v[:, 0] * a[:, 0] + v[:, 1] * a[:, 1])  # of the speed in a step
        # (times the speed), or to a neighbouring sample when larger: a file's finite differences at its last sample,
        # where it comes to rest, give a velocity of 1e-5 m/s across the path, square to its acceleration, whose
        # tangent was a 'tangent-angle jump' of a quarter turn
        change = np.maximum(change, speed * np.maximum(np.abs(np.diff(speed, prepend=speed[:1])),
                                                       np.abs(np.diff(speed, append=speed[-1:]))))
        steady = ~at_rest & (change <= slow * speed**2)
        chi = np.where(~at_rest & (change <= speed**2), np.arctan2(v[:, 1], v[:, 0]), np.nan)
        cross = v[:, 0] * a[:, 1] - v[:, 1] * a[:, 0]
        kappa = np.where(steady, cross / speed**3, np.nan) * _travel_sign(chi)
        chi_rate = np.where(steady, cross / speed**2, np.nan)
        kappa_rate = np.gradient(kappa, t) * (t[1] - t[0])
    kappa_rate[:_EDGE] = kappa_rate[-_EDGE:] = np.nan
    return {"position": p[:, :2], "theta": p[:, 2], "velocity": v[:, :2], "omega": v[:, 2], "acceleration": a[:, :2],
            "omega_rate": a[:, 2],
            "chi": chi, "chi_rate": chi_rate, "kappa": kappa,
            "kappa_rate": kappa_rate, "at_rest": at_rest}


#: Samples at either end where the curvature rate is undefined: a third difference of a file's positions, it takes
#: one-sided differences there (of the velocity, the acceleration and the curvature), off by about half of itself
#: (0.25, 0.31, 0.44 for a clothoid's 0.5 1/(m s)): a 'curvature-rate jump' at the start of a clothoid, and at its
#: end once the rate's slope no longer hid it.
_EDGE = 3


def _travel_sign(chi: np.ndarray) -> np.ndarray:
    """+1, then -1 after each reversal of the direction of travel (the tangent ``atan2`` turning by more than a
    quarter turn between defined samples), so that the curvature is the path's, signed against the vehicle and not
    against its direction of travel: (8.41) divides by the signed speed. A car reversing along a curve keeps its
    steering; ``omega_g / v_a`` of (8.33) flipped sign there."""
    defined = np.flatnonzero(np.isfinite(chi))
    sign = np.ones(len(chi))
    if len(defined) > 1:
        flips = np.abs(wrap_angle(np.diff(chi[defined]))) > math.pi / 2
        sign[defined[1:]] = np.where(np.cumsum(flips) % 2, -1.0, 1.0)
        sign[: defined[0]] = 1.0
        sign = sign[np.maximum.accumulate(np.where(np.isfinite(chi), np.arange(len(chi)), 0))]
    return sign



#: Signals from the normal acceleration (second differences of the positions, for a file), and the curvature rate
#: (a third), judged at a spacing where the rounding of the positions and times does not dominate them.
_CURVATURE = ("chi_rate", "kappa", "kappa_rate")
#: Rounding noise [1/(m s)] allowed in the curvature rate: 1/200 of its jump floor.
_RATE_NOISE = 1e-4


def _curvature_reference(reference: Reference) -> Reference | None:
    """The reference every few samples, re-differentiated, for the curvature signals when it is so dense that
    rounding dominates them; None when it is not.

    The second difference of positions rounded to ``eps L`` (``L`` their size, plus the distance covered in the
    rounding of the times) over a step ``h`` errs by about ``4 eps L / h^2``, its curvature by that over ``v^2`` and
    the curvature rate by that over ``h``: the step is the smallest multiple of the sample spacing that keeps the rate
    within :data:`_RATE_NOISE` at the typical moving speed ``v`` (a 3 m circle at 1 m/s sampled every 3 us had
    curvature-rate 'jumps' of 3 1/(m s) from rounding alone; it is judged every 0.6 ms, 200 samples)."""
    t, p = reference.t, reference.pose
    n = len(t)
    spacing = (t[-1] - t[0]) / (n - 1)
    speed = np.hypot(*reference.velocity[:: max(1, n // 10_000), :2].T)
    moving = speed[speed > 1e-6]
    if not len(moving):
        return None
    v = float(np.median(moving))
    size = float(np.abs(p[:, :2]).max()) + v * float(np.abs(t).max())
    h = (4 * np.finfo(float).eps * size / (v * v * _RATE_NOISE)) ** (1 / 3)
    step = int(min(math.ceil(h / spacing), (n - 1) // 4))
    if step <= 1:
        return None
    # the heading plays no part in these signals (and every few samples a spinning one may turn by more than half a
    # turn, which a file is refused for)
    return reference_from_samples(reference.name, t[::step], np.column_stack([p[::step, :2], np.zeros(len(t[::step]))]))

