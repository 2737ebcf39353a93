"""One control tick in a single call (issue item 4): position law (8.2)/(8.53), admissible twist, per-wheel IK.

For a controller that runs once per sample: scalars in, caller-owned arrays out, nothing allocated per call (but
two small work arrays per Newton step inside the compiled call of a robot with coupled steering). The law and the
point-velocity map are :func:`scalar_law` (a few scalar operations, also the dynamic loop's controller; for a robot
whose steering couplings leave one steering degree of freedom, the Newton solve of :mod:`.coupled_solve`, compiled
once by :mod:`._coupled_kernel`), compiled here together with the robot's per-wheel IK kernel of
:func:`wmrkit.kinematics.realtime.realtime`. The numbers are those of :func:`.loop.law_controller` followed by
:func:`~wmrkit.kinematics.wheel_ik.wheel_commands` (tested).
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from ..limits import MAX_COORDINATE
from ..robot import Robot
from . import coupled_solve
from .laws import PositionLaw
from .points import ControlError, ControlPoint, control_point

__all__ = ["ControlTick", "control_tick", "scalar_law"]

TWO_PI = 2.0 * math.pi
#: Most bytes of compiled ticks cached for this file (one per robot and law, about 0.2 MB each, as
#: :data:`wmrkit.kinematics.realtime.MAX_CACHE_BYTES`); beyond, the cache is dropped before the next tick compiles.
MAX_CACHE_BYTES = 32 << 20


@dataclass(frozen=True, eq=False)
class ControlTick:
    """A compiled control tick for one robot and law (build with :func:`control_tick`; eq=False: array fields).

    ``tick(x, y, theta, x_ref, y_ref, theta_ref, vx_ref, vy_ref, omega_ref, heading, twist_out, rates_out,
    heading_out) -> bool``: pose and reference (world frame, the reference's velocity in G), current headings
    ``(n_steer,)``; writes the body twist ``(3,)``, the joint rates ``(n_rates,)`` (``robot.rate_names``) and the new
    headings ``(n_steer,)``; returns whether the twist is feasible. Reduced robots ignore ``theta_ref`` and
    ``omega_ref`` (their heading is the zero dynamics). One compiled call: the law, the point-velocity map and the
    robot's per-wheel IK kernel.
    """

    robot: Robot
    reduced: bool
    point: tuple[float, float]
    gain_matrix: tuple[float, ...]  # row-major (3, 2) of ControlPoint.gain, reduced only (not coupled: none)
    a: tuple[float, float, float]
    gate: float
    tick: Any


def control_tick(robot: Robot, law: PositionLaw | None = None, point: ArrayLike | None = None, *,
                 reduced: bool | None = None) -> ControlTick:
    """Compile the single-call tick of `robot` for `law` (``"p"``, gated or not; default P with a = 1 s^-1) at the
    control point ``control_point(robot, point, reduced=reduced)`` (a robot whose steering couplings leave one
    steering degree of freedom: its twist solved by Newton's method, :mod:`.coupled_solve`, unless `reduced` is
    False)."""
    from ..kinematics.realtime import realtime

    law = law or PositionLaw.uniform("p", 1.0)
    if law.kind != "p":
        raise ControlError(f"control_tick: only the P + feedforward law (8.2)/(8.53), got '{law.kind}'")
    cp = control_point(robot, point, reduced=reduced)
    gain = tuple(float(v) for v in np.asarray(cp.gain).ravel()) if cp.gain is not None else ()
    kernel = _tick_kernel(realtime(robot).ik, scalar_law(cp, law, compiled=True))
    return ControlTick(robot, cp.reduced, (float(cp.point[0]), float(cp.point[1])), gain, law.a,
                       math.inf if law.gate is None else float(law.gate), kernel)


def scalar_law(cp: ControlPoint, law: PositionLaw, *, compiled: bool = False):
    """The laws (8.1)-(8.3) with the gate (8.53) at control point `cp`, then the admissible twist (3.15), on scalars:
    ``law(x, y, theta, x_ref, y_ref, theta_ref, vx_ref, vy_ref, omega_ref, i0, i1, i2) -> (vx, vy, omega, e0, e1,
    e2)`` (pose, reference and its velocity in G, the error's integral; the body twist and the error). Reduced
    control points ignore ``theta_ref`` and ``omega_ref``. Plain Python that numba also compiles (the tick: `compiled`,
    a coupled robot's twist then solved by the compiled :mod:`._coupled_kernel`)."""
    px, py = float(cp.point[0]), float(cp.point[1])
    reduced, integral, feedforward = bool(cp.reduced), law.kind == "pi", law.kind != "point"
    (a0, a1, a2), (b0, b1, b2) = law.a, law.b
    gate = math.inf if law.gate is None else float(law.gate)
    coupled = cp.coupled  # its law gives the point's velocity in R, then the coupled twist (.coupled_solve)
    gains = np.eye(3, 2) if coupled is not None else cp.gain if reduced else np.zeros((3, 2))
    g00, g01, g10, g11, g20, g21 = (float(v) for v in np.asarray(gains, dtype=float).ravel())

    def law_twist(x, y, theta, x_ref, y_ref, theta_ref, vx_ref, vy_ref, omega_ref, i0, i1, i2):
        c, s = math.cos(theta), math.sin(theta)
        e0 = x_ref - (x + c * px - s * py)  # point_pose
        e1 = y_ref - (y + s * px + c * py)
        if reduced:  # the reference is followed by the point; its heading is free (zero dynamics)
            theta_ref, omega_ref = theta, 0.0
        e2 = theta_ref - theta
        e2 -= TWO_PI * math.floor(e2 / TWO_PI + 0.5)  # wheels.wrap_angle: (-pi, pi]
        e2 = e2 + TWO_PI if e2 <= -math.pi else (e2 - TWO_PI if e2 > math.pi else e2)
        u0, u1, u2 = a0 * e0, a1 * e1, a2 * e2  # law_velocity
        if feedforward:
            ff = 0.0 if math.hypot(e0, e1) > gate else 1.0
            u0, u1, u2 = u0 + ff * vx_ref, u1 + ff * vy_ref, u2 + ff * omega_ref
        if integral:
            u0, u1, u2 = u0 + b0 * i0, u1 + b1 * i1, u2 + b2 * i2
        r0, r1 = c * u0 + s * u1, -s * u0 + c * u1  # twist_for_velocity: the point's velocity in R
        if reduced:
            return g00 * r0 + g01 * r1, g10 * r0 + g11 * r1, g20 * r0 + g21 * r1, e0, e1, e2
        return r0, r1, u2, e0, e1, e2

    if coupled is None:
        return law_twist
    cx, cy, sign, u0 = coupled._scalars
    lines, pivots, ratios, null, turns, angles = coupled.arrays
    if compiled:  # the pieces numba calls from the tick: compiled as they are
        import numba

        from ._coupled_kernel import twist as point_twist
        law_twist = numba.njit(inline="always")(law_twist)
    else:
        point_twist = coupled_solve.twist

    def coupled_twist(x, y, theta, x_ref, y_ref, theta_ref, vx_ref, vy_ref, omega_ref, i0, i1, i2):
        r0, r1, _, e0, e1, e2 = law_twist(x, y, theta, x_ref, y_ref, theta_ref, vx_ref, vy_ref, omega_ref, i0, i1, i2)
        vx, vy, w = point_twist(r0, r1, cx, cy, sign, u0, lines, pivots, ratios, null, turns, angles)
        return vx, vy, w, e0, e1, e2

    return coupled_twist


def _tick_kernel(ik, law_twist):
    """The tick: `law_twist` (:func:`scalar_law`) compiled around the robot's IK kernel `ik`, cached on disk (keyed by
    the IK's and the law's constants: one kernel per robot and law, :data:`MAX_CACHE_BYTES`)."""
    import numba

    from .._jit import compile_cached, float64_vector

    _drop_stale_ticks()
    law = numba.njit(inline="always")(law_twist)
    shapes = "tick: twist_out must be a float64 array of shape (3,)"
    big = MAX_COORDINATE
    bad = f"tick: the pose, the reference and its velocity must be finite, each at most {big:g} in size"

    def tick(x, y, theta, x_ref, y_ref, theta_ref, vx_ref, vy_ref, omega_ref, heading, twist_out, rates_out,
             heading_out):
        if not (float64_vector(twist_out) and twist_out.shape[0] == 3):
            raise ValueError(shapes)
        if not (abs(x) <= big and abs(y) <= big and abs(theta) <= big and abs(x_ref) <= big and abs(y_ref) <= big
                and abs(theta_ref) <= big and abs(vx_ref) <= big and abs(vy_ref) <= big and abs(omega_ref) <= big):
            raise ValueError(bad)  # NaN included
        vx, vy, w, _, _, _ = law(x, y, theta, x_ref, y_ref, theta_ref, vx_ref, vy_ref, omega_ref, 0.0, 0.0, 0.0)
        twist_out[0], twist_out[1], twist_out[2] = vx, vy, w
        return ik(vx, vy, w, heading, rates_out, heading_out)

    return compile_cached(tick)  # a later process loads it (seconds to compile)


@functools.cache
def _drop_stale_ticks() -> None:
    """Bound the ticks' cache and drop it when the code compiled into them changed (once per process, before the
    first tick compiles or loads: :func:`~wmrkit._jit.drop_stale_cache`)."""
    from .. import _jit
    from ..kinematics import linkage_law, realtime
    from . import _coupled_kernel

    _jit.drop_stale_cache([__file__], [realtime.__file__, _jit.__file__, coupled_solve.__file__,
                                       _coupled_kernel.__file__, linkage_law.__file__])
    _jit.drop_oversized_cache(__file__, MAX_CACHE_BYTES)
