"""Per-wheel inverse kinematics (thesis §8.4) and forward kinematics by least squares (4.11), batched.

:func:`wheel_commands` turns desired body twists into what every wheel must do: steering angles, spin rates,
steering rates, roller rates, and each fixed wheel's lateral slip so that an infeasible twist is reported, never
silently accepted. :func:`forward_kinematics` goes the other way: some joint rates given, the twist that best
explains them and the slip they leave. ``docs/wheel-ik.md`` states the policies (closest steering angle, zero speed).
"""

from __future__ import annotations

import warnings
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from .._shapes import as_names, as_reals, as_vectors, finite_number, readonly
from ..couplings import Coupling, GearWarning
from ..errors import ShapeError, UnknownNameError
from ..limits import MAX_QUERY_RATE
from ..robot import Robot, check_robot
from ..units import Kind
from ..wheels import heading_from_beta, heading_in_range
from . import _ik_fast
from ._ik_fast import wrap_angle
from .gear_check import GEAR_RTOL, contact_lever, gear_table, gears_hold, given_gear_breaches, steer_gears_hold
from .linalg import decision_matrix, geared_twist_determined, robot_size, robot_solve
from .linkage_check import LinkageAngleWarning, given_breaches, linkage_holds

__all__ = ["GEAR_RTOL", "WheelCommands", "forward_kinematics", "gear_error", "resolve_rate_name", "twist_is_determined",
           "wheel_commands", "wrap_angle"]

#: :func:`wheel_commands`' default ``speed_tol`` [m/s]: a steering axis slower than this holds its angle.
SPEED_TOL = 1e-12
#: :func:`wheel_commands`' default ``slip_tol`` [m/s]: a fixed wheel's side slip, and a gear's departure at a contact
#: (:mod:`.gear_check`), within it roll (also the floor of ``realtime``'s ik, the generated ``in_gear`` and
#: :func:`forward_kinematics_check`'s tolerance and gear check).
SLIP_TOL = 1e-9


@dataclass(frozen=True, eq=False)
class WheelCommands:
    """Per-wheel commands for a batch of body twists (§8.4). Frozen; every array is read-only.

    ``eq=False``: array fields. With ``N`` wheels, ``n_steer`` steering angles and ``n_rates`` joint rates:

    - ``steer`` ``(..., N)`` [rad] in ``(-pi, pi]``: steerable and double wheels the angle zeroing the lateral slip
      (8.9), closest to the current one (a linked wheel: the root its linkage sets); castors the current angle; NaN
      for wheels that do not steer.
    - ``spin`` ``(..., N)`` [rad/s]: spin rate; double wheels and double castors the mean of the two (3.28)/(3.35).
    - ``steer_rate`` ``(..., N)`` [rad/s]: castors (8.24), double castors; 0 for double wheels (angle held
      relative to the body); NaN where the twist alone does not define it (steerable) or there is no joint.
    - ``rates`` ``(..., n_rates)``: every joint rate in ``robot.rate_names`` order (rollers, ``spin1``/``spin2``).
    - ``slip`` ``(..., N)`` [m/s]: lateral slip (3.11) row 0 / (8.14) left at each fixed wheel, 0 elsewhere and
      where it is round-off (``_ik_fast.SLIP_ROUNDOFF``).
    - ``feasible`` ``(...)`` bool: every ``|slip| <= slip_tol``, every heading within its wheel's ``steer_range``,
      every gear coupling's rates in its ratios (``in_gear``), every steering gear's angles in its ratios
      (``in_steer_gear``) and every held linkage's angles on its law (``in_linkage``).
    - ``in_range`` ``(..., N)`` bool: the wheel's heading lies in its ``steer_range`` (True for wheels without one,
      and for those that do not steer). The root of (8.9) is the one closest to the current heading unless only
      the other lies within the range; when neither does the twist is not feasible (the steering cannot reach it).
    - ``beta`` ``(..., n_steer)`` [rad]: the steering configuration the commands hold at (``steer_names`` order).
    - ``heading`` ``(..., N)`` [rad] in ``(-pi, pi]``: the users' steering angle, each wheel's rolling direction
      (0 = straight ahead, +x), ``steer + delta - pi/2`` (:func:`wmrkit.wheels.heading_from_beta`); NaN for wheels
      that do not steer. ``steer`` is the same angle in the thesis's convention (β, the axle).
    - ``held`` ``(..., N)`` bool: the steering axis does not move, the angle is undefined and was kept.
    - ``in_gear`` ``(..., n_couplings)`` bool, one per ``robot.couplings``: a ``gear``'s joint rates are
      ``ratio_j * u`` for one ``u`` (:func:`~wmrkit.kinematics.gear_check.gears_hold`: each departure within
      ``GEAR_RTOL`` of the largest rate, or moving its contact by at most ``slip_tol``); True for the other
      kinds (a differential leaves the rates' difference free).
    - ``in_linkage`` ``(..., n_couplings)`` bool: a ``linkage``'s steering angles on the ideal law it holds
      (:mod:`~wmrkit.kinematics.linkage_check`: each wheel off it would slip sideways by at most ``slip_tol``);
      True for the other couplings and the linkages with no law to hold.
    - ``in_steer_gear`` ``(..., n_couplings)`` bool: a ``gear`` between steering joints turns their angles too,
      ``beta_j - beta_j0 = ratio_j u``: False where it cannot set the angles the twist needs (each wheel it sets
      off would slip sideways by more than ``slip_tol``; :func:`~wmrkit.kinematics.gear_check.steer_breach`); True
      for the other couplings.
    """

    wheel_names: tuple[str, ...]
    rate_names: tuple[str, ...]
    steer: np.ndarray
    spin: np.ndarray
    steer_rate: np.ndarray
    rates: np.ndarray
    slip: np.ndarray
    feasible: np.ndarray
    beta: np.ndarray
    held: np.ndarray
    heading: np.ndarray
    in_range: np.ndarray
    in_gear: np.ndarray
    in_linkage: np.ndarray
    in_steer_gear: np.ndarray
    couplings: tuple[Coupling, ...] = ()

    def velocity(self, twist_robot: ArrayLike) -> np.ndarray:
        """The velocity vector ``(twist; rates)`` of ``Robot.velocity_names``. ``(..., 3) -> (..., 3 + n_rates)``."""
        t = np.broadcast_to(as_vectors(twist_robot, 3, "twist_robot"), (*self.rates.shape[:-1], 3))
        return np.concatenate([t, self.rates], axis=-1)

    def to_dict(self) -> dict[str, Any]:
        """One twist's commands as plain data (the ``wmrkit ik --json`` output); NaN stays NaN (JSON: null).

        ``{"wheels": {name: {"heading", "spin", "steer_rate", other joint rates...}}, "slip": {name: m/s},
        "out_of_range": [names of wheels outside their steer_range], "out_of_gear": [channel names of the gear
        couplings the rates break], "out_of_steer_gear": [those of the steering gears that cannot set the headings],
        "out_of_linkage": [those of the linkages the headings break], "feasible": bool}``: ``heading`` [rad] only
        for steered wheels (0 = rolling straight ahead). Only for a single twist (batch shape ``()``).
        """
        if self.feasible.shape != ():
            raise ShapeError(f"to_dict: expected one twist (batch shape ()), got batch shape {self.feasible.shape}")
        wheels: dict[str, dict[str, float]] = {}
        for i, name in enumerate(self.wheel_names):
            entry = {"heading": float(self.heading[i])} if np.isfinite(self.heading[i]) else {}
            entry |= {"spin": float(self.spin[i]), "steer_rate": float(self.steer_rate[i])}
            for rate_name, value in zip(self.rate_names, self.rates.tolist(), strict=True):
                wheel, _, joint = rate_name.partition(".")
                if wheel == name and joint not in ("spin", "steer"):
                    entry[joint] = value
            wheels[name] = entry
        def broken(held: np.ndarray) -> list[str]:
            return [c.channel_name for c, ok in zip(self.couplings, held.tolist(), strict=True) if not ok]

        return {"wheels": wheels, "slip": dict(zip(self.wheel_names, self.slip.tolist(), strict=True)),
                "out_of_range": [n for n, ok in zip(self.wheel_names, self.in_range.tolist(), strict=True) if not ok],
                "out_of_gear": broken(self.in_gear), "out_of_steer_gear": broken(self.in_steer_gear),
                "out_of_linkage": broken(self.in_linkage), "feasible": bool(self.feasible)}


def check_tolerances(speed_tol: float, slip_tol: float) -> None:
    """Both tolerances finite numbers >= 0 [m/s] (a negative or NaN slip_tol called every twist infeasible)."""
    for name, value in (("speed_tol", speed_tol), ("slip_tol", slip_tol)):
        if not (finite_number(value) and value >= 0):
            raise ShapeError(f"{name}: expected a finite tolerance >= 0 [m/s], got {value!r}")


def wheel_commands(
    robot: Robot, twist_robot: ArrayLike, beta: ArrayLike | None = None, *, heading: ArrayLike | None = None,
    speed_tol: float = SPEED_TOL, slip_tol: float = SLIP_TOL,
) -> WheelCommands:
    """Per-wheel inverse kinematics of the thesis §8.4 for a batch of body twists.

    ``(..., 3), (..., n_steer) -> WheelCommands`` with batch shape the broadcast of both. `twist_robot`:
    ``(v_x [m/s], v_y [m/s], omega [rad/s])`` in the robot frame; current steering angles [rad] as the thesis's
    `beta` or the users' `heading` (``robot.steer_names`` order; default the described ones).

    - steerable / double wheels: angle (8.9) of the two solutions ``b`` and ``b + pi`` closest to the current
      angle (the spin sign flips rather than the wheel turning half round), or the other one when only it is within
      the wheel's ``steer_range``, spin (8.12) with that sign; a wheel in a held ``linkage`` the root its linkage
      sets from its reference wheel (:func:`~wmrkit.kinematics.linkage_check.linkage_turns`); where the
      steering axis moves slower than `speed_tol` [m/s] the angle is undefined: current angle kept, spin 0.
    - castor: steering rate (8.24) and spin (8.25) at the current angle; double castor likewise (3.31)-(3.36).
    - Swedish, ball, orthogonal: spin (8.27) and roller rate (8.28, with the roller radius r_r).
    - fixed: spin (8.12) at its constant angle, and the lateral slip (8.14) the twist leaves: ``feasible`` is
      False when any exceeds `slip_tol` [m/s] (e.g. ``v_y != 0`` for a differential drive).
    - a ``gear`` coupling (``robot.couplings``) whose joints the twist asks to turn out of its ratios (a solid rear
      axle asked to turn) makes it False too: ``in_gear``, a departure moving a contact by more than `slip_tol`
      (the floor of the slip check: a turn of 1e-320 rad/s rolls as a side speed of 1e-320 m/s does).
    - a ``gear`` between steering joints that cannot set the angles (8.9) the twist needs (two double wheels geared
      1:2 asked for 20.6 and -14.0 deg) makes it False too: ``in_steer_gear`` (:mod:`~wmrkit.kinematics.gear_check`).
    - a ``linkage`` whose held law the angles break (a synchro drive's wheels, turning together, asked to turn the
      robot) makes it False too: ``in_linkage`` (:mod:`~wmrkit.kinematics.linkage_check`).
    """
    check_robot(robot)
    check_tolerances(speed_tol, slip_tol)
    p = _ik_fast.plan(robot)
    twist = as_vectors(twist_robot, 3, "twist_robot")
    if not (np.abs(twist) <= MAX_QUERY_RATE).all():  # NaN included
        raise ShapeError(f"twist_robot: expected finite speeds and turn rates within {MAX_QUERY_RATE:g} (m/s, "
                         f"rad/s; beyond, the wheel rates overflow), got {_first_bad(twist)}")
    beta = robot.steering(beta, heading)
    current = robot.beta if beta is None else beta
    try:
        batch = np.broadcast_shapes(twist.shape[:-1], current.shape[:-1])
    except ValueError:
        raise ShapeError(f"twist_robot {twist.shape} and the steering {current.shape}: their batch shapes (all but "
                         "the last axis) do not broadcast") from None
    n = p.n_wheels
    rates, config, held, spin = _rates(robot, p, twist, current, batch, speed_tol, slip_tol)
    if len(p.fixed_wheels) == 0:
        slip = np.broadcast_to(0.0, (*batch, n))
        feasible = np.broadcast_to(True, batch)
    else:
        slip = np.zeros((*batch, n))
        lateral = twist @ p.fixed_lateral
        slip[..., p.fixed_wheels] = np.where(np.abs(lateral) <= np.abs(twist) @ p.fixed_roundoff, 0.0, lateral)
        feasible = np.all(np.abs(slip) <= slip_tol, axis=-1)
    steer = _steer_columns(p, config, batch, n)
    heading = heading_from_beta(steer, p.wheel_delta)
    if p.steer_range is None:
        in_range = np.broadcast_to(True, (*batch, n))
    else:  # a wheel that does not steer (NaN heading) has no range
        in_range = heading_in_range(np.nan_to_num(heading), *p.steer_range)
        feasible = feasible & np.all(in_range, axis=-1)
    in_gear = np.ones((*batch, len(robot.couplings)), dtype=bool)
    gears = gear_table(robot, p.rate_names) if robot.couplings else None
    if gears is not None and gears.coupling:
        in_gear[..., list(gears.coupling)] = gears_hold(gears, rates, slip_tol)
    in_linkage = linkage_holds(robot, twist, config, slip_tol)
    in_steer_gear = steer_gears_hold(robot, twist, config, slip_tol)
    feasible = feasible & np.all(in_gear & in_steer_gear & in_linkage, axis=-1)
    return WheelCommands(
        wheel_names=p.wheel_names, rate_names=p.rate_names, steer=_ro(steer), spin=_ro(spin),
        steer_rate=_ro(_columns(rates, p.steer_rate_select, batch, n)), rates=_ro(rates), slip=_ro(slip),
        feasible=_ro(feasible), beta=_ro(config), held=_ro(held), heading=_ro(heading), in_range=_ro(in_range),
        in_gear=_ro(in_gear), in_linkage=_ro(in_linkage), couplings=robot.couplings,
        in_steer_gear=_ro(in_steer_gear),
    )


def _rates(robot: Robot, p: _ik_fast.Plan, twist: np.ndarray, current: np.ndarray, batch: tuple[int, ...],
           speed_tol: float, slip_tol: float) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The joint rates, steering configuration, held flags and spins ``(..., N)`` of :func:`wheel_commands`."""
    if p.only_steerable:  # swerve-like: the angles are the configuration, the spins the rates
        config, rates, held = _ik_fast.steer_linked(robot, p, twist, current, batch, speed_tol, slip_tol)
    else:
        rates, config, held = _general(robot, p, twist, current, batch, speed_tol, slip_tol)
    spin = _columns(rates, p.spin_select, batch, p.n_wheels)
    doubles = p.spin2_col >= 0
    if doubles.any():
        spin = spin.copy()  # may be a view of rates
        spin[..., doubles] = 0.5 * (spin[..., doubles] + rates[..., p.spin2_col[doubles]])
    return rates, config, held, spin


def gear_error(coupling: Coupling, rate_names: tuple[str, ...], rates: np.ndarray) -> np.ndarray:
    """How far joint `rates` ``(..., n_rates)`` (`rate_names` order) are from turning together as a ``gear``
    coupling turns them, ``q_j = ratio_j * u`` (``docs/description-format.md``): the largest ``|q_j - ratio_j u|``
    at the least-squares ``u = k.q / k.k`` [rad/s], ``(...)``; 0 for the other kinds, which impose no rate."""
    if coupling.kind != "gear":
        return np.zeros(rates.shape[:-1])
    q = rates[..., [rate_names.index(j) for j in coupling.joints]]
    k = np.array(coupling.ratios, dtype=float)
    return np.max(np.abs(q - (q @ k / (k @ k))[..., None] * k), axis=-1)


def _steer_columns(p: _ik_fast.Plan, config: np.ndarray, batch: tuple[int, ...], n: int) -> np.ndarray:
    """The steering angles β ``(..., n_steer)`` as ``(..., N)`` columns, NaN for wheels that do not steer."""
    if p.n_steer == n:
        steer = config
    elif p.n_steer == 0:
        steer = np.broadcast_to(np.nan, (*batch, n))
    else:
        steer = np.full((*batch, n), np.nan)
        steer[..., p.steer_wheels] = config
    return steer


def _general(
    robot: Robot, p: _ik_fast.Plan, twist: np.ndarray, current: np.ndarray, batch: tuple[int, ...], speed_tol: float,
    slip_tol: float,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Rates ``(..., n_rates)``, configuration ``(..., n_steer)`` and held flags ``(..., N)`` of any robot."""
    if p.has_constant:  # fixed wheels' spins (3.11), Swedish spins and rollers (8.27)/(8.28)
        rates = _ik_fast.constant_rates(p, twist)
        if rates.shape[:-1] != batch:
            rates = np.broadcast_to(rates, (*batch, p.n_rates))
        if p.n_steer:
            rates = rates.copy()  # other wheels' columns are filled in below
    else:
        rates = np.zeros((*batch, p.n_rates))
    if p.n_steer == 0:
        return rates, np.broadcast_to(current, (*batch, 0)), np.broadcast_to(False, (*batch, p.n_wheels))
    if len(p.steered_beta):
        config = np.broadcast_to(wrap_angle(current), (*batch, p.n_steer)).copy()
        held = np.zeros((*batch, p.n_wheels), dtype=bool)
        angles, spins, held_o = _ik_fast.steer_linked(robot, p, twist, current, batch, speed_tol, slip_tol)
        config[..., p.steered_beta] = angles
        rates[..., p.steered_spin_col] = spins
        held[..., p.steer_wheels[p.steered_beta]] = held_o
    else:  # only castors steer: the configuration is the current one, unbatched if it is
        config = wrap_angle(current)
        held = np.broadcast_to(False, (*batch, p.n_wheels))
    if len(p.element_beta):
        beta_dot, spins = _ik_fast.solve_elements(p, twist, config)
        rates[..., p.element_steer_col] = beta_dot
        rates[..., p.element_spin_col] = spins
    config = np.broadcast_to(config, (*batch, p.n_steer))
    return rates, config, held


def resolve_rate_name(robot: Robot, name: str) -> int:
    """Column in ``robot.velocity_names`` of a joint-rate name: ``'wheel'`` (its spin) or ``'wheel.joint'``.

    Twist components ``'vx'``, ``'vy'``, ``'omega'`` are accepted too (e.g. a gyro's rate). Unknown names raise
    :class:`UnknownNameError` listing the valid ones.
    """
    names = robot.velocity_names
    qualified = name if "." in name or name in names else f"{name}.spin"
    if qualified in names:
        return names.index(qualified)
    valid = [w.name for w in robot.wheels if "spin" in w.kind.rates] + list(names)
    raise UnknownNameError(f"robot '{robot.name}' has no joint rate '{name}' (valid: {', '.join(valid)})")


def forward_kinematics(
    robot: Robot, rates: Mapping[str, ArrayLike], beta: ArrayLike | None = None, *, heading: ArrayLike | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """Body twist from some joint rates: the rest solved by least squares, ranks method (4.9)-(4.11).

    `rates`: name -> rate [rad/s] (or [m/s] for ``vx``/``vy``), real numbers each ``(...)`` (text is refused: the
    Python API reads no units; ``wmrkit.parse_quantity(text, rate_kind(name))`` reads it as the CLI); names as in
    :func:`resolve_rate_name`. Steering ``(..., n_steer)`` [rad] as the thesis's `beta` or the users' `heading`
    (default the described ones).
    Returns ``(twist_robot (..., 3), residual (...))``: the residual is the norm of the slip ``A q_dot`` [m/s]
    left by the assignment, 0 when the rates are consistent (the slip indicator of (4.11)/(4.82)). When the
    given rates do not determine the twist the minimum-norm one is returned: check :func:`twist_is_determined`.
    """
    check_robot(robot)
    columns = _assigned_columns(robot, list(_mapping(robot, rates)))
    given = {k: _rate_value(k, v) for k, v in rates.items()}
    try:
        values = np.broadcast_arrays(*given.values())
    except ValueError:
        shapes = ", ".join(f"{k} {v.shape}" for k, v in given.items())
        raise ShapeError(f"rates: the rates' shapes do not broadcast together: {shapes}") from None
    q_assigned = np.stack(values, axis=-1)
    _check_finite_rates(list(given), q_assigned)
    q_dot, slip = robot_solve(robot, robot.constraint_matrix(beta, heading=heading), columns, q_assigned, "rates")
    return readonly(q_dot[..., :3]), readonly(np.linalg.norm(slip, axis=-1))


#: Slip tolerance of :func:`forward_kinematics_check`: a residual above this fraction of the fastest wheel's
#: surface speed (plus 1e-9 m/s) means the given rates contradict each other (documented in docs/wheel-ik.md).
FK_SLIP_RTOL = 0.02


@dataclass(frozen=True, eq=False)
class ForwardKinematics:
    """The twist that best explains some joint rates, and whether the rates agree with each other (one sample).

    ``twist`` (3,) [m/s, rad/s]; ``residual`` the slip norm [m/s]; ``wheel_slip`` (N,) each wheel's slip norm
    [m/s]; ``tolerance`` [m/s]; ``consistent``: ``residual <= tolerance`` and no gear broken; ``slipping``: the
    wheels whose slip exceeds the tolerance; ``out_of_gear``: the channel names of the ``gear`` couplings whose given
    joints break its ratios (each used as given, so the slip does not show it: a :class:`GearWarning` each);
    ``out_of_linkage``: those of the ``linkage`` couplings whose law the steering breaks (a
    :class:`~wmrkit.kinematics.linkage_check.LinkageAngleWarning` each).
    """

    twist: np.ndarray
    residual: float
    wheel_slip: np.ndarray
    tolerance: float
    consistent: bool
    slipping: tuple[str, ...]
    out_of_gear: tuple[str, ...] = ()
    out_of_linkage: tuple[str, ...] = ()


def forward_kinematics_check(
    robot: Robot, rates: Mapping[str, float], beta: ArrayLike | None = None, *, heading: ArrayLike | None = None,
    rtol: float = FK_SLIP_RTOL,
) -> ForwardKinematics:
    """:func:`forward_kinematics` for one sample (`rates`: name -> one real number), with the slip split by wheel
    and judged against a tolerance.

    The tolerance is `rtol` times the fastest speed a given rate stands for (:func:`_speed_per_rate`: a spin's
    ``|r phi_dot|``, a Swedish roller's ``|r_r phi_r_dot|``, a steering rate's contact speed, ``omega`` times the
    robot's size) plus :data:`SLIP_TOL`: rates that contradict each other beyond it (slip larger than measurement
    noise) are not ``consistent``, nor are given joints of a ``gear`` out of its ratios beyond round-off
    (:data:`wmrkit.couplings.GEAR_EXACT_RTOL`) by more than :data:`SLIP_TOL` at a contact: each such gear is named in
    ``out_of_gear``, with a :class:`~wmrkit.couplings.GearWarning`; nor is a steering that breaks a held ``linkage``'s
    law by more than ``asin(rtol)`` (a wheel so set would slip at that fraction of its speed: ``out_of_linkage``, a
    :class:`~wmrkit.kinematics.linkage_check.LinkageAngleWarning`). `rtol`: a fraction in [0, 1], else
    :class:`~wmrkit.errors.ShapeError`.
    """
    if not (finite_number(rtol) and not isinstance(rtol, bool) and 0.0 <= rtol <= 1.0):
        raise ShapeError(f"rtol: expected a fraction of the fastest wheel's speed in [0, 1], got {rtol!r}")
    columns = _assigned_columns(robot, list(_mapping(robot, rates)))
    given = {k: _rate_value(k, v) for k, v in rates.items()}
    shaped = next((k for k, v in given.items() if v.size != 1), None)
    if shaped is not None:  # float() of an array of two said "only length-1 arrays can be converted"
        raise ShapeError(f"rates: {shaped}: expected one number (one sample; forward_kinematics takes arrays), got "
                         f"shape {given[shaped].shape}")
    q_assigned = np.array([float(v.reshape(())) for v in given.values()])
    _check_finite_rates(list(rates), q_assigned)
    a = robot.constraint_matrix(beta, heading=heading)
    q_dot, slip = robot_solve(robot, a, columns, q_assigned)
    owner = robot.row_wheels
    wheel_slip = np.sqrt(np.bincount(owner, weights=slip**2, minlength=len(robot.wheels)))
    speeds = [abs(v) * _speed_per_rate(robot, n)
              for n, v in zip((robot.velocity_names[c] for c in columns), q_assigned, strict=True)]
    tolerance = rtol * max(speeds, default=0.0) + SLIP_TOL
    residual = float(np.linalg.norm(slip))
    slipping = tuple(robot.wheel_names[i] for i in np.flatnonzero(wheel_slip > tolerance))
    names = tuple(robot.velocity_names[c] for c in columns)
    breaches = given_gear_breaches(robot, names, q_assigned, SLIP_TOL)
    for b in breaches:
        warnings.warn(b.warning(names, q_assigned), GearWarning, stacklevel=2)
    steering = robot.steering(beta, heading)
    off = given_breaches(robot, robot.beta if steering is None else steering, rtol)
    for b in off:
        warnings.warn(f"the headings break a steering linkage: {b.describe(robot)}: it cannot set them, so the "
                      "twist found from them is not the robot's; check the headings", LinkageAngleWarning,
                      stacklevel=2)
    consistent = bool(residual <= tolerance) and not breaches and not off
    return ForwardKinematics(_ro(q_dot[:3]), residual, _ro(wheel_slip), tolerance, consistent, slipping,
                             tuple(b.coupling.channel_name for b in breaches),
                             tuple(robot.couplings[b.coupling].channel_name for b in off))


def _speed_per_rate(robot: Robot, name: str) -> float:
    """The contact speed [m/s] one unit of the velocity `name` stands for: a joint's
    :func:`~wmrkit.kinematics.gear_check.contact_lever` (a spin's ``r``, a Swedish roller's ``r_r``, a steering
    rate's ``hypot(d, b)``: not 1 m, which read 1 rad/s of a castor with d = 0.04 m as 1 m/s); ``omega``'s lever the
    robot's size (:func:`robot_size`: 1 m read a gyro's 0.5 rad/s on a robot 1 mm across as 0.5 m/s); 1 for vx and
    vy."""
    wheel, _, joint = name.partition(".")
    if not joint:
        return robot_size(robot) if name == "omega" else 1.0
    return contact_lever(robot.wheel(wheel), joint)


def twist_is_determined(robot: Robot, names: list[str] | tuple[str, ...], beta: ArrayLike | None = None, *,
                        heading: ArrayLike | None = None) -> np.ndarray:
    """Whether the named rates fix the twist under no slip (all solutions share it). ``(..., n_steer) -> (...)``;
    steering `beta` (thesis) or `heading` (0 = rolling forward).

    True iff ``rank(A_na) = n_twist_free + rank(A_rest)`` (4.10): ``A_na`` the columns not assigned, ``A_rest``
    those of the unknown joint rates, ``n_twist_free`` the twist components not assigned.
    """
    columns = _assigned_columns(robot, list(as_names(names, "names", "joint rate names", UnknownNameError)))
    assigned = tuple(columns.tolist())
    a = decision_matrix(robot, robot.constraint_matrix(beta, heading=heading), assigned)[0]
    return readonly(np.asarray(geared_twist_determined(a, robot.couplings, robot.velocity_names, assigned)))


def _assigned_columns(robot: Robot, names: list[str]) -> np.ndarray:
    if not names:
        raise ShapeError(f"rates: expected at least one joint rate of robot '{robot.name}', got none")
    columns = [resolve_rate_name(robot, name) for name in names]
    for j, c in enumerate(columns):
        if c in columns[:j]:
            raise UnknownNameError(f"rates: '{robot.velocity_names[c]}' given twice")
    return np.array(columns, dtype=int)


def _first_bad(a: np.ndarray) -> float:
    """The first entry of `a` that is not a finite number within :data:`MAX_QUERY_RATE`."""
    return float(a[np.unravel_index(int(np.argmax(~(np.abs(a) <= MAX_QUERY_RATE))), a.shape)])


def _check_finite_rates(names: list[str], q_assigned: np.ndarray) -> None:
    """Raise :class:`ShapeError` naming the first rate (``(..., n_a)``, in `names` order) that is not a finite
    number within :data:`MAX_QUERY_RATE` (the bound of ``wmrkit fk --spin``: beyond, the slip overflows)."""
    ok = (np.abs(q_assigned) <= MAX_QUERY_RATE).reshape(-1, len(names)).all(axis=0)
    if not ok.all():
        j = int(np.argmin(ok))
        raise ShapeError(f"rates: {names[j]}: expected finite numbers within {MAX_QUERY_RATE:g} (rad/s or m/s), "
                         f"got {_first_bad(q_assigned[..., j])}")


def rate_kind(name: str) -> Kind:
    """The kind of quantity a rate named `name` is: a speed [m/s] for the twist's ``vx``/``vy``, else an angular
    rate [rad/s] (a joint's, the twist's ``omega``), so that ``"500 mm/s"``, ``"120 rpm"``, ``"30 deg/s"`` read."""
    return "speed" if name in ("vx", "vy") else "angular rate"


def _mapping(robot: Robot, rates: object) -> Mapping:
    """`rates` if a mapping, else :class:`ShapeError` (an array was read as names: "numpy.float64 is not
    iterable")."""
    if not isinstance(rates, Mapping):
        raise ShapeError(f"rates: expected a mapping {{joint name: rate}} such as {{'{robot.rate_names[0]}': 10.0}}, "
                         f"got {type(rates).__name__}")
    return rates


def _rate_value(name: str, value: ArrayLike) -> np.ndarray:
    """The rate `value` of `name` as a float array: real numbers in SI units (the Python API reads no units,
    docs/conventions.md). Text, which was read here with its unit, is refused with the way to read it as
    ``wmrkit fk --spin`` does (:func:`wmrkit.parse_quantity` of :func:`rate_kind`)."""
    if isinstance(value, str):
        raise ShapeError(f"rates: {name}: got the text {value!r}, but the Python API reads no units: pass real numbers "
                         f"in {'m/s' if rate_kind(name) == 'speed' else 'rad/s'} (text as 'wmrkit fk --spin' reads "
                         f"it: wmrkit.parse_quantity({value!r}, {rate_kind(name)!r}))")
    return as_reals(value, f"rates: {name}")


def _columns(rates: np.ndarray, select: slice | np.ndarray | None, batch: tuple[int, ...], n: int) -> np.ndarray:
    """Columns of `rates` chosen by a :func:`_ik_fast.selector`; NaN where the index is -1 or all are."""
    if select is None:
        return np.broadcast_to(np.nan, (*batch, n))
    if isinstance(select, slice):
        return rates[..., select]  # a view
    out = rates[..., np.maximum(select, 0)]
    if (select < 0).any():
        out[..., select < 0] = np.nan
    return out


def _ro(a: np.ndarray) -> np.ndarray:
    return a if not a.flags.writeable else readonly(a)
