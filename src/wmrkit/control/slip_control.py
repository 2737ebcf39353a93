"""Control through the slip models (thesis §10.2, future work 4): the inverse of a quasi-static slip model.

The kinematic loop of §8.2 turns the position law's twist into joint commands with the no-slip per-wheel IK (§8.4).
Under lateral acceleration the tyres must slip to carry the centripetal force (7.41), so the robot does not move
with that twist; a skid-steer robot cannot even take it (its no-slip IK is inconsistent: it turns only by slipping).
Here the commands come from a slip model instead: the joint commands ``u`` (actuated wheel rates, actuated steering
angles) whose steady motion predicted by the **MQE** (7.41)-(7.48) (or the MCD, (7.63)) is the desired twist.
This is the thesis's "assigned = vehicle velocities" use of the slip models (§7.4.3, option 3), solved for any robot
by Gauss-Newton on the forward model :func:`wmrkit.slip.models.mqe` (velocity-input form, inputs the actuated rates
at the commanded steering), warm-started from the no-slip IK plus the previous correction:

    minimise  | S (twist_MQE(u) - twist_d) |,   and among the minimisers the ``u`` closest to the no-slip IK

(distance with the rates scaled by the wheel radius, in m/s, and the angles in rad). ``S`` is what the loop controls
(:func:`output_weights`): the whole twist for a robot of full mobility; for one of reduced mobility the velocity of
its controlled point only, since its heading is the zero dynamics of the loop (§8.3): the slip model then chooses
the turn rate too. (Asking a forklift for the no-slip turn rate as well leaves all the centripetal force to the
steered wheel and makes the drive wheels fight each other for the yaw moment.) The two spins of a ``differential``
coupling get one more equation, equal drive torques: an open differential cannot make them fight. When the
friction makes slip vanish the solution tends to the no-slip IK (tested). :func:`slip_commands` solves one instant;
:class:`SlipCommander` carries the warm start from one control period to the next.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike

from .._shapes import as_vectors, readonly
from ..dynamics.mass import Body
from ..errors import WmrkitError
from ..kinematics.models import configuration
from ..kinematics.wheel_ik import wheel_commands
from ..robot import Robot, check_robot
from ..slip.models import FrictionLaw, G, SlipSolution, mcd, mqe, tyre_friction
from ..wheels import heading_from_beta
from .points import ControlError, control_point

__all__ = ["SLIP_MODELS", "SlipCommander", "SlipCommands", "SlipInverse", "output_weights", "slip_commands",
           "slip_inverse"]

#: Slip models the commands can come from (``"none"``: the no-slip IK of §8.4).
SLIP_MODELS = ("none", "mqe", "mcd")


@dataclass(frozen=True, eq=False)
class SlipInverse:
    """What the inverse needs (eq=False: array fields, read-only): the ``robot``, the slip ``model`` (``"mqe"`` or
    ``"mcd"``), its ``friction`` law and ``body``; the velocity inputs ``assigned`` (the actuated wheel rates, in
    ``robot.velocity_names``), the commanded steering ``steered`` (indices into ``robot.steer_names``: actuated
    steerable wheels; castors follow), the output map ``weights`` ``(m, 3)`` and the column scale ``scale``
    ``(n_u,)`` of the inputs (wheel radius [m] for rates, 1 for angles); ``differentials``: per open differential
    of two assigned spins ``(a, b, row_a, row_b, r_a, r_b)`` (inputs, longitudinal force rows, radii): their drive
    torques ``r F`` must be equal (one more equation, :func:`slip_inverse`)."""

    robot: Robot
    model: str
    friction: FrictionLaw
    body: Body | None
    assigned: tuple[str, ...]
    steered: np.ndarray
    weights: np.ndarray
    scale: np.ndarray
    differentials: tuple[tuple[int, int, int, int, float, float], ...] = ()

    @property
    def n_inputs(self) -> int:
        """Number of commanded joints ``n_u``: the assigned rates, then the commanded steering angles."""
        return len(self.assigned) + len(self.steered)


def output_weights(robot: Robot, point: ArrayLike | None = None) -> np.ndarray:
    """``(m, 3)`` map from a twist error to the error the inverse minimises [m/s].

    Reduced mobility (:func:`~wmrkit.control.points.control_point`): the velocity of the controlled point in the
    robot frame ``(2, 3)``; full mobility: ``(vx, vy, reach * omega)`` ``(3, 3)`` (reach: the farthest wheel).
    """
    reach = max([w.l for w in robot.wheels] + [0.1])
    try:
        cp = control_point(robot, point)
    except ControlError:
        cp = None
    if cp is None or not cp.reduced:
        return np.diag([1.0, 1.0, reach])
    px, py = cp.point
    return np.array([[1.0, 0.0, -py], [0.0, 1.0, px]])


def slip_inverse(robot: Robot, model: str = "mqe", *, friction: FrictionLaw | None = None, body: Body | None = None,
                 point: ArrayLike | None = None, weights: ArrayLike | None = None,
                 differential: bool = True) -> SlipInverse:
    """The inverse slip model of `robot` (module docstring).

    `friction`: the law of :mod:`wmrkit.slip.models` (default the described tyres, :func:`tyre_friction`);
    `body`: mass properties (default the described ones; MQE only); `point`: the controlled point of a robot of
    reduced mobility (as :func:`~wmrkit.control.points.control_point`); `weights` ``(m, 3)``: overrides
    :func:`output_weights`. `differential`: the two spins of a ``differential`` coupling (the forklift's drive
    wheels) get equal drive torques (an open differential, wheel inertia neglected), so they do not fight each
    other for the yaw moment; False: each spin is free.
    """
    check_robot(robot)
    if model not in ("mqe", "mcd"):
        raise ControlError(f"slip model must be one of {', '.join(SLIP_MODELS[1:])}, got '{model}'")
    if model == "mqe" and body is None and robot.body is None:
        raise ControlError(f"robot '{robot.name}' has no mass properties ('body:' in its description): the MQE "
                           "needs them (or use the MCD)")
    friction = tyre_friction(robot) if friction is None else friction
    assigned = tuple(j for j in robot.actuated if not j.endswith(".steer"))
    steered = np.array([i for i, n in enumerate(robot.steer_names) if f"{n}.steer" in robot.actuated], dtype=int)
    if not assigned:
        raise ControlError(f"robot '{robot.name}' has no actuated wheel rate: nothing for the slip model to assign")
    radius = [robot.wheel(j.partition(".")[0]).r for j in assigned]
    w = output_weights(robot, point) if weights is None else np.array(weights, dtype=float).reshape(-1, 3)
    scale = np.array([*radius, *np.ones(len(steered))], dtype=float)
    return SlipInverse(robot, model, friction, body, assigned, readonly(steered), readonly(w), readonly(scale),
                       _differentials(robot, assigned) if differential else ())


def _differentials(robot: Robot, assigned: tuple[str, ...]) -> tuple[tuple[int, int, int, int, float, float], ...]:
    """``(a, b, row_a, row_b, r_a, r_b)`` of each two-wheel ``differential`` coupling of assigned spins."""
    row, e = {}, 0
    for w in robot.wheels:
        row[w.name] = 2 * e + 1  # the longitudinal row of its first contact
        e += len(w.elements())
    out = []
    for c in robot.couplings:
        if c.kind == "differential" and len(c.joints) == 2 and all(j in assigned for j in c.joints):
            wa, wb = (j.partition(".")[0] for j in c.joints)
            out.append((assigned.index(c.joints[0]), assigned.index(c.joints[1]), row[wa], row[wb],
                        robot.wheel(wa).r, robot.wheel(wb).r))
    return tuple(out)


@dataclass(frozen=True, eq=False)
class SlipCommands:
    """The commands of one instant (frozen, arrays read-only; eq=False: array fields).

    - ``rates`` ``(n_a,)`` [rad/s]: the assigned (actuated) wheel rates, in ``SlipInverse.assigned`` order;
    - ``beta`` ``(n_steer,)`` [rad, thesis β]: the steering configuration (commanded angles, castors as given);
      ``heading`` the same as headings (0 = straight ahead);
    - ``twist`` ``(3,)``: the twist the slip model predicts at these commands; ``q_dot`` every velocity
      (``robot.velocity_names``) of that prediction; ``error`` [m/s] ``|S (twist - desired)|``;
    - ``correction`` ``(n_u,)``: the commands minus the no-slip IK's (rates [rad/s], then angles [rad]);
    - ``converged``, ``iterations``, ``evaluations`` (forward solves); ``inputs`` ``(n_u,)`` the solver's unknowns
      (the rates, then the commanded angles); ``jacobian`` ``(3, n_u)``: d twist / d inputs.
    """

    rates: np.ndarray
    beta: np.ndarray
    heading: np.ndarray
    twist: np.ndarray
    q_dot: np.ndarray
    error: float
    correction: np.ndarray
    converged: bool
    iterations: int
    evaluations: int
    inputs: np.ndarray = field(repr=False)
    jacobian: np.ndarray = field(repr=False)


def slip_commands(inverse: SlipInverse, twist: ArrayLike, beta: ArrayLike | None = None, *,
                  start: SlipCommands | None = None, tol: float = 1e-9, max_iter: int = 25,
                  heading: ArrayLike | None = None) -> SlipCommands:
    """Joint commands whose slip-model motion is `twist` ``(3,)`` (robot frame), at the current steering `beta`
    (``(n_steer,)`` thesis β) or `heading` (0 = rolling forward), default as described; castors stay there,
    commanded wheels start there.

    Warm start: the no-slip IK of `twist` (:func:`~wmrkit.kinematics.wheel_ik.wheel_commands`) plus `start`'s
    ``correction`` and its Jacobian (the previous instant's answer). Stops when the weighted error is below `tol`
    [m/s] or after `max_iter` Gauss-Newton steps (then ``converged`` is False and the best commands are returned).
    """
    robot = inverse.robot
    twist_d = as_vectors(twist, 3, "twist").astype(float)
    beta_now = np.array(configuration(robot, beta, heading), dtype=float)
    ik = wheel_commands(robot, twist_d, beta_now)
    spin_cols = [robot.rate_names.index(j) for j in inverse.assigned]
    u_ik = np.concatenate([np.nan_to_num(np.asarray(ik.rates)[spin_cols]), np.asarray(ik.beta)[inverse.steered]])
    u = u_ik + (start.correction if start is not None else 0.0)
    jac = None if start is None else np.array(start.jacobian)
    p = len(inverse.differentials)
    s = np.zeros((len(inverse.weights) + p, 3 + p))  # the weighted outputs, then the torque balances [m/s]
    s[:len(inverse.weights), :3] = inverse.weights
    s[len(inverse.weights):, 3:] = np.eye(p)
    twist_d = np.concatenate([twist_d, np.zeros(p)])
    solver = _Forward(inverse, beta_now)
    q, y = solver(u)
    r = s @ (y - twist_d)
    err, it = float(np.linalg.norm(r)), 0
    stale = jac is not None  # the previous instant's Jacobian: refreshed if it stops helping
    while err > tol and it < max_iter:
        if jac is None:
            jac, stale = solver.jacobian(u, y), False
        a = s @ jac * inverse.scale  # Gauss-Newton for the solution nearest the IK: delta = a+ (a delta_k - r)
        delta = (u - u_ik) / inverse.scale
        step = inverse.scale * (np.linalg.pinv(a, rcond=1e-10) @ (a @ delta - r)) - (u - u_ik)
        accepted = False
        for _ in range(6):  # halve the step until the error decreases
            try:
                q_new, y_new = solver(u + step)
            except WmrkitError:  # a step beyond any rate or angle the slip model takes: too long, halve it
                step = step / 2
                continue
            r_new = s @ (y_new - twist_d)
            if np.linalg.norm(r_new) < err:
                accepted = True
                break
            step = step / 2
        it += 1
        if not accepted:
            if stale:  # an old Jacobian: refresh it and try again
                jac = None
                continue
            break
        jac = jac + np.outer(y_new - y - jac @ step, step) / (step @ step)  # Broyden's update
        stale = True
        u, q, y, r = u + step, q_new, y_new, r_new
        err = float(np.linalg.norm(r))
    if jac is None:
        jac = solver.jacobian(u, y)
    n_a = len(inverse.assigned)
    beta_out = solver.beta(u)
    delta = np.array([robot.wheel(n).delta for n in robot.steer_names], dtype=float)
    heading = np.asarray(heading_from_beta(beta_out, delta), dtype=float) if len(delta) else np.zeros(0)
    return SlipCommands(readonly(u[:n_a].copy()), readonly(beta_out), readonly(heading), readonly(y[:3].copy()),
                        readonly(q.copy()), err, readonly(u - u_ik), err <= tol, it, solver.evaluations,
                        readonly(u.copy()), readonly(jac))


class _Forward:
    """The forward slip model at commands ``u``: every velocity ``q_dot`` and the twist, warm-started."""

    def __init__(self, inverse: SlipInverse, beta_now: np.ndarray) -> None:
        self.inv, self.beta_now, self.last, self.evaluations = inverse, beta_now, None, 0
        body = inverse.body or inverse.robot.body
        # torque [N m] per m/s of the balance rows: the weight's torque at the mean wheel radius
        self.torque_scale = (body.mass * G if body is not None else 1.0) * float(np.mean(inverse.scale[:1]))

    def beta(self, u: np.ndarray) -> np.ndarray:
        b = self.beta_now.copy()
        b[self.inv.steered] = u[len(self.inv.assigned):]
        return b

    def __call__(self, u: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        inv = self.inv
        n_a = len(inv.assigned)
        beta = self.beta(u) if len(self.beta_now) else None
        if self.last is not None:
            z = np.zeros(0)
            start = SlipSolution(self.last, z, z, np.zeros(()), np.ones((), dtype=bool))
        else:
            start = None  # the slip model's own start: unweighted least squares
        if inv.model == "mqe":
            sol = mqe(inv.robot, inv.assigned, u[:n_a], inv.friction, beta, body=inv.body, start=start)
        else:
            sol = mcd(inv.robot, inv.assigned, u[:n_a], inv.friction, beta, start=start)
        self.evaluations += 1
        if not bool(sol.converged):  # retry from the slip model's own start
            sol2 = (mqe(inv.robot, inv.assigned, u[:n_a], inv.friction, beta, body=inv.body) if inv.model == "mqe"
                    else mcd(inv.robot, inv.assigned, u[:n_a], inv.friction, beta))
            self.evaluations += 1
            if bool(sol2.converged) or float(sol2.residual) < float(sol.residual):
                sol = sol2
        q, f = np.asarray(sol.q_dot, dtype=float), np.asarray(sol.forces, dtype=float)
        self.last = q
        torque = [(ra * f[ia] - rb * f[ib]) / self.torque_scale for _, _, ia, ib, ra, rb in inv.differentials]
        return q, np.concatenate([q[:3], torque])

    def jacobian(self, u: np.ndarray, y: np.ndarray) -> np.ndarray:
        """Forward differences of the twist in each input (step relative to the input's scale)."""
        last = self.last
        jac = np.empty((len(y), len(u)))
        for j in range(len(u)):
            h = 1e-6 * max(1.0, abs(u[j]) * self.inv.scale[j]) / self.inv.scale[j]
            du = np.zeros(len(u))
            du[j] = h
            jac[:, j] = (self(u + du)[1] - y) / h
            self.last = last
        return jac


class SlipCommander:
    """The inverse slip model across control periods: :meth:`__call__` ``(twist, beta) -> SlipCommands``, each
    warm-started from the previous answer (:func:`slip_commands`); counts the instants that did not converge."""

    def __init__(self, inverse: SlipInverse, tol: float = 1e-7, max_iter: int = 25) -> None:
        self.inverse, self.tol, self.max_iter = inverse, tol, max_iter
        self.previous: SlipCommands | None = None
        self.failures, self.calls, self.worst, self.evaluations = 0, 0, 0.0, 0

    def __call__(self, twist: ArrayLike, beta: ArrayLike | None = None) -> SlipCommands:
        """Commands for `twist` at steering `beta` (see :func:`slip_commands`)."""
        out = slip_commands(self.inverse, twist, beta, start=self.previous, tol=self.tol, max_iter=self.max_iter)
        if not (np.all(np.isfinite(out.inputs)) and math.isfinite(out.error)):
            out = slip_commands(self.inverse, twist, beta, tol=self.tol, max_iter=self.max_iter)
        self.calls += 1
        self.evaluations += out.evaluations
        self.failures += not out.converged
        self.worst = max(self.worst, out.error)
        self.previous = out
        return out
