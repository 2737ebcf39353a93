"""Sensing (thesis §4.4.5-4.4.6): sensed direct solution (4.31)/(4.32), sensing equation (4.34), Fig. 4.5.

The sensed joints are ``wheel.joint`` names (default: the robot's ``sensed``); the conventions are those of
:mod:`wmrkit.kinematics.actuation`: wheel rates are columns, the ``steer`` joint of a centred steerable wheel is a
configuration sensor (the model needs beta, 4.33), ``omega`` and roller rates are refused. Batched over ``beta``
``(..., n_steer)``; ``None`` is the described configuration.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from .._shapes import as_vectors, matvec, readonly
from ..couplings import gear_fill, gear_free
from ..robot import TWIST_NAMES, Robot, check_robot
from .actuation import (
    body_only,
    minimal_set_search,
    not_reduced,
    require_determined,
    steering_split,
    verdict_texts,
    where_determined,
)
from .linalg import coupled_constraints, nondimensional, nullity, unit_columns
from .models import bounded, configuration
from .search import SetList
from .trees import (
    TreeVerdict,
    eliminated_tree,
    jacobian_names,
    partitioned_solution,
    reduced_equation,
    reduction_exact,
    select_columns,
    selected_determined,
    undriven_motions,
)


def _split(robot: Robot, sensed: Sequence[str] | None, beta: ArrayLike | None, decisions: bool = False):
    """Sensed columns, sensed steering, ``(I_bar, J_s, J_ns)``: a gear's unsensed joints turn with its sensed ones
    (:func:`wmrkit.couplings.gear_fill`, as ``fk`` and ``odometry`` fill them), so they are known, not columns of
    ``J_ns``, and ``J_s`` carries them; a gear with no sensed joint is one unknown, its turn
    (:func:`wmrkit.couplings.gear_free`); last, the names of the unknowns of ``J_ns``. With `decisions` (rank
    decisions only) the columns of both changes of variables are unit vectors (:func:`~.linalg.unit_columns`)."""
    columns, steering = select_columns(robot, robot.sensed if sensed is None else sensed, "sensed")
    names = jacobian_names(robot)
    filled, fill = gear_fill(robot.couplings, names, columns)
    free, free_names = gear_free(robot.couplings, names, columns)
    if decisions:
        fill, free = unit_columns(fill), unit_columns(free)
    i_bar, j = robot.jacobian_form(configuration(robot, beta))
    return columns, steering, i_bar, j[..., list(filled)] @ fill, j @ free, free_names


def sensing_equation(
    robot: Robot, sensed: Sequence[str] | None = None, beta: ArrayLike | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """The vehicle sensing equation (4.34), ``I_s @ twist_robot = J_s @ q_dot_s``: ``(I_s (..., 3E, 3), J_s)``."""
    columns, _, i_bar, j_s, j_ns, _ = _split(robot, sensed, beta)
    _, _, _, j_s1, j_ns1, _ = _split(nondimensional(robot), sensed, beta, True)  # rank decisions: linalg
    require_determined(reduction_exact(j_s1, j_ns1), not_reduced(robot, columns, "sensed", "(4.34)"))
    return reduced_equation(i_bar, j_s, j_ns), j_s


def sensed_direct_matrix(
    robot: Robot, sensed: Sequence[str] | None = None, beta: ArrayLike | None = None
) -> np.ndarray:
    """Reduced sensed direct solution (4.32): ``twist_robot = M @ q_dot_s``, ``(..., n_steer) -> (..., 3, n_s)``.

    ``M = (sum_i Delta(J_ins))^-1 (Delta(J_1ns) J_1s ... Delta(J_Nns) J_Ns)`` for one-contact wheels, here in
    the composite form ``(I_bar^T Delta(J_ns) I_bar)^-1 I_bar^T Delta(J_ns) J_s``. :class:`~wmrkit.SingularError`
    where the sensed rates do not fix the twist (``rank I_s < 3``, as :meth:`SensingAnalysis.twist`): the
    pseudo-inverse's minimum-norm twist would be one of many.
    """
    columns, _, i_bar, j_s, j_ns, _ = _split(robot, sensed, beta)
    _, _, i_bar1, _, j_ns1, _ = _split(nondimensional(robot), sensed, beta, True)  # rank decisions: linalg
    names = jacobian_names(robot)
    require_determined(selected_determined(i_bar1, j_ns1), twist_not_fixed(robot.name, [names[c] for c in columns]))
    return partitioned_solution(i_bar, j_ns) @ j_s


def sensed_full_matrix(
    robot: Robot, sensed: Sequence[str] | None = None, beta: ArrayLike | None = None
) -> np.ndarray:
    """Sensed direct solution (4.31) corrected: ``(twist; q_dot_ns) = (I_ns^T I_ns)^-1 I_ns^T J_s q_dot_s``.

    ``(..., n_steer) -> (..., 3 + n_ns, n_s)`` with ``I_ns = [I_bar, -J_ns]`` (4.30); the non-sensed
    velocities in :func:`jacobian_names` order (the omega copies included). :class:`~wmrkit.SingularError` where
    ``I_ns`` is rank deficient (insufficient sensors, ``SensingAnalysis.sufficient`` False): the twist is not fixed,
    or a motion with the sensed rates at rest turns unsensed joints (a drive unit on the spot, 4.69), and the
    pseudo-inverse's pick would be one of many (``SensingAnalysis.direct`` still gives a fixed twist).
    """
    columns, _, i_bar, j_s, j_ns, _ = _split(robot, sensed, beta)
    _, _, i_bar1, _, j_ns1, _ = _split(nondimensional(robot), sensed, beta, True)  # rank decisions: linalg
    names = [jacobian_names(robot)[c] for c in columns]
    require_determined(selected_determined(i_bar1, j_ns1), twist_not_fixed(robot.name, names))
    require_determined(undriven_motions(i_bar1, j_ns1) == 0, (
        f"robot '{robot.name}': the sensed rates ({', '.join(names)}) fix the twist but not the unsensed "
        "rates: a motion with them at rest turns other joints (a double wheel on the spot, 4.69), so (4.31) has many "
        "solutions; SensingAnalysis.direct gives the twist"))
    return _full(i_bar, j_s, j_ns)


def _full(i_bar: np.ndarray, j_s: np.ndarray, j_ns: np.ndarray) -> np.ndarray:
    i_ns = np.concatenate([np.broadcast_to(i_bar, (*j_ns.shape[:-2], *i_bar.shape)), -j_ns], axis=-1)
    return np.linalg.pinv(i_ns) @ j_s


def sensing_tree(
    robot: Robot, sensed: Sequence[str] | None = None, beta: ArrayLike | None = None,
    q_dot_s: ArrayLike | None = None,
) -> TreeVerdict:
    """The sensing tree of Fig. 4.5: Fig. 4.1 on (4.34) with ``A = I_s``, ``B = J_s``, ``y = q_dot_s``.

    ``determined``: basic sensing (twist known, slip not detectable); ``overdetermined``: consistent sensing
    (redundant sensors, slip detectable), and with readings ``q_dot_s`` ``(..., n_s)`` ``consistent`` (no slip
    nor noise) or ``inconsistent``; the other leaves: insufficient sensors.
    """
    _, _, i_bar, j_s, j_ns, _ = _split(nondimensional(robot), sensed, beta)  # rates are angular: same units
    return eliminated_tree(i_bar, j_s, j_ns, q_dot_s)  # the unsensed rates eliminated exactly


_SENSING_TEXT = {
    "determined": "basic sensing: the sensed rates give the twist, slip cannot be detected",
    "overdetermined": "consistent sensing: redundant sensed rates, slip (or sensor noise) is detectable",
    "indeterminate": "insufficient sensors: some degrees of freedom are not sensed",
    "underdetermined": "insufficient and redundant sensors: some degrees of freedom are not sensed and some "
                       "sensors sense the same ones",
    "body only": "insufficient sensors: the sensed rates give the body's twist, but not a motion of the joints with "
                 "the body at rest (a double wheel turning on the spot, 4.69), so the next configuration is unknown",
    "overdetermined, body only": "insufficient and redundant sensors: redundant for the body's twist, but a motion "
                                 "of the joints with the body at rest (a double wheel turning on the spot, 4.69) is "
                                 "not sensed",
}


@dataclass(frozen=True, eq=False)  # eq=False: array fields
class SensingAnalysis:
    """Sensing of a robot at a batch of configurations (§4.4.5-4.4.6, Fig. 4.5); arrays of the batch shape."""

    robot_name: str
    sensed: tuple[str, ...]  # sensed columns of the Jacobian form (wheel rates)
    steering: tuple[str, ...]  # steerable wheels whose steering angle is sensed
    steering_missing: tuple[str, ...]  # steerable wheels whose steering angle is not sensed
    mobility: np.ndarray  # (...) int
    tree: TreeVerdict
    direct_matrix: np.ndarray  # (..., 3, n_s), (4.32)
    full_matrix: np.ndarray  # (..., 3 + n_ns, n_s), (4.31): rows past the twist one of many where unsensed > 0
    full_names: tuple[str, ...]  # rows of full_matrix: vx, vy, omega, the unknowns (a gear unsensed: its channel)
    residual_matrix: np.ndarray  # (..., 3E, n_s): least-squares error of (4.31) per sensed rate
    unsensed: np.ndarray  # (...) int, motions with every sensed rate at rest (.trees.undriven_motions)

    @property
    def sufficient(self) -> np.ndarray:
        """``rank I_s = 3`` and no motion left with every sensed rate at rest (a double wheel's turntable, 4.69):
        the sensed rates determine the twist and how the configuration changes (sufficient sensors)."""
        return (self.tree.rank_a == 3) & (self.unsensed == 0)

    @property
    def slip_detectable(self) -> np.ndarray:
        """Sufficient and redundant sensors (``rank [I_s, J_s] > rank I_s``): slip shows in the residual."""
        return self.sufficient & (self.tree.rank_ab > self.tree.rank_a)

    @property
    def leaf(self) -> np.ndarray:
        """The leaf of Fig. 4.5 (``determined``, ``overdetermined``, ``indeterminate``, ``underdetermined``)."""
        return self.tree.leaf

    @property
    def verdict(self) -> np.ndarray:
        """One sentence per configuration: the tree's verdict, the counts, and missing steering sensors."""
        return verdict_texts(body_only(self.leaf, self.unsensed), _SENSING_TEXT, len(self.sensed), self.mobility,
                             self.steering_missing, "sensed")

    @property
    def twist_determined(self) -> np.ndarray:
        """``rank I_s = 3`` ``(...)`` bool: the sensed rates fix the twist, so (4.31)/(4.32) give it (elsewhere the
        twist is one of many; :meth:`twist` and :meth:`direct` refuse it)."""
        return self.tree.rank_a == 3

    def _require_twist(self) -> None:
        require_determined(self.twist_determined, twist_not_fixed(self.robot_name, self.sensed))

    def twist(self, q_dot_s: ArrayLike) -> np.ndarray:
        """The body twist from sensed rates, (4.32): ``(..., n_s) -> (..., 3)`` [m/s, rad/s]; :class:`SingularError`
        where the sensed rates do not fix it (:attr:`twist_determined`)."""
        q = bounded(as_vectors(q_dot_s, len(self.sensed), "q_dot_s"), self.sensed, "q_dot_s")
        self._require_twist()
        return matvec(self.direct_matrix, q, "q_dot_s")

    def direct(self, q_dot_s: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
        """Twist and residual from sensed rates, (4.31): ``(..., n_s) -> ((..., 3), (..., 3E))``.

        The residual is ``I_ns (twist; q_dot_ns) - J_s q_dot_s``: zero without slip or noise, the slip
        indicator otherwise (when ``slip_detectable``). :class:`SingularError` where the sensed rates do not fix the
        twist (:attr:`twist_determined`).
        """
        q = bounded(as_vectors(q_dot_s, len(self.sensed), "q_dot_s"), self.sensed, "q_dot_s")
        self._require_twist()
        return matvec(self.full_matrix, q, "q_dot_s")[..., :3], matvec(self.residual_matrix, q, "q_dot_s")

    def as_dict(self) -> dict[str, Any]:
        """JSON-ready summary (lists and plain values)."""
        return {
            "sensed": list(self.sensed), "steering_sensed": list(self.steering),
            "steering_not_sensed": list(self.steering_missing), "mobility": self.mobility.tolist(),
            "leaf": self.leaf.tolist(), "sufficient": self.sufficient.tolist(),
            "slip_detectable": self.slip_detectable.tolist(), "unsensed_motions": self.unsensed.tolist(),
            "verdict": self.verdict.tolist(),
            "direct_matrix": where_determined(self.direct_matrix, self.twist_determined),
            "twist_determined": self.twist_determined.tolist(),
        }


def twist_not_fixed(robot_name: str, sensed: Sequence[str]) -> str:
    """The refusal of the sensed direct solution (4.31)/(4.32) where the `sensed` rates do not fix the twist."""
    return (f"robot '{robot_name}': the sensed rates ({', '.join(sensed) or 'none'}) do not determine the twist "
            "(insufficient sensors, rank I_s < 3), so (4.32) has many solutions")


def sensing_analysis(
    robot: Robot, beta: ArrayLike | None = None, sensed: Sequence[str] | None = None, *,
    heading: ArrayLike | None = None,
) -> SensingAnalysis:
    """Analyse the sensors of `robot` (default: its described ``sensed`` joints) at `beta`, Fig. 4.5.

    ``beta`` (thesis) or ``heading`` (0 = rolling forward): ``(..., n_steer)`` or None. See
    :class:`SensingAnalysis` for ``.sufficient``, ``.slip_detectable``, ``.verdict``, and the sensed direct
    solution ``.twist`` / ``.direct``.
    """
    check_robot(robot)
    beta = configuration(robot, beta, heading)
    columns, steering, i_bar, j_s, j_ns, unknown = _split(robot, sensed, beta)
    unit = nondimensional(robot)  # rank decisions: the tolerance policy of .linalg
    a = coupled_constraints(unit, beta)  # the motions a gear allows, as the actuation analysis counts them
    _, _, i_bar1, j_s1, j_ns1, _ = _split(unit, sensed, beta, True)
    names = jacobian_names(robot)
    full = _full(i_bar, j_s, j_ns)
    i_ns = np.concatenate([np.broadcast_to(i_bar, (*j_ns.shape[:-2], *i_bar.shape)), -j_ns], axis=-1)
    return SensingAnalysis(
        robot.name, tuple(names[c] for c in columns), steering, steering_split(robot, steering),
        readonly(np.asarray(nullity(robot, a))),
        eliminated_tree(i_bar1, j_s1, j_ns1),
        readonly(partitioned_solution(i_bar, j_ns) @ j_s), readonly(full),
        TWIST_NAMES + unknown,
        readonly(i_ns @ full - j_s),
        readonly(undriven_motions(i_bar1, j_ns1)),
    )


def minimal_sensor_sets(
    robot: Robot, beta: ArrayLike | None = None, *, detect_slip: bool = False, heading: ArrayLike | None = None,
) -> tuple[tuple[str, ...], ...]:
    """The smallest sensor choices that determine the twist at every configuration (Fig. 4.5).

    ``detect_slip=False``: basic sensing (``determined``), m rates each (G, the body's degrees of freedom, plus
    one per double wheel, whose turn on the spot (4.69) must be sensed too); ``True``: the smallest sets with
    sufficient *redundant* sensors (``overdetermined``, slip detectable). Each set lists the wheel rates, then
    the ``steer`` joints of the centred steerable wheels (their angle must be sensed, 4.33). Steering: `beta`
    (thesis) or `heading` (0 = rolling forward), default as described.
    """
    beta = configuration(robot, beta, heading)
    a = coupled_constraints(nondimensional(robot), beta)  # m counts a gear's motions, as sensing_analysis does
    m = np.unique(nullity(robot, a))
    if len(m) != 1 or m[0] == 0:
        return SetList()
    names, steer = jacobian_names(robot), tuple(f"{w}.steer" for w in steering_split(robot, ()))
    wanted = "overdetermined" if detect_slip else "determined"
    sizes = range(int(m[0]) + 1, len(robot.rate_names) + 1) if detect_slip else (int(m[0]),)
    for size in sizes:  # bounded searches (.search), pruned by the null-space test at size m
        found = minimal_set_search(robot, beta, size, wanted, "minimal sensor sets", drive_all=True,
                                   couplings="sensed")
        if found or not found.complete:
            return SetList([tuple(names[c] for c in s) + steer for s in found], found.complete, found.note)
    return SetList()
