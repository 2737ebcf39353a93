"""Low-level loops of §8.2 (Fig. 8.1): one closed actuator loop per joint, ideal, first or second order.

The thesis's real forklift (§8.6.3) had uncoupled loops with a steering settling time of about 1.5 s (no
overshoot) and a traction settling time of about 3.5 s with 15 % overshoot. A loop is given by those two numbers:

- ``settling_time = 0``: ideal, the joint follows its command at once;
- ``overshoot = 0``: first order, ``y' = (u - y) / tau`` with ``tau = t_s / ln(50)`` (2 % settling);
- ``overshoot > 0``: second order, ``y'' = w_n^2 (u - y) - 2 zeta w_n y'`` with
  ``zeta = -ln(OS) / sqrt(pi^2 + ln(OS)^2)`` and ``w_n = ln(50) / (zeta t_s)`` (2 % envelope).

*Coupled* loops add ``C (u - y)`` to every joint's input (``C`` with zero diagonal): a joint is disturbed by the
others' errors, the mutual disturbance the thesis observed between the forklift's motors. Steering joints hold the
thesis's angle ``beta`` [rad] and their error is wrapped to (-pi, pi]; spin joints hold rates [rad/s].
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..wheels import wrap_angle
from .points import ControlError

__all__ = ["ActuatorLoop", "LowLevelLoops"]

LN50 = math.log(50.0)


@dataclass(frozen=True)
class ActuatorLoop:
    """One joint's closed loop: 2 % `settling_time` [s] (0: ideal) and fractional `overshoot` (0.15 = 15 %)."""

    settling_time: float = 0.0
    overshoot: float = 0.0

    def __post_init__(self) -> None:
        if not (math.isfinite(self.settling_time) and self.settling_time >= 0):
            raise ControlError(f"settling time: expected a number >= 0 s, got {self.settling_time}")
        if not (0 <= self.overshoot < 1):
            raise ControlError(f"overshoot: expected a fraction in [0, 1), got {self.overshoot}")

    @property
    def order(self) -> int:
        """0 (ideal), 1 or 2."""
        return 0 if self.settling_time == 0 else (1 if self.overshoot == 0 else 2)

    @property
    def tau(self) -> float:
        """First-order time constant [s]."""
        return self.settling_time / LN50

    @property
    def zeta(self) -> float:
        """Damping ratio of the second-order loop."""
        lo = math.log(self.overshoot)
        return -lo / math.sqrt(math.pi**2 + lo * lo)

    @property
    def omega_n(self) -> float:
        """Natural frequency [rad/s] of the second-order loop."""
        return LN50 / (self.zeta * self.settling_time)


@dataclass(frozen=True)
class LowLevelLoops:
    """Actuator loops of named joints (``'wheel.spin'``, ``'wheel.steer'``); joints not named are ideal.

    ``coupling``: None (uncoupled) or a square matrix (tuple of rows) with zero diagonal, in `joints` order.
    """

    joints: tuple[str, ...]
    loops: tuple[ActuatorLoop, ...]
    coupling: tuple[tuple[float, ...], ...] | None = None

    def __post_init__(self) -> None:
        if len(self.joints) != len(self.loops):
            raise ControlError(f"low-level loops: {len(self.joints)} joints but {len(self.loops)} loops")
        for j in self.joints:
            if j.rpartition(".")[2] not in ("spin", "steer"):
                raise ControlError(f"low-level loop on '{j}': only 'wheel.spin' and 'wheel.steer' joints")
        if self.coupling is not None:
            c = np.asarray(self.coupling, dtype=float)
            if c.shape != (len(self.joints),) * 2 or np.any(np.diag(c) != 0) or not np.all(np.isfinite(c)):
                raise ControlError(f"coupling: expected a {len(self.joints)}x{len(self.joints)} matrix, zero diagonal")

    @property
    def time_scale(self) -> float:
        """The fastest loop's time scale [s] (``tau``, or ``1 / omega_n`` of a second-order loop), shortened by the
        coupling (``1 + max row sum of |C|``); inf when every loop is ideal. A fixed-step integrator steps at most
        this long (explicit RK4 diverges beyond about 2.8 of them)."""
        scales = [lp.tau if lp.order == 1 else 1 / lp.omega_n for lp in self.loops if lp.order]
        gain = 1.0 if self.coupling is None else 1.0 + float(np.abs(np.asarray(self.coupling)).sum(axis=1).max())
        return min(scales, default=math.inf) / gain

    @property
    def size(self) -> int:
        """Number of states: two per joint (value and rate)."""
        return 2 * len(self.joints)

    def derivative(self, state: np.ndarray, command: np.ndarray) -> np.ndarray:
        """``d state / dt`` for held commands. ``(2 n,), (n,) -> (2 n,)``; state = values then their rates."""
        n = len(self.joints)
        y, z = state[:n], state[n:]
        err = command - y
        steer = np.array([j.endswith(".steer") for j in self.joints])
        err = np.where(steer, wrap_angle(err), err)
        if self.coupling is not None:
            err = err + np.asarray(self.coupling) @ err
        dy, dz = np.zeros(n), np.zeros(n)
        for i, lp in enumerate(self.loops):
            if lp.order == 1:
                dy[i] = err[i] / lp.tau
            elif lp.order == 2:
                dy[i] = z[i]
                dz[i] = lp.omega_n**2 * err[i] - 2 * lp.zeta * lp.omega_n * z[i]
        return np.concatenate([dy, dz])

    def settle_ideal(self, state: np.ndarray, command: np.ndarray) -> np.ndarray:
        """State with ideal joints set to their command (they have no dynamics)."""
        out = state.copy()
        for i, lp in enumerate(self.loops):
            if lp.order == 0:
                out[i] = command[i]
        return out

