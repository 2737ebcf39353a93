"""Which references a robot can follow with zero error (thesis §8.5, Table 8.1), where a reference breaks that, and
the remedy.

The column of Table 8.1 follows from the vehicle type (:func:`wmrkit.analysis.classify`) and where the tracking point
(the robot origin R, or a given point) lies: on the fixed axle (``beta_f - alpha_f = 0``) or off it, and for types 3
and 5 whether some steered wheel is away from it (``l_oi != 0``). The *kinematic* framework lets wheel rates jump;
the *dynamic* one needs them continuous, so every condition goes one derivative higher (§8.5). For types 3 and 5 with
some ``l_oi != 0`` a velocity or heading-rate step (kinematic), an acceleration or angular-acceleration step
(dynamic), is a violation only where a steered wheel's heading, respectively steering rate, changes across it
(:func:`_steered_turn`): a twist that only scales keeps them (docs/errata.md); a velocity or heading-rate step under
its floor is one too where it turns a steered wheel (:func:`_slow_turns`: a steering angle is a state at any speed).

The reference's signals come from :mod:`.reference_signals`, their discontinuities from :mod:`.jumps` (the spike of a
derivative around a step of its signal is that step, reported once), and whether a step turns a steered wheel from
:mod:`.steered_turns`. ``kappa`` and the rates are not judged where the reference rests or starts or stops, ``chi``
at rest: a jump across such samples is still found, across a rest only for a car's tangent (R on the fixed axle of a
type 4 cannot turn at rest; any other vehicle re-orients there, the remedy of Table 8.1).

Beyond Table 8.1: a car-like robot's steering stops bound how tightly the judged point turns
(:mod:`.turn_limits`); a stretch between the table's breaks that turns tighter is a :class:`TightTurn`, and the
reference is not feasible (:attr:`Feasibility.continuous` keeps the table's own verdict).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

import numpy as np

from ..analysis.classification import classify
from ..limits import MAX_SIZE
from ..robot import Robot
from .jumps import _FLOOR, _TURN, _detrended, _folded, _held, _jumps, _middle, _persists
from .jumps import BLOCK as BLOCK  # importable from here (track)
from .points import ControlError, control_point
from .reference_signals import _CURVATURE, _curvature_reference, signals
from .references import Reference
from .steered_turns import _STEERED, _slow_turns, _steered_turn
from .turn_limits import TurnExcess, turn_excess

__all__ = ["COLUMNS", "Feasibility", "Requirement", "TightTurn", "Violation", "feasibility", "requirement"]

_VEHICLE = "stop and re-orient the vehicle"
_WHEEL = "stop and re-orient the orientable wheel"
_WHEELS = "stop and re-orient the orientable wheels"
#: Table 8.1: column -> (pose references, kinematic signals, dynamic signals, remedy, footnote). The dynamic
#: framework of every column also needs the velocity continuous: the drive wheels' rates are proportional to the
#: speed, and the table's conditions on chi alone rest on (8.34) 'chi C1 => v_a C0', which a speed step on a line
#: (chi constant) contradicts. Its conditions include the kinematic ones (C1 is C0 too): a reference whose pose
#: jumps while its given derivatives stay smooth was 'feasible: yes' in the dynamic framework of types 1 and 2 off
#: the axle.
COLUMNS: dict[str, tuple[int, tuple[str, ...], tuple[str, ...], str]] = {
    "type 1": (3, ("position", "theta"), ("position", "theta", "velocity", "omega"),
               "the reference must be continuous"),
    "type 2, off axle": (2, ("position",), ("position", "velocity"), "the reference must be continuous"),
    "type 2, on axle": (2, ("position", "chi"), ("position", "chi", "velocity", "chi_rate"), _VEHICLE),
    "type 4, off axle": (2, ("position", "chi"), ("position", "chi", "velocity", "chi_rate"), _WHEEL),
    "type 4, on axle": (2, ("position", "chi", "kappa"), ("position", "chi", "velocity", "kappa", "kappa_rate"),
                        _WHEEL + " (both tangent and curvature jump: the vehicle, re-orienting the wheel twice)"),
    "types 3 and 5, l_o != 0": (3, ("position", "theta", "velocity", "omega"),
                                ("position", "theta", "velocity", "omega", "acceleration", "omega_rate"), _WHEELS),
    "type 3, l_o = 0": (3, ("position", "theta", "chi"), ("position", "theta", "chi", "velocity", "omega", "chi_rate"),
                        _WHEEL),
}
#: What each signal's continuity means in the thesis's words.
KINDS = {"position": "position jump (p_ref not C0)", "theta": "heading jump (theta_ref not C0)",
         "velocity": "velocity jump (p_ref not C1)", "omega": "heading-rate jump (theta_ref not C1)",
         "acceleration": "acceleration jump (p_ref not C2)",
         "omega_rate": "angular-acceleration jump (theta_ref not C2)", "chi": "tangent-angle jump (chi not C0)",
         "chi_rate": "turn-rate jump (chi not C1)", "kappa": "curvature jump (kappa not C0)",
         "kappa_rate": "curvature-rate jump (kappa not C1)"}


@dataclass(frozen=True)
class Requirement:
    """The Table 8.1 cell of a robot: ``column``, vehicle ``type``, number of pose ``references`` (2 or 3), the
    ``signals`` that must be continuous in the chosen ``framework``, and the ``remedy`` when one is not; ``note``:
    why a robot outside the table is judged by a column of it (a skid steer, as the differential drive it drives
    as; a robot whose steering couplings leave one steering degree of freedom, as type 4), or empty."""

    column: str
    type: int
    references: int
    framework: str
    signals: tuple[str, ...]
    remedy: str
    note: str = ""


@dataclass(frozen=True)
class Violation:
    """One discontinuity of the reference: time ``t`` [s], ``signal``, ``kind`` (text), ``size`` of the jump
    (m, rad, m/s, ... per signal), ``remedy``."""

    t: float
    signal: str
    kind: str
    size: float
    remedy: str

    def to_dict(self) -> dict[str, object]:
        """``{"t", "kind", "signal", "size", "remedy"}``."""
        return {"t": self.t, "kind": self.kind, "signal": self.signal, "size": self.size, "remedy": self.remedy}


#: The kind of a :class:`TightTurn`.
TIGHT_KIND = "turn tighter than the steering stops allow"


@dataclass(frozen=True)
class TightTurn(Violation):
    """A stretch from ``t`` to ``until`` [s] where the reference turns by ``turn`` [rad] over ``length`` [m], more
    than the judged point of a car-like robot can (:func:`.turn_limits.turn_excess`); ``size``: its mean radius
    ``length / turn`` [m]; ``radius``: the point's tightest turn, ``turning``: the robot's minimum turning radius
    (of its rear axle's midpoint) [m]; ``limit``: the most the point turns over ``length`` [rad]."""

    until: float = 0.0
    turn: float = 0.0
    length: float = 0.0
    radius: float = 0.0
    turning: float = 0.0
    limit: float = 0.0

    @classmethod
    def of(cls, e: TurnExcess) -> TightTurn:
        """The violation of a stretch."""
        limit = e.length / e.radius + e.span
        again = (f"on {e.radius:.4g} m at its tightest, and {math.degrees(e.span):.3g} deg more by re-steering; "
                 if e.span > 1e-9 else "")
        remedy = (f"a wider turn: over {e.length:.4g} m the point turns by {math.degrees(limit):.4g} deg at most "
                  f"({again}the robot's minimum turning radius is {e.turning:.4g} m, of its rear axle's midpoint at "
                  "its steering stops)")
        return cls(e.t, "turn", TIGHT_KIND, e.length / e.turn, remedy, e.until, e.turn, e.length, e.radius, e.turning,
                   limit)

    def to_dict(self) -> dict[str, object]:
        """:meth:`Violation.to_dict` and ``until``, ``turn`` [rad], ``length``, ``radius``, ``turning`` [m],
        ``limit`` [rad]."""
        return {**super().to_dict(), "until": self.until, "turn": self.turn, "length": self.length,
                "radius": self.radius, "turning": self.turning, "limit": self.limit}

    def words(self) -> str:
        """``turns by 349.6 deg over 6.105 m (t = 0 to 12.41 s; on 1 m on average)``."""
        return (f"turns by {math.degrees(self.turn):.4g} deg over {self.length:.4g} m (t = {self.t:.4g} to "
                f"{self.until:.4g} s; on {self.size:.4g} m on average)")


@dataclass(frozen=True)
class Feasibility:
    """Result of :func:`feasibility`: ``feasible`` and the ``violations`` of ``requirement`` (Table 8.1's, and a
    :class:`TightTurn` where the steering stops forbid the reference)."""

    requirement: Requirement
    violations: tuple[Violation, ...]

    @property
    def feasible(self) -> bool:
        """No violation: the reference is followed with zero error by ideal blocks from matching initial conditions."""
        return not self.violations

    @property
    def continuous(self) -> bool:
        """Table 8.1's own verdict: no continuity violation (a :class:`TightTurn` is none)."""
        return all(isinstance(v, TightTurn) for v in self.violations)

    def to_dict(self) -> dict[str, object]:
        """``{"feasible", "continuous", "column", "type", "framework", "signals", "violations": [...]}`` (the CLI's
        JSON; ``continuous``: Table 8.1's verdict)."""
        r = self.requirement
        return {"feasible": self.feasible, "continuous": self.continuous, "column": r.column, "type": r.type,
                "framework": r.framework, "signals": list(r.signals),
                "violations": [v.to_dict() for v in self.violations]}


def requirement(robot: Robot, framework: Literal["kinematic", "dynamic"] = "kinematic", *,
                point: tuple[float, float] | None = None) -> Requirement:
    """The Table 8.1 cell of `robot` tracked at `point` (default: its origin R, as in the thesis)."""
    if framework not in ("kinematic", "dynamic"):
        raise ControlError(f"framework must be 'kinematic' or 'dynamic', got {framework!r}")
    c = classify(robot)
    kind, note = c.type, ""
    if kind is None:
        degenerate = f"robot '{robot.name}' is degenerate ({'; '.join(c.reasons)})"
        if not _skid(robot):
            raise ControlError(f"{degenerate}: Table 8.1 does not apply")
        kind, note = 2, (f"{degenerate}: a skid steer turns only by slipping; Table 8.1 judges it as the "
                         "differential drive it drives as (type 2)")
    p = np.zeros(2) if point is None else np.asarray(point, dtype=float)
    if p.shape != (2,) or not (np.abs(p) <= MAX_SIZE).all():  # NaN read as a point on the axle
        raise ControlError(f"point: expected (x, y), finite and within {MAX_SIZE:g} m of the robot origin, got "
                           f"{p.tolist()}")
    if kind in (3, 5) and control_point(robot).coupled is not None:
        kind, note = 4, (f"robot '{robot.name}' steers through couplings that leave it one steering degree of "
                         "freedom and has no fixed wheel: Table 8.1 judges it as type 4, (x, y) of the tracked point, "
                         "the heading free (docs/control.md)")
    if kind in (2, 4):
        on_axle = _on_axle(robot, p)
        column = f"type {kind}, {'on' if on_axle else 'off'} axle"
    elif kind == 1:
        column = "type 1"
    else:
        steered = [w for w in robot.wheels if w.type in ("steerable", "double")]
        away = any(np.hypot(*(np.asarray(w.position) - p)) > 1e-9 for w in steered)
        column = "types 3 and 5, l_o != 0" if (away or kind == 5) else "type 3, l_o = 0"
    refs, kin, dyn, remedy = COLUMNS[column]
    return Requirement(column, kind, refs, framework, kin if framework == "kinematic" else dyn, remedy, note)


def _skid(robot: Robot) -> bool:
    """A skid steer: fixed wheels on parallel, distinct axles (the admissible twists of a differential drive, which
    ``wmrkit track`` gives it: :func:`.points.control_point`) and no other wheel but castors."""
    if not any(w.type == "fixed" for w in robot.wheels) or any(
            w.type not in ("fixed", "castor", "double_castor") for w in robot.wheels):
        return False
    try:
        return control_point(robot).skid
    except ControlError:
        return False


def _on_axle(robot: Robot, p: np.ndarray) -> bool:
    """The point's velocity cannot be assigned in the admissible twist space: it lies on the fixed axle."""
    try:
        control_point(robot, (float(p[0]), float(p[1])), reduced=True)
    except ControlError:
        return True
    return False


def feasibility(robot: Robot, reference: Reference, framework: Literal["kinematic", "dynamic"] = "kinematic", *,
                point: tuple[float, float] | None = None, jump_factor: float = 20.0) -> Feasibility:
    """Check `reference` against the Table 8.1 cell of `robot` (§8.5): every discontinuity and its remedy.

    A jump is a step of a signal larger than `jump_factor` (> 1) times the typical step where it is (the median of
    its block of ``BLOCK`` steps, or of a neighbouring block when larger) and than a floor. For a car-like robot, a
    stretch between those jumps that turns tighter than its steering stops let the point turn is a
    :class:`TightTurn` (:mod:`.turn_limits`), in either framework."""
    if not 1 < jump_factor < math.inf:  # NaN included: at 0 or NaN every step above the floor was a jump
        raise ControlError(f"jump_factor: expected a finite number > 1 (times the median step), got {jump_factor}")
    req = requirement(robot, framework, point=point)
    sig = signals(reference)
    dense = _curvature_reference(reference) if set(req.signals) & set(_CURVATURE) else None
    dense_sig = None if dense is None else signals(dense)
    found: list[Violation] = []
    seen: list[tuple[str, float, float]] = []  # (signal, from, to) of each jump reported or folded into another
    for name in req.signals:
        ref, s = (dense, dense_sig) if dense is not None and name in _CURVATURE else (reference, sig)
        x = s[name]
        if name == "kappa_rate":
            x = x / (ref.t[1] - ref.t[0])
        floor = _FLOOR[name]
        # a car (R on the fixed axle of a type 4) cannot turn at rest: its tangent is compared across a stop
        across = name == "chi" and req.column == "type 4, on axle"
        # a curvature-rate step, which finite differences spread over about five samples, is looked for with the
        # rate's slope taken out: on a slope of 1 1/(m s^2) at 100 Hz a step of 0.3 1/(m s) was not found
        level = _detrended(x, ref.t) if name == "kappa_rate" else x
        jumps = _jumps(level, ref.t, _TURN.get(name), floor, jump_factor, s["at_rest"], across)
        slow = []
        if req.column == "types 3 and 5, l_o != 0" and name in ("velocity", "omega"):
            slow = _slow_turns(robot, ref, point, x, jumps, jump_factor)
        for k, last, size in sorted(jumps + slow):
            if name == "kappa_rate":
                if not _persists(x, k, floor):
                    continue  # ringing of a third finite difference, not a step of the curvature rate
                # its size: the whole step less the rate's slope (finite differences spread it over about 5 samples,
                # of which only those over the jump limit were summed: a step of 0.5 1/(m s) on a slope of 1 1/(m s^2)
                # at 100 Hz was 0.313)
                held = abs(_held(x, k, last))
                size = held if math.isfinite(held) else size
            span = (name, float(ref.t[k]), float(ref.t[last + 1]))
            if _folded(span, seen):
                seen.append(span)
                continue  # the spike of a derivative where its signal steps: one discontinuity, reported once
            turns = None
            if req.column == "types 3 and 5, l_o != 0" and name in _STEERED:
                turns = (k, last, size) in slow or _steered_turn(robot, ref, point, k, last + 1, rate=_STEERED[name])
                if not turns and (req.framework == "kinematic" or _STEERED[name]):
                    continue  # the twist only scales (the same ICR): no steered wheel turns, only rates jump
            t = float(ref.t[_middle(level, ref.t, k, last) if name == "kappa_rate" else k + 1])
            seen.append(span)
            if any(v.t == t and v.signal in ("chi", "position") for v in found) and name != "position":
                continue  # already reported by a lower-order signal at the same instant
            found.append(Violation(t, name, KINDS[name], size, _remedy(req, name, turns)))
    tight = turn_excess(robot, reference.t, reference.pose[:, :2], (0.0, 0.0) if point is None else point,
                        [v.t for v in found])
    if tight is not None:  # the steering stops: the same in both frameworks (they bound an angle, not its rate)
        found.append(TightTurn.of(tight))
    found.sort(key=lambda v: v.t)
    return Feasibility(req, tuple(found))


#: The rate signals, by name: a jump of one leaves every steering angle and the heading continuous (the wheels'
#: rates jump), unless a steered wheel turns with a velocity or heading-rate step of types 3 and 5 (``turns``).
_RATES = {"velocity": "velocity", "omega": "heading rate", "acceleration": "acceleration",
          "omega_rate": "angular acceleration", "chi_rate": "turn rate", "kappa_rate": "curvature rate"}


def _remedy(req: Requirement, signal: str, turns: bool | None = None) -> str:
    """What to do about a jump of `signal` for `req`: Table 8.1's re-orientation only where an angle the vehicle
    holds (a steering angle, or the heading of a vehicle tracked on its fixed axle) would jump."""
    if signal == "position":
        return "the reference jumps: no vehicle can follow it; the position loop removes the error afterwards"
    if signal == "theta":  # the pose jumps: no wheel's re-orientation follows it
        return "an error appears that the position loop then removes (kinematics allows no jump here)"
    if req.column == "type 4, on axle" and signal == "chi":
        return (f"{_VEHICLE}, re-orienting the orientable wheel twice (tangent and curvature both jump)")
    if req.column == "type 4, on axle" and signal == "kappa":
        return _WHEEL
    if signal in _RATES and not (turns and signal in ("velocity", "omega")):
        if signal in ("velocity", "omega"):
            return (f"the {_RATES[signal]} steps (the wheels' rates would jump, which the dynamic framework "
                    "forbids): an error appears that the position loop then removes")
        # the angles stay continuous, their rates step: at rest on both sides every rate is 0 (the rates are the
        # speed times their rate along the path)
        return (f"the {_RATES[signal]} steps (the wheels' rates would jump, which the dynamic framework forbids; the "
                "angles do not): slow to rest there, or an error appears that the position loop then "
                "removes")
    return req.remedy
