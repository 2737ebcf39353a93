"""Simulation of the dynamic model (thesis §7.2) from joint torques (and servo references) to motion.

:func:`simulate` integrates :class:`~wmrkit.dynamics.model.DynamicModel` with a fixed step (``"semi-implicit"``:
linearly implicit Euler, stable with stiff tyres at a 1 kHz step; ``"rk4"``) or adaptively (``"adaptive"``:
scipy's LSODA), compiled with numba, with a ``tqdm`` bar on long runs. Inputs are an :class:`~.inputs.Inputs` value
(see :mod:`.programs` for CSV torque files and built-in programs); the result is a frozen :class:`Simulation`.
:class:`Stepper` (and the pure :func:`advance`) continue a run from its full state with new inputs: closed loops.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike

from .._shapes import as_vectors, readonly, real_number
from ..errors import ShapeError, WmrkitError
from ..limits import MAX_COORDINATE, MAX_SPEED
from ..robot import Robot
from ..wheels import heading_from_beta
from .deviation import PathDeviation, StepCheck, check_step, nominal_poses
from .inputs import (  # noqa: F401  (Inputs, joint_column: API)
    Inputs,
    compiled_inputs,
    held_values,
    joint_column,
    setpoint_problem,
)
from .linkages import linkage_breach
from .model import DynamicModel
from .runs import (  # noqa: F401  (LiftOffError, DivergedError: API)
    RANGE_CHECK,
    DivergedError,
    LiftOffError,
    StepLog,
    Stop,
    adaptive_run,
    adaptive_samples,
    check_lift_off,
    first_escape,
    fixed_run,
    levers,
    lifted,
    records,
)
from .tyres import Tyre

Method = Literal["semi-implicit", "rk4", "adaptive"]
METHODS = ("semi-implicit", "rk4", "adaptive")


@dataclass(frozen=True, eq=False)
class Simulation:
    """A simulated run; frozen, every array read-only. N samples, n velocities, E contacts.

    ``t (N,)`` [s]; ``pose (N, 3)`` world ``(x, y, theta)``; ``twist (N, 3)`` robot frame; ``joint_positions``,
    ``joint_rates``, ``torques (N, n - 3)`` over ``joint_names`` (``names[3:]``; wheel angles, steering angles β);
    ``heading (N, n_steer)`` steering headings; ``forces (N, E, 2)`` [N] tyre forces (lateral, longitudinal; frame
    Ē); ``loads (N, E)`` [N]; ``slip (N, E, 2)`` [m/s] slip velocities; ``wheel_speed (N, E)`` [m/s];
    ``nominal_pose (N, 3)`` or None: the poses of the program's twists (``Inputs.twist``) integrated from the
    initial pose, the path the run was programmed to drive (:meth:`deviation`).
    """

    names: tuple[str, ...]
    contacts: tuple[str, ...]
    t: np.ndarray
    pose: np.ndarray
    twist: np.ndarray
    joint_positions: np.ndarray
    joint_rates: np.ndarray
    torques: np.ndarray
    heading: np.ndarray
    forces: np.ndarray
    loads: np.ndarray
    slip: np.ndarray
    wheel_speed: np.ndarray
    method: str
    step: float
    info: dict = field(default_factory=dict)
    steered: tuple[str, ...] = ()  # the wheels of the heading columns
    nominal_pose: np.ndarray | None = None
    step_check: StepCheck | None = None  # the re-run at a shorter step that checked this one (simulate's `check`)

    def deviation(self) -> PathDeviation | None:
        """How far the run is from its program's path (:class:`~wmrkit.dynamics.deviation.PathDeviation`: end
        position and heading errors, largest position and heading errors, at the records' times); None for inputs
        that program no twists (torques)."""
        return None if self.nominal_pose is None else PathDeviation.of(self.t, self.pose, self.nominal_pose)

    @property
    def joint_names(self) -> tuple[str, ...]:
        """Names of the joint columns."""
        return self.names[3:]

    def joint_table(self) -> tuple[tuple[str, ...], np.ndarray]:
        """The joint positions as users read them: ``(names, (N, n - 3))``, each steering angle β replaced by the
        wheel's heading (``wheel.heading`` [rad], 0 = straight ahead), wheel angles as ``wheel.spin`` [rad]."""
        names, table = list(self.joint_names), np.array(self.joint_positions)
        for k, wheel in enumerate(self.steered):
            c = names.index(f"{wheel}.steer")
            names[c], table[:, c] = f"{wheel}.heading", self.heading[:, k]
        return tuple(names), table

    def friction_power(self) -> np.ndarray:
        """Power of the contact forces on the slips ``(N,)`` [W]; never positive for dissipative tyres."""
        return np.einsum("nec,nec->n", self.forces, self.slip)

    def to_dict(self) -> dict:
        """Plain data (lists) for JSON: time, pose, twist, joints (positions as :meth:`joint_table`: headings for
        steering), loads and forces."""
        position_names, positions = self.joint_table()
        return {"t": self.t.tolist(), "pose": self.pose.tolist(), "twist": self.twist.tolist(),
                "positions": list(position_names), "joint_positions": positions.tolist(),
                "joints": list(self.joint_names), "joint_rates": self.joint_rates.tolist(),
                "contacts": list(self.contacts), "forces": self.forces.tolist(), "loads": self.loads.tolist(),
                "method": self.method, "step": self.step}


#: Most integration steps a command runs (``wmrkit simulate``, ``track --dynamics``): the forklift takes about 1e6
#: steps a second, so under a minute.
MAX_STEPS = 50_000_000

#: Most numbers a simulation records (1 GiB of float64); a sample holds ``3 n + 6 e + 1``, 40 for the forklift.
MAX_RECORD_VALUES = 1 << 27


def record_capacity(model: DynamicModel) -> int:
    """Most samples a simulation of `model` records (:data:`MAX_RECORD_VALUES` over the numbers in a sample)."""
    return MAX_RECORD_VALUES // (3 * model.n + 6 * len(model.contacts) + 1)


def recordable_step(model: DynamicModel, duration: float, step: float, wanted: float) -> float:
    """The least record step >= `wanted` [s] keeping a run of `duration` within :func:`record_capacity`."""
    return max(wanted, step * math.ceil(duration / step / (record_capacity(model) - 2)))


def simulate(robot: Robot | DynamicModel, inputs: Inputs, duration: float, *, step: float = 1e-3,
             method: Method = "semi-implicit", tyre: Tyre | str | None = None, initial_twist: ArrayLike = (0, 0, 0),
             initial_pose: ArrayLike = (0, 0, 0), record_step: float | None = None, rtol: float = 1e-6,
             progress: bool | None = None, jac_every: int = 20, allow_lift_off: bool = False,
             check: bool = True) -> Simulation:
    """Integrate the dynamic model for `duration` [s] from `inputs`.

    The initial velocities roll without slip at `initial_twist` (wheel IK, §8.4) with the steering at its IK
    headings (or as described when the twist is 0). `record_step` [s] (default `step`, at least 1 ms for
    ``"adaptive"``) sets the output sampling; `progress` shows a tqdm bar (default: runs of 500 000 steps or more);
    `jac_every`: steps between refreshes of the tyre Jacobian of the semi-implicit method (1: every step);
    `rtol` in (0, 1): the adaptive method's relative tolerance. At most :data:`MAX_STEPS` fixed steps and samples,
    and at most :func:`record_capacity` samples (1 GiB).

    A wheel loaded at rest whose normal load falls to 0 lifts off; the planar model cannot follow it (it clips the
    load and keeps the wheel down), so the run stops with a :class:`WmrkitError` naming the contact and the time,
    unless `allow_lift_off`. A fixed-step run that stops so (or diverges) is re-run to its end at a shorter step
    (:func:`~wmrkit.dynamics.runs.recheck_step`); when that one does not stop, the error says the step was too long
    for the tyres (the integrator unstable, not the robot) and names the step that ran; when it stops later, it
    names that stop too; when the re-check's budget ends first, it says the verdict is not known
    (:func:`~wmrkit.dynamics.runs.judge`). A fixed-step run that goes on is re-run at that shorter step, when `check`,
    if its step is longer than :data:`~wmrkit.dynamics.runs.RECHECK_MAX_STEP` or it left its twist program's path,
    and refused when the two runs are far apart or the shorter one stops (:func:`~.deviation.check_step`).
    """
    model = robot if isinstance(robot, DynamicModel) else DynamicModel.of(robot, tyre)
    if method not in METHODS:
        raise WmrkitError(f"unknown method '{method}' (methods: {', '.join(METHODS)})")
    if not isinstance(inputs, Inputs):  # a mapping raised "'dict' object has no attribute 'torques'"
        raise ShapeError(f"inputs: expected Inputs (Inputs.torques_only, twist_program, path_program), got "
                          f"{type(inputs).__name__}")
    if not (real_number(duration) and real_number(step) and duration > 0 and 0 < step <= duration):  # text: TypeError
        raise ShapeError(f"duration and step must be finite numbers [s] with 0 < step <= duration, got {duration!r}, "
                          f"{step!r}")
    if method != "adaptive" and duration / step > MAX_STEPS:
        raise ShapeError(f"duration {duration:g} s at step {step:g} s: more than {MAX_STEPS:.0e} integration steps")
    if record_step is not None and not (real_number(record_step) and record_step > 0):  # NaN included
        raise ShapeError(f"record_step: expected a finite number > 0 [s] (None: the step), got {record_step!r}")
    record = record_step or (max(step, 1e-3) if method == "adaptive" else step)
    if duration / record > MAX_STEPS:
        raise ShapeError(f"record_step: {record:g} s over {duration:g} s is more than {MAX_STEPS:.0e} samples")
    every = max(1, round(record / step))
    samples = adaptive_samples(duration, record) if method == "adaptive" else round(duration / step) // every + 1
    if samples > record_capacity(model):
        raise ShapeError(f"record_step: {record:g} s over {duration:g} s records {samples} samples, more than the "
                          f"{record_capacity(model)} of robot '{model.robot.name}' that fit in 1 GiB "
                          f"(MAX_RECORD_VALUES); record every {recordable_step(model, duration, step, step):g} s")
    if not (real_number(rtol) and 0 < rtol < 1):  # text raised "'<' not supported"
        raise ShapeError(f"rtol: expected a relative tolerance in (0, 1), got {rtol}")
    s0 = initial_state(model, initial_twist, initial_pose)
    inp = compiled_inputs(model, inputs)
    if method == "adaptive":
        rec, info = adaptive_run(model, s0, inp, duration, record, rtol, allow_lift_off)
    else:
        rec, info = fixed_run(model, s0, inp, duration, step, every, 0 if method == "semi-implicit" else 1, progress,
                           jac_every, allow_lift_off)
    sim = _result(model, rec, method, step, info)
    if inputs.twist is not None:
        nominal = nominal_poses(np.atleast_1d(inputs.twist_time), inputs.twist, sim.t, s0[:3])
        sim = dataclasses.replace(sim, nominal_pose=readonly(nominal))
    if check:
        sim = dataclasses.replace(sim, step_check=check_step(model, inputs, sim, initial_twist, jac_every,
                                                             allow_lift_off))
    return sim


class Stepper:
    """A running fixed-step simulation that continues from its full state with new inputs (closed loops).

    `state` ``(2n,)``: pose ``(x, y, theta)``, the joint positions of the columns ``model.names[3:]``, then the
    velocities ``nu (n,)`` (default :func:`initial_state`, at rest); a float64 C-contiguous array is used in place
    (caller-owned), anything else is copied. :meth:`advance` integrates with the semi-implicit method (or ``"rk4"``)
    at `step` [s] from time `t` [s]; it raises when a wheel lifts off unless `allow_lift_off` (as
    :func:`simulate`), and a stop is re-checked as there: the inputs it was given (logged: :class:`~.runs.StepLog`)
    are run again at a shorter step to their end (:meth:`~.runs.StepLog.recheck`), and when that run goes on, the
    error blames the step and names the one that ran (`recheck` False: no log and no re-check, for a caller that
    re-runs itself, as the loops through the dynamics do: :func:`wmrkit.control.dynamic_plant.rechecked`). The
    stepper carries all the integrator carries (the last acceleration for the load transfer, the tyre Jacobian and
    its refresh phase): advancing in pieces gives, bit for bit, the run of one :func:`simulate` call.
    """

    def __init__(self, model: Robot | DynamicModel, state: ArrayLike | None = None, *, step: float = 1e-3,
                 method: Literal["semi-implicit", "rk4"] = "semi-implicit", jac_every: int = 20, t: float = 0.0,
                 tyre: Tyre | str | None = None, allow_lift_off: bool = False, recheck: bool = True) -> None:
        from ..kinematics.gear_check import given_gear_breaches
        from ..kinematics.wheel_ik import SLIP_TOL
        from ._integrate import model_work_arrays

        self.model = model if isinstance(model, DynamicModel) else DynamicModel.of(model, tyre)
        if method not in ("semi-implicit", "rk4"):
            raise WmrkitError(f"unknown stepping method '{method}' (methods: semi-implicit, rk4)")
        if not (real_number(step) and step > 0 and real_number(t)):  # text raised math's TypeError
            raise ShapeError(f"step must be finite and > 0 and t finite, got {step}, {t}")
        if not (isinstance(jac_every, int) and jac_every >= 1):
            raise ShapeError(f"jac_every must be an integer >= 1, got {jac_every!r}")
        n = self.model.n
        if state is None:
            state = initial_state(self.model)
        elif not (isinstance(state, np.ndarray) and state.dtype == np.float64 and state.flags.c_contiguous
                  and state.flags.writeable and state.shape == (2 * n,)):
            state = np.array(as_vectors(state, 2 * n, "state"), dtype=float)
        if not np.all(np.isfinite(state)):
            raise ShapeError("state: every entry must be finite")
        for breach in given_gear_breaches(self.model.robot, self.model.names, state[n:], SLIP_TOL):
            rates = ", ".join(f"{self.model.names[i]} {state[n + i]:.6g}" for i in breach.given)
            raise WmrkitError(f"state: {breach.head} ({rates} rad/s): the dynamics hold the gear, so a state turns "
                              "its joints in its ratios (initial_state does)")
        linked = linkage_breach(self.model, state[list(self.model.steer_columns)], state[n:])
        if linked:
            raise WmrkitError(f"state: {linked}: the dynamics hold the linkage, so a state steers its wheels as it "
                              "does (initial_state does)")
        self.state: np.ndarray = state
        self.step, self.jac_every, self.allow_lift_off = float(step), jac_every, allow_lift_off
        self._method = 0 if method == "semi-implicit" else 1
        self._k = round(t / step)
        self._phase = self._k  # the tyre Jacobian is refreshed at the first step, then every jac_every steps
        self._acc = np.zeros(n)
        self._w = model_work_arrays(self.model)
        self._rec = records(self.model, 0)
        self._inputs: tuple | None = None  # compiled; hold() replaces the arrays it changes (the log keeps them)
        self._fight = False  # the last inputs' fight_linkages: hold() lets their servos fight a linkage too
        self._log = StepLog(self.step, self._method) if recheck else None
        self._delta = np.array([w.delta for w in self.model.robot.wheels if w.kind.steers], dtype=float)
        self._lever = levers(self.model, state[list(self.model.steer_columns)])  # runs.first_escape's
        self._top_rate = MAX_SPEED / self._lever  # a quick test of the range before first_escape says why
        self._unrecorded = (np.zeros(0), np.zeros((0, 2 * n)))  # no records: first_escape judges the state alone

    @property
    def t(self) -> float:
        """Simulation time [s] of :attr:`state`."""
        return self._k * self.step

    def advance(self, inputs: Inputs | None, duration: float) -> np.ndarray:
        """Integrate ``round(duration / step)`` steps (at most :data:`MAX_STEPS`) with `inputs` (time axis: the
        simulation time; None: the last ones); changes :attr:`state` in place and returns it. Heading set-points
        that break a held linkage are refused, as :func:`simulate` refuses them (``Inputs.fight_linkages``: run).
        A state that leaves the physical range (:func:`~.runs.first_escape`, judged at the end and every
        :data:`~.runs.RANGE_CHECK` s) stops it there, as :func:`simulate`'s runs stop (a :class:`DivergedError`)."""
        from ._integrate import run

        if inputs is not None:
            self._inputs, self._fight = compiled_inputs(self.model, inputs), inputs.fight_linkages
        if self._inputs is None:
            raise WmrkitError("advance: no inputs given yet")
        if not (real_number(duration) and 0 <= duration / self.step <= MAX_STEPS):  # text: a TypeError
            raise ShapeError(f"duration must be >= 0 and at most {MAX_STEPS:.0e} steps of {self.step:g} s, got "
                              f"{duration}")
        n_steps, log, far = round(duration / self.step), self._log, None
        piece, n = max(1, round(RANGE_CHECK / self.step)), self.model.n  # the range judged after each piece
        while n_steps and far is None:  # with a log, in pieces of at most its span, each logged for a re-check
            steps = n_steps if log is None else log.add(self._k, n_steps, self.state, self._inputs)
            n_steps -= steps
            while steps and far is None:  # the same steps, the range judged every `piece` of them
                part = min(steps, piece)
                run(self.state, self._k, self.step, part, 1 << 62, self._method, self.jac_every, self._acc,
                    self.model.pack, self._inputs, self._w, self._rec, 0, self._phase)
                self._k += part
                steps -= part
                if (np.abs(self.state[n:]) > self._top_rate).any():
                    far = first_escape(self.model, self._lever, *self._unrecorded, self.t, self.state)
        diverged = not math.isfinite(self.state.sum())  # NaN and infinities propagate into the sum
        if log is not None and (diverged or far is not None or lifted(self._w, self.allow_lift_off)):
            log.recheck(self.model, self._w, self.t, self.step, self._method, self.jac_every, self.allow_lift_off,
                        far, self._lever)
        if lifted(self._w, self.allow_lift_off):  # first, when the state diverged after it
            check_lift_off(self.model, self._w)
        if far is not None:
            what = Stop.escaped(*far).what
            raise DivergedError(f"{what}; use smaller torques or speeds", far[0], what)
        if diverged:
            raise DivergedError(f"the simulation diverged before t = {self.t:.6g} s; use a smaller step", self.t)
        return self.state

    def hold(self, rate_reference: ArrayLike | None = None, heading_reference: ArrayLike | None = None,
             torques: ArrayLike | None = None) -> None:
        """Hold new joint references from now on (a controller's period): wheel-rate references ``(n,)`` [rad/s]
        over ``model.names``, steering headings ``(n_steer,)`` [rad], feed-forward torques ``(n,)`` [N m]. Gains,
        limits and the values not given are those of the last inputs at the current time (in place, a few µs; new
        rows while the stepper logs them). Headings that break a held linkage are refused, as :meth:`advance`
        refuses them (unless the last inputs' ``fight_linkages``), before anything is held."""
        if self._inputs is None:
            raise WmrkitError("hold: give inputs (their servo gains) to advance() first")
        tk, tau, rref, gain, limit, bref, kp, kd, steer_limit = self._inputs
        if heading_reference is not None:
            heading_reference = held_values(heading_reference, bref.shape[1], "heading_reference")
            if (len(self.model.pack[17]) or self.model.pack[16].shape[1]) and not self._fight:
                problem = setpoint_problem(self.model, heading_reference, set(np.flatnonzero(kp > 0).tolist()))
                if problem:
                    raise WmrkitError(f"hold: heading_reference: at t = {self.t:.6g} s, {problem}")
        if tk.shape[0] != 1:  # the values at the current time, held from now on
            t = self.t
            tau, rref, bref = (np.array([np.interp(t, tk, col) for col in a.T], dtype=float).reshape(1, a.shape[1])
                               for a in (tau, rref, bref))
            tk = np.array([t])
            self._inputs = (tk, tau, rref, gain, limit, bref, kp, kd, steer_limit)
        elif self._log is not None:  # the log keeps the rows it advanced with: new ones
            tau, rref, bref = tau.copy(), rref.copy(), bref.copy()
            self._inputs = (tk, tau, rref, gain, limit, bref, kp, kd, steer_limit)
        if rate_reference is not None:
            rref[0] = held_values(rate_reference, rref.shape[1], "rate_reference")
        if torques is not None:
            tau[0] = held_values(torques, tau.shape[1], "torques")
        if heading_reference is not None:  # the thesis's beta = heading - delta + pi/2, as Robot.beta_of_heading
            row = bref[0]
            np.subtract(heading_reference, self._delta, out=row)
            row += 0.5 * math.pi


def advance(model: Robot | DynamicModel, state: ArrayLike, inputs: Inputs, duration: float, *, step: float = 1e-3,
            t: float = 0.0, method: Literal["semi-implicit", "rk4"] = "semi-implicit",
            jac_every: int = 20, allow_lift_off: bool = False) -> np.ndarray:
    """The state ``(2n,)`` after `duration` [s] of `inputs` from the full `state` at time `t` (a new array; a fresh
    integrator: ``Stepper(model, copy of state, t=t).advance(inputs, duration)``)."""
    m = model if isinstance(model, DynamicModel) else DynamicModel.of(model)
    stepper = Stepper(m, np.array(as_vectors(state, 2 * m.n, "state"), dtype=float), step=step, method=method,
                      jac_every=jac_every, t=t, allow_lift_off=allow_lift_off)
    return stepper.advance(inputs, duration)


def initial_state(model: DynamicModel, twist: ArrayLike = (0, 0, 0), pose: ArrayLike = (0, 0, 0)) -> np.ndarray:
    """State ``(2n,)`` rolling without slip at `twist`: pose, joint positions (steering at IK angles), velocities.
    A twist at which a ``gear``'s joints would turn out of its ratios (a solid axle turning) keeps the twist and turns
    each gear at the least-squares fit of those rates: the wheels slip from the start. One whose steering a
    ``linkage`` cannot set (:mod:`.linkages`) is refused, naming it.

    The twist's speeds and turn rate are within ``limits.MAX_SPEED`` (m/s, rad/s), the pose's position within
    ``limits.MAX_COORDINATE`` and its heading finite."""
    from ..kinematics.wheel_ik import wheel_commands

    twist, pose, n = as_vectors(twist, 3, "initial_twist"), as_vectors(pose, 3, "initial_pose"), model.n
    if twist.shape != (3,) or not np.all(np.abs(twist) <= MAX_SPEED):  # NaN included
        raise ShapeError(f"initial twist {twist.tolist()}: expected three finite numbers, speeds within "
                          f"{MAX_SPEED:g} m/s and a turn rate within {MAX_SPEED:g} rad/s")
    if pose.shape != (3,) or not (np.all(np.abs(pose[:2]) <= MAX_COORDINATE) and math.isfinite(pose[2])):
        raise ShapeError(f"initial pose {pose.tolist()}: expected a position within {MAX_COORDINATE:g} m and a "
                          "finite heading")
    s = np.zeros(2 * n)
    s[:3] = pose
    beta = np.array(model.robot.beta, dtype=float)
    s[n:n + 3] = twist
    if np.any(twist != 0):
        cmd = wheel_commands(model.robot, twist)
        beta = np.asarray(cmd.beta, dtype=float)
        s[n + 3:n + 3 + len(cmd.rates)] = cmd.rates
        gears = model.pack[16]
        if gears.shape[1]:  # a twist a gear forbids: its joints at their least-squares turn (the wheels slip)
            s[n:] = gears @ ((gears.T @ s[n:]) / (gears * gears).sum(axis=0))
    breach = linkage_breach(model, beta)
    if breach:
        raise WmrkitError(f"initial twist {twist.tolist()}: its wheels' steering (wheel IK) breaks a linkage "
                          f"({breach}), which the dynamics hold")
    for k, c in enumerate(model.steer_columns):
        s[c] = beta[k]
    return s


def _result(model: DynamicModel, rec: tuple, method: str, step: float, info: dict) -> Simulation:
    t, s, f, fz, v, vw, tau = rec
    n = model.n
    beta = s[:, list(model.steer_columns)]
    delta = np.array([w.delta for w in model.robot.wheels if w.kind.steers])
    return Simulation(model.names, model.contacts, *(readonly(np.ascontiguousarray(a)) for a in (
        t, s[:, :3], s[:, n:n + 3], s[:, 3:n], s[:, n + 3:], tau[:, 3:], heading_from_beta(beta, delta), f, fz, v,
        vw)), method=method, step=step, info=info,
        steered=tuple(w.name for w in model.robot.wheels if w.kind.steers))
