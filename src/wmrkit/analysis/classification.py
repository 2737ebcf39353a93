"""The five vehicle types: degrees of mobility and steerability, degeneracy (thesis §5.2-5.3, Table 5.1).

The motion constraints on the twist are the axle lines of the fixed and steerable wheels (``K_r*`` of
(5.2)-(5.8), rows ``E_i``; :func:`wmrkit.analysis.lines.constraint_lines` with nothing assigned). With
``r_f`` the rank of the fixed wheels' rows:

- ``m`` (5.13) is ``3 - rank K_r*`` at a generic *admissible* configuration, i.e. one where every steered axle
  passes through a common ICR (for two or fewer independent steered wheels that is every configuration; with
  more, e.g. Ackermann or swerve, the steering must be coordinated: digest §2.3, the merged-wheel rule);
- ``d`` (5.14) is what the steering adds: ``m + d = 3 - r_f`` (digest §2.1, from (5.15));
- the robot is *degenerate* (5.11)-(5.12) if it cannot move, if fixed wheels have different axles (they fight),
  if a steered wheel sits on the fixed axle or two steered wheels share a centre (the ICR is pinned), or if
  ``(m, d)`` is not in Table 5.1.

Generic ranks are used because m and d as written in (5.13)-(5.14) depend on the configuration (errata §8.17);
the configurations where m rises are reported as :class:`SpecialConfiguration`.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from ..couplings import steering_mechanisms
from ..errors import WmrkitError
from ..kinematics.linalg import centred, centroid, characteristic_length, matrix_rank
from ..kinematics.models import configuration, own_turn, random_steering
from ..limits import check_seed
from ..robot import Robot, check_robot
from .icr import steer_to_icr
from .lines import constraint_lines, line_residual

#: Table 5.1: (m, d) -> type.
TABLE_5_1 = {(3, 0): 1, (2, 0): 2, (2, 1): 3, (1, 1): 4, (1, 2): 5}
TYPE_NAMES = {
    1: "omnidirectional", 2: "differential: one fixed axle", 3: "one steered wheel, synchro-like",
    4: "fixed axle and steering: tricycle, bicycle, car", 5: "steered wheels only, like two independent ones",
}


@dataclass(frozen=True)
class SpecialConfiguration:
    """A steering configuration ``beta`` ``(n_steer,)`` [rad] where the mobility differs from the generic one."""

    beta: tuple[float, ...]
    mobility: int
    description: str


@dataclass(frozen=True)
class Classification:
    """Result of :func:`classify` (Table 5.1). ``type`` is None for a degenerate robot."""

    mobility: int
    steerability: int
    type: int | None
    degenerate: bool
    reasons: tuple[str, ...]
    coordinated: bool  # the steered wheels must be coordinated (one common ICR) for the robot to move
    fixed_rank: int
    special: tuple[SpecialConfiguration, ...]
    #: d the robot's steering mechanisms can command: at most one per steered wheel or ``linkage`` of them
    #: (``couplings.steering_mechanisms``); below d when a linkage steers wheels that d counts as independent
    commanded_steerability: int

    @property
    def name(self) -> str:
        """Type name of Table 5.1, or "degenerate"."""
        return TYPE_NAMES[self.type] if self.type else "degenerate"

    def describe(self) -> str:
        """One line for people: type, m, d, and what makes the robot degenerate or coordinated."""
        head = (f"type {self.type} ({self.name})" if self.type else "degenerate") + \
            f": mobility m = {self.mobility}, steerability d = {self.steerability}"
        extra = list(self.reasons)
        if self.coordinated:
            extra.append("the steered wheels must be coordinated so that all axles meet at one ICR")
        if self.commanded_steerability < self.steerability:
            extra.append(f"its steering linkages command d = {self.commanded_steerability} (couplings)")
        return head + ("; " + "; ".join(extra) if extra else "")


def instantaneous_mobility(robot: Robot, beta: ArrayLike | None = None, *,
                           heading: ArrayLike | None = None, geared: bool = False) -> np.ndarray:
    """Degrees of freedom of the twist, ``3 - rank K_r*(beta)`` (5.13). ``(..., n_steer) -> (...)``; steering
    `beta` (thesis) or `heading` (0 = rolling forward), default as described. `geared`: with the robot's ``gear``
    couplings held (the lines they add, as :func:`.icr.icr` holds them), the twists the mechanism allows.

    Equals ``k - rank A`` (6.8) for robots whose wheel rates are all fixed by the twist (all but double wheels:
    their joints also move with the body at rest, which this m does not count).
    """
    check_robot(robot)
    beta = configuration(robot, beta, heading)
    cl = constraint_lines(robot, coupled=geared and any(c.kind == "gear" for c in robot.couplings))
    if not cl.labels:
        return np.full(beta.shape[:-1], 3)
    return 3 - matrix_rank(centred(robot, cl.lines(beta), metres=True))


def classify(robot: Robot, *, samples: int = 8, seed: int = 0) -> Classification:
    """Type (1)-(5) of Table 5.1, degrees of mobility m and steerability d, degeneracy (5.11)-(5.15).

    `samples` random admissible configurations (axles aimed at random ICRs) give the generic ranks: the largest
    rank met, i.e. the least m, since a rank only drops on a special set of configurations (and numerically near
    it: two axles 100 nm apart aimed at an ICR 100 m away read as one line).
    """
    check_robot(robot)
    if isinstance(samples, bool) or not isinstance(samples, int | np.integer) or not 1 <= samples <= 10_000:
        raise WmrkitError(f"samples must be an integer in [1, 10000], got {samples!r}")
    check_seed(seed, WmrkitError)
    cl = constraint_lines(robot)
    steer = set(robot.steer_names)
    fixed_rows = [i for i, w in enumerate(cl.wheels) if w not in steer]
    steered = sorted({w for w in cl.wheels if w in steer}, key=robot.steer_names.index)
    g_fixed = centred(robot, cl.lines(robot.beta)[fixed_rows], metres=True)
    rf = int(matrix_rank(g_fixed)) if fixed_rows else 0
    reasons: list[str] = []
    if rf >= 2:
        names = sorted({cl.wheels[i] for i in fixed_rows}, key=robot.wheel_names.index)
        reasons.append(f"fixed wheels {', '.join(names)} have different axles: they fight (5.11)")
    rng = np.random.default_rng(seed)
    admissible = _admissible_configurations(robot, g_fixed, rf, samples, rng)
    m = int(instantaneous_mobility(robot, admissible).min()) if len(admissible) else 0
    random_beta = random_steering(robot, samples, rng)
    m_random = int(instantaneous_mobility(robot, random_beta).min())
    coordinated = m_random < m
    d = max(3 - rf - m, 0)
    if m == 0:
        reasons.append("it cannot move without slipping (rank K_r* = 3, 5.6-5.8)")
    reasons += _pinned(robot, cl, fixed_rows, steered, rf)
    if (m, d) not in TABLE_5_1 and not reasons:
        reasons.append(f"(m, d) = ({m}, {d}) is not in Table 5.1 (5.15)")
    kind = None if reasons else TABLE_5_1.get((m, d))
    special = _special(robot, steered, rf, m) if not reasons else ()
    return Classification(m, d, kind, bool(reasons), tuple(reasons), coordinated, rf, special,
                          min(d, steering_mechanisms(robot.couplings, steered)))


def _size(robot: Robot) -> float:
    """The length the rank decisions are made in: the robot's size (the tolerance policy of kinematics.linalg)."""
    return characteristic_length(robot)


def _admissible_configurations(robot: Robot, g_fixed: np.ndarray, rf: int, n: int, rng) -> np.ndarray:
    """Configurations with every steered axle through a common random ICR allowed by the fixed wheels. `g_fixed`:
    their lines about the wheels' centroid, nondimensional (``linalg.centred``). The twists are drawn in the axes
    of :func:`~wmrkit.kinematics.models.own_turn` and projected onto those the fixed wheels allow (a projector,
    unlike a basis, is unique), so they are the same twists of the wheels in every robot frame."""
    if rf >= 3:
        return np.zeros((0, len(robot.steer_names)))
    _, _, vh = np.linalg.svd(np.vstack([g_fixed, np.zeros((3, 3))]))
    allowed = vh[rf:].T @ vh[rf:]  # projector onto the twists of the centroid (vx, vy, omega L) the fixed wheels allow
    c, s = np.cos(own_turn(robot)), np.sin(own_turn(robot))
    drawn = rng.normal(size=(n, 3)) @ np.array([[c, s, 0.0], [-s, c, 0.0], [0.0, 0.0, 1.0]])  # turned into the frame
    twists = (drawn @ allowed) * np.array([1.0, 1.0, 1.0 / _size(robot)])
    cx, cy = centroid(robot)  # ICRs about the centroid, back in the robot frame
    icr_h = np.stack([-twists[:, 1] + cx * twists[:, 2], twists[:, 0] + cy * twists[:, 2], twists[:, 2]], axis=-1)
    beta = steer_to_icr(robot, icr_h)
    castors = [j for j, s in enumerate(robot.steer_names) if s not in set(constraint_lines(robot).wheels)]
    beta[:, castors] = own_turn(robot) + rng.uniform(-np.pi, np.pi, (n, len(castors)))
    return beta


def _pinned(robot: Robot, cl, fixed_rows: list[int], steered: list[str], rf: int) -> list[str]:
    """(5.12b): a steered wheel centred on the fixed axle, or two steered wheels sharing a centre."""
    out = []
    if rf == 1:
        axle = cl.lines(robot.beta)[fixed_rows[0]]
        for name in steered:
            if abs(line_residual(axle, robot.wheel(name).position)) < 1e-9 * _size(robot):
                out.append(f"steered wheel {name} is centred on the fixed axle: the ICR is pinned at its centre "
                           "unless it stays aligned with the axle (5.12b)")
    for a, b in itertools.combinations(steered, 2):
        if np.hypot(*np.subtract(robot.wheel(a).position, robot.wheel(b).position)) < 1e-9 * _size(robot):
            out.append(f"steered wheels {a} and {b} share a centre: the ICR is pinned there unless they stay "
                       "parallel (5.12b)")
    return out


def _deg(x: float) -> str:
    """`x` [deg] with one decimal, never "-0.0"."""
    text = f"{x:.1f}"
    return "0.0" if text == "-0.0" else text


def _special(robot: Robot, steered: list[str], rf: int, m: int) -> tuple[SpecialConfiguration, ...]:
    """Configurations where m rises above the generic value: all steered axles on one line (digest §2.3)."""
    if rf != 0 or len(steered) < 2:
        return ()
    centres = np.array([robot.wheel(n).position for n in steered])
    about = (centres - centroid(robot)) / _size(robot)  # collinear in every frame alike
    if matrix_rank(np.hstack([about, np.ones((len(steered), 1))])) > 2:
        return ()
    direction = centres[-1] - centres[0]
    beta = steer_to_icr(robot, np.array([direction[0], direction[1], 0.0]))  # ICR at infinity along the line
    m_here = int(instantaneous_mobility(robot, beta))
    if m_here <= m:
        return ()
    names = ", ".join(steered)
    line = float(np.degrees(np.arctan2(direction[1], direction[0]))) % 180  # the wheels roll across it
    heading = line - 90  # in [-90, 90), and the heading 180 deg away in [90, 180] or (-180, -90]
    text = (f"m = {m_here} when the axles of {names} all lie on the line through their centres (the line at "
            f"{_deg(line)} deg: headings {_deg(heading)} or {_deg(heading + 180 if heading <= 0 else heading - 180)} "
            "deg)")
    return (SpecialConfiguration(tuple(float(b) for b in beta), m_here, text),)
