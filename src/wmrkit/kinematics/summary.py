"""A robot's chapter-4 summary at one configuration: what ``wmrkit kinematics`` prints, as data and as text."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ..couplings import coupling_words
from ..errors import SingularError
from ..robot import Robot
from .actuation import actuation_analysis, minimal_actuator_sets
from .extended import extended_dof
from .linalg import RANK_RTOL, characteristic_length
from .models import (
    KinematicModel,
    assignable_sets,
    direct_model,
    generic_mobility,
    generically_assignable_sets,
    inverse_model,
    mobility,
)
from .sensing import minimal_sensor_sets, sensing_analysis
from .trees import vehicle_dof


def _model(build, robot: Robot) -> dict[str, Any]:
    try:
        model: KinematicModel = build(robot)
    except SingularError as err:
        return {"error": str(err)}
    out = model.as_dict()
    beta = out.pop("beta")  # the users' headings (0 = straight ahead) beside the thesis's beta, in its order
    return {**out, "heading": robot.heading_of_beta(model.beta).tolist(), "beta": beta}


def kinematics_summary(robot: Robot) -> dict[str, Any]:
    """Mobility, assignable sets, direct (sensed) and inverse models, actuation and sensing at the described beta.

    JSON-ready (plain lists and numbers). Steer the robot first with :meth:`wmrkit.Robot.with_steering`.
    """
    here = assignable_sets(robot)
    generic = generically_assignable_sets(robot)
    here_set = set(here)
    act_sets, sen_sets = minimal_actuator_sets(robot), minimal_sensor_sets(robot)
    searches = {"assignable_sets": here, "generically_assignable_sets": generic, "minimal_actuator_sets": act_sets,
                "minimal_sensor_sets": sen_sets}
    return {
        "robot": robot.name,
        "steering": dict(zip(robot.steer_names, robot.heading.tolist(), strict=True)),  # headings [rad]
        "beta": dict(zip(robot.steer_names, robot.beta.tolist(), strict=True)),  # the thesis's angles [rad]
        "velocity_names": list(robot.velocity_names),
        "size": characteristic_length(robot),  # L [m]: vx, vy in units of L make the models' entries comparable
        "mobility": int(mobility(robot, gears=False)),  # the wheels' m (4.3), the thesis's
        "vehicle_dof": int(vehicle_dof(robot)),  # G (4.22): of the m above, motions of the body
        # m with the gear couplings held (analyze's coupled_mobility): the sets' size, the models' m
        "coupled_mobility": int(mobility(robot)),
        "gears": [c.channel_name for c in robot.couplings if c.kind == "gear"],  # held by the sets and models
        "linkages": [c.channel_name for c in robot.couplings if c.kind == "linkage"],  # not counted by extended_dof
        "generic_mobility": generic_mobility(robot),  # the models' m at generic steering
        "extended_dof": extended_dof(robot),
        "assignable_sets": [list(s) for s in here],
        "lost_here": [list(s) for s in generic if s not in here_set] if getattr(here, "complete", True) else [],
        "direct_model": _model(direct_model, robot),
        "inverse_model": _model(inverse_model, robot),
        "actuation": actuation_analysis(robot).as_dict(),
        "sensing": sensing_analysis(robot).as_dict(),
        "minimal_actuator_sets": [list(s) for s in act_sets],
        "minimal_sensor_sets": [list(s) for s in sen_sets],
        # bounded searches that stopped early (.search, docs/limits.md): what was not listed
        "incomplete": {k: v.note for k, v in searches.items() if not getattr(v, "complete", True)},
    }


#: A computed value printed as 0: within this fraction of its scale, round-off (docs: cli._shown).
ROUNDOFF = 1e-12

#: A model entry printed as 0: within this fraction of the matrix's largest entry, both in the robot's size L
#: (vx, vy in L/s), where the models are solved: what the rank rule cannot tell from 0 (``linalg.RANK_RTOL``, the
#: heading resolution), least-squares round-off (5.5e-12 rad/s per rad/s on 64 castors whose largest entry is 415)
#: or the slip of headings rounded to that resolution (vy = 7.7e-9 m/s per rad/s of a car's rear spin at headings
#: printed to 4 decimals of a degree), not a value. The JSON keeps the computed values.
MODEL_ROUNDOFF = RANK_RTOL


def printed_matrix(model: dict[str, Any], size: float) -> np.ndarray:
    """`model`'s matrix ``(n_solved, n_assigned)`` with the entries within :data:`MODEL_ROUNDOFF` of its scale set
    to 0."""
    matrix = np.asarray(model["matrix"], dtype=float).reshape(len(model["solved"]), len(model["assigned"]))
    in_l = [1.0 / size if n in ("vx", "vy") else 1.0 for n in model["solved"]]  # rows: the solved velocities
    per_l = [size if n in ("vx", "vy") else 1.0 for n in model["assigned"]]
    scaled = np.abs(matrix) * np.array(in_l)[:, None] * np.array(per_l)
    return np.where(scaled <= MODEL_ROUNDOFF * scaled.max(initial=0.0), 0.0, matrix)


def _cell(v: float, width: int) -> str:
    text = f"{v:.6g}"
    return f"{text:>{width}}" if len(text) < width else " " + text  # never run into the previous entry


def _matrix_table(model: dict[str, Any], size: float, indent: str = "    ") -> list[str]:
    if "error" in model:
        return [f"{indent}not available: {model['error']}"]
    if not model["assigned"]:
        return [f"{indent}the robot cannot move (m = 0): every velocity is zero"]
    width = max([12, *(len(n) + 2 for n in model["assigned"])])
    name_width = max(len(n) for n in model["solved"]) if model["solved"] else 1
    head = f"{indent}{'':<{name_width}} = " + "".join(f"{n:>{width}}" for n in model["assigned"])
    rows = [head]
    for name, row in zip(model["solved"], printed_matrix(model, size), strict=True):
        rows.append(f"{indent}{name:<{name_width}} = " + "".join(_cell(v, width) for v in row.tolist()))
    return rows


def _sets(sets: list[list[str]], limit: int | None, indent: str = "    ") -> list[str]:
    """Sets of names, wrapped to lines of at most 110 characters; past `limit` sets, a count and how to see all."""
    shown = sets if limit is None else sets[:limit]
    lines, line = [], indent
    for s in shown:
        item = "(" + ", ".join(s) + ")"
        if len(line) + len(item) > 110 and line.strip():
            lines.append(line.rstrip())
            line = indent
        line += item + "  "
    if line.strip():
        lines.append(line.rstrip())
    if len(shown) < len(sets):
        lines.append(f"{indent}... and {len(sets) - len(shown)} more (--all lists every set)")
    return lines


def format_kinematics_summary(summary: dict[str, Any], *, limit: int | None = 12, couplings: tuple = ()) -> str:
    """Human-readable text of :func:`kinematics_summary`: counts, sets, model tables, verdicts.

    Steering angles are headings in degrees (0 = rolling straight ahead). At most `limit` sets are listed per
    list (None: all). The robot's `couplings` name its couplings in the description's terms
    (:func:`wmrkit.couplings.coupling_words`: ``linkage of fl and fr`` in a list of identifiers; without them, by
    channel name, as the JSON does).
    """
    steer = ", ".join(f"heading {n} = {math.degrees(v):.6g} deg" for n, v in summary["steering"].items())
    m, generic, coupled = summary["mobility"], summary["generic_mobility"], summary["coupled_mobility"]
    gears = summary["gears"]
    special = "" if coupled == generic else (f" at this steering (m = {generic} at generic steering: a special "
                                             "configuration)")
    mobility = f"  mobility m = {m}" + (" of the wheels alone" if gears else special)
    self_motions = m - summary["vehicle_dof"]
    if self_motions > 0:
        mobility += (f" (4.3): {summary['vehicle_dof']} of the body (G, 4.22; the classification's m) and "
                     f"{self_motions} of the joints with the body at rest")
    extra = summary["extended_dof"] - generic  # n_o: extended_dof is m at generic steering plus n_o (4.76)
    lines = [f"robot {summary['robot']} ({steer or 'no steering'})", mobility]
    if summary.get("headings_note"):  # rounded headings (wmrkit kinematics adds it: analysis.icr)
        lines.append(f"  note: {summary['headings_note']}")
    if gears:
        named = ", ".join(coupling_words(couplings, g, short=True) for g in gears)
        lines.append(f"  with its gear couplings m = {coupled}{special} ({named}, q_j = ratio_j * u): "
                     "the sets and models below hold them")
    if extra > 0:
        n = summary["extended_dof"]
        linked = [coupling_words(couplings, c) for c in summary.get("linkages") or ()]
        lines.append(f"  with its {extra} steering angle{'s' if extra > 1 else ''} (extended solutions, §4.5), "
                     f"{n} velocit{'ies' if n > 1 else 'y'} can be assigned"
                     + (f" (each steered wheel counted, {', '.join(linked)} not as one: the solutions judge their "
                        f"angles against {'its' if len(linked) == 1 else 'their'} law"
                        f"{'' if len(linked) == 1 else 's'})"
                        if linked else ""))
    lines += [f"  velocities (vx, vy [m/s]; omega, joint rates [rad/s]): {', '.join(summary['velocity_names'])}",
              f"  assignable sets ({len(summary['assignable_sets'])}):", *_sets(summary["assignable_sets"], limit)]
    lost = [s for s in summary["lost_here"] if s]
    if lost:
        lines += [f"  not assignable at this steering, though they are at generic steering ({len(lost)}):",
                  *_sets(lost, limit)]
    for title, key in (("direct model", "direct_model"), ("inverse model", "inverse_model")):
        model = summary[key]
        kind = "" if "error" in model or not model["assigned"] else (  # m = 0: nothing assigned, one line says so
            f" ({model['kind']}, assigned: {', '.join(model['assigned'])})")
        lines += [f"  {title}{kind}:", *_matrix_table(model, summary["size"])]
    act, sen = summary["actuation"], summary["sensing"]
    actuators = [coupling_words(couplings, a, short=True) for a in act["actuated"] + act["steering_actuators"]]
    lines.append(f"  actuation [{', '.join(actuators)}]: "
                 f"{act['verdict']}")
    lines.append(f"  sensing [{', '.join(sen['sensed'] + [s + '.steer' for s in sen['steering_sensed']])}]: "
                 f"{sen['verdict']}")
    for title, key in (("minimal actuator sets", "minimal_actuator_sets"),
                       ("minimal sensor sets", "minimal_sensor_sets")):
        lines += [f"  {title} ({len(summary[key])}):", *(_sets(summary[key], limit) or ["    none"])]
    lines += [f"  note: {key.replace('_', ' ')}: {note}" for key, note in summary.get("incomplete", {}).items()]
    return "\n".join(lines)
