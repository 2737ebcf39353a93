"""Isotropy: condition numbers of kinematic models and the natural characteristic length (thesis §5.4-5.5).

``kappa = sigma_max / sigma_min`` (5.28) measures how a model amplifies relative errors; it is 1 for an
isotropic model (5.29). Linear and angular velocities have different units, so the angular velocity is
multiplied by a characteristic length D (its column of H divided by D); the D that makes the model best
conditioned is the *natural* length (§5.4; D = l12 for a differential drive, 5.51).

Two views are offered:

- :func:`isotropy_matrix` is the thesis's ``H = B_a B_na_s^-1`` (5.30)-(5.31) between m assigned and m selected
  velocities, as used in §5.5 for each vehicle type;
- :func:`twist_condition_number` is the model between the twist and a set of joint rates (by default the
  actuated ones): the joint rates as a linear map of the twist, restricted to the twists the robot can make at
  that configuration (an orthonormal basis of them after scaling omega by D). For the thesis's vehicle pairs
  (v_y, omega) it is the matrix of (5.47)-(5.48); it is basis independent.

The batched kernels use closed-form eigenvalues (:mod:`._sym`), so a map over 10^6 configurations takes well
under a second.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from .._shapes import as_names, as_reals, readonly
from ..couplings import gear_fill
from ..errors import ShapeError, UnknownNameError
from ..kinematics.linalg import centred, matrix_rank, reach
from ..kinematics.models import configuration
from ..robot import Robot, check_robot
from . import _fast
from .classification import classify
from .lines import _rate_block, constraint_lines, element_rows, line_parameters, rows_at
from .singularity import check_positive_length, robot_size

#: Search interval of the natural length (see :func:`natural_length`): from ``LENGTH_RANGE[0]`` robot sizes to
#: ``LENGTH_RANGE[1]`` times the robot's largest length from its origin (:func:`~wmrkit.kinematics.linalg.reach`).
LENGTH_RANGE = (1e-3, 1e3)


def condition_number(h: ArrayLike) -> np.ndarray:
    """``kappa = sigma_max / sigma_min`` of eq. (5.28); ``inf`` where H is singular (``sigma_min <= 1e-13
    sigma_max``). ``(..., f, f') -> (...)``, finite entries, ``f, f' >= 1``. H maps the `f'` inputs (twist
    coordinates) to the `f` outputs (joint rates): with fewer outputs than inputs some inputs give no output
    (``inf``). Each matrix is divided by its largest entry first (kappa does not change): its SVD can neither
    overflow (entries of 1.7e308 gave kappa inf for 1) nor lose sigma_min to underflow."""
    h = as_reals(h, "condition_number: h")  # text raised numpy's 'could not convert string to float'
    if h.ndim < 2 or 0 in h.shape[-2:] or not np.all(np.isfinite(h)):
        raise ShapeError(f"condition_number: expected matrices (..., f, f') with f, f' >= 1 and finite entries, got "
                         f"shape {h.shape}" + ("" if np.all(np.isfinite(h)) else " with entries that are not finite"))
    if h.shape[-2] < h.shape[-1]:  # f joints cannot tell f' > f motions apart (the SVD would give f values)
        return np.full(h.shape[:-2], np.inf)
    top = np.abs(h).max(axis=(-2, -1), keepdims=True)
    s = np.linalg.svd(h / np.where(top > 0, top, 1.0), compute_uv=False)
    # the ratio only where it is kappa: elsewhere s_max / s_min overflowed (s_min 1e-310) before np.where chose inf
    regular = s[..., -1] > 1e-13 * s[..., 0]
    return np.divide(s[..., 0], s[..., -1], out=np.full(s.shape[:-1], np.inf), where=regular)


def isotropy_matrix(robot: Robot, beta: ArrayLike | None, assigned: tuple[str, ...], selected: tuple[str, ...],
                    *, length: float = 1.0, heading: ArrayLike | None = None) -> np.ndarray:
    """``H = B_a B_na_s^-1`` of eqs. (5.30)-(5.31): ``H q_na_s = q_a``, with omega scaled by `length` [m].

    ``(..., n_steer) -> (..., m, m)`` with ``m = len(assigned) = len(selected)`` the mobility. If omega is among
    `selected` its column is divided by `length`; if among `assigned` its row is multiplied by it (§5.4). B is a
    basis of the null space of the slip matrix (6.7); H does not depend on which basis. Steering: `beta` (thesis,
    None: as described) or `heading` (0 = rolling forward).
    """
    check_robot(robot)
    length = check_positive_length(length)
    beta = robot.steering(beta, heading)
    assigned, selected = (as_names(v, k, "velocity names", UnknownNameError)
                          for k, v in (("assigned", assigned), ("selected", selected)))
    if len(assigned) != len(selected) or set(assigned) & set(selected):
        raise UnknownNameError(f"isotropy_matrix: need as many selected as assigned velocities, disjoint; got "
                               f"{list(assigned)} and {list(selected)}")
    ia = [robot.velocity_index(n) for n in assigned]
    isel = [robot.velocity_index(n) for n in selected]
    a = robot.constraint_matrix(beta)
    k, m = a.shape[-1], len(assigned)
    pad = np.zeros((*a.shape[:-2], max(k - a.shape[-2], 0), k))
    vh = np.linalg.svd(np.concatenate([a, pad], axis=-2))[2]
    b = np.swapaxes(vh[..., k - m:, :], -1, -2)  # (..., k, m)
    h = b[..., ia, :] @ np.linalg.inv(b[..., isel, :])
    col = np.array([1.0 / length if n == "omega" else 1.0 for n in selected])
    row = np.array([length if n == "omega" else 1.0 for n in assigned])
    return h * col * row[:, None]


def isotropy_length(robot: Robot, beta: ArrayLike | None, assigned: tuple[str, ...],
                    selected: tuple[str, ...], *, heading: ArrayLike | None = None) -> tuple[float, float]:
    """Natural length and condition number of :func:`isotropy_matrix` at one configuration: ``(D [m], kappa)``;
    steering `beta` (thesis) or `heading` (0 = rolling forward).

    Without omega among the velocities there is no D to choose: returns ``(nan, kappa)``.
    """
    check_robot(robot)
    beta = robot.steering(beta, heading)
    assigned, selected = (as_names(v, k, "velocity names", UnknownNameError)
                          for k, v in (("assigned", assigned), ("selected", selected)))
    if "omega" not in assigned + selected:
        return float("nan"), float(condition_number(isotropy_matrix(robot, beta, assigned, selected)))
    return _minimise_length(lambda d: float(condition_number(isotropy_matrix(robot, beta, assigned, selected,
                                                                             length=d))), robot)


def default_joints(robot: Robot) -> tuple[str, ...]:
    """The actuated joint rates that enter the velocity vector, or every wheel spin if none is declared."""
    check_robot(robot)
    rates = set(robot.rate_names)
    actuated = tuple(n for n in robot.actuated if n in rates)
    return actuated or tuple(n for n in robot.rate_names if n.split(".")[-1].startswith("spin"))


@dataclass(frozen=True, eq=False)
class TwistModel:
    """Joint rates as linear maps of the twist, and the robot's motion constraints, for fast batched evaluation.

    ``rates(beta) @ twist_robot`` gives the `joints` rates (per wheel ``-W^+ P``, eqs. 3.22, 4.5); the twists
    the robot can make satisfy ``constraints(beta) @ twist_robot = 0`` (5.7). ``mobility`` is the generic m;
    `geared`: with the robot's ``gear`` couplings held (:func:`twist_model`), m the one they leave as described.
    """

    robot: Robot
    joints: tuple[str, ...]
    mobility: int
    coefficients: np.ndarray  # (n_joints, 2 n_elements)
    geared: bool = False

    def rates(self, beta: ArrayLike | None = None) -> np.ndarray:
        """``(..., n_steer) -> (..., n_joints, 3)``: d(joint rate)/d(twist), rad/m and rad."""
        return np.einsum("jk,...kc->...jc", self.coefficients, element_rows(self.robot, beta))

    def constraints(self, beta: ArrayLike | None = None) -> np.ndarray:
        """``(..., n_steer) -> (..., n_lines, 3)``: the axle lines K_r* (5.2), normalised (with the lines a gear
        adds when `geared`)."""
        return constraint_lines(self.robot, coupled=self.geared).lines(beta)


def twist_model(robot: Robot, joints: tuple[str, ...] | None = None, *, geared: bool = False) -> TwistModel:
    """The :class:`TwistModel` of `robot` for `joints` (names from ``robot.rate_names``; default actuated).

    `geared` (on a robot with a ``gear`` coupling; else ignored): the gears held, as ``fk`` and the actuation analysis
    hold them. A gear is one mechanism, so one of its joints among `joints` brings in all of them
    (:func:`~wmrkit.couplings.gear_fill`: the same model whichever of them the description lists), and the twists
    are those the gears allow: the lines :func:`.lines.constraint_lines` gives with ``coupled``, m = 3 minus their
    rank at the described configuration (a gear of two omni wheels' spins leaves m = 2: one line the ICR lies on,
    the thesis's (v, D omega) pair about it, as for a fixed axle).
    """
    check_robot(robot)
    joints = default_joints(robot) if joints is None else as_names(joints, "joints", "joint rate names",
                                                                   UnknownNameError)
    for n in joints:
        if n not in robot.rate_names:
            raise UnknownNameError(f"robot '{robot.name}' has no joint rate '{n}' "
                                   f"(rates: {', '.join(robot.rate_names)})")
    if not (geared and any(c.kind == "gear" for c in robot.couplings)):
        return _twist_model(robot, joints)
    names = robot.rate_names
    filled = gear_fill(robot.couplings, names, tuple(map(names.index, joints)))[0]
    return _twist_model(robot, tuple(names[i] for i in filled), True)


def _geared_mobility(robot: Robot) -> int:
    """3 minus the rank of the lines the twist obeys with the gears held, at the described configuration (about the
    wheels' centroid in the robot's size: the rank decisions of :mod:`..kinematics.linalg`)."""
    lines = constraint_lines(robot, coupled=True).lines()
    if len(lines) == 0:
        return 3
    return 3 - int(matrix_rank(centred(robot, lines, metres=True)))


@functools.lru_cache(maxsize=256)
def _twist_model(robot: Robot, joints: tuple[str, ...], geared: bool = False) -> TwistModel:
    n_rows = 2 * sum(len(w.elements()) for w in robot.wheels)
    coefficients = np.zeros((len(joints), n_rows))
    start = 0
    for w in robot.wheels:
        rows = 2 * len(w.elements())
        inverse = -np.linalg.pinv(_rate_block(w))  # (n_rates, rows): rates = -W^+ P twist
        for j, name in enumerate(joints):
            if name in w.rate_names:
                coefficients[j, start:start + rows] = inverse[w.rate_names.index(name)]
        start += rows
    mobility = _geared_mobility(robot) if geared else classify(robot).mobility
    return TwistModel(robot, joints, mobility, readonly(coefficients), geared)


def twist_condition_number(robot: Robot, beta: ArrayLike | None = None, *, joints: tuple[str, ...] | None = None,
                           length: float | None = None, heading: ArrayLike | None = None,
                           geared: bool = False) -> np.ndarray:
    """Condition number (5.28) of the joint rates as a function of the admissible twists ``(vx, vy, D omega)``.

    ``(..., n_steer) -> (...)``; `joints` default to :func:`default_joints`, `length` D [m] to the natural
    length at the described configuration. ``inf`` where the joints cannot tell some motions apart (a singular
    model, ch. 6); ``nan`` where the robot cannot move (uncoordinated steering). With m = 1 it is 1 wherever
    defined: isotropy does not apply to types 4 and 5 (§5.5.4-5.5.5). Steering as `beta` or `heading`;
    `geared`: over the motions the robot's gears allow (:func:`twist_model`).
    """
    check_robot(robot)
    model = twist_model(robot, joints, geared=geared)
    beta = configuration(robot, beta, heading)
    if length is None:
        length = natural_length(robot, joints=model.joints, geared=geared)[0]
    else:
        length = check_positive_length(length)
    return _kappa(model, beta, float(length))


def _kappa(model: TwistModel, beta: np.ndarray, length: float) -> np.ndarray:
    """Condition numbers at configurations `beta` ``(..., n_steer) -> (...)``, in cache-sized chunks."""
    flat = beta.reshape(int(np.prod(beta.shape[:-1])), beta.shape[-1])
    out = np.empty(len(flat))
    p = line_parameters(model.robot)
    for s in range(0, len(flat), _fast.CHUNK):
        rows = _element_rows_one(p, flat[0]) if len(flat) == 1 else _fast.element_rows_cm(p, flat[s:s + _fast.CHUNK])
        rates, lines, unit = _in_robot_lengths(model, rows)
        out[s:s + _fast.CHUNK] = _fast.kappa_cm(model.mobility, rates, lines, float(length) / unit)
    return out.reshape(beta.shape[:-1])


def kappa_function(model: TwistModel, beta: np.ndarray):
    """``length -> kappa (N,)`` at configurations `beta` ``(N, n_steer)`` (one chunk), rows computed once."""
    rates, lines, unit = _in_robot_lengths(model, _fast.element_rows_cm(line_parameters(model.robot), beta))
    return lambda length: _fast.kappa_cm(model.mobility, rates, lines, float(length) / unit)


def length_applies(mobility: int, kappa: float) -> bool:
    """Whether a natural length goes with a condition number `kappa` of a robot of `mobility` m: where kappa is
    finite and depends on the length (m >= 2). Elsewhere :func:`natural_length` falls back to the robot size, which
    minimises nothing."""
    return mobility >= 2 and bool(np.isfinite(kappa))


def natural_length(robot: Robot, beta: ArrayLike | None = None, *, joints: tuple[str, ...] | None = None,
                   heading: ArrayLike | None = None, geared: bool = False) -> tuple[float, float]:
    """The characteristic length minimising :func:`twist_condition_number` at one configuration: ``(D [m], kappa)``.

    m = 2: closed form ``D = |h_omega| / |h_v|``, the ratio of the column norms (equal diagonals of ``H^T H``,
    (5.50)-(5.51): D = l12 for a differential drive). m = 3: a 1-D search (D = sqrt(2) L for the isotropic
    three-wheel omni robot). Where kappa does not depend on D (m = 1) D is the robot size. Steering: `beta`
    (thesis) or `heading` (0 = rolling forward), default as described; `geared` as :func:`twist_model`.
    """
    check_robot(robot)
    model = twist_model(robot, joints, geared=geared)
    beta = configuration(robot, beta, heading)
    if beta.ndim != 1:
        raise UnknownNameError("natural_length takes one configuration (shape (n_steer,))")
    return _natural_length(model, beta, robot_size(robot))


def described_condition(robot: Robot, length: float | None = None) -> tuple[tuple[str, ...], float, float]:
    """The condition number ``analyze`` and the studio give, at the described configuration: ``(joints, D [m],
    kappa)``. The joints are :func:`default_joints` with each gear's joints (one mechanism), the gears held
    (``geared``, :func:`twist_model`); D is the natural length (:func:`natural_length`) unless `length` is given."""
    joints = twist_model(robot, default_joints(robot), geared=True).joints
    if length is None:
        d, kappa = natural_length(robot, joints=joints, geared=True)
        return joints, float(d), float(kappa)
    return joints, float(length), float(twist_condition_number(robot, joints=joints, length=length, geared=True))


def _natural_length(model: TwistModel, beta: np.ndarray, size: float) -> tuple[float, float]:
    """:func:`natural_length` at one checked configuration ``(n_steer,)``, the element rows computed once (the
    values of :func:`_kappa`); for m = 3 the search grid of lengths is one batched SVD."""
    p = line_parameters(model.robot)
    rates, lines, unit = _in_robot_lengths(model, _element_rows_one(p, beta))
    if model.mobility == 2:
        a, b, ok = _fast.columns_m2(rates, lines)
        v, w = float(np.linalg.norm(a)), float(np.linalg.norm(b))
        if not ok[0]:  # kappa_cm's value, with these columns
            return size, np.nan
        if _blind(v, w):  # w / v was a length of 1e-18 m (or 7e15 m) with a kappa of round-off
            return size, np.inf
        length = w / v
        return length * unit, float(condition_number(np.stack([a[:, 0], b[:, 0] / length], axis=-1)))
    if model.mobility == 3:  # kappa_cm's SVD route for one configuration, without its batch bookkeeping
        h = rates[:, :, 0]
        if _blind(float(np.linalg.norm(h[:, :2])), float(np.linalg.norm(h[:, 2]))):
            return size, np.inf  # the search found a kappa of 1e11 where the omega column's round-off met D = 1e-6 m

        def many(lengths: np.ndarray) -> np.ndarray:
            scale = np.ones((len(lengths), 3))
            scale[:, 2] = 1.0 / (lengths / unit)  # as kappa_cm scales (kappa_function: the same values)
            return condition_number(h * scale[:, None, :])

        def one(length: float) -> float:  # condition_number's value and threshold, on one (J, 3) matrix
            if h.shape[0] < 3:
                return np.inf
            sv = np.linalg.svd(h * np.array([1.0, 1.0, 1.0 / (length / unit)]), compute_uv=False)
            return float(sv[0] / sv[-1]) if sv[-1] > 1e-13 * sv[0] else np.inf

        return _minimise_length(one, model.robot, many)
    return size, float(_fast.kappa_cm(model.mobility, rates, lines, size / unit)[0])


def _in_robot_lengths(model: TwistModel, rows: np.ndarray) -> tuple[np.ndarray, np.ndarray, float]:
    """The joint rates ``(J, 3, N)`` and normalised axle lines ``(R, 3, N)`` at element `rows` in the robot's
    largest length from its origin ``L`` (:func:`~wmrkit.kinematics.linalg.reach`: the twist is the origin's), and
    ``L`` [m]: the twist's lengths and the lines' ``d`` divided by L (rates per unit speed times L). Every
    threshold of :mod:`._fast` is then relative: a robot of 1 um had its axles "one line" within 1e-6 m, all of
    them. Condition numbers are unchanged; a length D of the robot is ``D / L`` here."""
    unit = reach(model.robot)
    scale = np.array([unit, unit, 1.0])[None, :, None]
    lines = _fast.combine_lines(constraint_lines(model.robot, coupled=model.geared), rows) * np.array(
        [1.0, 1.0, 1.0 / unit])[None, :, None]
    return _fast.combine_rates(model.coefficients, rows) * scale, _fast.normalize_cm(lines), unit


def _blind(v: float, w: float) -> bool:
    """Whether joints whose rates have norm `v` per unit speed and `w` per unit turn rate, in the robot's largest
    length (:func:`_in_robot_lengths`), are blind to the translation or to the turn rate: kappa is then infinite at
    every D (one below 1e-13 of the other is round-off of 0; two steering rates blind to the speed once gave a
    natural length of 7e15 m)."""
    return not (v > 1e-13 * w and w > 1e-13 * v)


def _element_rows_one(p, beta: np.ndarray) -> np.ndarray:
    """``_fast.element_rows_cm(p, beta[None])`` for one configuration ``(n_steer,)``: ``(2E, 3, 1)``, from
    :func:`.lines.rows_at` (vectorised over the elements instead of the configurations)."""
    wheel_beta = np.array(p.beta_described, dtype=float)
    wheel_beta[p.steer_wheels] = beta
    return rows_at(p, wheel_beta)[..., None]


def _minimise_length(kappa, robot: Robot, many=None) -> tuple[float, float]:
    """Minimise ``kappa(D)`` over D from ``LENGTH_RANGE[0]`` times `robot`'s size (:func:`robot_size`)
    to ``LENGTH_RANGE[1]`` times its :func:`~wmrkit.kinematics.linalg.reach` (log scale); ties go to the size.
    `many`, if given, is `kappa` over an array of lengths at once (the same values). The top is not 1000 sizes: a
    double castor of 0.5 m offset and radius mounted at the origin, natural length 0.29 m, once sized 1 mm, was
    searched up to 1 m only."""
    size = robot_size(robot)
    lo, hi = np.log(LENGTH_RANGE[0] * size), np.log(LENGTH_RANGE[1] * reach(robot))
    grid = np.linspace(lo, hi, 121)
    values = many(np.exp(grid)) if many is not None else np.array([kappa(np.exp(x)) for x in grid])
    k_size = kappa(size)
    finite = np.isfinite(values)
    if not finite.any():
        return size, k_size
    if np.nanmax(values[finite]) - np.nanmin(values[finite]) < 1e-9 * np.nanmin(values[finite]):
        return size, k_size
    i = int(np.nanargmin(np.where(finite, values, np.inf)))
    x = golden_section(lambda t: kappa(np.exp(t)), grid[max(i - 1, 0)], grid[min(i + 1, len(grid) - 1)])
    fx = kappa(np.exp(x))
    return (float(np.exp(x)), float(fx)) if fx <= values[i] else (float(np.exp(grid[i])), float(values[i]))


def golden_section(f, a: float, b: float, *, tol: float = 1e-13) -> float:
    """Minimiser of a unimodal `f` on ``[a, b]`` by golden-section search (no smoothness needed: kappa has a
    kink at its isotropic minimum, where two singular values cross)."""
    ratio = (np.sqrt(5) - 1) / 2
    c, d = b - ratio * (b - a), a + ratio * (b - a)
    fc, fd = f(c), f(d)
    while b - a > tol * max(1.0, abs(a) + abs(b)):
        if fc <= fd:
            b, d, fd = d, c, fc
            c = b - ratio * (b - a)
            fc = f(c)
        else:
            a, c, fc = c, d, fd
            d = a + ratio * (b - a)
            fd = f(d)
    return (a + b) / 2


def condition_map(robot: Robot, beta: ArrayLike | None = None, *, joints: tuple[str, ...] | None = None,
                  length: float | None = None, heading: ArrayLike | None = None, geared: bool = False) -> np.ndarray:
    """:func:`twist_condition_number` over many configurations (the same kernel): ``(..., n_steer) -> (...)``,
    steering `beta` (thesis) or `heading` (0 = rolling forward); `geared` as :func:`twist_model`.

    Closed-form eigenvalues in cache-sized chunks: 10^6 configurations in well under 2 s (benchmarks/).
    """
    check_robot(robot)
    return twist_condition_number(robot, beta, joints=joints, length=length, heading=heading, geared=geared)
