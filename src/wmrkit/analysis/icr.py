"""The instantaneous centre of rotation (ICR, "CIR"): thesis §5.3, eqs. (5.9)-(5.10) and (5.19)-(5.21) corrected.

A twist ``(vx, vy, omega)`` turns the robot about ``(x_c, y_c) = (-vy / omega, vx / omega)``; in homogeneous
coordinates ``(x, y, w) = (-vy, vx, omega)``, with ``w = 0`` for a translation (a point at infinity). The ICR
lies on every constraint line of the robot (the axles of its fixed and steerable wheels, :mod:`.lines`), so the
set of admissible ICRs is their common point, a line (all axles coincide), or the whole plane (no axles).
The thesis's closed form (5.21) swaps x and y (errata, docs/errata.md); the null vector used here does not.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass, field, replace

import numpy as np
from numpy.typing import ArrayLike
from scipy.linalg import null_space

from .._shapes import as_vectors
from ..errors import ShapeError
from ..kinematics.linalg import centred, centroid, characteristic_length, matrix_rank
from ..kinematics.models import configuration
from ..robot import Robot, check_robot
from ..units import MAX_ANGLE
from .lines import ConstraintLines, common_point, constraint_lines, element_rows


def icr_of_twist(twist_robot: ArrayLike) -> np.ndarray:
    """Homogeneous ICR ``(-vy, vx, omega)`` of body twists (§2.2 of the digest). ``(..., 3) -> (..., 3)``."""
    t = as_vectors(twist_robot, 3, "twist_robot")
    return np.stack([-t[..., 1], t[..., 0], t[..., 2]], axis=-1)


def twist_of_icr(icr_h: ArrayLike) -> np.ndarray:
    """A unit twist about the homogeneous ICR ``(x, y, w)``: ``(y, -x, w)`` normalised. ``(..., 3) -> (..., 3)``."""
    h = _homogeneous(icr_h)
    t = np.stack([h[..., 1], -h[..., 0], h[..., 2]], axis=-1)
    return t / np.linalg.norm(t, axis=-1, keepdims=True)


def _homogeneous(icr_h: ArrayLike) -> np.ndarray:
    """`icr_h` ``(..., 3)``, or :class:`ShapeError` unless every point is finite and not ``(0, 0, 0)`` (no point:
    it gave NaN twists, and steering left at the described angles)."""
    h = as_vectors(icr_h, 3, "icr_h")
    bad = ~(np.isfinite(h).all(axis=-1) & (np.abs(h).max(axis=-1, initial=0.0) > 0))
    if bad.any():
        raise ShapeError(f"icr_h: expected finite homogeneous points (x, y, w), not all zero, got "
                         f"{h[bad][0].tolist()}")
    return h


def to_cartesian(icr_h: ArrayLike) -> np.ndarray:
    """``(x / w, y / w)`` [m]; infinite where ``w = 0``. ``(..., 3) -> (..., 2)``."""
    h = as_vectors(icr_h, 3, "icr_h")
    with np.errstate(divide="ignore", invalid="ignore"):
        return h[..., :2] / h[..., 2:]


@dataclass(frozen=True)
class ICRSet:
    """The admissible ICRs of a robot at one configuration (5.9)-(5.10).

    ``kind``: "point" (``point`` [m]), "infinity" (translation only, along ``direction``), "line" (any point of
    ``line``, eq. 6.18), "plane" (anywhere: no axles), "none" (the robot cannot move).
    """

    kind: str
    point: tuple[float, float] | None = None
    direction: tuple[float, float] | None = None
    line: tuple[float, float, float] | None = None
    # "none" whose steered axles miss one point by at most ROUNDING, or a point (at infinity) they miss by more than
    # ROUNDOFF_MISS (the rank rule read rounded headings as meeting there): the headings [rad] at which they meet,
    # and the wheel that misses most with its miss [rad] (rounded headings, not a robot that cannot move)
    consistent: tuple[tuple[str, float], ...] | None = None
    miss: tuple[str, float] | None = None
    #: decimals of the coordinates [m] in :meth:`describe` (:func:`coordinate_decimals` of the robot: 3 from 10 cm up)
    decimals: int = field(default=3, compare=False)

    def homogeneous(self) -> np.ndarray | None:
        """The ICR as a homogeneous point ``(x, y, w)``: the point (w = 1), at infinity (w = 0, perpendicular to the
        translation), the foot of the line (its point nearest the origin); None for "plane" and "none"."""
        if self.kind == "point":
            return np.array([*self.point, 1.0])
        if self.kind == "infinity":
            return np.array([-self.direction[1], self.direction[0], 0.0])
        if self.kind == "line":
            lx, ly, d = self.line
            return np.array([d * ly, -d * lx, 1.0])
        return None

    def describe(self) -> str:
        """One line for people, e.g. ``ICR at (0.000, -2.747) m``."""
        f = functools.partial(format_coordinate, decimals=self.decimals)
        if self.kind == "point":
            return f"ICR at ({f(self.point[0])}, {f(self.point[1])}) m" + self.rounding_note()
        if self.kind == "infinity":
            u = format_coordinate  # a unit vector: 3 decimals at any scale
            return (f"ICR at infinity: translation only, along +-({u(self.direction[0])}, {u(self.direction[1])})"
                    + self.rounding_note())
        if self.kind == "line":
            lx, ly, d = self.line
            return (f"ICR anywhere on the line through ({f(d * ly)}, {f(-d * lx)}) m along ({format_coordinate(lx)}, "
                    f"{format_coordinate(ly)})")
        if self.kind == "plane":
            return "ICR anywhere in the plane (no wheel axle constrains it)"
        text = "no ICR: the robot cannot move without slipping"
        return text + (f"; {self.heading_note()}" if self.consistent is not None else "")

    def rounding_note(self) -> str:
        """``"; "`` and :meth:`heading_note` for a point (at infinity) the rank rule reads rounded axles as meeting
        at, else ``""``."""
        return f"; {self.heading_note()}" if self.kind in ("point", "infinity") and self.consistent else ""

    def heading_note(self) -> str | None:
        """What the steered axles miss when the headings look rounded from consistent ones (None if not): at an ICR
        the rank rule reads them as meeting at (within ``linalg.HEADING_RESOLUTION``), ``"its steered axles miss the ICR
        by 7.3e-06 deg at most ...: rounded headings, read as front_left 32.58070728 deg, ..."``; with no
        ICR (missing one point by at most :data:`ROUNDING`), ``"... miss one point by ...: rounded headings? They
        meet at headings ..."``."""
        if self.consistent is None or self.miss is None:
            return None
        aimed = ", ".join(f"{name} {math.degrees(h):.10g} deg" for name, h in self.consistent)
        by = f"by {math.degrees(self.miss[1]):.2g} deg at most ({self.miss[0]})"
        if self.kind == "none":
            return f"its steered axles miss one point {by}: rounded headings? They meet at headings {aimed}"
        return f"its steered axles miss the ICR {by}: rounded headings, read as {aimed}"


#: Largest heading error [rad] :func:`icr` reads as rounding of consistent headings (0.5 deg).
ROUNDING = math.radians(0.5)

#: Rounding of the common point's ``w`` (nondimensional, unit vector) per unit condition number of two axles: an
#: ICR whose ``w`` is below it times ``s_1 / s_2`` is the intersection of axles parallel within rounding, not a point.
ROUNDING_W = 1e3 * np.finfo(float).eps


def format_coordinate(x: float, decimals: int = 3) -> str:
    """`x` with `decimals` decimals, never "-0.000" (the ICR texts)."""
    text = f"{x:.{decimals}f}"
    return text.removeprefix("-") if float(text) == 0 else text


def coordinate_decimals(robot: Robot) -> int:
    """Decimals that show an ICR's coordinates [m] to 1 % of the robot's size (``characteristic_length``), at
    least 3 (mm): a 2 mm robot's ICR at (0.4 mm, 7.1 mm) read ``(0.000, 0.007)``, its axle ``through (0.000,
    0.000)``."""
    return max(3, math.ceil(-math.log10(0.01 * characteristic_length(robot))))


def icr(robot: Robot, beta: ArrayLike | None = None, *, heading: ArrayLike | None = None,
        geared: bool = False) -> ICRSet:
    """The admissible ICRs of `robot` at one steering configuration ``(n_steer,)`` (5.9)-(5.10), given as the
    thesis's `beta` or the users' `heading` (default the described one).

    `geared`: with the robot's ``gear`` couplings held (as ``analyze``, ``fk`` and the actuation analysis hold them):
    the ICR also lies on the line each gear adds (:func:`.lines.constraint_lines` with ``coupled``), e.g. the line
    of ICRs two omni wheels' spins on one gear leave, or the one point a solid axle's ratio fixes."""
    check_robot(robot)
    found = _admissible(robot, configuration(robot, beta, heading), geared)
    return replace(found, decimals=coordinate_decimals(robot))


def icr_homogeneous(robot: Robot, beta: np.ndarray) -> np.ndarray | None:
    """:meth:`ICRSet.homogeneous` of :func:`icr` at the thesis's steering `beta` ``(n_steer,)``, without what only
    its text uses (the rounded-headings note: a third of a call, and a loop over a singular set's configurations
    reads the point alone)."""
    return _admissible(robot, beta, False, noted=False).homogeneous()


def _admissible(robot: Robot, beta: np.ndarray, geared: bool, *, noted: bool = True) -> ICRSet:
    cl = constraint_lines(robot, coupled=geared and any(c.kind == "gear" for c in robot.couplings))
    g = cl.lines(beta)
    rank = line_rank(robot, g)
    if rank == 0:
        return ICRSet("plane")
    if rank == 3:
        return _nearly_consistent(robot, beta, cl, g)
    if rank == 1:
        row = g[np.argmax(np.linalg.norm(g, axis=-1))]
        return ICRSet("line", line=tuple(float(v) for v in row))
    found = meeting_point(robot, g)
    return _rounded(robot, beta, cl, g, found) if noted else found


def meeting_point(robot: Robot, lines: np.ndarray) -> ICRSet:
    """The common point of `robot`'s `lines` ``(n, 3)`` of rank 2: "point", or "infinity" where they are parallel
    within rounding (:data:`ROUNDING_W`)."""
    size, (cx, cy) = characteristic_length(robot), centroid(robot)
    _, s, vt = np.linalg.svd(centred(robot, lines, metres=True))  # about the wheels' centroid, in robot sizes
    x, y, w = -vt[-1, 1], vt[-1, 0], vt[-1, 2]  # the common point as common_point maps it, in robot sizes
    # no distance beyond which a point is "at infinity": the same axles would meet in one frame and not in another
    if abs(w) <= ROUNDING_W * s[0] / s[1]:
        n = np.hypot(x, y) * (1.0 if y > 1e-12 or (abs(y) <= 1e-12 and x < 0) else -1.0)  # either sign: +x first
        return ICRSet("infinity", direction=(float(y / n), float(-x / n)))
    return ICRSet("point", point=(float(cx + size * x / w), float(cy + size * y / w)))


#: Largest miss [rad] of a steered axle at the ICR read as the float round-off of consistent headings: beyond it
#: the headings were rounded (to the rank rule's resolution, ``linalg.HEADING_RESOLUTION``) and the ICR says so.
ROUNDOFF_MISS = 1e-9


def _rounded(robot: Robot, beta: np.ndarray, cl: ConstraintLines, lines: np.ndarray, found: ICRSet) -> ICRSet:
    """`found` (a point or a point at infinity), with the headings that aim every steered axle exactly at the point
    of the fixed axles nearest them (:func:`_aimed`) and the largest miss, when some axle misses it by more than
    :data:`ROUNDOFF_MISS`: the rank rule read rounded headings as consistent ones (:meth:`ICRSet.rounding_note`)."""
    got = _aimed(robot, beta, cl, lines)
    if got is None or got[1].max() <= ROUNDOFF_MISS:
        return found
    return _with_headings(robot, found, *got)


def _with_headings(robot: Robot, found: ICRSet, aimed: np.ndarray, miss: np.ndarray) -> ICRSet:
    worst = int(np.argmax(miss))
    headings = robot.heading_of_beta(aimed)
    return replace(found, consistent=tuple(zip(robot.steer_names, headings.tolist(), strict=True)),
                   miss=(robot.steer_names[worst], float(miss[worst])))


def _aimed(robot: Robot, beta: np.ndarray, cl: ConstraintLines,
           lines: np.ndarray) -> tuple[np.ndarray, np.ndarray] | None:
    """The steering that aims every steered axle at the point of the fixed axles nearest them, and each steering
    angle's miss [rad] ``(n_steer,)``; None without a steered axle or a point on every fixed one. `lines`: those of
    `cl` at `beta`."""
    steered = np.array(cl.steered, dtype=bool)
    fixed = null_space(lines[~steered]) if (~steered).any() else np.eye(3)  # points on every fixed axle
    if not steered.any() or fixed.shape[1] == 0:
        return None
    v = fixed @ np.linalg.svd(lines[steered] @ fixed)[2][-1]  # of those, the nearest to the steered axles
    point = np.array([-v[1], v[0], v[2]])  # as common_point maps a line-space vector (unit norm)
    aimed = steer_to_icr(robot, point)
    miss = np.abs(np.remainder(aimed - beta + np.pi / 2, np.pi) - np.pi / 2)  # an axle is a line: beta ~ beta + pi
    _, j, cx, cy, _, _ = _aimed_axles(robot)
    at = np.hypot(point[0] - point[2] * cx, point[1] - point[2] * cy) <= 1e-9 * characteristic_length(robot)
    miss[j[at]] = 0.0  # a wheel at the point: its axle passes through it at any angle (steer_to_icr keeps it)
    return aimed, miss


def line_rank(robot: Robot, lines: np.ndarray) -> int:
    """Rank of the constraint lines, about the wheels' centroid and nondimensional (``linalg.centred``; 0: no
    line): the same in every robot frame."""
    return int(matrix_rank(centred(robot, lines, metres=True))) if len(lines) else 0


def _nearly_consistent(robot: Robot, beta: np.ndarray, cl: ConstraintLines, lines: np.ndarray) -> ICRSet:
    """"none", with the headings that make the axles meet when re-aiming the steered wheels at the nearest common
    point moves none of them by more than :data:`ROUNDING` (e.g. Ackermann headings given to 0.001 deg). `lines`:
    those of `cl` at `beta` (a gear's line moves with the steering of any of its wheels)."""
    got = _aimed(robot, beta, cl, lines)
    if got is None or got[1].max() > ROUNDING or line_rank(robot, cl.lines(got[0])) == 3:
        return ICRSet("none")
    return _with_headings(robot, ICRSet("none"), *got)


def icr_points(robot: Robot, beta: ArrayLike | None = None, *, heading: ArrayLike | None = None) -> np.ndarray:
    """Homogeneous common point of the axles at each configuration, ``(..., n_steer) -> (..., 3)``, steering `beta`
    (thesis, None: as described) or `heading` (0 = rolling forward).

    Meaningful where the robot has one degree of mobility (types 4 and 5, eqs. 5.18-5.21 corrected): then it is
    the ICR. Least-squares nearest point otherwise.
    """
    check_robot(robot)
    return common_point(constraint_lines(robot).lines(configuration(robot, beta, heading)))


def steer_to_icr(robot: Robot, icr_h: ArrayLike) -> np.ndarray:
    """Steering configuration turning every steerable wheel's axle through the ICR ``(..., 3) -> (..., n_steer)``,
    as the thesis's β (``robot.heading_of_beta`` gives the headings, 0 = rolling forward).

    Each axle is aimed at the ICR (the branch nearest the described angle, since beta and beta + pi give the same
    axle, the other where the nearest is beyond the angle limit: a beta described within a quarter turn of 1e6
    turns); castors and wheels at the ICR keep their described angle. This is the coordination (Ackermann, swerve)
    that lets a robot with several steered wheels move (§5.3, consequence 3 of 5.12).
    """
    check_robot(robot)
    h = _homogeneous(icr_h)
    steering, j, cx, cy, offset, described = _aimed_axles(robot)
    beta = np.broadcast_to(steering, (*h.shape[:-1], len(steering))).copy()
    if not len(j):
        return beta
    dx, dy = h[..., :1] - h[..., 2:] * cx, h[..., 1:2] - h[..., 2:] * cy  # (..., n_aimed), every wheel at once
    ok = np.hypot(dx, dy) > 1e-12 * np.maximum(np.abs(h).max(axis=-1), 1e-300)[..., None]
    axle = np.arctan2(dy, dx) + offset
    branch = axle + np.pi * np.round((described - axle) / np.pi)
    branch = np.where(np.abs(branch) <= MAX_ANGLE, branch, branch - np.pi * np.sign(branch))  # the limit's side
    beta[..., j] = np.where(ok, branch, described)
    return beta


@functools.lru_cache(maxsize=512)
def _aimed_axles(robot: Robot) -> tuple[np.ndarray, ...]:
    """``robot.beta``, then the steering wheels with an axle line (cached per robot): their indices in
    ``robot.steer_names``, mount points x and y [m], :func:`_axle_offset` and described beta, one array each."""
    aimed = set(constraint_lines(robot).wheels)
    j = [k for k, name in enumerate(robot.steer_names) if name in aimed]
    probe = element_rows(robot, robot.beta)
    wheels = [robot.wheel(robot.steer_names[k]) for k in j]
    return (robot.beta, np.array(j, dtype=int), np.array([w.position[0] for w in wheels], dtype=float),
            np.array([w.position[1] for w in wheels], dtype=float),
            np.array([_axle_offset(robot, w.name, probe) for w in wheels], dtype=float),
            np.array([w.beta for w in wheels], dtype=float))


def _axle_offset(robot: Robot, name: str, probe: np.ndarray | None = None) -> float:
    """Steering angle minus the direction of the wheel's axle line (0 for steerable and double wheels)."""
    probe = element_rows(robot, robot.beta) if probe is None else probe
    cl = constraint_lines(robot)
    i = cl.wheels.index(name)
    lam = np.einsum("k,kc->c", cl.coefficients[i], probe)
    return float(robot.wheel(name).beta - np.arctan2(lam[1], lam[0]))
