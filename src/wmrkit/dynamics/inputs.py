"""Inputs of the simulator (:class:`Inputs`): joint torques, servo references and gains over time, checked where they
are made, and compiled for the kernels against a model (:func:`compiled_inputs`)."""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from .._shapes import as_reals, readonly
from ..errors import ShapeError, WmrkitError
from ..limits import MAX_TORQUE
from .linkages import SETPOINT_TOL, continued, first_breach, heading_breach, setpoint_knots
from .model import DynamicModel


@dataclass(frozen=True, eq=False)
class Inputs:
    """Joint inputs over time, linear between the knots ``time`` and held outside them.

    ``torques (K, n)`` [N m]: feed-forward generalized torques on the columns of ``DynamicModel.names`` (wheel
    spins, steering); ``rate_reference (K, n)`` [rad/s] and ``rate_gain (n,)`` [N m s/rad]: wheel-rate servos
    ``tau += gain (reference - rate)``, saturated at ``torque_limit (n,)``; ``heading_reference (K, n_steer)``
    [rad, headings: 0 = rolling straight ahead] with ``steer_kp``, ``steer_kd (n_steer,)``: steering servos,
    saturated smoothly at ``steer_limit (n_steer,)`` [N m] (``limit tanh(pd / limit)``; default and inf: none);
    ``twist (M, 3)`` [m/s, m/s, rad/s] at the knots ``twist_time (M,)`` [s], or None: the body twists whose no-slip
    motion the servo references are, linear between their knots (a twist program's, on its own time axis so that
    ``dataclasses.replace(inputs, time=...)`` keeps them whole); :func:`~.simulate.simulate` integrates them into
    :attr:`~.simulate.Simulation.nominal_pose`. Checked when made (shapes that agree,
    times strictly increasing, finite values, gains and limits >= 0); a simulator checks the widths against its
    model, and the heading set-points of the servoed (``steer_kp > 0``) wheels of each ``linkage`` it holds: on its
    law at every knot (within ``linkages.SETPOINT_TOL``; else :func:`~.simulate.simulate` and a
    :class:`~.simulate.Stepper` refuse them: the servos would fight it) and, between knots, its followers set by
    the law from the reference's interpolation (its leader's, else its first servoed follower's;
    :func:`~.linkages.setpoint_knots`); ``fight_linkages`` True: neither (the servos fight through the linkage, as
    :func:`~.programs.twist_program` lets them with ``allow_slip``).
    """

    time: np.ndarray
    torques: np.ndarray
    rate_reference: np.ndarray
    rate_gain: np.ndarray
    torque_limit: np.ndarray
    heading_reference: np.ndarray
    steer_kp: np.ndarray
    steer_kd: np.ndarray
    steer_limit: np.ndarray | None = None
    twist: np.ndarray | None = None
    twist_time: np.ndarray | None = None
    fight_linkages: bool = False

    def __post_init__(self) -> None:
        _check_inputs(self)  # once, where the inputs are made; a simulator checks their widths against its model

    @classmethod
    def torques_only(cls, model: DynamicModel, time: ArrayLike, torques: dict[str, ArrayLike]) -> Inputs:
        """Pure torque inputs: `torques` maps actuated joints (``wheel.spin``, ``wheel.steer``) to values (K,)."""
        if not isinstance(torques, Mapping):  # a list raised "'list' object has no attribute 'items'"
            raise ShapeError(f"torques: expected a mapping {{joint: values [N m]}} such as {{'left.spin': 1.0}}, got "
                             f"{type(torques).__name__} {torques!r:.60}")
        t = knots(time)
        tau = np.zeros((len(t), model.n))
        for name, values in torques.items():
            column, values = joint_column(model, name), as_reals(values, f"torques['{name}']")
            if values.shape not in ((), (1,), t.shape):
                raise ShapeError(f"torques['{name}']: expected one value or {len(t)}, one per time, got shape "
                                 f"{values.shape}")
            tau[:, column] = values
        s = len(model.steer_columns)
        return cls(*(readonly(a) for a in (t, tau, np.zeros_like(tau), np.zeros(model.n), np.full(model.n, np.inf),
                                            np.zeros((len(t), s)), np.zeros(s), np.zeros(s))))


def joint_column(model: DynamicModel, name: str) -> int:
    """Column of the actuated joint `name` (``wheel.spin``, ``wheel.steer``...), or a one-line error."""
    if name not in model.names[3:]:
        raise WmrkitError(f"robot '{model.robot.name}' has no joint '{name}' (joints: {', '.join(model.names[3:])})")
    if not model.is_actuated(model.names.index(name)):
        raise WmrkitError(f"joint '{name}' of robot '{model.robot.name}' is not actuated (actuated: "
                          f"{', '.join(model.robot.actuated) or 'none'})")
    return model.names.index(name)


def knots(time: ArrayLike) -> np.ndarray:
    """`time` as the knots of inputs ``(K,)`` [s], or a one-line error: at least one, finite, strictly increasing."""
    t = np.atleast_1d(as_reals(time, "time"))  # strictly increasing with finite ends: finite
    if t.ndim != 1 or not len(t) or not (math.isfinite(t[0]) and math.isfinite(t[-1]) and (t[1:] > t[:-1]).all()):
        raise ShapeError(f"time: input times must be at least one, finite and strictly increasing, got "
                          f"{t.tolist() if t.size <= 6 else f'shape {t.shape}'}")
    return t


#: The fields of :class:`Inputs` after ``time``, in the kernels' order, and the values each one may hold.
_INPUT_FIELDS = (("torques", f"torques within {MAX_TORQUE:g} N m (limits.MAX_TORQUE)"),
                 ("rate_reference", "finite numbers"),
                 ("rate_gain", "finite numbers >= 0"), ("torque_limit", "numbers >= 0 (inf: no limit)"),
                 ("heading_reference", "finite numbers"), ("steer_kp", "finite numbers >= 0"),
                 ("steer_kd", "finite numbers >= 0"))


def _check_inputs(inputs: Inputs) -> None:
    """Raise :class:`ShapeError` naming the field of `inputs` whose shape does not agree with the others (K times,
    n velocities, n_steer steering joints) or whose values make no sense (times not strictly increasing, values not
    finite, gains or limits below 0); the model's sizes are checked by :func:`compiled_inputs`."""
    k = len(knots(inputs.time))
    arrays = [np.asarray(getattr(inputs, name), dtype=float) for name, _ in _INPUT_FIELDS]
    for j, size in ((0, "n"), (4, "n_steer")):
        if arrays[j].ndim != 2 or len(arrays[j]) != k:
            raise ShapeError(f"{_INPUT_FIELDS[j][0]}: expected shape (K, {size}) with K = {k} rows, one per time, "
                             f"got {arrays[j].shape}")
    n, s = arrays[0].shape[1], arrays[4].shape[1]
    for (name, want), a, shape in zip(_INPUT_FIELDS, arrays, ((k, n), (k, n), (n,), (n,), (k, s), (s,), (s,)),
                                      strict=True):
        if a.shape != shape:
            raise ShapeError(f"{name}: expected shape {shape} ({n} velocities as torques, {s} steering joints as "
                             f"heading_reference), got {a.shape}")
        bad = ~(a >= 0) if name == "torque_limit" else ~np.isfinite(a) | (a < 0 if ">=" in want else False)
        if name == "torques":
            bad = ~(np.abs(a) <= MAX_TORQUE)  # NaN included
        if bad.any():
            raise ShapeError(f"{name}: expected {want}, got {float(a[bad].flat[0])!r}")
    if (inputs.twist is None) != (inputs.twist_time is None):
        raise WmrkitError("twist, twist_time: give both (body twists at their knots) or neither")
    if inputs.twist is not None:
        m = len(knots(inputs.twist_time))
        if not (np.shape(inputs.twist) == (m, 3) and np.all(np.isfinite(inputs.twist))):
            raise ShapeError(f"twist: expected finite body twists of shape ({m}, 3), one per twist_time, got shape "
                             f"{np.shape(inputs.twist)}")


def compiled_inputs(model: DynamicModel, inputs: Inputs) -> tuple:
    """The kernels' inputs (writable C copies: one compiled signature); :class:`ShapeError` naming the field of
    `inputs` whose width does not fit `model` (the kernels would read out of bounds). Heading set-points on the law
    of each held linkage at every knot get knots between them on it (:class:`Inputs`); set-points off it at a knot
    are refused (:func:`setpoint_problem`), unless ``inputs.fight_linkages``: then both are run as given. Each step of
    a steering set-point between knots turns the short way (:func:`~.linkages.continued`: +179 deg then -179 deg is
    2 deg, not 358)."""
    arrays = [np.array(getattr(inputs, name), dtype=float, order="C") for name, _ in _INPUT_FIELDS]
    n, s = model.n, len(model.steer_columns)
    for (name, _), a, width in zip(_INPUT_FIELDS, arrays, (n, n, n, n, s, s, s), strict=True):
        if a.shape[-1] != width:
            raise ShapeError(f"{name}: expected {width} columns for robot '{model.robot.name}' (n = {n} velocities "
                             f"of model.names, n_steer = {s}), got shape {a.shape}")
    tau, rref, gain, limit, href, kp, kd = arrays
    tk = np.array(np.atleast_1d(inputs.time), dtype=float)
    beta_ref = np.array(model.robot.beta_of_heading(href), dtype=float, order="C") if s else href
    commanded = set(np.flatnonzero(kp > 0).tolist())
    if (len(model.pack[17]) or model.pack[16].shape[1]) and commanded and not inputs.fight_linkages:
        k = first_breach(model, href, commanded)  # every row at once
        problem = None if k is None else setpoint_problem(model, href[k], commanded)
        if problem:
            raise WmrkitError(f"heading_reference: at t = {tk[k]:g} s, {problem}")
        at, on_law = setpoint_knots(model, tk, beta_ref, commanded)
        if len(at) > len(tk):  # the linkages' followers on their laws between the knots
            tau, rref = (np.column_stack([np.interp(at, tk, c) for c in a.T]) for a in (tau, rref))
            tk, beta_ref = at, np.ascontiguousarray(on_law)
        else:
            beta_ref = on_law
    elif s:
        beta_ref = continued(model, beta_ref, set())  # each step the short way (a heading written wrapped)
    return (tk, np.ascontiguousarray(tau), np.ascontiguousarray(rref), gain, limit, beta_ref, kp, kd,
            _steer_limits(model, inputs.steer_limit))


def setpoint_problem(model: DynamicModel, headings: np.ndarray, commanded: set[int]) -> str | None:
    """Why heading set-points `headings` ``(n_steer,)`` [rad] of the servoed indices `commanded` break a linkage
    or steering gear `model` holds (:func:`~.linkages.heading_breach`), naming the wheels; None when they do not."""
    breach = heading_breach(model, headings, commanded)
    if breach is None:
        return None
    j, ref, want, c = breach
    steered = model.robot.steer_names
    by = "whatever the others do" if ref is None else f"with {steered[ref]}'s at {headings[ref]:.6g} rad"
    kind = c.kind
    return (f"{steered[j]}'s {headings[j]:.6g} rad breaks {c.words()}, which sets {steered[j]} at heading "
            f"{want:.6g} rad {by}: the steering servos would fight the {kind} the dynamics hold; give headings on its "
            f"{'law' if kind == 'linkage' else 'ratios'} (within {SETPOINT_TOL:g} rad), steer_kp > 0 on one wheel per "
            f"{kind}, or fight_linkages=True")


def _steer_limits(model: DynamicModel, limit: ArrayLike | None) -> np.ndarray:
    """The compiled kernels' steering-servo limits, 0 where there is none (no infinity may reach them)."""
    if limit is None:
        return np.zeros(len(model.steer_columns))
    limit = np.asarray(limit, dtype=float)
    if limit.shape != (len(model.steer_columns),) or not np.all(limit > 0):  # NaN included
        raise ShapeError(f"steer_limit: expected {len(model.steer_columns)} torques > 0 N m (inf: none), got "
                          f"{limit.tolist()}")
    return np.where(np.isinf(limit), 0.0, limit)


def held_values(value: ArrayLike, size: int, name: str) -> np.ndarray:
    """`value` as `size` floats for :meth:`~.simulate.Stepper.hold` (its argument `name`), or a one-line error."""
    value = np.asarray(value, dtype=float)
    if value.shape != (size,):
        raise ShapeError(f"hold: {name} must be {size} numbers, got shape {value.shape}")
    return value  # not checked for NaN here: a NaN reference makes the state NaN, which advance() reports
