"""The plant of the kinematic loop (:mod:`.loop`): per-run arrays of which steering angles are commanded,
integrated (castors) or in a low-level loop, the wheel commands with the steering policy and ranges applied, and
the twist the ideal plant realises when a wheel is held at the end of its range."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from ..kinematics._ik_fast import in_range_one, wrap_one
from ..kinematics.linalg import solve_assigned
from ..kinematics.wheel_ik import checked_rates, checked_steering_config, forward_kinematics
from ..limits import MAX_QUERY_RATE
from ..robot import Robot
from .actuators import LowLevelLoops
from .points import ControlError
from .steering import checked_steering, reverse_spins, spin_columns, steer_ranges, unit_spin

_SPINS = (".spin", ".spin1", ".spin2")  # the joints that drive a wheel

#: A steered wheel of the ideal plant held at an end of its steering range stays there unless the other end serves
#: the heading asked of it better by more than this [rad] (:func:`~.steering.choose_steering` ``hold_margin``).
HOLD_MARGIN = math.radians(2.0)


class _Commands(NamedTuple):
    """One evaluation of the wheel commands: the steering targets (thesis beta), the joint rates
    (``robot.rate_names``) and the spins of the steered wheels for the chosen roots, and whether each steered
    wheel's target lies within its range."""

    target: np.ndarray
    rates: np.ndarray
    spin: np.ndarray
    fits: np.ndarray


@dataclass(frozen=True)
class Plant:
    """How the commands move the robot: `loops` (None: ideal joints), steering `policy` (see :mod:`.steering`)."""

    loops: LowLevelLoops | None = None
    policy: str = "closest"


class _Sim:
    """Per-run arrays: which steering angles are commanded, integrated (castors), or in a low-level loop."""

    def __init__(self, robot: Robot, plant: Plant) -> None:
        self.robot, self.plant = robot, plant
        names = robot.steer_names
        types = [robot.wheel(n).type for n in names]
        self.passive = np.array([t in ("castor", "double_castor") for t in types], dtype=bool)
        self.delta = np.array([robot.wheel(n).delta for n in names], dtype=float)
        self.ranges, self.spin_columns = steer_ranges(robot), spin_columns(robot)
        self.wheel_of_steer = np.array([robot.wheel_names.index(n) for n in names], dtype=int)
        self.castor_rate_columns = np.array([robot.rate_names.index(f"{n}.steer") for n, p in zip(names, self.passive,
                                                                                                    strict=True) if p],
                                            dtype=int)  # the castors' steering rates (8.24) in the IK's rates
        loops = plant.loops
        self.joints = () if loops is None else loops.joints
        for j in self.joints:
            wheel, _, joint = j.partition(".")
            w = robot.wheel(wheel)
            if joint == "steer" and w.type not in ("steerable", "double"):
                raise ControlError(f"low-level loop on '{j}': only steerable and double wheels have a commanded angle")
            if joint == "spin" and "spin" not in w.kind.rates:
                raise ControlError(f"low-level loop on '{j}': wheel '{wheel}' has no 'spin' joint")
        self.limited = bool(np.isfinite(self.ranges).any())
        self.ranged = [(k, float(self.delta[k]), float(lo), float(hi)) for k, (lo, hi) in enumerate(self.ranges)
                       if not self.passive[k] and np.isfinite([lo, hi]).any()]  # the steered wheels with a range
        spins = [j for j in self.joints if j.endswith(".spin")]
        if (loops is not None or self.limited) and not spins:
            spins = [j for j in robot.actuated if j.endswith(_SPINS)]
        if self.limited and not spins:  # no actuator described: every wheel spins as the IK commands it
            spins = [j for j in robot.rate_names if j.endswith(_SPINS)]
        self.drive = tuple(spins)
        self.drive_columns = np.array([robot.velocity_names.index(j) for j in spins], dtype=int)
        self.n_loop = 0 if loops is None else loops.size
        self.hold_margin = HOLD_MARGIN  # the continuous loop holds ends within a step (inf) and switches at events

    def commands(self, twist: np.ndarray, beta: np.ndarray, hold_margin: float | None = None,
                 ik: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None) -> _Commands:
        """Wheel commands at steering `beta`, with the policy and ranges applied to the steered wheels; a wheel held
        at an end changes ends past `hold_margin` (default ``self.hold_margin``). `ik`: the IK's rates, steering and
        spins at `(twist, beta)` (:func:`checked_rates`), when already computed."""
        rates, target, spin_all = checked_rates(self.robot, twist, beta) if ik is None else ik
        target, rates = np.array(target), np.array(rates)
        fits = np.ones(len(target), dtype=bool)
        if len(target) and (self.plant.policy != "closest" or self.limited):
            steered = ~self.passive
            heading = target - math.pi / 2 + self.delta
            margin = self.hold_margin if hold_margin is None else hold_margin
            chosen, _, in_range, reverse = checked_steering(heading, spin_all[self.wheel_of_steer],
                                                            beta - math.pi / 2 + self.delta, self.plant.policy,
                                                            self.ranges, margin)
            target = np.where(steered, chosen + math.pi / 2 - self.delta, target)
            reverse_spins(rates, self.spin_columns, reverse & steered)
            fits = in_range | self.passive
        spin = np.where(self.passive, spin_all[self.wheel_of_steer], unit_spin(rates, self.spin_columns))
        return _Commands(target, rates, spin, fits)

    def realised(self, twist: np.ndarray, beta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The ideal plant's twist and which steered wheels fit their ranges: the commanded twist, or, when a wheel
        is held at the end of its range, the least-squares twist (4.11) of the actuated wheels' commanded rates at
        the steering reached (the wheels scrub: the robot cannot move as commanded)."""
        if not self.limited:
            return twist, np.ones(len(self.ranges), dtype=bool)
        if self.all_fit(checked_steering_config(self.robot, twist, beta)):  # the commanded twist: no wheel is held
            return twist, np.ones(len(self.ranges), dtype=bool)
        cmd = self.commands(twist, beta)
        if cmd.fits.all():
            return twist, cmd.fits
        return self.least_squares_twist(cmd, cmd.target, {}), cmd.fits

    def all_fit(self, target: list[float]) -> bool:
        """Whether every steered wheel has a root of (8.9) within its range, the IK's steering `target` or that
        plus pi: :func:`.steering.checked_steering`'s ``in_range`` (of any policy), in plain floats, the same
        operations."""
        for k, delta, lo, hi in self.ranged:
            h0 = wrap_one(target[k] - math.pi / 2 + delta)
            if not (in_range_one(h0, lo, hi) or in_range_one(wrap_one(h0 + math.pi), lo, hi)):
                return False
        return True

    def least_squares_twist(self, cmd: _Commands, beta: np.ndarray, actual: dict[str, float]) -> np.ndarray:
        """Twist (4.11) of the drive joints' rates (`actual` where given, else commanded) at steering `beta`:
        :func:`forward_kinematics`' numbers, its columns found once a run."""
        q = np.array([actual[j] if j in actual else float(cmd.rates[c - 3])  # chosen roots
                      for j, c in zip(self.drive, self.drive_columns, strict=True)])
        if not (np.abs(q) <= MAX_QUERY_RATE).all():  # NaN included: refused by it, naming the rate
            return np.asarray(forward_kinematics(self.robot, dict(zip(self.drive, q.tolist(), strict=True)), beta)[0])
        return solve_assigned(self.robot.constraint_matrix(beta), self.drive_columns, q)[0][:3]

    def joint_commands(self, cmd: _Commands) -> np.ndarray:
        out = np.zeros(len(self.joints))
        for i, j in enumerate(self.joints):
            wheel, _, joint = j.partition(".")
            if joint == "steer":
                out[i] = cmd.target[self.robot.steer_names.index(wheel)]
            else:  # the rate of the chosen root
                out[i] = cmd.rates[self.robot.rate_names.index(j)]
        return out

    def plant_twist(self, twist_cmd: np.ndarray, cmd: _Commands, beta: np.ndarray,
                    loop_state: np.ndarray) -> np.ndarray:
        if self.plant.loops is None or not self.drive:
            return twist_cmd
        return self.least_squares_twist(cmd, beta, {j: loop_state[self.joints.index(j)] for j in self.drive
                                                    if j in self.joints})

    def actual_beta(self, target: np.ndarray, beta: np.ndarray, loop_state: np.ndarray) -> np.ndarray:
        out = np.where(self.passive, beta, target)
        for i, j in enumerate(self.joints):
            if j.endswith(".steer"):
                out[self.robot.steer_names.index(j.partition(".")[0])] = loop_state[i]
        return out
