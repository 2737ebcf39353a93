"""The kinematic loop closed through the chapter-7 dynamics (beyond the thesis, issue item 7).

Each period the controller's twist becomes the servo inputs of :func:`wmrkit.dynamics.programs.twist_program`
(rate servos on the actuated wheels, PD servos on the actuated steering, at the IK's no-slip joint motion), and the
Lagrange model with tyres (:mod:`wmrkit.dynamics`) is integrated over the period from the *full* state it reached
(pose, steering, wheel angles, every velocity: tyre slip carries over). The robot needs its mass properties and
tyres in its description (the catalog ``forklift`` has them).
"""

from __future__ import annotations

import math

import numpy as np

from .loop import TwistController
from .points import ControlError

__all__ = ["simulate_dynamics"]


def simulate_dynamics(robot, controller: TwistController, initial_pose: np.ndarray, duration: float, *,
                      period: float, delay: int = 0, tyre: str | None = None, step: float = 1e-3,
                      feedback: str = "pose") -> dict[str, np.ndarray]:
    """Close the loop of `controller` on the dynamic model of `robot` (same outputs as :func:`.loop.simulate`).

    `period` [s]: control period (commands held); `delay`: measurement delay in samples; `tyre`: traction model
    name (default: as described); `step` [s]: integration step of the dynamics (1 kHz default, semi-implicit).
    `feedback`: ``"pose"`` (the true pose is measured) or ``"odometry"`` (the pose estimated from the sensed joints,
    one exact SE(2) step per period, :func:`wmrkit.kinematics.realtime.realtime`); the estimate is returned as
    ``estimate (n, 3)``.
    """
    from ..dynamics import simulate as dsim
    from ..dynamics.model import DynamicModel
    from ..dynamics.programs import twist_program

    if not (math.isfinite(period) and period >= step > 0):
        raise ControlError(f"period: expected a control period >= the dynamics step {step} s, got {period}")
    if feedback not in ("pose", "odometry"):
        raise ControlError(f"feedback must be 'pose' or 'odometry', got {feedback!r}")
    model = DynamicModel.of(robot, tyre)
    n_steps = max(1, round(period / step))
    s = dsim.initial_state(model, (0.0, 0.0, 0.0), initial_pose)
    steer = list(model.steer_columns)
    n = math.floor(duration / period + 1e-9) + 1
    history, integral = [s[:3].copy()], np.zeros(3)
    odometer = _Odometer(robot, model, s) if feedback == "odometry" else None
    keys = ("t", "pose", "twist", "beta", "target", "estimate")
    records: dict[str, list] = {k: [] for k in keys}
    for k in range(n):
        t = k * period
        twist, de = controller(t, history[max(0, k - delay)], integral)
        integral = integral + period * de
        inputs = twist_program(model, [0.0, period], [twist, twist])
        target = np.asarray(robot.beta_of_heading(inputs.heading_reference[0]), dtype=float)
        values = (t, s[:3].copy(), np.asarray(twist, float), s[steer].copy(), target, history[-1].copy())
        for key, value in zip(keys, values, strict=True):
            records[key].append(value)
        if k == n - 1:
            break
        rec, _ = dsim._fixed(model, s, dsim._compiled_inputs(model, inputs), n_steps * step, step, n_steps, 0,
                             False, 20)
        s = np.array(rec[1][-1], dtype=float)
        history.append(s[:3].copy() if odometer is None else odometer.step(s))
    return {key: np.array(values) for key, values in records.items()}


class _Odometer:
    """Odometry from the sensed joints of the simulated state (the robot's compiled single-call step)."""

    def __init__(self, robot, model, s: np.ndarray) -> None:
        from ..kinematics.realtime import realtime

        self.rt = realtime(robot)
        self.cols = [model.names.index(j) for j in self.rt.rate_joints]
        self.steer = [model.steer_columns[robot.steer_names.index(j.partition(".")[0])] for j in self.rt.steer_joints]
        self.delta = np.array([robot.wheel(j.partition(".")[0]).delta for j in self.rt.steer_joints], dtype=float)
        self.pose = s[:3].copy()
        self.previous = s[self.cols].copy()
        self.beta = s[self.steer].copy()

    def step(self, s: np.ndarray) -> np.ndarray:
        beta = s[self.steer]
        heading_mid = 0.5 * (beta + self.beta) + self.delta - 0.5 * math.pi
        self.beta = beta.copy()
        self.rt.odometry_step(self.pose, self.previous, np.ascontiguousarray(s[self.cols]), heading_mid)
        return self.pose.copy()
