"""Actuation (thesis §4.4.3-4.4.4): actuated inverse solution (4.26)/(4.27), actuation equation (4.28), Fig. 4.4.

The actuated joints are ``wheel.joint`` names (default: the robot's ``actuated``). Wheel rates (spins, castor and
double-wheel steering rates) are columns of the Jacobian form; the ``steer`` joint of a centred steerable wheel
is a *configuration* actuator: it sets beta and does not appear in the instantaneous equations, but the thesis
requires it to be actuated for the model to hold (§4.5). ``omega`` and roller rates are refused (§4.4.3).
Batched over ``beta`` ``(..., n_steer)``; ``None`` is the described configuration.
"""

from __future__ import annotations

import itertools
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from .._shapes import as_vectors, matvec, readonly
from ..couplings import channel_names, coupled_columns, gear_fill, gear_free, linked_steering
from ..errors import SingularError
from ..robot import TWIST_NAMES, Robot, check_robot
from .linalg import coupled_constraints, nondimensional, nullity, unit_columns
from .models import bounded, configuration
from .search import MAX_MINIMAL_SETS, SetList, exact_budget, null_space_cost, null_space_prefilter, search_sets
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


def split_jacobian(
    robot: Robot, columns: Sequence[int], beta: ArrayLike | None = None
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(I_bar, J_sel, J_rest)`` of the Jacobian form (3.20) split by columns (4.24); ``J_rest`` keeps omega.

    ``(..., n_steer) -> (3E, 3), (..., 3E, n_sel), (..., 3E, n_w - n_sel)``.
    """
    i_bar, j = robot.jacobian_form(configuration(robot, beta))
    rest = [c for c in range(j.shape[-1]) if c not in columns]
    return i_bar, j[..., list(columns)], j[..., rest]


def coupled_split(
    robot: Robot, columns: Sequence[int], beta: ArrayLike | None = None, *, decisions: bool = False
) -> tuple[np.ndarray, np.ndarray, np.ndarray, tuple[str, ...]]:
    """:func:`split_jacobian` under the robot's mechanical couplings (``wmrkit.couplings``), with channel names.

    Without couplings the selected joints are the channels; a differential or gear coupling makes its joints one
    channel (``"differential(a.spin, b.spin)"``), and a gear holds the rates across its ratios at zero. With
    `decisions` (rank decisions only) each channel in units that make its direction a unit vector
    (:func:`~.linalg.unit_columns`).
    """
    if not any(c.rates for c in robot.couplings):
        i_bar, j_sel, j_rest = split_jacobian(robot, columns, beta)
        names = jacobian_names(robot)
        return i_bar, j_sel, j_rest, tuple(names[c] for c in columns)
    i_bar, j = robot.jacobian_form(configuration(robot, beta))
    t_sel, channels, t_rest, _ = coupled_columns(robot.couplings, jacobian_names(robot), tuple(columns))
    if decisions:
        t_sel, t_rest = unit_columns(t_sel), unit_columns(t_rest)
    return i_bar, j @ t_sel, j @ t_rest, channels


def actuation_equation(
    robot: Robot, actuated: Sequence[str] | None = None, beta: ArrayLike | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """The vehicle actuation equation (4.28), ``I_u @ twist_robot = J_u @ q_dot_u``.

    ``(..., n_steer) -> (I_u (..., 3E, 3), J_u (..., 3E, n_u))``. A wheel with no actuated rate contributes
    its motion constraint ``-Delta(J_i)``; the others ``I - J_inu (J_inu^T Delta(J_iu) J_inu)^-1 J_inu^T
    Delta(J_iu)``.
    """
    columns, _ = select_columns(robot, robot.actuated if actuated is None else actuated, "actuated")
    i_bar, j_u, j_nu = split_jacobian(robot, columns, beta)
    _, j_u1, j_nu1 = split_jacobian(nondimensional(robot), columns, beta)  # rank decisions: the tolerance policy
    require_determined(reduction_exact(j_u1, j_nu1), not_reduced(robot, columns, "actuated", "(4.28)"))
    return reduced_equation(i_bar, j_u, j_nu), j_u


def actuated_inverse_matrix(
    robot: Robot, actuated: Sequence[str] | None = None, beta: ArrayLike | None = None
) -> np.ndarray:
    """Actuated inverse solution (4.26)/(4.27): ``q_dot_u = M @ twist_robot``, ``(..., n_steer) -> (..., n_u, 3)``.

    Per wheel ``(J_iu^T Delta(J_inu) J_iu)^-1 J_iu^T Delta(J_inu)``; ``J_i^-1`` for an omnidirectional wheel with
    every variable actuated. The twist must satisfy the motion constraints or the wheels slip. :class:`SingularError`
    where the twist does not fix the actuated rates (as :meth:`ActuationAnalysis.inverse`): M would be one of many.
    """
    columns, _ = select_columns(robot, robot.actuated if actuated is None else actuated, "actuated")
    i_bar, j_u, j_nu = split_jacobian(robot, columns, beta)
    _, j_u1, j_nu1 = split_jacobian(nondimensional(robot), columns, beta)  # rank decisions: the tolerance policy
    names = jacobian_names(robot)
    require_determined(selected_determined(j_u1, j_nu1), not_fixed(robot.name, tuple(names[c] for c in columns)))
    return partitioned_solution(j_u, j_nu) @ i_bar


def actuation_tree(
    robot: Robot, actuated: Sequence[str] | None = None, beta: ArrayLike | None = None,
    q_dot_u: ArrayLike | None = None,
) -> TreeVerdict:
    """The actuation tree of Fig. 4.4: Fig. 4.1 on (4.28) with ``A = I_u``, ``B = J_u``, ``y = q_dot_u``.

    ``determined``: consistent actuation (sufficient, no conflict possible); ``overdetermined``: possible
    conflict, and with commands ``q_dot_u`` ``(..., n_u)`` ``consistent`` (actuator coupling respected) or
    ``inconsistent`` (the wheels fight and slip); ``indeterminate``/``underdetermined``/``incompatible``:
    insufficient actuators. The tree of :func:`actuation_analysis`: the unselected rates eliminated exactly
    (:func:`.trees.eliminated_tree`), the robot's couplings held, and ``q_dot_u`` one rate per actuated channel
    (``ActuationAnalysis.actuated``).
    """
    columns, _ = select_columns(robot, robot.actuated if actuated is None else actuated, "actuated")
    i_bar, j_u, j_nu, _ = coupled_split(nondimensional(robot), columns, beta, decisions=True)  # rates: angular
    return eliminated_tree(i_bar, j_u, j_nu, q_dot_u)


_ACTUATION_TEXT = {
    "determined": "consistent actuation: the actuated rates drive every degree of freedom and cannot conflict",
    "overdetermined": "over-actuated: more actuated rates than degrees of freedom, so the actuators must be "
                      "coordinated (or mechanically coupled: 'couplings' in the description) or they fight and "
                      "the wheels slip",
    "body only": "insufficient actuators: the actuated rates drive the body, but a motion of the joints with the "
                 "body at rest (a double wheel turning on the spot, 4.69) is not actuated",
    "overdetermined, body only": "over-actuated and insufficient: more actuated rates than the body's degrees of "
                                 "freedom, which they may fight over, while a motion of the joints with the body at "
                                 "rest (a double wheel turning on the spot, 4.69) is not actuated",
    "indeterminate": "insufficient actuators: some degrees of freedom are not actuated",
    "underdetermined": "insufficient and conflicting actuators: some degrees of freedom are not actuated and "
                       "the actuated rates can fight",
}


@dataclass(frozen=True, eq=False)  # eq=False: array fields
class ActuationAnalysis:
    """Actuation of a robot at a batch of configurations (§4.4.3-4.4.4, Fig. 4.4); arrays of the batch shape."""

    robot_name: str
    actuated: tuple[str, ...]  # actuated columns of the Jacobian form (wheel rates)
    steering: tuple[str, ...]  # steerable wheels whose steering joint is actuated
    steering_missing: tuple[str, ...]  # steerable wheels whose steering is not actuated
    mobility: np.ndarray  # (...) int, m (3.22) with the gear couplings held: the motions the mechanism allows
    tree: TreeVerdict
    inverse_matrix: np.ndarray  # (..., n_u, 3), (4.26); one of many where not inverse_determined
    undriven: np.ndarray  # (...) int, motions with every actuated rate at rest (:func:`undriven_motions`)
    #: (...) bool: the twist fixes the actuated rates, so (4.26) is their solution; False where some of them also turn
    #: joints with the body at rest (a drive unit's two spins steer it on the spot, 4.69): many rates give one twist
    inverse_determined: np.ndarray
    #: the steering actuators: a ``linkage``'s joints one (its channel, ``linkage(a.steer, b.steer)``), else ``w.steer``
    steering_actuators: tuple[str, ...] = ()

    @property
    def sufficient(self) -> np.ndarray:
        """``rank I_u = 3`` and no motion left with every actuated rate at rest (a double wheel's turntable, 4.69):
        every feasible motion is reached by the actuators (sufficient actuators)."""
        return (self.tree.rank_a == 3) & (self.undriven == 0)

    @property
    def consistent(self) -> np.ndarray:
        """``rank [I_u, J_u] = rank I_u``: the actuated rates can be set independently without fighting."""
        return self.tree.rank_ab == self.tree.rank_a

    @property
    def leaf(self) -> np.ndarray:
        """The leaf of Fig. 4.4 (``determined``, ``overdetermined``, ``indeterminate``, ``underdetermined``)."""
        return self.tree.leaf

    @property
    def verdict(self) -> np.ndarray:
        """One sentence per configuration: the tree's verdict, the counts, and missing steering actuators; a body
        driven while a joint motion is not (a double wheel's free turntable) is not called consistent."""
        return verdict_texts(body_only(self.leaf, self.undriven), _ACTUATION_TEXT, len(self.actuated), self.mobility,
                             self.steering_missing, "actuated")

    def inverse(self, twist_robot: ArrayLike) -> np.ndarray:
        """Actuated rates for a (feasible) body twist, (4.26): ``(..., 3) -> (..., n_u)`` [rad/s, m/s]."""
        t = bounded(as_vectors(twist_robot, 3, "twist_robot"), TWIST_NAMES, "twist_robot")
        require_determined(self.inverse_determined, not_fixed(self.robot_name, self.actuated))
        return matvec(self.inverse_matrix, t, "twist_robot")

    def as_dict(self) -> dict[str, Any]:
        """JSON-ready summary (lists and plain values)."""
        return {
            "actuated": list(self.actuated), "steering_actuated": list(self.steering),
            "steering_not_actuated": list(self.steering_missing),
            "steering_actuators": list(self.steering_actuators), "mobility": self.mobility.tolist(),
            "leaf": self.leaf.tolist(), "sufficient": self.sufficient.tolist(),
            "consistent": self.consistent.tolist(), "undriven_motions": self.undriven.tolist(),
            "verdict": self.verdict.tolist(),
            "inverse_matrix": where_determined(self.inverse_matrix, self.inverse_determined),
            "inverse_determined": self.inverse_determined.tolist(),
        }


def require_determined(determined: np.ndarray, message: str) -> None:
    """Raise :class:`SingularError` with `message` (and the first configuration of a batch where it applies) unless
    every entry of `determined` ``(...)`` is True: a solution that is one of many is refused, not returned."""
    if determined.all():
        return
    where = "" if not determined.ndim else f" (configuration {np.argwhere(~determined)[0].tolist()} of the batch)"
    raise SingularError(message + where)


def not_fixed(robot_name: str, actuated: Sequence[str]) -> str:
    """The refusal of the actuated inverse (4.26) where the twist does not fix the `actuated` rates."""
    return (f"robot '{robot_name}': the twist does not determine the actuated rates ({', '.join(actuated)}): they"
            " also turn joints with the body at rest (a double wheel steering on the spot, 4.69), so (4.26) has "
            "many solutions; assign those joints' rates too (the inverse model, 'wmrkit ik')")


def not_reduced(robot: Robot, columns: Sequence[int], role: str, equation: str) -> str:
    """The refusal of the reduced equation `equation` where the selected rates (`columns` of
    :func:`jacobian_names`) and the twist do not fix the others: (4.26) substitutes one of many values for them, and
    motions of the no-slip equations (3.22) break the equation (docs/errata.md)."""
    names = jacobian_names(robot)
    return (f"robot '{robot.name}': the {role} rates ({', '.join(names[c] for c in columns) or 'none'}) and the "
            "twist do not determine the other joints' rates (as a double wheel's steering, shared by its two "
            f"contacts, 4.69), so the reduced equation {equation} does not hold: its left-hand matrix would be one "
            f"of many; the {role} tree eliminates them exactly")


def where_determined(matrix: np.ndarray, determined: np.ndarray) -> Any:
    """`matrix` ``(..., r, c)`` as nested lists, each configuration's matrix None where `determined` ``(...)`` is
    False (JSON null: no matrix that is one of many)."""
    out = np.empty(determined.shape, dtype=object)
    for index in np.ndindex(determined.shape):
        out[index] = matrix[index].tolist() if determined[index] else None
    return out.tolist() if determined.ndim else out[()]


def body_only(leaf: np.ndarray, free: np.ndarray) -> np.ndarray:
    """The leaves of a tree ``(...)``, ``determined`` and ``overdetermined`` marked ``body only`` where `free`
    ``(...)`` motions of the joints are left with the selected rates at rest: the trees look at the body alone."""
    marked = {"determined": "body only", "overdetermined": "overdetermined, body only"}
    return np.where(free > 0, np.vectorize(lambda lf: marked.get(lf, lf), otypes=[object])(leaf), leaf)


def verdict_texts(leaf: np.ndarray, texts: dict[str, str], n: int, m: np.ndarray,
                  missing: tuple[str, ...], role: str) -> np.ndarray:
    """One sentence per leaf of a tree ``(...)`` str: the leaf's text, counts, and missing steering joints. `m` is
    the joint model's mobility (4.3, the gears held), named so: it is not the type's m (Table 5.1) of a robot whose
    joints move with the body at rest (a drive unit's turntable: m = 1, the joint model's 2)."""
    note = (f"; the thesis needs the steering of {', '.join(missing)} {role} too (the model depends on beta)"
            if missing else "")
    plural = "" if n == 1 else "s"
    words = np.frompyfunc(
        lambda lf, mob: f"{texts[lf]} ({n} {role} rate{plural}; the joint model's mobility {mob}, eq. 4.3){note}", 2, 1)
    return readonly(np.asarray(words(leaf, m), dtype=object))


def steering_channels(robot: Robot, wheels: Sequence[str]) -> tuple[str, ...]:
    """The steering actuators of the steered `wheels`, in their order: the channel of each ``linkage`` holding one
    of them (``linkage(a.steer, b.steer)``: one mechanism, one actuator), else the wheel's ``w.steer``."""
    out: list[str] = []
    for w in wheels:
        c = next((c for c in robot.couplings if c.kind == "linkage" and f"{w}.steer" in c.joints), None)
        name = f"{w}.steer" if c is None else c.channel_name
        if name not in out:
            out.append(name)
    return tuple(out)


def actuator_names(robot: Robot, joints: Sequence[str]) -> tuple[str, ...]:
    """`joints` (``wheel.joint``) as the actuators that drive them, once each: a rate coupling's joints as its
    channel (:func:`wmrkit.couplings.channel_names`), a steering ``linkage``'s as its channel."""
    rates = channel_names(robot.couplings, tuple(joints))
    out: list[str] = []
    for j in rates:
        wheel, _, part = j.partition(".")
        name = steering_channels(robot, (wheel,))[0] if part == "steer" and wheel in robot.steer_names else j
        if name not in out:
            out.append(name)
    return tuple(out)


def steering_split(robot: Robot, steering: tuple[str, ...]) -> tuple[str, ...]:
    """The centred steerable wheels not in `steering` (their steering is not actuated/sensed)."""
    return tuple(w.name for w in robot.wheels if w.type == "steerable" and w.name not in steering)


def actuation_analysis(
    robot: Robot, beta: ArrayLike | None = None, actuated: Sequence[str] | None = None, *,
    heading: ArrayLike | None = None,
) -> ActuationAnalysis:
    """Analyse the actuators of `robot` (default: its described ``actuated`` joints) at `beta`, Fig. 4.4.

    ``beta`` (thesis) or ``heading`` (0 = rolling forward): ``(..., n_steer)`` or None. See
    :class:`ActuationAnalysis` for ``.consistent``, ``.sufficient``, ``.verdict`` and the actuated inverse
    solution ``.inverse``.
    """
    check_robot(robot)
    beta = configuration(robot, beta, heading)
    columns, steering = select_columns(robot, robot.actuated if actuated is None else actuated, "actuated")
    i_bar, j_u, j_nu, channels = coupled_split(robot, columns, beta)
    steering = linked_steering(robot.couplings, steering)
    unit = nondimensional(robot)  # rank decisions: the tolerance policy of .linalg
    a = coupled_constraints(unit, beta)
    i_bar1, j_u1, j_nu1, _ = coupled_split(unit, columns, beta, decisions=True)
    return ActuationAnalysis(
        robot.name, channels, steering, steering_split(robot, steering),
        readonly(np.asarray(nullity(robot, a))),
        eliminated_tree(i_bar1, j_u1, j_nu1),
        readonly(partitioned_solution(j_u, j_nu) @ i_bar),
        readonly(undriven_motions(i_bar1, j_nu1)),
        readonly(np.asarray(selected_determined(j_u1, j_nu1))),
        steering_channels(robot, steering),
    )


def subset_trees(robot: Robot, beta: np.ndarray, size: int) -> tuple[list[tuple[int, ...]], TreeVerdict | None]:
    """The trees (4.28)/(4.34) of every set of `size` selectable wheel rates at once: leaves ``(S, ...)``.

    Selectable: every wheel rate but rollers (column indices of :func:`jacobian_names`). ``None`` when there
    is no such set.
    """
    subsets = list(itertools.combinations(selectable_rates(robot), size))
    if not subsets:
        return [], None
    return subsets, trees_of(robot, beta, np.array(subsets, dtype=int).reshape(len(subsets), size))


def selectable_rates(robot: Robot) -> list[int]:
    """Columns of :func:`jacobian_names` an actuator or a sensor can be put on: every wheel rate but rollers."""
    return [i for i, n in enumerate(robot.rate_names) if not n.endswith(".roller")]


def minimal_set_search(robot: Robot, beta: np.ndarray, size: int, wanted: str, what: str, *,
                       drive_all: bool = False, couplings: str = "") -> SetList:
    """The sets of `size` selectable rates whose tree (4.28)/(4.34) is `wanted` with rank 3 at every
    configuration (and, `drive_all`, no motion left with them at rest: :func:`undriven_motions`): a bounded search
    (:mod:`.search`) pruned by the null-space test when ``size`` is the mobility (then the rates must be an
    assignable set of the direct model), listing at most MAX_MINIMAL_SETS. `couplings` ``"sensed"`` or
    ``"actuated"``: each set judged under the robot's couplings as :func:`_split_sets` says (the sensing or the
    actuation analysis), the null-space test on the motions the gears allow (:func:`coupled_constraints`)."""
    def exact(sel: np.ndarray) -> np.ndarray:
        i_bar, j_sel, j_rest, zeroed = _split_sets(robot, beta, sel, couplings)
        tree = eliminated_tree(i_bar, j_sel, j_rest)
        ok = (tree.leaf == wanted) & (tree.rank_a == 3)
        if drive_all:  # a zero (padding) column of j_rest adds one to the nullity, no motion
            ok &= undriven_motions(i_bar, j_rest) == zeroed.reshape(len(sel), *(1,) * (ok.ndim - 1))
        return ok.reshape(len(sel), -1).all(axis=1) & (zeroed >= 0)

    unit = nondimensional(robot)
    a = coupled_constraints(unit, beta) if couplings else unit.constraint_matrix(beta)
    m = np.unique(nullity(robot, a))
    prefilter = null_space_prefilter(a, size, offset=3) if len(m) == 1 and m[0] == size else None
    sets, complete, note = search_sets(selectable_rates(robot), size, exact, prefilter=prefilter,
                                       limit=MAX_MINIMAL_SETS, max_exact=exact_budget(
                                           nondimensional(robot).jacobian_form(beta)[1].shape, 4),
                                       walk_cost=null_space_cost(a.shape, size), what=what)
    return SetList(sets, complete, note)


def trees_of(robot: Robot, beta: np.ndarray, sel: np.ndarray) -> TreeVerdict:
    """The trees (4.28)/(4.34) of the sets of rate columns `sel` ``(S, size)``: leaves ``(S, ...)``."""
    return eliminated_tree(*_split_sets(robot, beta, sel)[:3])


def _split_sets(robot: Robot, beta: np.ndarray, sel: np.ndarray,
                couplings: str = "") -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """``(I_bar, J_sel, J_rest, zeroed)`` of the nondimensional Jacobian form split by each set of columns `sel`
    ``(S, size)``: ``(3E, 3), (S, ..., 3E, size), (S, ..., 3E, n_w - size or n_w), (S,)``. Under the couplings,
    ``J_sel = J T_sel`` and ``J_rest = J T_rest``, padded with zero columns (`zeroed` counts those of ``J_rest``;
    -1 marks a set of fewer channels than rates, never a minimal set): ``"sensed"`` as the sensing analysis (a
    gear's joints known from a set's rates, :func:`wmrkit.couplings.gear_fill`; a gear with none of them one
    unknown, :func:`wmrkit.couplings.gear_free`), ``"actuated"`` as the actuation analysis
    (:func:`wmrkit.couplings.coupled_columns`: a coupling's joints one channel, a gear's across motions held)."""
    names = jacobian_names(robot)
    n_w, size = len(names), sel.shape[1]
    i_bar, j = nondimensional(robot).jacobian_form(beta)
    kinds = ("gear",) if couplings == "sensed" else ("gear", "differential")
    if not couplings or not any(c.kind in kinds for c in robot.couplings):
        rest = np.array([[c for c in range(n_w) if c not in s] for s in sel.tolist()], dtype=int).reshape(
            len(sel), n_w - size)
        j_sel, j_rest = np.moveaxis(j[..., sel], -2, 0), np.moveaxis(j[..., rest], -2, 0)  # (..., 3E, S, k) -> (S, ...)
        return i_bar, j_sel, j_rest, np.zeros(len(sel), dtype=int)
    t_sel, t_rest = np.zeros((len(sel), n_w, size)), np.zeros((len(sel), n_w, n_w))  # rest: fewer channels, more
    zeroed = np.zeros(len(sel), dtype=int)
    for i, s in enumerate(sel.tolist()):
        if couplings == "sensed":
            filled, fill = gear_fill(robot.couplings, names, tuple(s))
            t_sel[i, list(filled)] = fill
            free = gear_free(robot.couplings, names, tuple(s))[0]
        else:
            chosen, _, free, _ = coupled_columns(robot.couplings, names, tuple(s))
            t_sel[i, :, :chosen.shape[1]] = chosen
        t_rest[i, :, :free.shape[1]] = free
        zeroed[i] = n_w - free.shape[1] if couplings == "sensed" or chosen.shape[1] == size else -1
    t_sel, t_rest = unit_columns(t_sel), unit_columns(t_rest)  # each channel's unit: rank decisions only
    return i_bar, np.einsum("...rn,snk->s...rk", j, t_sel), np.einsum("...rn,snk->s...rk", j, t_rest), zeroed


def minimal_actuator_sets(robot: Robot, beta: ArrayLike | None = None, *,
                          heading: ArrayLike | None = None) -> tuple[tuple[str, ...], ...]:
    """The smallest actuator choices with consistent actuation (Fig. 4.4 ``determined``) at every configuration.

    Each set has m (B.3.8) wheel rates, followed by the ``steer`` joints of the centred steerable wheels, which the
    thesis requires actuated: one per steering ``linkage`` (its first joint; any one actuates the mechanism).
    m = G, the body's degrees of freedom, except with a double wheel, whose steering turns with the body at rest
    (4.69): one more rate must drive it (:func:`undriven_motions`). Empty when no
    choice of wheel rates works (e.g. m = 0). Steering: `beta` (thesis) or `heading` (0 = rolling forward),
    default as described.
    """
    beta = configuration(robot, beta, heading)
    a = coupled_constraints(nondimensional(robot), beta)  # m counts a gear's motions, as actuation_analysis does
    m = np.unique(nullity(robot, a))
    if len(m) != 1 or m[0] == 0:
        return SetList()
    found = minimal_set_search(robot, beta, int(m[0]), "determined", "minimal actuator sets", drive_all=True,
                               couplings="actuated")
    steer = tuple(_first_joint(robot, c) for c in steering_channels(robot, steering_split(robot, ())))
    names = jacobian_names(robot)
    return SetList([tuple(names[c] for c in s) + steer for s in found], found.complete, found.note)


def _first_joint(robot: Robot, channel: str) -> str:
    """The first joint of the steering actuator `channel` (:func:`steering_channels`): itself, or its linkage's."""
    return next((c.joints[0] for c in robot.couplings if c.channel_name == channel), channel)
