"""The plant of the kinematic loop (:mod:`.loop`): per-run arrays of which steering angles are commanded,
integrated (castors) or in a low-level loop, the wheel commands with the steering policy and ranges applied (and a
held linkage's law and a steering gear's ratios: :func:`.steering.range_keeper`, as the loops through the dynamics),
and the twist the ideal plant realises when a wheel is held at the end of its range or off the IK's heading."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from .._shapes import readonly
from ..kinematics import _ik_fast
from ..kinematics._ik_fast import in_range_one, wrap_one
from ..kinematics.linalg import solve_assigned
from ..kinematics.loop_ik import checked_castor_rates, checked_rates, checked_steering_config
from ..kinematics.wheel_ik import forward_kinematics
from ..limits import MAX_QUERY_RATE
from ..robot import Robot
from .actuators import LowLevelLoops
from .linked_ranges import LinkedRanges
from .points import ControlError
from .steering import range_keeper, spin_columns, steer_ranges, unit_spin

_SPINS = (".spin", ".spin1", ".spin2")  # the joints that drive a wheel

#: A steered wheel of the ideal plant held at an end of its steering range stays there unless the other end serves
#: the heading asked of it better by more than this [rad] (:func:`~.steering.choose_steering` ``hold_margin``).
HOLD_MARGIN = math.radians(2.0)
#: A steered wheel's axle within this [rad] of the IK's (mod pi) rolls as the commanded twist asks (round-off of a
#: linkage's law or a gear's ratios, 4e-16 rad on the catalog car); further, the ideal plant moves it by least squares.
AXLE_TOL = 1e-9


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
        self.castors = bool(self.passive.any())
        self._all_fit = readonly(np.ones(len(names), dtype=bool))  # every steered wheel within its range
        self.delta = np.array([robot.wheel(n).delta for n in names], dtype=float)
        self.ranges, self.spin_columns = steer_ranges(robot), spin_columns(robot)
        self.wheel_of_steer = np.array([robot.wheel_names.index(n) for n in names], dtype=int)
        columns = _ik_fast.plan(robot).element_steer_col.tolist()  # the castors' steering rates (8.24) among the IK's
        self.castor_elements = [columns.index(robot.rate_names.index(f"{n}.steer"))
                                for n, p in zip(names, self.passive, strict=True) if p]
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
        self.links = LinkedRanges.of(robot, self.ranges)  # the wheels kept on a law or in ratios
        self.linked = self.links is not None
        self.keep = range_keeper(robot, plant.policy)
        kept = self.ranges if self.links is None else self.links.ranges  # a leader's: where its followers fit
        held = set() if self.links is None else set(self.links.followers.tolist())
        leads = set() if self.links is None else set(self.links.leaders.tolist())
        self.ranged = [(k, float(self.delta[k]), float(lo), float(hi), k in leads) for k, (lo, hi) in enumerate(kept)
                       if not self.passive[k] and k not in held and np.isfinite([lo, hi]).any()]  # with a range
        spins = [j for j in self.joints if j.endswith(".spin")]
        if (loops is not None or self.limited or self.linked) and not spins:
            spins = [j for j in robot.actuated if j.endswith(_SPINS)]
        if (self.limited or self.linked) and not spins:  # no actuator described: each wheel spins as the IK says
            spins = [j for j in robot.rate_names if j.endswith(_SPINS)]
        self.drive = tuple(spins)
        self.drive_columns = np.array([robot.velocity_names.index(j) for j in spins], dtype=int)
        self.n_loop = 0 if loops is None else loops.size
        self.hold_margin = HOLD_MARGIN  # the continuous loop holds ends within a step (inf) and switches at events
        # the steering targets are the IK's own (no policy, range, linkage or gear to apply): plain floats suffice
        self.plain = plant.policy == "closest" and not (self.limited or self.linked)

    def commands(self, twist: np.ndarray, beta: np.ndarray, hold_margin: float | None = None,
                 ik: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None) -> _Commands:
        """Wheel commands at steering `beta`, with the policy, ranges, linkages and gears applied to the steered
        wheels (:func:`.steering.range_keeper`); a wheel held at an end changes ends past `hold_margin` (default
        ``self.hold_margin``). `ik`: the IK's rates, steering and spins at `(twist, beta)` (:func:`checked_rates`),
        when already computed."""
        rates, target, spin_all = checked_rates(self.robot, twist, beta) if ik is None else ik
        target, rates = np.array(target), np.array(rates)
        fits = np.ones(len(target), dtype=bool)
        if len(target) and (self.plant.policy != "closest" or self.limited or self.linked):
            heading = target - math.pi / 2 + self.delta
            margin = self.hold_margin if hold_margin is None else hold_margin
            fits = self.keep(heading, rates, beta - math.pi / 2 + self.delta, margin) | self.passive
            target = np.where(self.passive, target, heading + math.pi / 2 - self.delta)
        spin = np.where(self.passive, spin_all[self.wheel_of_steer], unit_spin(rates, self.spin_columns))
        return _Commands(target, rates, spin, fits)

    def castor_rates(self, twist: np.ndarray, beta: np.ndarray) -> np.ndarray:
        """The castors' steering rates (8.24) ``(n_castors,)`` [rad/s] at `twist` and steering `beta`
        (:func:`checked_castor_rates`: a few µs)."""
        return np.array(checked_castor_rates(self.robot, twist, beta, self.castor_elements))

    def targets(self, twist: np.ndarray, beta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """:meth:`commands`' steering targets and fits alone: for a :attr:`plain` plant the IK's configuration in
        plain floats (:func:`checked_steering_config`, a few µs instead of the rates' hundred), every wheel fitting."""
        if self.plain:
            return np.array(checked_steering_config(self.robot, twist, beta)), self._all_fit
        cmd = self.commands(twist, beta)
        return cmd.target, cmd.fits

    def realised(self, twist: np.ndarray, beta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The ideal plant's twist and which steered wheels fit their ranges: the commanded twist, or, when a wheel
        is held at the end of its range or off the IK's axle (set by a linkage's law or a gear's ratios), the
        least-squares twist (4.11) of the actuated wheels' commanded rates at the steering reached (the wheels
        scrub: the robot cannot move as commanded)."""
        if not (self.limited or self.linked):
            return twist, self._all_fit
        if self.all_fit(checked_steering_config(self.robot, twist, beta)):  # no wheel is held or moved
            return twist, self._all_fit
        ik = checked_rates(self.robot, twist, beta)
        cmd = self.commands(twist, beta, ik=ik)
        off = np.abs(np.remainder(cmd.target - np.asarray(ik[1]) + math.pi / 2, math.pi) - math.pi / 2)
        if cmd.fits.all() and (self.passive | (off <= AXLE_TOL)).all():  # every axle where the IK puts it
            return twist, cmd.fits
        return self.least_squares_twist(cmd, cmd.target, {}), cmd.fits

    def all_fit(self, target: list[float]) -> bool:
        """Whether every steered wheel has a root of (8.9) within its range, the IK's steering `target` or that
        plus pi: :func:`.steering.checked_steering`'s ``in_range`` (of any policy), in plain floats, the same
        operations. With linkages or gears (:attr:`links`), only where the keeper surely keeps the IK's axles (False
        sends :meth:`realised` the long way, which decides): policy ``"closest"``, each leader's IK root itself
        within its kept arc (so the one the keeper takes), each follower's IK axle where the law or ratios set it
        from there."""
        if self.links is not None and self.plant.policy != "closest":
            return False
        for k, delta, lo, hi, lead in self.ranged:
            h0 = wrap_one(target[k] - math.pi / 2 + delta)
            if not (in_range_one(h0, lo, hi) or (not lead and in_range_one(wrap_one(h0 + math.pi), lo, hi))):
                return False
        for link in () if self.links is None else self.links.links:
            f = link.to_follower(target[link.leader] - math.pi / 2 + float(self.delta[link.leader]))
            if abs(math.remainder(f - target[link.follower] + math.pi / 2 - float(self.delta[link.follower]),
                                  math.pi)) > AXLE_TOL:
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
