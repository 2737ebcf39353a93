"""Collision characterisation of symmetric-arc manoeuvres (thesis §9.3.2.C): (9.32)-(9.36), Algorithms 1 and 2.

Closed forms in the frame of one manoeuvre (digest §3.3): origin at P_f's start, lateral axis toward the side
the manoeuvre displaces to, longitudinal axis along the motion. The second arc turns about the ICR ``(Z, Y)``
(9.31); its angle ``theta`` runs from ``xi`` (start of arc 2) down to 0 (end).
"""

from __future__ import annotations

import math

from .geometry import Vehicle, arcs_displacement, corner_angle, corner_distance


def lateral_reach(vehicle: Vehicle, rho: float, xi: float, corner: int) -> float:
    """Farthest lateral reach of the leading outer corner over the second arc, (9.32)-(9.33) [m].

    Measured from P_f's start toward the displacement side; ``corner`` 1 (reversing) or 2 (forward). (9.33)
    places the maximum at ``theta = delta_i``, which lies on the arc only when ``delta_i <= xi``; otherwise the
    maximum is at the arc's start ``theta = xi`` (erratum: the clamp).
    """
    d = corner_distance(vehicle, rho, corner)
    delta = corner_angle(vehicle, rho, corner)
    theta = min(delta, xi)
    return d * math.cos(theta - delta) + rho * (1 - 2 * math.cos(xi))


def trailing_dip(vehicle: Vehicle, rho: float, xi: float, corner: int) -> float:
    """How far the trailing corner on the far side swings back across its start line in the first arc [m].

    During the first arc the car turns about an ICR on the displacement side; the trailing corner on the other
    side (front when reversing, ``corner`` 2 with ``a1``; rear when going forward, 1 with ``b1``) rotates about it
    at ``d_i`` (9.28) and crosses its start line by ``d_i cos(min(delta_i, xi) - delta_i) - (rho + c1/2)``
    (the mirror image of (9.33)). Used by Algorithm 4 when the car moves away from the obstacles.
    """
    d = corner_distance(vehicle, rho, corner)
    delta = corner_angle(vehicle, rho, corner)
    return d * math.cos(min(delta, xi) - delta) - (rho + vehicle.c1 / 2)


def front_rear_collision(vehicle: Vehicle, rho: float, xi: float, corner: int = 3) -> bool:
    """Algorithm 1 corrected: does the car overshoot its final longitudinal extent (front/rear collision)?

    (9.34) puts the extremum of the inner corner's longitudinal coordinate at ``theta = delta - pi/2``, inside
    the arc iff ``c1/2 - ab tan(xi) < rho < c1/2`` (9.35, ``ab = b1`` for corners 1, 3 and ``a1`` for 2, 4), and
    Algorithm 1 reads "no extremum inside" as "no collision". But for ``rho < c1/2`` the ICR lies within the
    car's width and the inner corner moves against the motion during the whole arc, so with the extremum beyond
    ``xi`` it is farthest at the arc's start: it overshoots all the same (erratum). The car overshoots iff
    ``rho < c1/2``, whatever `corner`, `xi` and `ab`.
    """
    return rho < vehicle.c1 / 2


def front_rear_collision_printed(vehicle: Vehicle, rho: float, xi: float, corner: int) -> bool:
    """Algorithm 1 as printed (kept to show the erratum): no collision if ``rho >= c1/2`` or
    ``rho <= c1/2 - ab tan(xi)``."""
    half = vehicle.c1 / 2
    if rho >= half:
        return False
    ab = vehicle.b1 if corner in (1, 3) else vehicle.a1
    return xi >= math.pi / 2 or not rho <= half - ab * math.tan(xi)


def approach_offset_closed_form(vehicle: Vehicle, rho: float, xi: float) -> float | None:
    """Algorithm 2 in closed form: the ``dx1`` at which corner P2 grazes the front obstacle's corner [m].

    With ``Y = 2 rho sin(xi)``, (9.36) reads ``y_P2 = Y - R sin(theta + delta_2)``, ``R = d_2`` (9.28), so the
    upward zero of ``y_P2`` is ``theta* = asin(Y / R) - delta_2`` and ``x_P2(theta*) = 0`` gives
    ``dx1 = rho (1 - 2 cos xi) + sqrt(R^2 - Y^2)``. None when P2 is past the obstacle's face during the whole
    second arc (``Y >= R`` or ``theta* > xi``): no constraint; ``inf`` when P2 never clears the face
    (``theta* < 0``, i.e. ``Y < a1``: the car does not fit).
    """
    _, Y, Z = arcs_displacement(rho, xi)
    R = corner_distance(vehicle, rho, 2)
    if Y >= R:
        return None
    theta = math.asin(Y / R) - corner_angle(vehicle, rho, 2)
    if theta > xi:
        return None
    if theta < 0:
        return math.inf
    return Z + math.sqrt(R * R - Y * Y)


def approach_offset_sweep(vehicle: Vehicle, rho: float, xi: float, steps: int = 20000) -> float | None:
    """Algorithm 2 as printed: sweep ``theta`` from ``xi`` down to 0 along (9.36), take the upward zero of y_P2.

    Steps 2-3 (the ``aux`` flag) amount to accepting only a zero at which ``y_P2`` increases as ``theta``
    decreases. The zero is refined by linear interpolation between samples. Slower than
    :func:`approach_offset_closed_form`; kept as the thesis's procedure and as its check.
    """
    a, half = vehicle.a1, vehicle.c1 / 2
    Y = 2 * rho * math.sin(xi)

    def y_p2(theta: float) -> float:
        return Y - ((rho + half) * math.sin(theta) + a * math.cos(theta))

    prev_t, prev_y = xi, y_p2(xi)
    for k in range(1, steps + 1):
        t = xi * (1 - k / steps)
        y = y_p2(t)
        if prev_y < 0 <= y:  # upward crossing (theta decreasing)
            t_star = prev_t + (t - prev_t) * (-prev_y) / (y - prev_y)
            return rho * (1 - 2 * math.cos(xi)) + (rho + half) * math.cos(t_star) - a * math.sin(t_star)
        prev_t, prev_y = t, y
    return math.inf if prev_y < 0 else None
