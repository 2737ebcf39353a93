"""The generated ``in_linkage`` of :func:`wmrkit.kinematics.codegen.write_code` (robots with a held ``linkage``):
``wmrkit ik``'s check of steering headings against the linkages' laws (:mod:`.linkage_check`) for a twist.

The Python file carries the judge's own source (:func:`~.linkage_check._breach` with its ``_reference`` and
``_breach_at``, :func:`~.linkage_law.law`, :func:`~.linkage_law.leader_of`, :func:`~.linkage_law.remainder`); the
C, the same steps printed in C99 (its ``remainder`` is the IEEE one). Both take the linkages' rows
(:func:`~.linkage_law.linkage_table`) as tables.
"""

from __future__ import annotations

import inspect
import math

from . import linkage_check, linkage_law
from ._codegen_plan import Plan
from .linkage_law import LINKAGE_TOL
from .wheel_ik import SLIP_TOL

_PI = repr(math.pi)


def has_linkages(plan: Plan) -> bool:
    """Whether the robot holds a linkage with a law (the generated code judges it)."""
    return len(plan.links.lead) > 0


def c_doc(plan: Plan, names: str) -> list[str]:
    """The header's lines on the linkages, `names` the last (their list, made a safe C comment)."""
    n, p = plan.name, plan.name.upper()
    return [f" * {n}_in_linkage: whether each steering linkage holds the headings for the twist,",
            f" *   in_linkage[{p}_N_LINKAGES], as wmrkit ik (kinematics/linkage_check.py): the linkage's angles",
            " *   taken from its wheel whose steering axis moves fastest, a wheel off the law by e (mod pi) whose",
            f" *   axis moves at s breaks it when |e| > {LINKAGE_TOL!r} rad and s |sin e| > {SLIP_TOL!r} m/s; returns",
            " *   1 if all hold, else 0 (also for a non-finite input). Give it the headings the wheels are set at",
            " *   (wmrkit ik's for the twist).", names]


def c_in_linkage(plan: Plan, proto: str) -> list[str]:
    """The tables, helpers and body of ``NAME_in_linkage``."""
    if not has_linkages(plan):
        return []
    t, p = plan.links, plan.name.upper()
    rows = ",\n    ".join("{" + ", ".join(repr(float(v)) for v in row) + "}" for row in t.table.tolist())
    return [
        "/* the linkages' rows (kinematics/linkage_law.py): follower, leader, -, law (0 parallel, 1 axle), x_i, x_j,",
        " * y_i - y_j, beta_i - psi_i, beta_i0, beta_j0; linkage g's rows link_start[g] to link_start[g + 1] - 1 */",
        f"static const double link_table[{len(t.table)}][10] = {{\n    {rows}}};",
        f"static const int link_start[{len(t.start)}] = {{{', '.join(map(str, t.start.tolist()))}}};",
        f"static const int link_lead[{p}_N_LINKAGES] = {{{', '.join(map(str, t.lead.tolist()))}}};",
        f"static const double link_x[{p}_N_STEER] = {{{', '.join(map(repr, t.x.tolist()))}}}; /* axes [m] */",
        f"static const double link_y[{p}_N_STEER] = {{{', '.join(map(repr, t.y.tolist()))}}};", "",
        "/* the follower's angle the row sets at the leader's angle beta */",
        "static double link_law(const double *row, double beta)", "{",
        "    if (row[3] == 0.0) return row[9] + beta - row[8];",
        "    if (row[5] == 0.0) return row[9]; /* a follower on the axle line */",
        "    const double xi = row[4], xj = row[5], dy = row[6], psi = beta - row[7], psi0 = row[8] - row[7];",
        "    const double s = sin(psi), c = cos(psi), s0 = sin(psi0), c0 = cos(psi0);",
        "    const double u = xj * s, v = xi * c + dy * s, u0 = xj * s0, v0 = xi * c0 + dy * s0;",
        "    return row[9] + atan2(u * v0 - v * u0, v * v0 + u * u0);", "}", "",
        "/* the leader's angle at which the row sets its follower at beta (the law's inverse) */",
        "static double link_leader(const double *row, double beta)", "{",
        "    if (row[3] == 0.0) return row[8] + beta - row[9];",
        "    const double xi = row[4], xj = row[5], dy = row[6];",
        "    const double s0 = sin(row[8] - row[7]), c0 = cos(row[8] - row[7]);",
        "    const double psi_j = beta - row[9] + atan2(xj * s0, xi * c0 + dy * s0);",
        "    const double psi_i = atan2(xi * sin(psi_j), xj * cos(psi_j) - dy * sin(psi_j));",
        f"    const double lead = row[8] + remainder(psi_i + row[7] - row[8], {_PI});",
        f"    return fabs(remainder(link_law(row, lead) - beta, 2 * {_PI})) < {_PI} / 2 ? lead : lead + {_PI};",
        "}", "",
        proto[:-1], "{",
        f"    double beta[{p}_N_STEER], speed[{p}_N_STEER];",
        "    int finite = isfinite(twist[0]) && isfinite(twist[1]) && isfinite(twist[2]), all = 1;",
        f"    for (int k = 0; k < {p}_N_STEER; ++k) {{",
        f"        static const double offset[{p}_N_STEER] = {{{', '.join(map(repr, plan.offsets))}}};",
        "        beta[k] = heading[k] + offset[k]; /* beta = heading + pi/2 - delta */",
        "        speed[k] = hypot(twist[0] - twist[2] * link_y[k], twist[1] + twist[2] * link_x[k]);",
        "        finite = finite && isfinite(heading[k]);",
        "    }",
        f"    for (int g = 0; g < {p}_N_LINKAGES; ++g) {{",
        "        const int first = link_start[g], last = link_start[g + 1], lead = link_lead[g];",
        "        int ref = lead, ref_row = -1, ok = finite;",
        "        double top = speed[lead];",
        "        for (int r = first; r < last; ++r) top = speed[(int)link_table[r][0]] > top ? "
        "speed[(int)link_table[r][0]] : top;",
        "        for (int r = first; ok && top != 0.0 && r < last; ++r) { /* the first fastest giving the leader */",
        "            const int k = (int)link_table[r][0], gives = link_table[r][3] == 0.0 || link_table[r][5] != 0.0;",
        "            if (gives && speed[k] > speed[ref]) { ref = k; ref_row = r; }",
        "        }",
        "        const double b = ref_row < 0 ? beta[lead] : link_leader(link_table[ref_row], beta[ref]);",
        "        for (int r = first - 1; ok && top != 0.0 && r < last; ++r) { /* the leader, then its followers */",
        "            const int k = r < first ? lead : (int)link_table[r][0];",
        f"            const double off = remainder(beta[k] - (r < first ? b : link_law(link_table[r], b)), {_PI});",
        f"            if (fabs(off) > {LINKAGE_TOL!r} && speed[k] * fabs(sin(off)) > {SLIP_TOL!r}) ok = 0;",
        "        }",
        "        in_linkage[g] = ok;",
        "        all = all && ok;",
        "    }",
        "    return all;", "}", "",
    ]


def py_constants(plan: Plan) -> str:
    """The generated Python's linkage tables (robots with a held linkage), else nothing."""
    if not has_linkages(plan):
        return ""
    t = plan.links
    return "\n".join([
        "", f"LINKAGE_NAMES = {plan.linkage_names!r}", f"LINKAGE_TOL = {LINKAGE_TOL!r}  # [rad]",
        *([] if plan.geared else [f"SLIP_TOL = {SLIP_TOL!r}  # [m/s]"]),
        "# the linkages' rows: follower, leader, -, law (0 parallel, 1 axle), x_i, x_j, y_i - y_j, beta_i - psi_i,",
        "# beta_i0, beta_j0; linkage g's rows _LINK_START[g]:_LINK_START[g + 1]; its leader _LINK_LEAD[g]",
        f"_LINK_TABLE = numpy.array({t.table.tolist()!r})", f"_LINK_START = {tuple(t.start.tolist())!r}",
        f"_LINK_LEAD = {tuple(t.lead.tolist())!r}",
        f"_LINK_X = numpy.array({t.x.tolist()!r})  # steering axes [m]", f"_LINK_Y = numpy.array({t.y.tolist()!r})"])


def py_in_linkage(plan: Plan) -> str:
    """The generated ``in_linkage`` and the judge's source (robots with a held linkage), else nothing."""
    if not has_linkages(plan):
        return ""
    sources = "\n\n".join(inspect.getsource(f).rstrip() for f in (
        linkage_law.law, linkage_law.leader_of, linkage_law.remainder, linkage_check._reference,
        linkage_check._breach, linkage_check._breach_at))
    n = len(plan.linkage_names)
    return f'''


def in_linkage(twist, heading=None):
    """Whether each steering linkage (``LINKAGE_NAMES``) holds the headings for the twist, as ``wmrkit ik`` checks
    them: the linkage's angles taken from its wheel whose steering axis moves fastest, a wheel off the law by ``e``
    (mod pi) whose axis moves at ``s`` breaks it when ``|e| > LINKAGE_TOL`` and ``s |sin e| > SLIP_TOL`` [m/s];
    ``(..., 3), (..., {len(plan.beta)}) -> (..., {n})`` bool, False for a non-finite input. Give it the headings
    the wheels are set at (``wmrkit ik``'s for the twist).
    """
    twist, beta = _vectors(twist, 3, "twist"), _beta(heading)
    shape = numpy.broadcast_shapes(twist.shape[:-1], beta.shape[:-1])
    twist = numpy.broadcast_to(twist, shape + (3,)).reshape(-1, 3)
    beta = numpy.broadcast_to(beta, shape + ({len(plan.beta)},)).reshape(-1, {len(plan.beta)})
    speed = numpy.hypot(twist[:, 0:1] - twist[:, 2:3] * _LINK_Y, twist[:, 1:2] + twist[:, 2:3] * _LINK_X)
    out = numpy.isfinite(twist).all(axis=-1)[:, None] & numpy.isfinite(beta).all(axis=-1)[:, None]
    out = out & numpy.ones((1, {n}), dtype=bool)
    for i in range(len(beta)):
        for g in range(len(_LINK_LEAD)):
            if out[i, g] and _breach(_LINK_TABLE, _LINK_START[g], _LINK_START[g + 1], _LINK_LEAD[g], beta[i],
                                     speed[i], True, SLIP_TOL, LINKAGE_TOL)[0] >= 0:
                out[i, g] = False
    return out.reshape(shape + ({n},))


# wmrkit's judge (kinematics/linkage_law.py, linkage_check.py), as it is
{sources}'''
