"""How far a simulated run is from the path its program commands.

A twist program (:func:`~wmrkit.dynamics.programs.twist_program`, the built-in paths of
:func:`~wmrkit.dynamics.programs.path_program`) drives the wheels at the no-slip rates of body twists and does not
feed the pose back: the robot goes where its tyres take it. :func:`nominal_poses` integrates the commanded twists
(the pose rate of (3.15), ``R(theta) (vx, vy)`` and ``omega``) into the path the program describes, and
:class:`PathDeviation` compares the simulated poses with it at the records' times, and :func:`check_step` refuses a
fixed-step run whose deviation a shorter step does not reproduce (the step's, not the robot's).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from ..errors import WmrkitError

#: Largest position deviation, as a share of the programmed path's size, and largest heading deviation, as a share
#: of the programmed turn taken within [:data:`MIN_TURN`, one turn], that a run may show without a warning (measured
#: over the catalog's robots with mass properties and the dynamics tests' robots x built-in paths x tyre models:
#: docs/dynamics.md, "Deviation from the program": the forklift's largest 0.133 and 0.140, the skid steer's
#: smallest 0.50 and 0.33 where it turns).
POSITION_SHARE, TURN_SHARE = 0.25, 0.2
#: Least programmed turn [rad] the heading share is taken of (a straight path's heading may drift 0.1 rad); the
#: most is a turn (a heading 72 deg off is off the path, however many loops it has).
MIN_TURN = 0.5
#: Largest heading change [rad] of one quadrature piece of :func:`nominal_poses`, its turn-rate change times its
#: duration included (three Gauss points a piece).
_PIECE_TURN = 0.05
_GAUSS = ((0.5 - 0.5 * math.sqrt(0.6), 5 / 18), (0.5, 8 / 18), (0.5 + 0.5 * math.sqrt(0.6), 5 / 18))


def nominal_poses(time: np.ndarray, twists: np.ndarray, t: np.ndarray, pose0=(0.0, 0.0, 0.0)) -> np.ndarray:
    """Poses ``(len(t), 3)`` [m, m, rad] at the increasing times `t` of the robot moving at body `twists` ``(K,
    3)`` (robot frame, linear between the knots `time`, held outside them) from `pose0` at ``t[0]``.

    The heading is exact (the integral of a piecewise-linear turn rate); the position is integrated by three-point
    Gauss quadrature on pieces whose turn plus turn-rate change times duration is at most 0.05 rad (relative error
    about 1e-13), at most 64 pieces between two samples or knots.
    """
    t = np.asarray(t, dtype=float)
    grid = np.union1d(t, time[(time > t[0]) & (time < t[-1])])
    tw = np.column_stack([np.interp(grid, time, twists[:, k]) for k in range(3)])
    h = np.diff(grid)
    theta = pose0[2] + np.concatenate([[0.0], np.cumsum(h * (tw[:-1, 2] + tw[1:, 2]) / 2)])
    xy = np.zeros((len(grid), 2))
    xy[0] = pose0[:2]
    bend = np.abs(theta[1:] - theta[:-1]) + np.abs(tw[1:, 2] - tw[:-1, 2]) * h
    pieces = np.clip(np.ceil(bend / _PIECE_TURN), 1, 64).astype(int)
    chunk = 1 << 16
    for lo in range(0, len(h), chunk):  # bounded memory: at most 64 x 3 x chunk nodes at once
        sl = slice(lo, lo + chunk)
        m = pieces[sl]
        interval = np.repeat(np.arange(len(m)), m)
        first = np.repeat(np.cumsum(m) - m, m)
        k = np.arange(len(interval)) - first  # the piece's index within its interval
        increments = np.zeros((len(m), 2))
        for g, share in _GAUSS:
            s = (k + g) / m[interval]  # fraction of the interval
            i = interval + lo
            hi = h[i]
            w0, w1 = tw[i], tw[i + 1]
            v = w0 + (w1 - w0) * s[:, None]  # the twist, linear in time
            th = theta[i] + hi * s * (w0[:, 2] + v[:, 2]) / 2  # exact: the mean of a linear rate
            c, sn = np.cos(th), np.sin(th)
            weight = hi / m[interval] * share
            increments[:, 0] += np.bincount(interval, (c * v[:, 0] - sn * v[:, 1]) * weight, len(m))
            increments[:, 1] += np.bincount(interval, (sn * v[:, 0] + c * v[:, 1]) * weight, len(m))
        xy[lo + 1:lo + 1 + len(m)] = xy[lo] + np.cumsum(increments, axis=0)
    at = np.searchsorted(grid, t)
    return np.column_stack([xy[at], theta[at]])


@dataclass(frozen=True)
class PathDeviation:
    """A simulated run against its program's path (:func:`nominal_poses`), at the records' times.

    ``end_position`` [m]: the distance between the last simulated and programmed positions; ``end_heading`` [rad]:
    the simulated heading minus the programmed one at the last sample (not wrapped: a robot that turned half as
    much as programmed in a rectangle is about -3.1 rad off); ``max_position`` [m] at ``max_time`` [s]: the largest
    position distance over the samples; ``max_heading`` [rad]: the largest heading difference (signed); ``size``
    [m]: the programmed path's size (the diagonal of its positions' bounding box, at least 1 m); ``turn`` [rad]:
    the programmed path's whole turn (the sum of its heading changes' magnitudes between samples).
    """

    end_position: float
    end_heading: float
    max_position: float
    max_time: float
    max_heading: float
    size: float
    turn: float

    @classmethod
    def of(cls, t: np.ndarray, pose: np.ndarray, nominal: np.ndarray) -> PathDeviation:
        """The deviation of simulated poses ``(N, 3)`` at times `t` from the programmed poses `nominal`."""
        distance = np.hypot(*(pose[:, :2] - nominal[:, :2]).T)
        heading = pose[:, 2] - nominal[:, 2]
        k = int(np.argmax(distance))
        size = float(np.hypot(*np.ptp(nominal[:, :2], axis=0)))
        turn = float(np.abs(np.diff(nominal[:, 2])).sum())
        return cls(float(distance[-1]), float(heading[-1]), float(distance[k]), float(t[k]),
                   float(heading[np.argmax(np.abs(heading))]), max(size, 1.0), turn)

    @property
    def large(self) -> bool:
        """Whether the run left its program's path: its largest position deviation is more than
        :data:`POSITION_SHARE` of the path's size, or its largest heading deviation more than :data:`TURN_SHARE`
        of the programmed turn (within [:data:`MIN_TURN`, 2 pi])."""
        return (self.max_position > POSITION_SHARE * self.size
                or abs(self.max_heading) > TURN_SHARE * min(max(self.turn, MIN_TURN), 2 * math.pi))

    def to_dict(self) -> dict:
        """Plain data for JSON (m, rad, s)."""
        return {"end_position": self.end_position, "end_heading": self.end_heading,
                "max_position": self.max_position, "max_time": self.max_time, "max_heading": self.max_heading,
                "path_size": self.size, "path_turn": self.turn, "large": self.large}


def deviation_warning(model, inputs, deviation: PathDeviation, max_slip: float) -> str:
    """One line saying that a run left its program's path, by how much, and why where that is knowable: a program
    whose twists have no no-slip motion (a skid steer's turns: fixed wheels must slip sideways) turns less than its
    wheel rates command; one whose twists a ``gear`` forbids (a solid axle asked to turn) cannot follow them."""
    from ..kinematics.wheel_ik import wheel_commands
    from .programs import SLIP_TOL

    line = (f"the robot left the programmed path: up to {deviation.max_position:.3g} m from it (t = "
            f"{deviation.max_time:g} s; the path is {deviation.size:.3g} m across and turns {deviation.turn:.3g} rad), "
            f"{deviation.end_position:.3g} m and {deviation.end_heading:.3g} rad off at the end; ")
    cmd = wheel_commands(model.robot, inputs.twist, slip_tol=SLIP_TOL)  # at the program's knots
    slip = np.abs(cmd.slip)
    geared = cmd.in_gear.all(axis=0).tolist()
    broken = [c for c, ok in zip(model.robot.couplings, geared, strict=True) if not ok]
    if broken:
        ratios = ", ".join(f"{k:g}" for k in broken[0].ratios)
        return line + (f"its twists turn {broken[0].joints_words()} out of its ratios ({ratios}), and the "
                       "gear holds them together: its servos fight and the robot cannot follow those twists (wmrkit "
                       "ik says which twists a gear allows)")
    if slip.max() > SLIP_TOL:
        w = model.robot.wheel_names[int(np.argmax(slip.max(axis=0)))]
        return line + (f"its twists have no no-slip motion (fixed wheel '{w}' must slip sideways, as a skid steer's "
                       "do when it turns): the robot turns less than its wheel rates command (an effective track: "
                       "wmrkit calibrate, docs/slip.md)")
    return line + (f"its tyres slip (up to {max_slip:.3g} m/s): the program drives the wheel rates, not the pose "
                   "(docs/dynamics.md)")


@dataclass(frozen=True)
class StepCheck:
    """A fixed-step run against its re-run at a shorter ``step`` [s] from t = 0 to ``until`` [s]: ``apart``, the
    run's :class:`PathDeviation` from the re-run (its size and turn the program's, else the re-run's)."""

    step: float
    until: float
    apart: PathDeviation

    def to_dict(self) -> dict:
        """Plain data for JSON (m, rad, s)."""
        return {"step": self.step, "until": self.until, "max_position": self.apart.max_position,
                "max_heading": self.apart.max_heading}


def check_step(model, inputs, sim, initial_twist=(0.0, 0.0, 0.0), jac_every: int = 20,
               allow_lift_off: bool = False) -> StepCheck | None:
    """Refuse a fixed-step run `sim` of `inputs` (from `initial_twist` at ``sim.pose[0]``) whose result is the
    step's, not the robot's. The run is re-run from t = 0 at :func:`~wmrkit.dynamics.runs.recheck_step` over at most
    :data:`~wmrkit.dynamics.runs.RECHECK_STEPS` of its steps (a quarter for rk4), on the run's record times, when

    - it left its twist program's path (:attr:`PathDeviation.large`): refused when the two runs are as far apart as
      that yardstick (the program's size and turn), or when the re-run does not leave the path by it (the warning
      is the step's: rk4's turn at 1 ms, 0.52 m off, was 0.42 m from its 0.1 ms run, which keeps within 0.23 m, and
      blamed the tyres); a run that left its path by as much at both steps passes;
    - its step is longer than :data:`~wmrkit.dynamics.runs.RECHECK_MAX_STEP` (torque inputs too): refused when the
      re-run stops (a long step can damp a lift-off away, docs/dynamics.md) or the two are that far apart (the
      re-run's own size and turn without a program).

    Returns the comparison of a run that passes (:class:`StepCheck`), None when it was not re-run. Its error names
    the step keyword (:data:`~wmrkit.dynamics.runs.SIMULATE_STEP`; the CLI its option: ``at_door``)."""
    from .runs import RECHECK_MAX_STEP, SIMULATE_STEP, recheck_budget, recheck_step
    from .simulate import simulate

    if sim.method == "adaptive" or len(sim.t) < 2:
        return None
    method = 0 if sim.method == "semi-implicit" else 1
    deviation = sim.deviation()
    off_path = deviation is not None and deviation.large
    if not off_path and sim.step <= RECHECK_MAX_STEP[method] * (1 + 1e-9):
        return None
    step, fine = sim.step, recheck_step(sim.step, method)
    every = round((sim.t[1] - sim.t[0]) / step)  # steps between records
    m = min(len(sim.t), recheck_budget(method) // (every * round(step / fine)) + 1)
    if m < 2:
        return None
    what = (f"the robot left the programmed path at step {step:g} s (up to {deviation.max_position:.3g} m from it)"
            if off_path else f"the run at step {step:g} s (longer than the {RECHECK_MAX_STEP[method]:g} s at which "
            f"the tyres' integration is checked) went on")
    try:
        check = simulate(model, inputs, (m - 1) * every * step, step=fine, method=sim.method,
                         initial_twist=initial_twist, initial_pose=sim.pose[0], record_step=every * step,
                         progress=False, jac_every=jac_every, allow_lift_off=allow_lift_off, check=False)
    except WmrkitError as e:
        err = WmrkitError(f"{what}, and a run at step {fine:.3g} s to check it stops: {e}")
        err.where = getattr(e, "where", "")  # the stop's advice, said at each door its own way (runs.at_door)
        raise err from None
    t = sim.t[:m]
    along = PathDeviation.of(t, check.pose, check.pose if sim.nominal_pose is None else sim.nominal_pose[:m])
    apart = dataclasses.replace(PathDeviation.of(t, sim.pose[:m], check.pose), size=along.size, turn=along.turn)
    off_within = off_path and PathDeviation.of(t, sim.pose[:m], sim.nominal_pose[:m]).large  # over the re-run's time
    if apart.large or (off_within and not along.large):  # far from the re-run, or off a path the re-run keeps to
        kept = (f", but a run at step {fine:.3g} s to t = {t[-1]:g} s keeps within {along.max_position:.3g} m of the "
                "path and" if off_path else f"; a run at step {fine:.3g} s to t = {t[-1]:g} s")
        err = WmrkitError(
            f"{what}{kept} is up to {apart.max_position:.3g} m and {abs(apart.max_heading):.3g} rad from that run: "
            f"the step is too long for the tyres (the integration's error, not the robot's "
            f"{'path' if off_path else 'motion'}); use a step of at most {fine:.3g} s {SIMULATE_STEP}")
        err.where = SIMULATE_STEP  # the CLI says its option (runs.at_door)
        raise err
    return StepCheck(fine, float(t[-1]), apart)
