"""Pure pursuit's and Stanley's steering written for the turn ``u`` of a robot with coupled steering
(:mod:`.coupled_point`): the arcs its admissible twists ``n(u)`` drive, not a car's about its virtual axle.

At turn ``u`` every body point moves on a circle about the ICR of ``n(u)`` (its velocity ``M_T n``, rigid body), so:

- **pure pursuit**: the goal ``G`` lies on the circle of the tracked point ``T`` when the ICR is on the
  perpendicular bisector of ``TG``, which is linear in ``n``: ``w . n(u) = 0`` with ``w = (2 (T_y - G_y), 2 (G_x -
  T_x), |G|^2 - |T|^2)`` (:func:`turn_through`; the ICR ``(-n_y / omega, n_x / omega)`` on it; a translation along
  ``G - T`` when ``omega = 0``). A car's ICR is on its axle line through ``T``: the root is then its textbook arc,
  curvature ``2 y_g / L_d^2``;
- a curvature ``kappa`` of ``T``'s path (pure pursuit turning round to a goal behind): ``omega / |M_T n| = kappa``
  (:func:`turn_of_curvature`);
- **Stanley** sets the direction of its front point's velocity, ``chi - atan(k e / v)`` (the car's ``psi + delta``),
  which :meth:`.coupled_point.CoupledSteering.solve` turns into ``u`` at that point (:func:`front_steering`).

Each root is sought on the branch of the control point's table (:attr:`CoupledSteering.turns`, around straight
driving): the table's sign changes bracket it, safeguarded Newton's method (``dn/du`` exact) refines it, and the root
nearest straight driving ``u0`` is taken. The twist ``s n(u)`` is admissible by construction (every wheel's lateral
constraint at the coupled headings).
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from .coupled_point import CoupledSteering, _at_point, coupled_steering
from .coupled_solve import NEWTON_STEPS, SAMPLES

__all__ = ["arc_twist", "front_steering", "rotates", "turn_of_curvature", "turn_through", "within"]

#: The turn is refined until Newton's step is below this [rad].
TURN_TOL = 1e-13

Value = Callable[[np.ndarray, np.ndarray], tuple[np.ndarray, np.ndarray]]


def rotates(cs: CoupledSteering) -> bool:
    """Whether some turn of `cs` rotates the robot (a virtual axle); False for a synchro drive, which only
    translates (its heading is then no direction of travel: the followers take the path's)."""
    return bool(np.abs(cs.arrays[3][:, 2]).max() > 1e-9)


def _table(cs: CoupledSteering) -> tuple[np.ndarray, np.ndarray]:
    """The branch's turns, increasing, and ``n`` there (the table's samples); a branch round the whole turn (a synchro
    drive) closes on its first sample, one turn on."""
    turns = np.sort(cs.turns)
    k = np.rint((turns + math.pi) * (SAMPLES / (2 * math.pi))).astype(int) % SAMPLES
    null = cs.arrays[3][k]
    if len(turns) == SAMPLES:
        turns, null = np.append(turns, turns[0] + 2 * math.pi), np.vstack([null, null[:1]])
    return turns, null


def _root(cs: CoupledSteering, value: Value, keep: Callable[[np.ndarray], bool] | None = None) -> float | None:
    """The turn on the branch nearest ``u0`` where `value` ``(n, dn) -> (f, df/du)`` is 0 (and `keep(n)` holds);
    None when there is none."""
    turns, null = _table(cs)
    f = value(null, np.zeros_like(null))[0]
    cross = np.flatnonzero((f[:-1] <= 0) != (f[1:] <= 0))
    roots = [_refine(cs, value, float(turns[i]), float(turns[i + 1]), float(f[i])) for i in cross]
    kept = [u for u in roots if keep is None or keep(cs.twist_direction(u)[0])]
    return min(kept, key=lambda u: abs(u - cs.u0)) if kept else None


def _refine(cs: CoupledSteering, value: Value, lo: float, hi: float, f_lo: float) -> float:
    """Safeguarded Newton's method for the root of `value` in ``[lo, hi]`` (`f_lo` its value at `lo`)."""
    u = 0.5 * (lo + hi)
    for _ in range(NEWTON_STEPS):
        n, dn = cs.twist_direction(u)
        f, slope = (float(x) for x in value(n, dn))
        if f == 0.0:
            return u
        if (f <= 0) == (f_lo <= 0):
            lo = u
        else:
            hi = u
        step = u - f / slope if slope != 0 else math.nan
        new = step if lo < step < hi else 0.5 * (lo + hi)
        if abs(new - u) <= TURN_TOL:
            return new
        u = new
    return u


def turn_through(cs: CoupledSteering, tracked: np.ndarray, goal: np.ndarray) -> float | None:
    """The turn whose ICR puts `goal` ``(2,)`` [m, robot frame] on the circle `tracked` ``(2,)`` drives on, moving
    towards it (forward, along the branch's ``n``): nearest straight driving; None when no turn of the branch does."""
    t, g = np.asarray(tracked, dtype=float), np.asarray(goal, dtype=float)
    w = np.array([2 * (t[1] - g[1]), 2 * (g[0] - t[0]), g @ g - t @ t])
    chord = g - t

    def value(n: np.ndarray, dn: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        return n @ w, dn @ w

    return _root(cs, value, lambda n: float(_at_point(t, n) @ chord) > 0)


def turn_of_curvature(cs: CoupledSteering, tracked: np.ndarray, kappa: float) -> float:
    """The turn at which `tracked` ``(2,)`` [m, robot frame], driven forward, turns at path curvature `kappa` [1/m]
    (``omega / |M_T n|``, left positive): nearest straight driving; the table's nearest where the branch has none
    (the coupling's tightest turn)."""
    t = np.asarray(tracked, dtype=float)

    def value(n: np.ndarray, dn: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        v, dv = _at_point(t, n), _at_point(t, dn)
        speed = np.hypot(v[..., 0], v[..., 1])
        return n[..., 2] - kappa * speed, dn[..., 2] - kappa * np.sum(v * dv, axis=-1) / speed

    u = _root(cs, value)
    if u is None:
        turns, null = _table(cs)
        u = float(turns[np.argmin(np.abs(value(null, np.zeros_like(null))[0]))])
    return u


def arc_twist(cs: CoupledSteering, tracked: np.ndarray, goal: np.ndarray | None, speed: float,
              kappa: float = 0.0) -> np.ndarray:
    """Pure pursuit's admissible body twist ``s n(u)`` ``(3,)``: `tracked` ``(2,)`` [m, robot frame] at `speed` [m/s]
    on the arc through `goal` ``(2,)`` (:func:`turn_through`), or at path curvature `kappa` [1/m] when `goal` is
    None or no arc of the branch reaches it driving forward (:func:`turn_of_curvature`)."""
    u = None if goal is None else turn_through(cs, tracked, goal)
    if u is None:
        u = cs.u0 if kappa == 0.0 else turn_of_curvature(cs, tracked, kappa)
    n = cs.twist_direction(u)[0]
    return speed / float(np.hypot(*_at_point(np.asarray(tracked, dtype=float), n))) * n


def within(cs: CoupledSteering, angle: float) -> float:
    """`angle` [rad, robot frame] of the control point's velocity, held within its branch's arc (driven forward: the
    coupling's steering limit, as a car's steering stops; :meth:`CoupledSteering.solve` would drive an angle beyond
    it backward)."""
    lo, hi = float(cs.angles[0]), float(cs.angles[-1])
    mid = 0.5 * (lo + hi)
    return min(max(mid + math.remainder(angle - mid, 2 * math.pi), lo), hi)


def front_steering(cs: CoupledSteering, front: np.ndarray) -> CoupledSteering:
    """The coupled steering of the same robot controlled at Stanley's front point `front` ``(2,)`` [m, robot
    frame]: its branch turns the direction of that point's velocity (:meth:`CoupledSteering.solve`)."""
    out = coupled_steering(cs.robot, np.asarray(front, dtype=float))
    assert out is not None  # the same robot: its coupling is found again
    return out
