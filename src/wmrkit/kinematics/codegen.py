"""Code generation: a robot's kinematic models as dependency-free C99 or numpy code (from the symbolic models).

``inverse(twist, heading) -> wheel rates`` is the closed form of :func:`~wmrkit.kinematics.symbolic.symbolic_model`
with the twist assigned (4.11): exact when the twist is assignable, else least squares per wheel, as a
controller needs it. ``forward(sensed, heading) -> twist`` solves the no-slip equations for the twist and every
unsensed rate by least squares (4.11): the generated C carries a small Householder-QR routine (no closed form
to blow up), the generated Python calls ``numpy.linalg.pinv``; the residual ``|A q|`` [m/s] is the slip (4.16).
Both are printed from the same symbolic constraint matrix (3.22), with common-subexpression elimination.
The steering inputs are headings (0 = rolling straight ahead, counter-clockwise positive), what encoders and
controllers use; the generated code turns each into the thesis's angle, ``beta = heading + pi/2 - delta``.
"""

from __future__ import annotations

import json
import keyword
import math
import os
import re
from collections.abc import Sequence
from pathlib import Path
from typing import Literal

import numpy as np
import sympy as sp
from sympy.printing.c import C99CodePrinter
from sympy.printing.numpy import NumPyPrinter

from .._shapes import as_names
from ..errors import SingularError, WmrkitError, name_list
from ..robot import TWIST_NAMES, Robot
from .linalg import free_columns, matrix_rank, nondimensional
from .symbolic import printable, sensed_rates, symbolic_constraint_matrix, symbolic_model

C_KEYWORDS = frozenset(
    "auto break case char const continue default do double else enum extern float for goto if inline int long "
    "register restrict return short signed sizeof static struct switch typedef union unsigned void volatile while "
    "_Bool _Complex _Imaginary".split()
)


#: Longest file name (bytes) most file systems allow (ext4, APFS, NTFS); longer robot names are refused.
MAX_FILENAME = 255
#: Largest workspace of the C forward model kept on the stack [doubles, 4 KiB]: a larger one (64 double wheels
#: sensing one spin each: 270 KB) overflowed small stacks (a 32 KiB thread, a microcontroller's task) and is static.
MAX_STACK_WORK = 512


class CodegenError(WmrkitError, ValueError):
    """A code-generation request that cannot be met (unknown language, sensed set, directory, existing file)."""


def identifier(name: str) -> str:
    """A C and Python identifier from a robot name: ``"diff-drive 2" -> "diff_drive_2"``, never a keyword."""
    ident = re.sub(r"\W", "_", name, flags=re.ASCII).strip("_") or "robot"
    if ident[0].isdigit():
        ident = f"robot_{ident}"
    return f"{ident}_" if ident in C_KEYWORDS or keyword.iskeyword(ident) else ident


class _Plan:
    """Everything the printers need: symbols, the constraint matrix, inverse closed form, forward split."""

    def __init__(self, robot: Robot, sensed: Sequence[str] | None) -> None:
        self.robot, self.name = robot, identifier(robot.name)
        self.beta = tuple(sp.Symbol(f"b{i}", real=True) for i in range(len(robot.steer_names)))
        # beta = heading + offset (Robot.beta_of_heading; the offset is beta at heading 0, pi/2 - delta)
        self.offsets = tuple(float(b) for b in robot.beta_of_heading(np.zeros(len(self.beta))))
        self.twist = tuple(sp.Symbol(n, real=True) for n in TWIST_NAMES)
        self.sensed = as_names(sensed, "sensed", error=CodegenError) if sensed is not None else sensed_rates(robot)
        for n in self.sensed:
            if robot.velocity_index(n) < 3:
                raise CodegenError(f"sensed: '{n}' is a body velocity; sensed inputs are wheel joint rates")
        if len(set(self.sensed)) != len(self.sensed) or not self.sensed:
            raise CodegenError(f"sensed: expected distinct wheel rates, got ({', '.join(self.sensed)})")
        self.q = tuple(sp.Symbol(f"q{i}", real=True) for i in range(len(self.sensed)))
        self.a = symbolic_constraint_matrix(robot, self.beta)
        self.sensed_cols = [robot.velocity_index(n) for n in self.sensed]
        self.unknown_cols = [j for j in range(self.a.cols) if j not in self.sensed_cols]
        self._check_forward()
        self.free_steer = robot.free_steering  # a double wheel's steering rate: an input besides the twist
        self.steer_rate = tuple(sp.Symbol(f"s{i}", real=True) for i in range(len(self.free_steer)))
        model = symbolic_model(robot, TWIST_NAMES + self.free_steer, self.beta, gears=False)  # (warned)
        self.inverse_exact = model.exact
        self.rates = model.solved
        self.inverse = [e for e in model.matrix * sp.Matrix(self.twist + self.steer_rate)]

    def _check_forward(self) -> None:
        beta = np.random.default_rng(7).uniform(-math.pi, math.pi, (3, len(self.robot.steer_names)))
        # on the nondimensional robot, as the numeric models decide ranks: raw, a 1 um robot's 1 nm castor was lost
        a = nondimensional(self.robot).constraint_matrix(beta)
        a_na = a[..., self.unknown_cols]
        ranks = matrix_rank(a_na)
        if int(ranks.max()) < len(self.unknown_cols):  # name the rates left free, not every unknown
            free = free_columns(a_na[int(np.argmax(ranks))])
            names = name_list([self.robot.velocity_names[j] for j, f in zip(self.unknown_cols, free, strict=True) if f])
            raise SingularError(f"robot '{self.robot.name}': the sensed rates ({name_list(self.sensed)}) do not "
                                f"determine ({names}); sense more joints (the wheels' 'sensed' field of the "
                                "description, or sensed= in Python)")

    def forward_exprs(self) -> tuple[list[sp.Expr], list[sp.Expr]]:
        """Entries of ``A_na`` (row-major) and of ``b = -A_s q_s``."""
        a_na = self.a[:, self.unknown_cols]
        b = -self.a[:, self.sensed_cols] * sp.Matrix(self.q)
        return list(a_na), list(b)


def write_code(
    robot: Robot,
    lang: Literal["c", "python"],
    directory: str | os.PathLike[str],
    *,
    sensed: Sequence[str] | None = None,
) -> list[Path]:
    """Write the robot's kinematic models as C99 (``NAME_kinematics.h`` + ``.c``) or Python (``.py``).

    `sensed`: wheel-rate names that feed the forward model (default: the robot's sensed rates, see
    :func:`~wmrkit.kinematics.symbolic.sensed_rates`). Returns the written paths. :class:`SingularError` if
    the sensed rates do not determine the twist, or the twist the wheel rates; :class:`CodegenError`, before any
    file is written, if one would replace a folder or a file that is not this robot's generated code.
    """
    if lang not in ("c", "python"):
        raise CodegenError(f"lang: expected 'c' or 'python', got {lang!r}")
    directory = Path(directory)
    if directory.exists() and not directory.is_dir():
        raise CodegenError(f"{directory}: not a directory")
    plan = _Plan(robot, sensed)
    files = _c_files(plan) if lang == "c" else _python_file(plan)
    for filename, text in files:  # every file checked before any is written: no half-written pair
        _check_target(directory, filename, text, robot.name)
    directory.mkdir(parents=True, exist_ok=True)
    paths = []
    for filename, text in files:
        path = directory / filename
        path.write_text(text, encoding="utf-8")
        paths.append(path)
    return paths


def _check_target(directory: Path, filename: str, text: str, robot_name: str) -> None:
    """Refuse to write `filename` over a folder, over a file that is not this robot's generated code (a user's
    file, or another robot's whose name gives the same identifier), or beside a file whose name differs only by
    case (the same header guard and macros; the same file where names ignore case)."""
    path = directory / filename
    if len(filename.encode()) > MAX_FILENAME:
        raise CodegenError(f"robot '{printable(robot_name)[:40]}...': its file name {filename[:40]}... would have "
                           f"{len(filename.encode())} bytes, file systems allow {MAX_FILENAME}; give the robot a "
                           "shorter name")
    if path.is_dir():
        raise CodegenError(f"{path}: is a folder; remove it or choose another directory")
    if path.exists() and _head(path) != text.splitlines()[:2]:  # they name the robot and "generated by wmrkit"
        raise CodegenError(f"{path}: exists and is not wmrkit's code for robot '{printable(robot_name)}' (a user's "
                           "file, another robot's or an older wmrkit's); remove it or choose another directory")
    if directory.is_dir():
        for other in directory.iterdir():
            if other.name != filename and other.name.lower() == filename.lower():
                raise CodegenError(f"{other}: differs from {filename} only by case (same header guard and macros, "
                                   "the same file where names ignore case); remove it or choose another directory")


def _head(path: Path) -> list[str]:
    """The first two lines of an existing file (as text; bytes that are not UTF-8 never match generated code)."""
    with path.open(encoding="utf-8", errors="replace", newline="") as f:
        return [f.readline(10_000).rstrip("\n") for _ in range(2)]


def _c_numbers(e: sp.Expr) -> sp.Expr:
    table: dict[sp.Expr, sp.Expr] = {sp.pi: sp.Float(math.pi, 20)}
    for n in e.atoms(sp.Rational):
        if abs(n.p) > 2**31 or abs(n.q) > 2**31:
            table[n] = sp.Float(n, 20)
    return e.xreplace(table)


def _cse(exprs: list[sp.Expr], printer: C99CodePrinter | NumPyPrinter) -> tuple[list[str], list[str]]:
    """Common subexpressions ``t0, t1...`` as ``name = code`` lines, and the reduced expressions, printed."""
    if isinstance(printer, C99CodePrinter):  # C: no M_PI in strict C99, no integer literal beyond 64 bits
        exprs = [_c_numbers(e) for e in exprs]
    replacements, reduced = sp.cse(exprs, symbols=sp.numbered_symbols("t"), optimizations="basic")
    lines = [f"{sym} = {printer.doprint(value)}" for sym, value in replacements]
    return lines, [printer.doprint(e) for e in reduced]


# ---- C ---------------------------------------------------------------------------------------------------
_C_LSTSQ = """\
/* min |A x - b| by Householder QR; A: m x n row-major (m >= n), A and b are overwritten.
 * Returns 0, or -1 if A is rank deficient (what is left of a column once the previous ones are projected out is
 * <= 1e-9 * m (the rows) times its norm, whatever its units: then x is not set).
 * *residual (if not NULL) = |A x - b|. */
static int lstsq(int m, int n, double *a, double *b, double *x, double *residual)
{
    for (int k = 0; k < n; ++k) {
        double norm = 0.0, column = 0.0; /* the reflections keep the column's norm: rows < k hold its R part */
        for (int i = k; i < m; ++i) norm = hypot(norm, a[i * n + k]);
        for (int i = 0; i < k; ++i) column = hypot(column, a[i * n + k]);
        if (norm <= 1e-9 * m * hypot(column, norm)) return -1;
        const double alpha = a[k * n + k] > 0.0 ? -norm : norm;
        a[k * n + k] -= alpha; /* column k below the diagonal is now v = x - alpha e_k */
        double vv = 0.0;
        for (int i = k; i < m; ++i) vv += a[i * n + k] * a[i * n + k];
        for (int j = k + 1; j <= n; ++j) { /* j == n: the right-hand side b */
            double s = 0.0;
            for (int i = k; i < m; ++i) s += a[i * n + k] * (j < n ? a[i * n + j] : b[i]);
            s *= 2.0 / vv;
            for (int i = k; i < m; ++i) {
                if (j < n) a[i * n + j] -= s * a[i * n + k]; else b[i] -= s * a[i * n + k];
            }
        }
        a[k * n + k] = alpha; /* R_kk */
    }
    for (int k = n - 1; k >= 0; --k) {
        double s = b[k];
        for (int j = k + 1; j < n; ++j) s -= a[k * n + j] * x[j];
        x[k] = s / a[k * n + k];
    }
    if (residual) {
        double r = 0.0;
        for (int i = n; i < m; ++i) r = hypot(r, b[i]);
        *residual = r;
    }
    return 0;
}
"""


def _c_printer() -> C99CodePrinter:
    return C99CodePrinter({"math_macros": {}})


def _c_body(plan: _Plan, exprs: list[sp.Expr], targets: list[str], comments: list[str] | None = None) -> str:
    temps, reduced = _cse(exprs, _c_printer())
    lines = [f"    const double {t};" for t in temps]
    for k, (target, code) in enumerate(zip(targets, reduced, strict=True)):
        note = f" /* {_c_comment(comments[k])} */" if comments else ""
        lines.append(f"    {target} = {code};{note}")
    return "\n".join(lines)


def _c_unpack(plan: _Plan, sensed: bool = False, twist: bool = False) -> str:
    """Named locals for the inputs, each cast to void once: a model need not use every input."""
    lines, names = [], []
    if twist:
        lines.append("    const double vx = twist[0], vy = twist[1], omega = twist[2];")
        names += ["vx", "vy", "omega"]
        lines += [f"    const double s{i} = steer_rate[{i}]; /* {_c_comment(n)} */"
                  for i, n in enumerate(plan.free_steer)]
        names += [f"s{i}" for i in range(len(plan.free_steer))]
    if sensed:
        lines += [f"    const double q{i} = sensed[{i}]; /* {_c_comment(n)} */" for i, n in enumerate(plan.sensed)]
        names += [f"q{i}" for i in range(len(plan.sensed))]
    lines += [f"    const double b{i} = heading[{i}] + {off!r}; /* {_c_comment(n)}: beta = heading + pi/2 - delta */"
              for i, (n, off) in enumerate(zip(plan.robot.steer_names, plan.offsets, strict=True))]
    names += [f"b{i}" for i in range(len(plan.beta))] or ["heading"]
    lines.append("    " + " ".join(f"(void){n};" for n in names))
    return "\n".join(lines)


def _c_files(plan: _Plan) -> list[tuple[str, str]]:
    r, n, p = plan.robot, plan.name, plan.name.upper()
    beta_param = f"const double heading[{p}_N_STEER]" if plan.beta else "const double *heading"
    rows, na = plan.a.rows, len(plan.unknown_cols)
    sizes = {"N_STEER": len(plan.beta), "N_RATES": len(plan.rates), "N_SENSED": len(plan.sensed),
             "N_ROWS": rows, "N_VEL": plan.a.cols, "N_UNKNOWN": na, "N_WORK": rows * na + rows + na}
    on_stack = sizes["N_WORK"] <= MAX_STACK_WORK
    steer_param = ""
    if plan.free_steer:  # double wheels: their steering rates are inputs of the inverse model
        sizes["N_FREE_STEER"] = len(plan.free_steer)
        steer_param = f"const double steer_rate[{p}_N_FREE_STEER], "
    protos = [
        f"void {n}_constraint({beta_param}, double a[{p}_N_ROWS * {p}_N_VEL]);",
        f"void {n}_inverse(const double twist[3], {steer_param}{beta_param}, double rates[{p}_N_RATES]);",
        f"int {n}_forward(const double sensed[{p}_N_SENSED], {beta_param}, double twist[3], double *residual);",
        f"int {n}_forward_work(const double sensed[{p}_N_SENSED], {beta_param}, double twist[3], double *residual, "
        f"double work[{p}_N_WORK]);",
    ]
    work_bytes = 8 * sizes["N_WORK"]
    header = "\n".join([
        f"/* {n}_kinematics.h: no-slip kinematic models of robot '{_c_comment(r.name)}' (L. Gracia's thesis, ch. 4).",
        " * Generated by wmrkit; do not edit, regenerate with `wmrkit kinematics ROBOT --codegen c DIR`.",
        " * C99, needs only <math.h> (link with -lm). SI units; robot frame x forward, y left.",
        " *",
        " * Array orders:",
        " *   twist[3]  = (vx [m/s], vy [m/s], omega [rad/s]), body twist in the robot frame",
        *([_c_list(f" *   steer_rate[{p}_N_FREE_STEER] = steering rates of the double wheels [rad/s] (an input: "
                   "no twist determines them)", plan.free_steer)] if plan.free_steer else []),
        _c_list(f" *   heading[{p}_N_STEER] = steering headings [rad], 0 = rolling straight ahead, counter-clockwise "
                "positive", r.steer_names),
        _c_list(f" *   rates[{p}_N_RATES] = wheel joint rates [rad/s]", plan.rates),
        _c_list(f" *   sensed[{p}_N_SENSED] = sensed joint rates [rad/s]", plan.sensed),
        _c_list(f" *   a[{p}_N_ROWS * {p}_N_VEL] = slip matrix A (3.22), row-major, slip = A q; columns",
                r.velocity_names),
        " *",
        f" * {n}_constraint: A (3.22) at the headings, two rows per contact point (along and across the roller axis).",
        f" * {n}_inverse: wheel rates for a twist{' and steering rates' if plan.free_steer else ''} "
        f"({'exact' if plan.inverse_exact else 'least squares per wheel'},"
        " thesis 4.11).",
        f" * {n}_forward: least-squares twist from the sensed rates (4.11); *residual = |A q| [m/s], the slip",
        " *   (may be NULL). Returns 0, or -1 if the sensed rates do not determine the twist at these headings or an",
        " *   input is not finite (NaN, inf); then twist and *residual are NaN.",
        f" *   Its workspace ({work_bytes} bytes) is "
        + ("on the stack (reentrant)." if on_stack else
           f"a static buffer (not reentrant: over {8 * MAX_STACK_WORK} bytes, too many for small stacks)."),
        f" * {n}_forward_work: {n}_forward in the caller's workspace, work[{p}_N_WORK] (reentrant: one per thread).",
        " */",
        f"#ifndef {p}_KINEMATICS_H", f"#define {p}_KINEMATICS_H", "",
        *[f"#define {p}_{k} {v}" for k, v in sizes.items()], "",
        "#ifdef __cplusplus", 'extern "C" {', "#endif", "", *protos, "", "#ifdef __cplusplus", "}", "#endif", "",
        f"#endif /* {p}_KINEMATICS_H */", "",
    ])
    a_targets = [f"a[{i * plan.a.cols + j}]" for i in range(plan.a.rows) for j in range(plan.a.cols)]
    a_na, b = plan.forward_exprs()
    fw_targets = [f"a[{k}]" for k in range(len(a_na))] + [f"b[{i}]" for i in range(len(b))]
    source = "\n".join([
        f"/* {n}_kinematics.c: generated by wmrkit from robot '{_c_comment(r.name)}'; see {n}_kinematics.h. */",
        "#include <math.h>", f'#include "{n}_kinematics.h"', "", _C_LSTSQ,
        protos[0][:-1], "{", _c_unpack(plan), _c_body(plan, list(plan.a), a_targets), "}", "",
        protos[1][:-1], "{", _c_unpack(plan, twist=True),
        _c_body(plan, plan.inverse, [f"rates[{i}]" for i in range(len(plan.rates))], list(plan.rates)), "}", "",
        protos[2][:-1], "{",
        f"    {'' if on_stack else 'static '}double work[{p}_N_WORK];"
        f"{'' if on_stack else f' /* {work_bytes} bytes: too many for small stacks; not reentrant */'}",
        f"    return {n}_forward_work(sensed, heading, twist, residual, work);", "}", "",
        protos[3][:-1], "{",
        f"    double *a = work, *b = work + {p}_N_ROWS * {p}_N_UNKNOWN, *x = b + {p}_N_ROWS;",
        _c_unpack(plan, sensed=True),
        f"    /* unknowns x: {_c_comment(', '.join(r.velocity_names[j] for j in plan.unknown_cols))} */",
        _c_body(plan, a_na + b, fw_targets),
        f"    int status = lstsq({p}_N_ROWS, {na}, a, b, x, residual);",
        f"    for (int i = 0; status == 0 && i < {na}; ++i) if (!isfinite(x[i])) status = -1; /* NaN or inf input */",
        "    for (int i = 0; i < 3; ++i) twist[i] = status == 0 ? x[i] : (double)NAN;",
        "    if (status != 0 && residual) *residual = NAN;",
        "    return status;", "}", "",
    ])
    return [(f"{n}_kinematics.h", header), (f"{n}_kinematics.c", source)]


def _c_comment(text: str) -> str:
    """`text` inside a C comment: printable, no ``*/`` or ``/*``, and no trigraph (``??/`` ends a line in C99)."""
    return re.sub(r"\?(?=\?)", "?\\\\", printable(text)).replace("*/", "* /").replace("/*", "/ *")


def _c_list(title: str, names: Sequence[str]) -> str:
    items = ", ".join(f"{i} {_c_comment(name)}" for i, name in enumerate(names)) or "(none)"
    return f"{title}: {items}"


# ---- Python ----------------------------------------------------------------------------------------------
def _py_body(exprs: list[sp.Expr], targets: list[str]) -> str:
    temps, reduced = _cse(exprs, NumPyPrinter())
    lines = [f"    {t}" for t in temps]
    lines += [f"    {target} = {code}" for target, code in zip(targets, reduced, strict=True)]
    return "\n".join(lines)


def _python_file(plan: _Plan) -> list[tuple[str, str]]:
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

import numpy

STEER_NAMES = {tuple(r.steer_names)!r}
RATE_NAMES = {tuple(plan.rates)!r}
SENSED_NAMES = {tuple(plan.sensed)!r}
FREE_STEER_NAMES = {tuple(plan.free_steer)!r}
VELOCITY_NAMES = {tuple(r.velocity_names)!r}
HEADING_DESCRIBED = {tuple(float(h) for h in r.heading)!r}
_BETA_OFFSET = {tuple(plan.offsets)!r}  # the thesis's beta = heading + pi/2 - delta
_SENSED_COLUMNS = {list(plan.sensed_cols)!r}
_UNKNOWN_COLUMNS = {list(plan.unknown_cols)!r}


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


{inverse_def}


def forward_with_residual(sensed, heading=None):
    """Least-squares twist (4.11) and slip residual ``|A q|`` [m/s].

    ``(..., {len(plan.sensed)}) -> (..., 3), (...)``. Both are NaN where the sensed rates do not determine the twist
    at those headings (the smallest singular value of the unknowns' columns, each scaled to norm 1 whatever its
    units, <= 1e-9 rows) or an input is not finite, as the C code's -1.
    """
    sensed = _vectors(sensed, {len(plan.sensed)}, "sensed")
    a = constraint_matrix(heading)
    finite = numpy.isfinite(a).all(axis=(-2, -1)) & numpy.isfinite(sensed).all(axis=-1)
    a = numpy.where(finite[..., None, None], a, 0.0)
    sensed = numpy.where(finite[..., None], sensed, 0.0)
    a_na = a[..., _UNKNOWN_COLUMNS]
    rhs = -(a[..., _SENSED_COLUMNS] @ sensed[..., None])
    norms = numpy.linalg.norm(a_na, axis=-2, keepdims=True)  # columns of norm 1: m/s and m alike
    unit = a_na / numpy.where(norms > 0, norms, 1.0)
    x = (numpy.linalg.pinv(unit) @ rhs) / numpy.where(norms > 0, norms, 1.0).swapaxes(-1, -2)
    residual = numpy.linalg.norm((a_na @ x - rhs)[..., 0], axis=-1)
    ok = finite & (numpy.linalg.svd(unit, compute_uv=False)[..., -1] > 1e-9 * a_na.shape[-2])
    return numpy.where(ok[..., None], x[..., :3, 0], numpy.nan), numpy.where(ok, residual, numpy.nan)


def forward(sensed, heading=None):
    """Least-squares body twist from sensed rates (4.11): ``(..., {len(plan.sensed)}) -> (..., 3)``."""
    return forward_with_residual(sensed, heading)[0]
'''
    return [(f"{plan.name}_kinematics.py", text)]
