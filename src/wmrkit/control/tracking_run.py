"""The result of a closed-loop run, :class:`TrackingRun` (what :func:`.track.track` returns and ``wmrkit track``
prints): its series, the intervals where a steered wheel was held beyond its range or a fixed wheel slipped, its
summary and its JSON form."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from ..couplings import Coupling
from ..kinematics.wheel_ik import WheelCommands
from ..robot import Robot
from ..wheels import wrap_angle
from .feasibility import Feasibility

__all__ = ["AXLE_MISS_TOL", "SLIP_TOL", "TrackingRun"]

#: Lateral slip [m/s] of a fixed wheel's commands beyond which a run reports it (:meth:`TrackingRun.slip_violations`).
SLIP_TOL = 1e-6
#: A wheel of a ``linkage`` or steering ``gear`` whose commanded axle is more than this [rad] (mod pi) off the one the
#: commanded twist needs is held off it (:meth:`TrackingRun.held_off_axle`): a metre rolled there scrubs 1 um sideways.
AXLE_MISS_TOL = 1e-6
#: A commanded heading within this [rad] of an end of its wheel's range is at that end (the keeper sets a linked
#: wheel there from its leader's end through the law: round-off away).
AT_END = 1e-9


def steers_together(coupling: Coupling) -> bool:
    """Whether `coupling` is a ``linkage`` or ``gear`` holding the steering of two or more wheels together."""
    return coupling.kind in ("linkage", "gear") and sum(j.endswith(".steer") for j in coupling.joints) > 1


def _holder(robot: Robot, wheel: str) -> str | None:
    """The ``linkage`` or ``gear`` coupling that holds `wheel`'s steering with another wheel's, by its channel name,
    or None."""
    for c in robot.couplings:
        if steers_together(c) and f"{wheel}.steer" in c.joints:
            return c.channel_name
    return None


@dataclass(frozen=True, eq=False)
class TrackingRun:
    """A closed-loop run (frozen; arrays read-only; eq=False: array fields). ``n`` samples:

    - ``t`` ``(n,)`` [s]; ``pose`` ``(n, 3)`` world pose of R ``(x, y, theta)``;
    - ``reference`` ``(n, 3)`` the reference at ``t``; ``tracked`` ``(n, 3)`` the pose of the tracked point
      (the control point for the thesis's laws, the axle point for pure pursuit, the front point for Stanley);
    - ``error`` ``(n,)`` [m] distance of the tracked point from the reference at ``t``; ``cross_track`` ``(n,)``
      [m] its distance from the reference path;
    - ``twist`` ``(n, 3)`` commanded body twist; ``heading`` ``(n, n_steer)`` [rad] actual steering headings;
    - ``commands``: the per-wheel commands (:class:`WheelCommands`, batch ``(n,)``) at the commanded steering;
    - ``estimate`` ``(n, 3)``: the odometry's pose estimate when the loop was closed on it, else None;
    - ``slip_model``: where the wheel commands came from (``"none"``: the no-slip IK; ``"mqe"``, ``"mcd"``: the
      inverse slip model, :mod:`.slip_control`); ``feedback``: what the controller measured (:mod:`.slip_loop`);
    - ``beyond_range`` ``(n, n_steer)`` bool: where a steered wheel was asked for a heading outside its
      ``steer_range`` and held at the end of it (the robot then moves with the least-squares twist of its drive
      wheels: it cannot follow as commanded); :meth:`range_violations` lists them per wheel;
    - ``feasibility``: the reference judged by Table 8.1 (§8.5, :func:`.feasibility.feasibility`) for the tracked
      point, in the kinematic framework (the dynamic one through the dynamics), its violations up to the run's end;
      None for a robot Table 8.1 does not apply to (degenerate: the skid steer);
    - ``commanded`` ``(n, n_steer)`` [rad]: the commanded steering headings (the policy, ranges, linkages and gears
      applied), which ``heading`` follows (at once with ideal joints);
    - ``moved`` ``(n, 3)``: the body twist the kinematic plant with ideal joints moved the robot with (``twist``, or
      the least-squares twist of its wheels where one is held at its range's end or off the commanded twist's axle by
      a linkage or gear: :meth:`held_off_axle`); None through the dynamics or low-level loops.
    """

    robot: Robot
    controller: str
    t: np.ndarray
    pose: np.ndarray
    reference: np.ndarray
    tracked: np.ndarray
    error: np.ndarray
    cross_track: np.ndarray
    twist: np.ndarray
    heading: np.ndarray
    commands: WheelCommands
    period: float | None = None
    delay: int = 0
    estimate: np.ndarray | None = None
    slip_model: str = "none"
    feedback: str = "pose"
    beyond_range: np.ndarray | None = None
    feasibility: Feasibility | None = None
    commanded: np.ndarray | None = None
    moved: np.ndarray | None = None

    def range_violations(self) -> list[dict[str, Any]]:
        """Per steered wheel held at the end of its range: ``{"wheel", "from", "to", "duration"}`` ([s]: first
        and last sample, and the time spent beyond the range: each such sample's interval to the next, none after
        the run's last sample). A wheel a ``linkage`` or steering ``gear`` held with another one at its end, its own
        commanded heading short of its range's ends, is listed apart, with ``"held_by"`` (the coupling's
        :attr:`~wmrkit.couplings.Coupling.channel_name`) and ``"headings"`` ([rad] the least and largest it was held
        at): it was not asked beyond its own range."""
        if self.beyond_range is None:
            return []
        names = self.robot.steer_names
        target = self.heading if self.commanded is None else self.commanded
        by = [_holder(self.robot, n) for n in names]
        short = np.zeros_like(self.beyond_range)
        for k, name in enumerate(names):
            rng = self.robot.wheel(name).steer_range
            if by[k] is not None:  # its coupling's other wheel at an end, or this one at its own
                short[:, k] = True if rng is None else ~np.any([np.abs(wrap_angle(target[:, k] - e)) <= AT_END
                                                                for e in rng], axis=0)
        out = self._intervals(names, self.beyond_range & ~short)
        for v in self._intervals(names, self.beyond_range & short):
            k = names.index(v["wheel"])
            held = target[self.beyond_range[:, k] & short[:, k], k]
            out.append({**v, "held_by": by[k], "headings": [float(held.min()), float(held.max())]})
        return sorted(out, key=lambda v: names.index(v["wheel"]))  # stable: a wheel's own end first

    def held_off_axle(self, tol: float = AXLE_MISS_TOL) -> list[dict[str, Any]]:
        """Per ``linkage`` or steering ``gear`` that held a wheel's axle more than `tol` [rad] (mod pi) off the one the
        commanded twist needs (the IK's, ``commands``), none of its wheels at the end of its range
        (:meth:`range_violations` lists those): the commanded twist is not realisable there, the wheels scrub.
        ``{"coupling", "wheels", "from", "to", "duration", "axle_miss"}`` (its channel name, its steered wheels, the
        times as :meth:`range_violations`, [rad] the largest miss) and, with :attr:`moved`, ``"twist_miss"``: the
        largest ``[speed of R [m/s], turn rate [rad/s]]`` of the commanded twist less the one the robot moved with."""
        if self.commanded is None:
            return []
        names = self.robot.steer_names
        ik = np.asarray(self.commands.heading)[:, [self.robot.wheel_names.index(n) for n in names]]
        miss = np.abs(np.remainder(ik - self.commanded + 0.5 * np.pi, np.pi) - 0.5 * np.pi)
        beyond = np.zeros(miss.shape, dtype=bool) if self.beyond_range is None else self.beyond_range
        by = [_holder(self.robot, n) for n in names]
        out = []
        for coupling in dict.fromkeys(b for b in by if b is not None):
            idx = [k for k, b in enumerate(by) if b == coupling]
            hit = (miss[:, idx] > tol).any(axis=1) & ~beyond[:, idx].any(axis=1)
            if not hit.any():
                continue
            when = self._intervals((coupling,), hit[:, None])[0]
            entry = {"coupling": coupling, "wheels": [names[k] for k in idx], "from": when["from"],
                     "to": when["to"], "duration": when["duration"], "axle_miss": float(miss[hit][:, idx].max())}
            if self.moved is not None:
                d = self.twist[hit] - self.moved[hit]
                entry["twist_miss"] = [float(np.hypot(d[:, 0], d[:, 1]).max()), float(np.abs(d[:, 2]).max())]
            out.append(entry)
        return out

    def slip_violations(self, tol: float = SLIP_TOL) -> list[dict[str, Any]]:
        """Per fixed wheel whose commands leave a lateral slip (8.14) beyond `tol` [m/s] (a skid steer turning: the
        wheels must scrub to move as commanded, which the kinematic plant does not show): listed as by
        :meth:`range_violations`."""
        return self._intervals(self.robot.wheel_names, np.abs(np.asarray(self.commands.slip)) > tol)

    def _intervals(self, names: tuple[str, ...], hits: np.ndarray) -> list[dict[str, Any]]:
        if not hits.any():
            return []
        dt = np.diff(self.t, append=self.t[-1])  # each sample's interval to the next; the run ends at the last
        out = []
        for k, name in enumerate(names):
            hit = hits[:, k]
            if hit.any():
                idx = np.flatnonzero(hit)
                out.append({"wheel": name, "from": float(self.t[idx[0]]), "to": float(self.t[idx[-1]]),
                            "duration": float(dt[hit].sum())})
        return out

    def summary(self, settle: float = 0.0) -> dict[str, float]:
        """RMS, max and final tracking and cross-track errors [m] after time `settle` [s]."""
        m = self.t >= settle
        e, c = self.error[m], self.cross_track[m]
        return {"rms_error": float(np.sqrt(np.mean(e * e))), "max_error": float(e.max()),
                "final_error": float(self.error[-1]), "rms_cross_track": float(np.sqrt(np.mean(c * c))),
                "max_cross_track": float(c.max())}

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready: ``t``, ``pose`` and ``reference`` as ``(x, y, theta)`` rows, ``tracking_error`` (the
        tracked point's distance from the reference, :attr:`error`; never ``error``, the key of a failure), per-wheel
        ``heading`` (steering, null for wheels that do not steer) and ``spin`` series, the summary,
        ``beyond_steer_range`` (:meth:`range_violations`), ``held_off_axle`` (:meth:`held_off_axle`) and
        ``feasibility``."""
        wheels: dict[str, dict[str, Any]] = {}
        steer = self.robot.steer_names
        for i, name in enumerate(self.robot.wheel_names):
            h = self.heading[:, steer.index(name)].tolist() if name in steer else None
            wheels[name] = {"heading": h, "spin": np.asarray(self.commands.spin[:, i]).tolist()}
        out = {"robot": self.robot.name, "controller": self.controller, "period": self.period, "delay": self.delay,
               "t": self.t.tolist(), "pose": self.pose.tolist(), "reference": self.reference.tolist(),
               "tracking_error": self.error.tolist(), "wheels": wheels, "summary": self.summary()}
        if self.estimate is not None:
            out["estimate"] = self.estimate.tolist()
        if self.slip_model != "none" or self.feedback != "pose":
            out["slip_model"], out["feedback"] = self.slip_model, self.feedback
        out["beyond_steer_range"] = self.range_violations()
        out["held_off_axle"] = self.held_off_axle()
        out["feasibility"] = None if self.feasibility is None else self.feasibility.to_dict()
        return out
