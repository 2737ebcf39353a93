"""The generated numpy module of :func:`wmrkit.kinematics.codegen.write_code`."""

from __future__ import annotations

import json

import sympy as sp
from sympy.printing.numpy import NumPyPrinter

from . import _codegen_steer_gear
from ._codegen_linkage import has_linkages, py_constants, py_in_linkage
from ._codegen_plan import Plan, cse
from .gear_check import GEAR_RTOL
from .linalg import RANK_RTOL
from .symbolic import printable
from .wheel_ik import SLIP_TOL


def _py_body(exprs: list[sp.Expr], targets: list[str]) -> str:
    temps, reduced = cse(exprs, NumPyPrinter())
    lines = [f"    {t}" for t in temps]
    lines += [f"    {target} = {code}" for target, code in zip(targets, reduced, strict=True)]
    return "\n".join(lines)


def _py_unknowns(plan: Plan) -> str:
    """The constants of the forward model's unknowns: the columns of ``A``, or with a gear ``q = F x + K q_s``
    (and the gears the inverse model's rates are checked against)."""
    if not plan.geared:
        return f"_SENSED_COLUMNS = {list(plan.sensed_cols)!r}\n_UNKNOWN_COLUMNS = {list(plan.unknown_cols)!r}"
    return "\n".join([
        f"GEAR_NAMES = {plan.gear_names!r}",
        f"GEAR_RTOL = {GEAR_RTOL!r}",
        f"SLIP_TOL = {SLIP_TOL!r}  # [m/s]",
        f"_GEARS = {_py_gears(plan)!r}  # (joints in the rates, ratios, levers [m])",
        "# the forward model's unknowns x: the twist, the unsensed rates, a gear none of whose joints is sensed (its",
        "# turn u); every velocity q = _FREE @ x + _KNOWN @ sensed, a gear's joints turning together, "
        "q_j = ratio_j * u",
        f"UNKNOWN_NAMES = {tuple(plan.unknown_names)!r}",
        f"_FREE = numpy.array({plan.free.tolist()!r})",
        f"_KNOWN = numpy.array({plan.known.tolist()!r})"])


def _py_gears(plan: Plan) -> tuple[tuple[tuple[int, ...], tuple[float, ...], tuple[float, ...]], ...]:
    """Each gear's joints (positions in the rates then the steering rates), ratios and levers [m]."""
    t = plan.gear_table
    spans = [slice(int(t.start[g]), int(t.start[g + 1])) for g in range(len(t.coupling))]
    return tuple((tuple(t.joint[s].tolist()), tuple(t.ratio[s].tolist()), tuple(t.lever[s].tolist())) for s in spans)


def _py_decision(plan: Plan) -> str:
    """The constants of the forward model's rank decision (``Plan.decide``, ``linalg.RANK_RTOL``)."""
    return "\n".join([
        f"RANK_RTOL = {RANK_RTOL!r}  # wmrkit.kinematics.linalg.RANK_RTOL: the library's rank rule",
        "# the unknowns' columns times _DECIDE: the library's decision matrix (lengths over the robot's size L, the",
        "# twist of the wheels' centroid); the unknowns are _DECIDE @ its unknowns",
        f"_DECIDE = numpy.array({plan.decide.tolist()!r})"])


def _py_forward_system(plan: Plan) -> str:
    """The generated lines setting the forward model's ``a_na`` and ``rhs`` from ``a`` and ``sensed``."""
    if not plan.geared:
        return "    a_na = a[..., _UNKNOWN_COLUMNS]\n    rhs = -(a[..., _SENSED_COLUMNS] @ sensed[..., None])"
    return "    a_na = a @ _FREE\n    rhs = -(a @ (_KNOWN @ sensed[..., None]))"


def _py_in_gear(plan: Plan) -> str:
    """The generated ``in_gear`` (robots with a gear): ``wmrkit ik``'s check of the inverse model's rates."""
    if not plan.geared:
        return ""
    n, s = len(plan.rates), len(plan.free_steer)
    args, inputs = ("rates", f'_vectors(rates, {n}, "rates")')
    if s:  # a double wheel's steering rate, an input of inverse, after the rates
        args, inputs = "rates, steer_rate", f"""_vectors(rates, {n}, "rates")
    steer_rate = _vectors(steer_rate, {s}, "steer_rate")
    shape = numpy.broadcast_shapes(rates.shape[:-1], steer_rate.shape[:-1])
    q = numpy.concatenate([numpy.broadcast_to(rates, shape + ({n},)),
                           numpy.broadcast_to(steer_rate, shape + ({s},))], axis=-1)"""
    return f'''

def in_gear({args}):
    """Whether each gear (``GEAR_NAMES``) turns its joints in its ratios, ``q_j = ratio_j * u``, as ``wmrkit ik``
    checks a twist: with ``u = k.q / k.k`` and ``e_j = |q_j - ratio_j u|``, every ``e_j <= GEAR_RTOL max |q|`` or
    every ``e_j lever_j <= SLIP_TOL`` [m/s] (the contact speed of the departure);
    ``(..., {len(plan.rates)})`` rates{" and steering rates" if plan.free_steer else ""} (from ``inverse``) \
``-> (..., {len(plan.gear_names)})`` bool.
    """
    {"rates" if s else "q"} = {inputs}
    scale = GEAR_RTOL * numpy.abs(q).max(axis=-1)
    out = []
    for joints, ratios, levers in _GEARS:
        kq = kk = 0.0
        for j, k in zip(joints, ratios):
            kq = kq + k * q[..., j]
            kk = kk + k * k
        relative = absolute = True
        for j, k, lever in zip(joints, ratios, levers):
            e = numpy.abs(q[..., j] - k * (kq / kk))
            relative = relative & (e <= scale)
            absolute = absolute & (e * lever <= SLIP_TOL)
        out.append(relative | absolute)
    return numpy.stack(out, axis=-1)'''


def _py_imports(plan: Plan) -> str:
    """The generated module's imports: numpy, and for the linkages' or steering gears' judge math and numpy as
    ``np``."""
    if has_linkages(plan):
        return "\nimport math\n\nimport numpy\n\nnp = numpy  # the linkages' judge (below) names it np\n"
    if _codegen_steer_gear.has_steer_gears(plan):
        return "\nimport math\n\nimport numpy\n\nnp = numpy  # the steering gears' judge (below) names it np\n"
    return "\nimport numpy\n"


def python_file(plan: Plan) -> list[tuple[str, str]]:
    r = plan.robot
    unpack = "\n".join(f"    b{i} = beta[..., {i}]  # {printable(n)}" for i, n in enumerate(r.steer_names))
    a_targets = [f"out[..., {i}, {j}]" for i in range(plan.a.rows) for j in range(plan.a.cols)]
    inputs, k = plan.twist + plan.steer_rate, 3 + len(plan.free_steer)
    m = sp.Matrix(plan.inverse).jacobian(sp.Matrix(inputs))
    m_targets = [f"out[..., {i}, {j}]" for i in range(m.rows) for j in range(k)]
    inputs_doc = "(twist, steer_rate)" if plan.free_steer else "twist"
    if plan.free_steer:
        steer_doc = (f"\n- ``steer_rate``: ``(..., {len(plan.free_steer)})`` steering rates of the double wheels "
                     "[rad/s], order ``FREE_STEER_NAMES``\n  (an input of the inverse model: no twist determines "
                     "them);")
        inverse_def = f'''def inverse(twist, steer_rate, heading=None):
    """Wheel rates [rad/s] for body twists and double-wheel steering rates:
    ``(..., 3), (..., {len(plan.free_steer)}), (..., {len(plan.beta)}) -> (..., {m.rows})``.
    """
    twist = _vectors(twist, 3, "twist")
    steer_rate = _vectors(steer_rate, {len(plan.free_steer)}, "steer_rate")
    shape = numpy.broadcast_shapes(twist.shape[:-1], steer_rate.shape[:-1])
    inputs = numpy.concatenate([numpy.broadcast_to(twist, shape + (3,)),
                                numpy.broadcast_to(steer_rate, shape + ({len(plan.free_steer)},))], axis=-1)
    return (inverse_matrix(heading) @ inputs[..., None])[..., 0]'''
    else:
        steer_doc = ""
        inverse_def = f'''def inverse(twist, heading=None):
    """Wheel rates [rad/s] for body twists: ``(..., 3), (..., {len(plan.beta)}) -> (..., {m.rows})``."""
    twist = _vectors(twist, 3, "twist")
    return (inverse_matrix(heading) @ twist[..., None])[..., 0]'''
    text = f'''"""No-slip kinematic models of robot {json.dumps(r.name)} (thesis ch. 4), generated by wmrkit.

Do not edit; regenerate with ``wmrkit kinematics ROBOT --codegen python DIR``. Needs only numpy. SI units,
robot frame x forward, y left. Arrays take leading batch axes, which broadcast:

- ``twist``: ``(..., 3)`` = (vx [m/s], vy [m/s], omega [rad/s]) in the robot frame;{steer_doc}
- ``heading``: ``(..., {len(plan.beta)})`` steering headings [rad], 0 = rolling straight ahead, counter-clockwise
  positive, order ``STEER_NAMES`` (None: as described);
- wheel rates: ``(..., {len(plan.rates)})`` [rad/s], order ``RATE_NAMES``;
- ``sensed``: ``(..., {len(plan.sensed)})`` [rad/s], order ``SENSED_NAMES``.
"""
{_py_imports(plan)}
STEER_NAMES = {tuple(r.steer_names)!r}
RATE_NAMES = {tuple(plan.rates)!r}
SENSED_NAMES = {tuple(plan.sensed)!r}
FREE_STEER_NAMES = {tuple(plan.free_steer)!r}
VELOCITY_NAMES = {tuple(r.velocity_names)!r}
HEADING_DESCRIBED = {tuple(float(h) for h in r.heading)!r}
_BETA_OFFSET = {tuple(plan.offsets)!r}  # the thesis's beta = heading + pi/2 - delta
{_py_unknowns(plan)}
{_py_decision(plan)}{py_constants(plan)}{_codegen_steer_gear.py_constants(plan)}


def _beta(heading):
    heading = numpy.asarray(HEADING_DESCRIBED if heading is None else heading, dtype=float)
    if heading.shape[-1:] != ({len(plan.beta)},):
        raise ValueError(f"heading: expected shape (..., {len(plan.beta)}), got {{heading.shape}}")
    return heading + numpy.asarray(_BETA_OFFSET)


def _vectors(x, n, name):
    x = numpy.asarray(x, dtype=float)
    if x.shape[-1:] != (n,):
        raise ValueError(f"{{name}}: expected shape (..., {{n}}), got {{x.shape}}")
    return x


def constraint_matrix(heading=None):
    """Slip matrix A (3.22), roller frame, columns VELOCITY_NAMES.

    ``(..., {len(plan.beta)}) -> (..., {plan.a.rows}, {plan.a.cols})``.
    """
    beta = _beta(heading)
{unpack}
    out = numpy.zeros(beta.shape[:-1] + ({plan.a.rows}, {plan.a.cols}))
{_py_body(list(plan.a), a_targets)}
    return out


def inverse_matrix(heading=None):
    """``rates = M @ {inputs_doc}`` ({"exact" if plan.inverse_exact else "least squares per wheel"}, 4.11).

    ``(..., {len(plan.beta)}) -> (..., {m.rows}, {k})``.
    """
    beta = _beta(heading)
{unpack}
    out = numpy.zeros(beta.shape[:-1] + ({m.rows}, {k}))
{_py_body(list(m), m_targets)}
    return out


{inverse_def}{_py_in_gear(plan)}{py_in_linkage(plan)}{_codegen_steer_gear.py_in_steer_gear(plan)}


def forward_with_residual(sensed, heading=None):
    """Least-squares twist (4.11) and slip residual ``|A q|`` [m/s].

    ``(..., {len(plan.sensed)}) -> (..., 3), (...)``. Both are NaN where the sensed rates do not determine the twist
    at those headings or an input is not finite, as the C code's -1: wmrkit's rank rule (``twist_is_determined``),
    ``rank D = 3 + rank D_joints`` with singular values at or below ``RANK_RTOL * max(s_max, 1)`` counted as 0, ``D``
    the unknowns' columns nondimensional and for the wheels' centroid's twist (``_DECIDE``), solved as ``fk``.
    """
    sensed = _vectors(sensed, {len(plan.sensed)}, "sensed")
    a = constraint_matrix(heading)
    finite = numpy.isfinite(a).all(axis=(-2, -1)) & numpy.isfinite(sensed).all(axis=-1)
    a = numpy.where(finite[..., None, None], a, 0.0)
    sensed = numpy.where(finite[..., None], sensed, 0.0)
{_py_forward_system(plan)}
    d = a_na @ _DECIDE
    u, s, vt = numpy.linalg.svd(d, full_matrices=False)
    keep = s > RANK_RTOL * numpy.maximum(s[..., :1], 1.0)
    y = vt.swapaxes(-1, -2) @ (numpy.divide(1.0, s, out=numpy.zeros_like(s), where=keep)[..., None]
                               * (u.swapaxes(-1, -2) @ rhs))
    residual = numpy.linalg.norm((d @ y - rhs)[..., 0], axis=-1)
    ok = finite & (keep.sum(axis=-1) == 3 + _rank(d[..., 3:]))
    return numpy.where(ok[..., None], (_DECIDE[:3] @ y)[..., 0], numpy.nan), numpy.where(ok, residual, numpy.nan)


def _rank(m):
    """The rank of ``(..., r, c)`` by wmrkit's rule: singular values above ``RANK_RTOL * max(s_max, 1)``."""
    if m.shape[-1] == 0:
        return numpy.zeros(m.shape[:-2], dtype=int)
    s = numpy.linalg.svd(m, compute_uv=False)
    return (s > RANK_RTOL * numpy.maximum(s[..., :1], 1.0)).sum(axis=-1)


def forward(sensed, heading=None):
    """Least-squares body twist from sensed rates (4.11): ``(..., {len(plan.sensed)}) -> (..., 3)``."""
    return forward_with_residual(sensed, heading)[0]
'''
    return [(f"{plan.name}_kinematics.py", text)]
