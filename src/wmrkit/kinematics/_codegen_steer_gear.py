"""The generated ``in_steer_gear`` of :func:`wmrkit.kinematics.codegen.write_code` (robots with a ``gear`` between
steering joints): ``wmrkit ik``'s check of steering headings against such a gear's ratios (``beta_j - beta_j0 =
ratio_j u``, :func:`~.gear_check.steer_breach`, ``out_of_steer_gear``) for a twist.

The Python file carries the judge's own source (:func:`~.gear_check.steer_breach`, and
:func:`~.linkage_law.remainder` unless the linkages' judge brought it); the C, the same steps printed in C99 (its
``remainder`` is the IEEE one). Both take the gears' entries (:func:`~.gear_check.steer_gears`) as tables.
"""

from __future__ import annotations

import inspect
import math

from . import gear_check, linkage_law
from ._codegen_linkage import has_linkages
from ._codegen_plan import Plan
from .linkage_law import LINKAGE_TOL
from .wheel_ik import SLIP_TOL

_PI = repr(math.pi)


def has_steer_gears(plan: Plan) -> bool:
    """Whether the robot has a gear between steering joints (the generated code judges it)."""
    return len(plan.steer_gears.table.coupling) > 0


def _ints(values) -> str:
    return ", ".join(map(str, values.tolist()))


def _floats(values) -> str:
    return ", ".join(repr(float(v)) for v in values.tolist())


def c_doc(plan: Plan, names: str) -> list[str]:
    """The header's lines on the steering gears, `names` the last (their list, made a safe C comment)."""
    n, p = plan.name, plan.name.upper()
    return [f" * {n}_in_steer_gear: whether each gear between steering joints can set the headings for the twist,",
            f" *   in_steer_gear[{p}_N_STEER_GEARS], as wmrkit ik (kinematics/gear_check.py, out_of_steer_gear): the",
            " *   gear turns its angles as beta_j - beta_j0 = ratio_j u, u from its wheel whose steering axis moves",
            " *   fastest (its heading, -1 to 2 turns on); a wheel the gear sets off its heading by e (mod 2 pi)",
            f" *   whose axis moves at s breaks it when |e| > {LINKAGE_TOL!r} rad and s sin(min(|e|, pi/2)) >",
            f" *   {SLIP_TOL!r} m/s; returns 1 if all hold, else 0 (also for a non-finite input). Give it the",
            " *   headings the wheels are set at (wmrkit ik's).",
            names]


def c_in_steer_gear(plan: Plan, proto: str) -> list[str]:
    """The tables and body of ``NAME_in_steer_gear``."""
    if not has_steer_gears(plan):
        return []
    sg, p = plan.steer_gears, plan.name.upper()
    t = sg.table
    return [
        "/* the steering gears' entries (kinematics/gear_check.py): gear g's joints (steering columns) and ratios",
        " * sg_start[g] to sg_start[g + 1] - 1; the described angles beta_0 and the steering axes [m] per column */",
        f"static const int sg_joint[{len(t.joint)}] = {{{_ints(t.joint)}}};",
        f"static const double sg_ratio[{len(t.ratio)}] = {{{_floats(t.ratio)}}};",
        f"static const int sg_start[{len(t.start)}] = {{{_ints(t.start)}}};",
        f"static const double sg_rest[{p}_N_STEER] = {{{_floats(sg.rest)}}};",
        f"static const double sg_x[{p}_N_STEER] = {{{_floats(sg.x)}}};",
        f"static const double sg_y[{p}_N_STEER] = {{{_floats(sg.y)}}};", "",
        proto[:-1], "{",
        f"    static const double offset[{p}_N_STEER] = {{{', '.join(map(repr, plan.offsets))}}};",
        "    const double vx = twist[0], vy = twist[1], w = twist[2];",
        f"    double beta[{p}_N_STEER];",
        "    int finite = isfinite(vx) && isfinite(vy) && isfinite(w), all = 1;",
        f"    for (int k = 0; k < {p}_N_STEER; ++k) {{",
        "        beta[k] = heading[k] + offset[k]; /* beta = heading + pi/2 - delta */",
        "        finite = finite && isfinite(heading[k]);",
        "    }",
        f"    for (int g = 0; g < {p}_N_STEER_GEARS; ++g) {{",
        "        const int first = sg_start[g], last = sg_start[g + 1];",
        "        int ref = -1, ok = finite;",
        "        double top = 0.0;",
        "        for (int t = first; t < last; ++t) { /* the reference: the wheel whose axis moves fastest */",
        "            const double s = hypot(vx - w * sg_y[sg_joint[t]], vy + w * sg_x[sg_joint[t]]);",
        "            if (s > top) { ref = t; top = s; }",
        "        }",
        "        if (ok && ref >= 0) {",
        f"            const double turn = remainder(beta[sg_joint[ref]] - sg_rest[sg_joint[ref]], 2.0 * {_PI});",
        "            int holds = 0;",
        "            for (int m = -1; m < 3 && !holds; ++m) { /* the reference's heading, whole turns on or back */",
        f"                const double u = (turn + 2.0 * m * {_PI}) / sg_ratio[ref];",
        "                int hit = 0;",
        "                for (int t = first; t < last && !hit; ++t) {",
        "                    const int k = sg_joint[t];",
        f"                    const double off = remainder(beta[k] - sg_rest[k] - sg_ratio[t] * u, 2.0 * {_PI});",
        f"                    if (t == ref || fabs(off) <= {LINKAGE_TOL!r}) continue;",
        f"                    hit = hypot(vx - w * sg_y[k], vy + w * sg_x[k]) * sin(fmin(fabs(off), 0.5 * {_PI}))",
        f"                          > {SLIP_TOL!r};",
        "                }",
        "                holds = !hit;",
        "            }",
        "            ok = holds;",
        "        }",
        "        in_steer_gear[g] = ok;",
        "        all = all && ok;",
        "    }",
        "    return all;", "}", "",
    ]


def py_constants(plan: Plan) -> str:
    """The generated Python's steering-gear tables (robots with a gear between steering joints), else nothing."""
    if not has_steer_gears(plan):
        return ""
    sg = plan.steer_gears
    t = sg.table
    return "\n".join([
        "", f"STEER_GEAR_NAMES = {plan.steer_gear_names!r}", f"STEER_GEAR_TOL = {LINKAGE_TOL!r}  # [rad]",
        "# the gears between steering joints: gear g's joints (steering columns) and ratios",
        "# _SG_JOINT[_SG_START[g]:_SG_START[g + 1]]; the described angles beta_0, the steering axes [m] per column",
        f"_SG_JOINT = numpy.array({t.joint.tolist()!r})", f"_SG_RATIO = numpy.array({t.ratio.tolist()!r})",
        f"_SG_START = {tuple(t.start.tolist())!r}", f"_SG_REST = numpy.array({sg.rest.tolist()!r})",
        f"_SG_X = numpy.array({sg.x.tolist()!r})", f"_SG_Y = numpy.array({sg.y.tolist()!r})"])


def py_in_steer_gear(plan: Plan) -> str:
    """The generated ``in_steer_gear`` and the judge's source (robots with a steering gear), else nothing."""
    if not has_steer_gears(plan):
        return ""
    functions = (() if has_linkages(plan) else (linkage_law.remainder,)) + (gear_check.gear_reference,
                                                                           gear_check.steer_breach)
    sources = "\n\n".join(inspect.getsource(f).rstrip() for f in functions)
    n, s = len(plan.steer_gear_names), len(plan.beta)
    return f'''


def in_steer_gear(twist, heading=None):
    """Whether each gear between steering joints (``STEER_GEAR_NAMES``) can set the headings for the twist, as
    ``wmrkit ik`` checks them (``out_of_steer_gear``): the gear turns its angles as ``beta_j - beta_j0 = ratio_j u``,
    ``u`` from its wheel whose steering axis moves fastest (its heading, -1 to 2 turns on); a wheel it sets
    off its heading by ``e`` (mod 2 pi) whose axis moves at ``s`` breaks it when ``|e| > STEER_GEAR_TOL`` and
    ``s sin(min(|e|, pi/2)) > SLIP_TOL`` [m/s];
    ``(..., 3), (..., {s}) -> (..., {n})`` bool, False for a non-finite input. Give it the headings the wheels are
    set at (``wmrkit ik``'s for the twist).
    """
    twist, beta = _vectors(twist, 3, "twist"), _beta(heading)
    shape = numpy.broadcast_shapes(twist.shape[:-1], beta.shape[:-1])
    twist = numpy.broadcast_to(twist, shape + (3,)).reshape(-1, 3)
    beta = numpy.broadcast_to(beta, shape + ({s},)).reshape(-1, {s})
    out = numpy.isfinite(twist).all(axis=-1)[:, None] & numpy.isfinite(beta).all(axis=-1)[:, None]
    out = out & numpy.ones((1, {n}), dtype=bool)
    for i in range(len(beta)):
        for g in range({n}):
            if out[i, g] and steer_breach(_SG_JOINT, _SG_RATIO, _SG_START[g], _SG_START[g + 1], _SG_REST, _SG_X,
                                          _SG_Y, *twist[i].tolist(), beta[i], SLIP_TOL, STEER_GEAR_TOL)[0] >= 0:
                out[i, g] = False
    return out.reshape(shape + ({n},))


# wmrkit's judge (kinematics/gear_check.py{"" if has_linkages(plan) else ", linkage_law.py"}), as it is
{sources}'''
