"""One call that tells a designer what their robot is: :func:`analyze` (thesis ch. 5-6, with ch. 4's verdicts).

Type and degrees of mobility/steerability (Table 5.1), the ICR, the actuation and sensing verdicts of ch. 4
(:mod:`wmrkit.kinematics.actuation`, :mod:`wmrkit.kinematics.sensing`), the condition number of the actuated
model at the natural length (§5.4) and where the actuated and sensed models are singular (ch. 6).
"""

from __future__ import annotations

import dataclasses
import math
import numbers
from dataclasses import dataclass
from typing import Any

import numpy as np

from .._shapes import as_real
from ..couplings import channel_names, coupling_words, gear_fill
from ..errors import WmrkitError
from ..kinematics.actuation import actuation_analysis, actuator_names
from ..kinematics.sensing import sensing_analysis
from ..limits import check_length
from ..robot import Robot, check_robot
from ..wheels import heading_from_beta
from .classification import Classification, classify, instantaneous_mobility
from .coordinated import coordinated_singular_set
from .icr import ICRSet, icr
from .isotropy import described_condition, length_applies
from .linkage_reach import LinkedReach, linked_reach, unreachable, unreachable_note
from .singularity import SingularSet, singular_set


@dataclass(frozen=True, eq=False)
class Analysis:
    """Result of :func:`analyze` for a robot at its described configuration."""

    robot: Robot
    classification: Classification
    instantaneous_mobility: int
    icr: ICRSet
    actuation: dict[str, Any]  # consistent, sufficient, verdict
    sensing: dict[str, Any]  # sufficient, verdict
    joints: tuple[str, ...]  # joint rates of the condition number
    condition_number: float
    characteristic_length: float
    natural: bool  # the length is the natural one (not given)
    singular: dict[str, SingularSet]  # "actuated", "sensed"
    #: the twist's m at the described steering with the motions a gear coupling forbids removed (as fk and odometry
    #: use a gear), comparable with the type line's m, the thesis's, of the wheels alone: the verdicts' k - rank A
    #: also counts the motions of a double wheel's joints with the body at rest
    coupled_mobility: int
    #: what the held steering ``linkage`` couplings leave of the ICRs the wheels allow (None without one): the
    #: classification above is the thesis's, of the wheels' geometry alone (:mod:`.linkage_reach`)
    linked: LinkedReach | None = None

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready summary (SI units, radians); the keys of ``wmrkit analyze --json``."""
        c = self.classification
        return {
            "robot": self.robot.name,
            "mobility": c.mobility, "coupled_mobility": self.coupled_mobility,
            "steerability": c.steerability, "commanded_steerability": c.commanded_steerability,
            "type": c.type, "type_name": c.name,
            "degenerate": c.degenerate, "reasons": list(c.reasons), "coordinated_steering": c.coordinated,
            "instantaneous_mobility": self.instantaneous_mobility,
            "special_configurations": [{"heading": self.robot.heading_of_beta(s.beta).tolist(), "beta": list(s.beta),
                                        "mobility": s.mobility, "description": s.description} for s in c.special],
            "icr": self.icr.describe(),
            "actuation": {k: self.actuation[k] for k in ("consistent", "sufficient", "verdict")},
            "sensing": {k: self.sensing[k] for k in ("sufficient", "verdict")},
            "isotropy_note": self.isotropy_note(),  # m <= 1, of the wheels or left by gears: as the text says
            "condition_number": None if self.isotropy_note() is not None else self.condition_number,
            "characteristic_length": self.characteristic_length if self.has_length else None,
            "condition_joints": list(self.joints), "natural_length": self.natural,
            "singular": {k: singular_dict(s, self.robot) for k, s in self.singular.items()},
            "linkages": None if self.linked is None else self.linked.to_dict(),
        }

    @property
    def has_length(self) -> bool:
        """A length goes with the condition number: given, or natural where it applies (:func:`.length_applies`;
        not where isotropy does not apply, m <= 1 of the wheels or left by gears)."""
        g = self.gear_mobility
        m = self.classification.mobility if g is None else g
        return not self.natural or length_applies(m, self.condition_number)

    @property
    def gear_mobility(self) -> int | None:
        """The m that gear couplings leave when below the wheels' m at the described steering, else None."""
        return self.coupled_mobility if self.coupled_mobility < self.instantaneous_mobility else None

    @property
    def gears_leave_one(self) -> bool:
        """Gear couplings leave at most one motion: no condition number (one encoder of a solid axle gives the
        twist, as fk says, and kappa = 1 says nothing)."""
        return self.gear_mobility is not None and self.gear_mobility <= 1

    def isotropy_note(self) -> str | None:
        """Why no condition number is given, or None: m <= 1 (§5.5.4-5.5.5), the wheels' or the one gear couplings
        leave. With gears that leave m >= 2 the condition number is over the motions they allow (the geared
        :func:`.isotropy.twist_model`)."""
        m, g = self.classification.mobility, self.gear_mobility
        if m <= 1:
            return f"does not apply (m = {m}: no two motions to balance)"
        if self.gears_leave_one:
            return f"does not apply (its gear couplings leave m = {g}: no two motions to balance)"
        return None

    def condition_words(self) -> str:
        """The condition number and its length in words (the text summary and the report)."""
        if not np.isfinite(self.condition_number):
            kappa = "infinite (these joints do not determine the twist)"
            return f"{kappa} at the given length D = {self.characteristic_length:.4g} m" if self.has_length else kappa
        how = "natural length" if self.natural else "given length"
        return f"{self.condition_number:.4g} at the {how} D = {self.characteristic_length:.4g} m"

    def gears_note(self) -> str | None:
        """What the type line adds when gear couplings leave fewer motions than the wheels (None otherwise)."""
        g = self.gear_mobility
        return None if g is None else f"its gear couplings leave m = {g} (couplings)"

    def linkage_note(self) -> str | None:
        """The line under the type when held steering linkages leave the robot fewer ICRs than its wheels allow
        (None otherwise): the type line is the wheels' geometry alone."""
        if self.linked is None or self.linked.every:
            return None
        return f"{self.linked.describe()}; the type is of the wheels alone (thesis Table 5.1)"

    def format_text(self) -> str:
        """A concise terminal summary."""
        c, r = self.classification, self.robot
        gears, linked = self.gears_note(), self.linkage_note()
        lines = [f"{r.name}: {c.describe()}" + ("" if gears is None else f"; {gears}")]
        if linked is not None:
            lines.append(f"  {linked}")
        if self.instantaneous_mobility != c.mobility:
            lines.append(f"  at the described steering: m = {self.instantaneous_mobility}")
        lines += [f"  {s.description}" for s in c.special]
        lines.append(f"  {self.icr.describe()}")
        # a differential's, a linkage's joints are one actuator, named in the description's terms (JSON: channels)
        actuators = [coupling_words(r.couplings, a, short=True) for a in actuator_names(r, r.actuated)]
        lines.append(f"  actuation: {actuation_words(self.actuation)} ({', '.join(actuators) or 'nothing declared'})")
        lines.append(f"  sensing: {_yes(self.sensing['sufficient'], 'sufficient', 'insufficient')} "
                     f"({', '.join(r.sensed) or 'nothing declared'})")
        if (note := self.isotropy_note()) is not None:
            lines.append(f"  isotropy: {note}")
        else:
            lines.append(f"  condition number {self.condition_words()}, joints {', '.join(self.joints) or '-'}")
        for key, s in self.singular.items():
            assigned = [coupling_words(r.couplings, a, short=True) for a in assigned_names(s, r)]
            lines.append(f"  singular ({key}: {', '.join(assigned) or '-'}): {describe_singular(s, r)}")
            if (note := unreachable_note(r, s, words=True)) is not None:  # a held linkage cannot set them
                lines.append(f"    {note}")
        return "\n".join(lines)


def _yes(flag: bool, yes: str, no: str) -> str:
    return yes if flag else no


def actuation_words(actuation: dict[str, Any]) -> str:
    """What the actuation verdict means for the user, in words (thesis Fig. 4.4)."""
    if not actuation["sufficient"]:
        return "insufficient: some motions are driven by no actuator"
    if actuation["consistent"]:
        return "sufficient, and the actuators cannot fight each other"
    return ("over-actuated: the actuators must be coordinated or they fight and the wheels slip "
            "(mechanical couplings go in the description's 'couplings')")


def assigned_names(s: SingularSet, robot: Robot) -> tuple[str, ...]:
    """The velocities a singular set assigns, each rate coupling's joints as its channel when it holds them."""
    return channel_names(robot.couplings, s.assigned) if s.coupled else s.assigned


def singular_dict(s: SingularSet, robot: Robot) -> dict[str, Any]:
    """JSON of a singular set: ``configurations`` as the thesis's β of `variables`, ``headings`` the same angles
    as the wheels' headings (0 = rolling straight ahead); ``unreachable``: per configuration listed, True where a held
    ``linkage`` cannot set it (:mod:`.linkage_reach`), and ``unreachable_note`` the report's line on it (or None)."""
    delta = np.array([robot.wheel(v).delta for v in s.variables], dtype=float)
    configs = s.configurations[:24]
    bad, _ = unreachable(robot, s)
    return {"assigned": list(s.assigned), "variables": list(s.variables), "always": s.always, "never": s.never,
            "exact": s.exact, "count": len(s.configurations), "configurations": configs.tolist(),
            "headings": heading_from_beta(configs, delta).tolist(), "reasons": list(s.reasons),
            "channels": list(assigned_names(s, robot)), "unreachable": bad[:24].tolist(),
            "unreachable_note": unreachable_note(robot, s)}


def describe_singular(s: SingularSet, robot: Robot | None = None, *, limit: int = 6) -> str:
    """One line: never / always (why) / at which steering angles: headings in degrees when `robot` is given."""
    if s.always:
        return "always" + (f" ({s.reasons[0]})" if s.reasons else "")
    if s.never:
        return ("never" if s.exact else "none found on the sampled grid") + (
            " (coordinated steering)" if s.coordinated else "")
    if s.coordinated:
        more = f" and {len(s.configurations) - limit} more" if len(s.configurations) > limit else ""
        return "with coordinated steering, when the " + "; ".join(
            r.replace("ICR at", "ICR is at", 1) for r in s.reasons[:limit]) + more
    if s.exact:
        values, what = (s.configurations[:, 0], "beta") if robot is None else (_headings(s, robot), "heading")
        angles = ", ".join(f"{math.degrees(v):.2f}" for v in values[:limit])
        more = f" and {len(s.configurations) - limit} more" if len(s.configurations) > limit else ""
        return f"at {what} {s.variables[0]} = {angles} deg{more}"
    return f"on curves over ({', '.join(s.variables)}), {len(s.configurations)} sampled points"


def _headings(s: SingularSet, robot: Robot) -> np.ndarray:
    """The singular angles of a one-variable exact set as headings of that wheel (0 = rolling straight ahead)."""
    return heading_from_beta(s.configurations[:, 0], robot.wheel(s.variables[0]).delta)


def model_rates(robot: Robot, joints: tuple[str, ...]) -> tuple[str, ...]:
    """The joints that are rates of the velocity vector (a steerable wheel's steering joint is not one)."""
    rates = set(robot.rate_names)
    return tuple(j for j in joints if j in rates)


def model_singular_set(robot: Robot, assigned: tuple[str, ...], cls: Classification,
                       resolution: int, *, coupled: bool = False) -> SingularSet:
    """Singular set of a model: over admissible (coordinated) configurations when the steering must be coordinated
    (:mod:`.coordinated`), else over the whole steering space (:func:`.singularity.singular_set`). `coupled`:
    through the robot's rate couplings (the actuated model: a differential is one actuator)."""
    if cls.coordinated:
        return coordinated_singular_set(robot, assigned, resolution=resolution, coupled=coupled)
    return singular_set(robot, assigned, resolution=resolution, max_samples=resolution * 8, coupled=coupled)


#: Grid points per turn of a steering angle for analyze and its report (``--resolution``): the maps' cost grows with
#: the square of the finest (1440: about 5 s for a swerve drive).
MIN_RESOLUTION, MAX_RESOLUTION = 8, 1440


def check_resolution(resolution: int, name: str = "resolution") -> None:
    """Raise :class:`WmrkitError` unless `resolution` is a whole number of grid points per turn from
    :data:`MIN_RESOLUTION` to :data:`MAX_RESOLUTION` (`name`: the option or keyword, for the message)."""
    if (isinstance(resolution, bool) or not isinstance(resolution, numbers.Integral)
            or not MIN_RESOLUTION <= resolution <= MAX_RESOLUTION):
        raise WmrkitError(f"{name}: need {MIN_RESOLUTION} to {MAX_RESOLUTION} points per turn (a quarter degree), "
                          f"got {resolution!r}")


def analyze(robot: Robot, *, length: float | None = None, resolution: int = 90) -> Analysis:
    """Analyse `robot` at its described configuration (see the module docstring).

    `length` [m]: characteristic length of the condition number (default: the natural one). `resolution`:
    grid points per turn for singular sets over two or more steering angles (:func:`check_resolution`, as
    ``--resolution``).
    """
    check_robot(robot)
    check_resolution(resolution)
    here = described_analysis(robot, length=length, resolution=resolution)
    cls = here.classification
    sensed = model_rates(robot, robot.sensed)  # with the rates a gear turns with them, known as fk knows them
    sensed = tuple(robot.rate_names[c] for c in gear_fill(robot.couplings, robot.rate_names,
                                                          tuple(map(robot.rate_names.index, sensed)))[0])
    singular = {key: model_singular_set(robot, names, cls, resolution, coupled=key == "actuated")
                for key, names in (("actuated", model_rates(robot, robot.actuated)), ("sensed", sensed))}
    return dataclasses.replace(here, singular=singular)


def described_analysis(robot: Robot, *, length: float | None = None, resolution: int = 90) -> Analysis:
    """:func:`analyze` without the singular sets over the steering space (``singular`` empty): the studio's
    per-edit analysis, the same numbers (type, ICR and condition number with the gears held, the ICRs the
    linkages leave on a grid of `resolution` points per turn)."""
    cls = classify(robot)
    if length is not None:  # as analyze --length: at 1e-9 m the twist read as undetermined
        length = as_real(length, "length")  # the Python API reads no units: '1' raised a bare TypeError
        check_length(length, WmrkitError)
    joints, d, kappa = described_condition(robot, length)
    act, sen = actuation_analysis(robot), sensing_analysis(robot)
    return Analysis(
        robot, cls, int(instantaneous_mobility(robot)), icr(robot, geared=True),
        {"consistent": bool(np.all(act.consistent)), "sufficient": bool(np.all(act.sufficient)),
         "verdict": str(act.verdict)},
        {"sufficient": bool(np.all(sen.sufficient)), "verdict": str(sen.verdict)},
        joints, kappa, d, length is None, {}, int(instantaneous_mobility(robot, geared=True)),
        linked_reach(robot, resolution),
    )
