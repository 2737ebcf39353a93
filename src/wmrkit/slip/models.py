"""The three slip models of thesis §7.4 for any robot: quasi-static (MQE), kinematic with slip (MCD), WLS.

All three take the assigned velocities (sensed or actuated wheel rates, §7.4.3 option 1/2) and return the
unassigned ones, the body twist first. They are built on the slip matrix ``A`` (3.22), ``v_slip = A q_dot``,
and the generalised force of friction ``Q = A^T F`` (7.16), whose twist part is the friction wrench on the
vehicle about the robot origin ``(F_x, F_y, M_z)`` and whose wheel parts are the friction torques on the joints:

- **MCD** (7.63 generalised): ``A_na^T F(A q_dot) = 0``: forces and moment balance (7.41) without its inertial
  side and (7.42), free wheels (7.48), free castors (7.47), Swedish rollers (7.46), in one equation per
  unassigned velocity.
- **MQE** (7.41)-(7.48): the same with the centripetal term: the twist rows equal ``(M a_cm, c x M a_cm)``,
  ``a_cm = omega J v_cm`` (7.40), and normal loads with that acceleration (7.64 generalised, :func:`normal_loads`).
- **WLS** (7.50)-(7.53): least squares of ``sqrt(mu) A q_dot = 0`` (:func:`~wmrkit.kinematics.linalg.solve_assigned`
  on the weighted rows). Its normal equations are MCD's with the linear law ``F = -mu v_slip`` (7.59): the
  equivalence theorem of §7.4.4, tested.

Friction laws are callables ``law(v_slip, v_body, loads) -> F`` on ``(..., E, 2)`` contact slips (lateral,
longitudinal), the contact velocities due to the body motion alone (for slip ratios and angles), and normal loads
``(..., E)`` [N]; they return the friction force on the vehicle in each contact frame ``(..., E, 2)`` [N].
:func:`tyre_friction` makes one from the robot's described tyres (:mod:`wmrkit.dynamics.tyres`).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike

from .._shapes import as_names, as_reals, batch_shape, real_number
from ..couplings import gear_unknowns
from ..dynamics.mass import Body, body_problem
from ..errors import ShapeError, WmrkitError
from ..kinematics.linalg import geared_solve
from ..limits import MAX_QUERY_RATE
from ..robot import Robot, check_robot, element_beta
from .weights import SlipWeights

FrictionLaw = Callable[[np.ndarray, np.ndarray, np.ndarray], np.ndarray]
G = 9.81  # m/s^2 (the thesis gives no value)


@dataclass(frozen=True, slots=True)
class LinearFriction:
    """The linear, uncoupled law (7.59): ``F_i = -diag(mu_x, mu_y) v_slip,i``; loads are ignored (absorbed in mu)."""

    mu: tuple[float, ...]  # (2 E,) per row of the slip matrix, lateral then longitudinal per contact

    def __post_init__(self) -> None:
        """Pairs of finite coefficients > 0 (as :class:`SlipWeights`: a NaN or negative one gave a wrong twist)."""
        mu = as_reals(self.mu, "LinearFriction")  # text ("0.8") was read as a number
        if mu.ndim != 1 or mu.size == 0 or mu.size % 2:
            raise ShapeError(f"LinearFriction: expected a (lateral, longitudinal) pair per contact, got {self.mu!r}")
        if not (np.isfinite(mu) & (mu > 0)).all():
            raise ShapeError(f"LinearFriction: every coefficient must be a finite number > 0, got {self.mu!r}")

    @classmethod
    def from_weights(cls, robot: Robot, weights: SlipWeights) -> LinearFriction:
        """The law whose coefficients are `weights`."""
        return cls(tuple(SlipWeights.checked(weights).row_mu(robot).tolist()))

    def __call__(self, v_slip: np.ndarray, v_body: np.ndarray, loads: np.ndarray) -> np.ndarray:
        return -np.asarray(self.mu).reshape(-1, 2) * v_slip


@dataclass(frozen=True, slots=True)
class TyreFriction:
    """The friction law of the robot's tyres (:class:`wmrkit.dynamics.tyres.Tyre`), one per contact element."""

    tyres: tuple  # (E,) Tyre
    groups: tuple = field(init=False, repr=False, compare=False)  # ((Tyre, contact indices), ...): one call each

    def __post_init__(self) -> None:
        groups: dict = {}
        for e, tyre in enumerate(self.tyres):
            groups.setdefault(tyre, []).append(e)
        object.__setattr__(self, "groups", tuple((tyre, np.array(ix)) for tyre, ix in groups.items()))

    def __call__(self, v_slip: np.ndarray, v_body: np.ndarray, loads: np.ndarray) -> np.ndarray:
        out = np.empty(np.broadcast_shapes(v_slip.shape, v_body.shape))
        for tyre, ix in self.groups:  # the contacts of one tyre model in one vectorised call
            v_wheel, v_long = v_body[..., ix, 1], v_slip[..., ix, 1]
            f = tyre._forces(loads[..., ix], v_slip[..., ix, 0], v_long, v_wheel, v_long - v_wheel)  # unchecked
            out[..., ix, 0], out[..., ix, 1] = f.lateral, f.longitudinal
        return out


def tyre_friction(robot: Robot) -> TyreFriction:
    """The friction law of `robot`'s described tyres (every wheel needs ``tyre:`` in its description)."""
    check_robot(robot)
    missing = [w.name for w in robot.wheels if w.tyre is None]
    if missing:
        raise WmrkitError(f"robot '{robot.name}': wheel '{missing[0]}' has no tyre model ('tyre:' in its description)")
    return TyreFriction(tuple(w.tyre for w in robot.wheels for _ in w.elements()))


@dataclass(frozen=True, eq=False)  # eq=False: array fields
class SlipSolution:
    """A slip model's answer, batched ``(...)``: ``q_dot`` ``(..., k)`` every velocity (named by
    ``robot.velocity_names``), ``slip`` ``(..., 2E)`` [m/s] ``A q_dot``, ``forces`` ``(..., 2E)`` [N] friction in
    the contact frames (WLS: ``-mu v_slip``), ``residual`` ``(...)`` the largest equation error [N] (0 for WLS),
    ``converged`` ``(...)`` bool."""

    q_dot: np.ndarray
    slip: np.ndarray
    forces: np.ndarray
    residual: np.ndarray
    converged: np.ndarray

    @property
    def twist(self) -> np.ndarray:
        """``(..., 3)``: ``(vx [m/s], vy [m/s], omega [rad/s])``."""
        return self.q_dot[..., :3]

    @property
    def dissipation(self) -> np.ndarray:
        """Power dissipated by friction ``-F . v_slip`` (7.3) ``(...)`` [W]; for WLS it is J_LS (7.53)."""
        return -np.sum(self.forces * self.slip, axis=-1)


def assigned_columns(robot: Robot, assigned: Sequence[str]) -> np.ndarray:
    """Column indices of the assigned velocity names (``WHEEL.spin``, ``WHEEL.steer``...)."""
    return np.array([robot.velocity_index(n) for n in assigned], dtype=int)


def _assigned(robot: Robot, assigned: Sequence[str], q_assigned: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    """Columns and values ``(..., n_a)`` of the assigned velocities; :class:`ShapeError` naming `q_assigned` when
    its last axis is not one value per name or a value is not a finite number within ``MAX_QUERY_RATE``."""
    assigned = as_names(assigned, "assigned", "velocity names")
    if not assigned or len(set(assigned)) != len(assigned):
        raise ShapeError(f"assigned: expected distinct velocity names, at least one, got {list(assigned)}")
    cols = assigned_columns(robot, assigned)
    q_a = as_reals(q_assigned, "q_assigned")  # text ("120", meant as rpm) was read as rad/s
    if q_a.shape[-1:] != (len(cols),):
        raise ShapeError(f"q_assigned: expected shape (..., {len(cols)}), one value per assigned velocity "
                          f"({', '.join(assigned)}), got {q_a.shape}")
    bad = ~(np.abs(q_a) <= MAX_QUERY_RATE).reshape(-1, len(cols))  # NaN included
    if bad.any():
        i, j = (int(x) for x in np.argwhere(bad)[0])
        raise ShapeError(f"q_assigned: {assigned[j]}: expected finite numbers within {MAX_QUERY_RATE:g} (rad/s or "
                          f"m/s), got {float(q_a.reshape(-1, len(cols))[i, j])}")
    return cols, q_a


def wls(robot: Robot, assigned: Sequence[str], q_assigned: ArrayLike, beta: ArrayLike | None = None,
        weights: SlipWeights | None = None, *, heading: ArrayLike | None = None) -> SlipSolution:
    """Weighted least squares (7.52): ``(..., n_a) -> SlipSolution``; steering `beta` (thesis) or `heading`
    (0 = rolling forward) ``(..., n_steer)``, default as described."""
    check_robot(robot)
    mu = SlipWeights.checked(weights).row_mu(robot)
    a = robot.constraint_matrix(beta, heading=heading)
    cols, q_a = _assigned(robot, assigned, q_assigned)
    q, _ = geared_solve(np.sqrt(mu)[:, None] * a, robot.couplings, robot.velocity_names, cols, q_a)
    slip = (a @ q[..., None])[..., 0]
    zero = np.zeros(slip.shape[:-1])
    return SlipSolution(q, slip, -mu * slip, zero, zero == 0)


def mcd(robot: Robot, assigned: Sequence[str], q_assigned: ArrayLike, friction: FrictionLaw,
        beta: ArrayLike | None = None, *, loads: ArrayLike | None = None, start: SlipSolution | None = None,
        tol: float = 1e-9, heading: ArrayLike | None = None) -> SlipSolution:
    """Kinematic model with slip (7.63) generalised: ``A_na^T F(A q_dot) = 0`` (module docstring).

    `loads` ``(E,)`` [N], the static normal loads (default 1 N each: the law's own normalisation). Solved per
    sample by Newton's method (``scipy.optimize.root``) from `start` (default: the unweighted WLS solution).
    Steering: `beta` (thesis) or `heading` (0 = rolling forward), default as described.
    """
    check_robot(robot)
    return _solve(robot, assigned, q_assigned, friction, robot.steering(beta, heading), loads, None, start, tol)


def mqe(robot: Robot, assigned: Sequence[str], q_assigned: ArrayLike, friction: FrictionLaw,
        beta: ArrayLike | None = None, *, body: Body | None = None, start: SlipSolution | None = None,
        g: float = G, tol: float = 1e-9, heading: ArrayLike | None = None) -> SlipSolution:
    """Quasi-static motion model (7.41)-(7.48): MCD plus the centripetal force and its load transfer (7.64).

    `body`: the mass properties (default the robot's described ``body``). Steering: `beta` (thesis) or `heading`
    (0 = rolling forward), default as described.
    """
    check_robot(robot)
    return _solve(robot, assigned, q_assigned, friction, robot.steering(beta, heading), None,
                  (_body(robot, body), g), start, tol)


def contact_positions(robot: Robot, beta: ArrayLike | None = None) -> np.ndarray:
    """Contact point of every element in the robot frame ``(..., E, 2)`` [m]: the steering joint plus the castor
    offset ``d`` along the steering arm (``S_y`` at angle ``beta + pi/2``)."""
    beta_e = element_beta(robot, beta)
    l_, al, d = (np.array(v, dtype=float) for v in zip(*[(e.l, e.alpha, e.d) for w in robot.wheels
                                                           for e in w.elements()], strict=True))
    x = l_ * np.cos(al) - d * np.sin(beta_e)  # + d (cos(beta + pi/2), sin(beta + pi/2)), (3.12), (7.18)
    y = l_ * np.sin(al) + d * np.cos(beta_e)
    return np.stack([x, y], axis=-1)


def normal_loads(robot: Robot, body: Body | None = None, accel_cm: ArrayLike = (0.0, 0.0),
                 beta: ArrayLike | None = None, g: float = G, *, heading: ArrayLike | None = None) -> np.ndarray:
    """Normal loads (7.64) generalised to any contact layout: ``sum F_N = M g`` and the pitch and roll moments
    about the centre of mass balance the inertial moment of ``M a_cm`` at height ``h_cm``:
    ``sum F_N (p - c) = -h M a_cm``. ``(..., 2) -> (..., E)`` [N]. With more than three contacts the loads are
    statically indeterminate: the minimum-norm solution (equal loads on a symmetric layout) is returned.
    The thesis's drive-torque reaction term of (7.64) is not included. `body`: default the robot's. Steering:
    `beta` (thesis) or `heading` (0 = rolling forward), default as described.
    """
    check_robot(robot)
    body, beta = _body(robot, body), robot.steering(beta, heading)
    a = as_reals(accel_cm, "accel_cm")
    if not (real_number(g) and 0 < g < np.inf) or a.shape[-1:] != (2,) or not np.isfinite(a).all():
        raise ShapeError(f"normal_loads: expected a gravity g > 0 and finite accelerations accel_cm (..., 2), got "
                          f"g = {g}, accel_cm of shape {a.shape}")
    h = body.com_height
    rhs = np.stack(np.broadcast_arrays(np.full(a.shape[:-1], body.mass * g), -h * body.mass * a[..., 0],
                                       -h * body.mass * a[..., 1]), axis=-1)
    load_map = _load_map(robot, body, beta)
    batch_shape(a.shape, load_map.shape[:-2], "accel_cm")  # numpy's message named neither
    loads = (load_map @ rhs[..., None])[..., 0]
    lifted = loads < -1e-9 * body.mass * g  # below 0 beyond round-off
    if lifted.any():
        from ..dynamics.model import contact_names

        at = np.unravel_index(int(np.argmax(lifted)), loads.shape)
        where = f"accel_cm {a.tolist()} m/s^2" if loads.ndim == 1 else f"sample {tuple(int(i) for i in at[:-1])}"
        raise WmrkitError(f"normal_loads: contact '{contact_names(robot)[at[-1]]}' lifts off the ground: its load "
                          f"would be {loads[at]:.4g} N < 0 (body.com {list(body.com)} m, {where}); (7.64) holds only "
                          "while every wheel is on the ground")
    return loads


def _load_map(robot: Robot, body: Body, beta: ArrayLike | None) -> np.ndarray:
    """``(..., E, 3)``: the loads of :func:`normal_loads` are this map times ``(M g, -h M a_x, -h M a_y)``."""
    p = contact_positions(robot, beta) - np.asarray(body.com, dtype=float)
    m = np.stack([np.ones(p.shape[:-1]), p[..., 0], p[..., 1]], axis=-2)  # (..., 3, E)
    return np.linalg.pinv(m)


def _body(robot: Robot, body: Body | None) -> Body:
    """`body`, or the robot's when None; a bad `body` argument is a :class:`ShapeError`, a bad robot's a
    :class:`WmrkitError` (both name the field)."""
    given, body = body is not None, robot.body if body is None else body
    if body is None:
        raise WmrkitError(f"robot '{robot.name}' has no mass properties ('body:' in its description)")
    problem = body_problem(body)
    if problem:
        raise (ShapeError if given else WmrkitError)(problem)
    return body


def _solve(robot, assigned, q_assigned, friction, beta, loads, quasi_static, start, tol) -> SlipSolution:
    from scipy.optimize import root

    if not (real_number(tol) and 0 < tol < np.inf):  # text raised "'<' not supported"
        raise ShapeError(f"tol: expected a finite tolerance > 0, got {tol}")
    if quasi_static is not None and not (real_number(quasi_static[1]) and 0 < quasi_static[1] < np.inf):
        raise ShapeError(f"g: expected a finite gravity > 0 m/s^2, got {quasi_static[1]}")

    cols, q_a = _assigned(robot, assigned, q_assigned)
    if quasi_static is not None and np.isin(cols, (0, 1, 2)).any():
        raise WmrkitError("MQE needs the body twist unassigned (the vehicle velocities are its unknowns), got "
                          f"assigned {list(assigned)}")
    a_all = robot.constraint_matrix(beta)
    batch = batch_shape(q_a.shape, a_all.shape[:-2], "q_assigned")
    a_all = np.broadcast_to(a_all, (*batch, *a_all.shape[-2:])).reshape(-1, *a_all.shape[-2:])
    q_a = np.broadcast_to(q_a, (*batch, len(cols))).reshape(-1, len(cols))
    k = a_all.shape[-1]
    free, given = gear_unknowns(robot.couplings, robot.velocity_names, tuple(cols.tolist()))  # q = free z + given q_a
    n_e = a_all.shape[-2] // 2
    n_s = len(robot.steer_names)
    betas = (None if beta is None or n_s == 0
             else np.broadcast_to(np.asarray(beta, float), (*batch, n_s)).reshape(-1, n_s))
    q0 = wls(robot, assigned, q_a, betas).q_dot if start is None else np.asarray(start.q_dot, dtype=float)
    if q0.shape[-1:] != (k,) or q0.size // k not in (1, len(q_a)):  # one for every sample, or one per sample
        raise ShapeError(f"start: expected velocities of shape {(*batch, k)} (one solution per sample, or one for "
                          f"all), got {q0.shape}")
    q0 = np.broadcast_to(q0.reshape(-1, k), (len(q_a), k))
    # scipy's hybr differences each unknown with a step relative to its size: a start of 1e-17 (round-off of an
    # exact 0) gives it a useless Jacobian column and it stalls (skid steer, tests/slip/test_models.py)
    q0 = np.where(np.abs(q0) < 1e-9 * np.maximum(1.0, np.abs(q0).max(axis=-1, keepdims=True)), 0.0, q0)
    static = np.ones(n_e) if loads is None else as_reals(loads, "loads")
    if static.shape != (n_e,):
        raise ShapeError(f"loads: expected {n_e} normal loads, one per contact, got shape {static.shape}")
    if not (static >= 0).all() or not np.isfinite(static).all() or not static.any():
        raise ShapeError(f"loads: expected finite normal loads >= 0, not all 0, got {static.tolist()}")
    q_out = np.empty((len(q_a), k))
    res = np.empty(len(q_a))
    ok = np.empty(len(q_a), dtype=bool)
    load_maps = None if quasi_static is None else _load_map(robot, quasi_static[0], betas)  # (E, 3) or (n, E, 3)
    for i in range(len(q_a)):
        a = a_all[i]
        known = given @ q_a[i]
        a_na, fixed = a @ free, a @ known
        body_part = a[:, :3]
        load_map = None if load_maps is None else load_maps[i] if load_maps.ndim == 3 else load_maps

        def equations(z, a_na=a_na, fixed=fixed, body_part=body_part, load_map=load_map, known=known):
            slip = a_na @ z + fixed
            twist = known[:3] + free[:3] @ z  # assigned components included: the contacts' body velocities
            v_body = body_part @ twist
            if quasi_static is None:
                f_n = static
                inertial = 0.0
            else:
                f_n, inertial = _centripetal(quasi_static, load_map, twist)
            f = friction(slip.reshape(n_e, 2), v_body.reshape(n_e, 2), f_n).reshape(-1)
            out = a_na.T @ f
            if quasi_static is not None:
                out[:3] -= inertial
            return out

        if i == 0:
            _check_law(friction, slip_shape=(n_e, 2), loads=static if quasi_static is None else None)
        z0 = free.T @ q0[i] / np.sum(free**2, axis=0)  # free's columns have disjoint supports
        scale = max(1.0, float(np.max(np.abs(equations(z0)))))
        sol = root(lambda z, s=scale: equations(z) / s, z0, method="hybr", tol=tol * 1e-3)
        q_out[i] = free @ sol.x + known
        res[i] = float(np.max(np.abs(equations(sol.x)), initial=0.0))
        ok[i] = res[i] <= tol * scale  # hybr may report no progress when it starts at the root
    a_b = a_all.reshape(*batch, *a_all.shape[-2:])
    q_out = q_out.reshape(*batch, k)
    slip = (a_b @ q_out[..., None])[..., 0]
    f_n = np.broadcast_to(static, (*batch, n_e))
    if quasi_static is not None:
        f_n = np.stack([_centripetal(quasi_static, load_maps[i] if load_maps.ndim == 3 else load_maps, q[:3])[0]
                        for i, q in enumerate(q_out.reshape(-1, k))]).reshape(*batch, n_e)
    body_v = (a_b[..., :3] @ q_out[..., :3, None])[..., 0]
    forces = friction(slip.reshape(*batch, n_e, 2), body_v.reshape(*batch, n_e, 2), f_n).reshape(*batch, 2 * n_e)
    return SlipSolution(q_out, slip, forces, res.reshape(batch), ok.reshape(batch))


def _check_law(friction: FrictionLaw, slip_shape: tuple[int, int], loads: np.ndarray | None) -> None:
    """Refuse a friction law that does not give one finite (lateral, longitudinal) force per contact."""
    if isinstance(friction, LinearFriction) and len(friction.mu) != 2 * slip_shape[0]:
        raise ShapeError(f"LinearFriction: {len(friction.mu) // 2} pairs of coefficients for {slip_shape[0]} "
                          "contacts (one (lateral, longitudinal) pair per contact)")
    probe = np.full(slip_shape, 0.1)
    try:
        f = np.asarray(friction(probe, probe, np.ones(slip_shape[0]) if loads is None else loads), dtype=float)
    except (ValueError, TypeError, IndexError) as err:
        raise ShapeError(f"friction law: fails on {slip_shape[0]} contacts ({err})") from None
    if f.shape != slip_shape or not np.isfinite(f).all():
        raise ShapeError(f"friction law: expected finite forces of shape {slip_shape}, one pair per contact, got "
                          f"shape {f.shape}" + ("" if f.shape != slip_shape else " with non-finite values"))


def _centripetal(quasi: tuple[Body, float], load_map: np.ndarray,
                 twist: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Loads (:func:`normal_loads` through its `load_map`) and the inertial wrench ``(M a_cm, c x M a_cm)`` about the
    origin of uniform curvilinear motion."""
    body, g = quasi
    cx, cy = body.com
    vx, vy, w = twist
    v_cm = np.array([vx - w * cy, vy + w * cx])
    a_cm = w * np.array([-v_cm[1], v_cm[0]])  # omega J v_cm (7.40)
    f = body.mass * a_cm
    h = body.com_height
    loads = load_map @ np.array([body.mass * g, -h * f[0], -h * f[1]])
    return loads, np.array([f[0], f[1], cx * f[1] - cy * f[0]])
