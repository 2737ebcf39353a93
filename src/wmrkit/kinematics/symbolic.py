"""Closed-form (symbolic) no-slip kinematic models with sympy: the methods of thesis ch. 4 done exactly.

The constraint matrix comes from the same kernels as the numeric one: :func:`wmrkit.wheels.slip_row_entries`
with ``sin=sympy.sin, cos=sympy.cos`` over each wheel's contact elements (``Wheel.elements()`` and their
``rate_map``), so the closed forms cannot drift from :meth:`wmrkit.Robot.constraint_matrix` (roller frame, 3.6).
Steering angles are symbols ``beta_<wheel>``; geometry is either the robot's numbers made exact (0.45 -> 9/20,
90 deg -> pi/2) or symbols (``l_<wheel>``, ``alpha_<wheel>``, ``r_<wheel>``...) so that the thesis's general
formulas appear. The ranks method (4.9)-(4.11) then runs fraction-free over polynomial rings in sin/cos of the
steering angles (sympy ``DomainMatrix``, see ``_exact_linalg``), and every result is reduced modulo
``sin^2 + cos^2 = 1``: exact, and the tricycle tables (4.80)-(4.82) take a fraction of a second.
The symbols and the checks of the users' inputs live in ``_symbolic_inputs`` (re-exported here).
"""

from __future__ import annotations

import functools
import itertools
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import sympy as sp

from .._shapes import as_names
from ..couplings import coupling_words
from ..errors import SingularError, WmrkitError, name_list
from ..robot import TWIST_NAMES, Robot
from ._exact_linalg import _components, closed_form, generic_ranks
from ._symbolic_held import held_gears, substituted_form
from ._symbolic_inputs import (  # noqa: F401  (the symbols: public API, re-exported)
    Geometry,
    _geometry_key,
    _steering_values,
    geometry_symbols,
    steering_symbols,
    velocity_symbols,
)
from ._symbolic_matrix import (  # noqa: F401  (exact_number, geometry_fields: re-exported, their first home)
    AssignmentError,
    _nice_number,
    constraint,
    exact_number,
    gear_rows,
    geometry_fields,
)
from .linalg import free_columns, matrix_rank
from .models import generic_inputs

#: Steering angles one least-squares closed form (4.11) may couple by default: its derivation grows about fourfold
#: per angle (castors: 3 take seconds, 4 about 20 s, 5 a minute and a half, 6 several minutes, 12 hours).
MAX_LSQ_ANGLES = 4


class ClosedFormTooLargeError(WmrkitError, ValueError):
    """A least-squares closed form that couples more steering angles than allowed (it would take too long)."""


class GearedLeastSquaresError(SingularError):
    """A set that is not assignable on the motions a robot's gears allow: no exact closed form holds the gears."""


def symbolic_constraint_matrix(
    robot: Robot, beta: Sequence[sp.Expr | float] | None = None, *, geometry: Geometry = "numeric",
    heading: Sequence[sp.Expr | float] | None = None,
) -> sp.ImmutableMatrix:
    """The slip matrix ``A`` of eq. (3.22) in closed form, roller frame (3.6); columns ``robot.velocity_names``.

    ``(2 * n_contacts, 3 + n_rates)``, the same matrix as :meth:`wmrkit.Robot.constraint_matrix` (built from the
    same kernel). `beta`: one angle per ``robot.steer_names`` (symbols ``beta_<wheel>`` by default; numbers are
    made exact), or `heading`: the users' steering angles (0 = rolling straight ahead), turned into
    ``beta = heading + pi/2 - delta``. `geometry`: ``"numeric"`` (the robot's numbers, exact), ``"symbolic"``
    (every field a symbol, see :func:`geometry_symbols`) or a mapping ``{"wheel.field": expression}`` for chosen
    fields only.
    """
    key = _geometry_key(robot, geometry)
    return constraint(robot, _steering_values(robot, beta, heading, key), key)


# ---- models ----------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class SymbolicModel:
    """A closed-form no-slip solution ``q_na = matrix @ q_a`` for one assigned set (thesis §4.2-4.3, §4.5).

    ``assigned``/``solved``: velocity names (``robot.velocity_names``) of ``q_a`` and ``q_na``; ``matrix``:
    ``(n_solved, n_assigned)``. ``exact``: the set is assignable (4.10) and ``matrix`` is the unique no-slip
    solution (4.5)/(4.11); otherwise it is the least-squares (extended) solution (4.11)/(4.82) and
    ``residual @ q_a`` (``(2 n_contacts, n_assigned)``, roller frame, m/s) is the slip it leaves (4.16).
    ``steering``: the steering angles used (symbols or exact values); ``rank``/``mobility``: generic rank of A
    and m = k - rank (4.3).
    """

    robot_name: str
    assigned: tuple[str, ...]
    solved: tuple[str, ...]
    matrix: sp.ImmutableMatrix
    residual: sp.ImmutableMatrix
    exact: bool
    steering: tuple[sp.Expr, ...]
    rank: int
    mobility: int

    def solution(self) -> sp.ImmutableMatrix:
        """``q_na`` as expressions of the assigned velocities' symbols (named as in :func:`velocity_symbols`)."""
        q_a = sp.Matrix([sp.Symbol(n, real=True) for n in self.assigned])
        return sp.ImmutableMatrix(self.matrix * q_a)

    def substitute(self, values: Mapping[sp.Symbol, sp.Expr]) -> sp.ImmutableMatrix:
        """The solution with `values` substituted (e.g. beta of (4.83) into (4.82)) and simplified: (4.84)."""
        for key, value in values.items():
            if not isinstance(key, sp.Symbol) or not isinstance(value, sp.Basic | int | float):
                raise AssignmentError(f"substitute: expected sympy symbols mapped to expressions, got {key!r}")
        return sp.ImmutableMatrix(self.solution().xreplace(dict(values)).applyfunc(sp.simplify))


def symbolic_model(
    robot: Robot,
    assigned: Sequence[str],
    beta: Sequence[sp.Expr | float] | None = None,
    *,
    geometry: Geometry = "numeric",
    max_lsq_angles: int = MAX_LSQ_ANGLES,
    heading: Sequence[sp.Expr | float] | None = None,
    gears: bool = True,
) -> SymbolicModel:
    """Closed-form solution of ``A q = 0`` for the velocities not in `assigned`, thesis (4.5)/(4.9)-(4.11).

    Exact when the set is assignable, ``rank A_na = rank A`` (4.10): a maximal independent set of rows is solved
    exactly (the ranks / null-space method). With more assigned velocities than the mobility m (the extended
    solution of §4.5) it is the least-squares solution ``-(A_na^T A_na)^-1 A_na^T A_a`` (4.11)/(4.82), as long
    as ``A_na`` keeps full column rank; otherwise :class:`SingularError`. Ranks are generic: evaluated at random
    values of every symbol. `beta`, `heading`, `geometry`: as in :func:`symbolic_constraint_matrix`. A
    least-squares form whose unknowns couple more than `max_lsq_angles` steering symbols (:data:`MAX_LSQ_ANGLES`)
    is refused at once with :class:`ClosedFormTooLargeError` (the derivation grows about fourfold per angle).
    `gears`: the robot's ``gear`` couplings are held, rows ``q_i / ratio_i - q_j / ratio_j`` under ``A`` (as
    :mod:`.models` does; ``rank``/``mobility`` count them); a least-squares form of a geared robot is refused
    (:class:`SingularError`: its fit would weigh the gear rows, rad/s, against slip, m/s). False: the wheels' alone.
    """
    names = as_names(assigned, "assigned", error=AssignmentError)
    for n in names:
        robot.velocity_index(n)
        if names.count(n) > 1:
            raise AssignmentError(f"assigned: velocity '{n}' listed twice")
    if isinstance(max_lsq_angles, bool) or not isinstance(max_lsq_angles, int) or max_lsq_angles < 0:
        raise AssignmentError(f"max_lsq_angles: expected a whole number >= 0, got {max_lsq_angles!r}")
    key = _geometry_key(robot, geometry)
    return _solve(robot, names, _steering_values(robot, beta, heading, key), key, max_lsq_angles, bool(gears))


@dataclass(frozen=True)
class _Ranked:
    """The system of one assignment (``A`` with the held gear rows under it) and its generic ranks."""

    a: sp.ImmutableMatrix
    a_idx: list[int]
    na_idx: list[int]
    points: list
    values: list
    rank: int
    rank_na: int


@functools.lru_cache(maxsize=128)
def _ranked(robot: Robot, assigned: tuple[str, ...], beta: tuple[sp.Expr, ...], geometry: tuple,
            gears: bool) -> _Ranked:
    """The ranks of :func:`_solve`'s system, without deriving its closed form; :class:`SingularError` when the
    assigned set leaves unknowns free."""
    a = constraint(robot, beta, geometry)
    held = gear_rows(robot) if gears else sp.ImmutableMatrix(0, a.cols, [])
    a = sp.ImmutableMatrix(a.col_join(held)) if held.rows else a
    a_idx = [robot.velocity_index(n) for n in assigned]
    na_idx = [j for j in range(a.cols) if j not in a_idx]
    points, values, rank, ranks_na = generic_ranks(a, na_idx)
    rank_na = max(ranks_na)
    solved = tuple(robot.velocity_names[j] for j in na_idx)
    if rank_na < len(na_idx):  # name the velocities left free, not every unknown
        free = free_columns(values[ranks_na.index(rank_na)][:, na_idx])
        raise SingularError(
            f"robot '{robot.name}': assigning ({name_list(assigned) or 'nothing'}) does not determine "
            f"({name_list([n for n, f in zip(solved, free, strict=True) if f])}): rank A_na = {rank_na} < "
            f"{len(na_idx)} unknowns (mobility m = {a.cols - rank})"
        )
    return _Ranked(a, a_idx, na_idx, points, values, rank, rank_na)


@functools.lru_cache(maxsize=128)
def _solve(robot: Robot, assigned: tuple[str, ...], beta: tuple[sp.Expr, ...], geometry: tuple,
           max_lsq_angles: int, gears: bool) -> SymbolicModel:
    """The closed form of :func:`symbolic_model`; a least-squares one of a geared robot is refused before its
    derivation (:class:`GearedLeastSquaresError`), which ``--symbolic`` then made in vain."""
    r = _ranked(robot, assigned, beta, geometry, gears)
    a, a_idx, na_idx, points, values, rank = r.a, r.a_idx, r.na_idx, r.points, r.values, r.rank
    solved = tuple(robot.velocity_names[j] for j in na_idx)
    exact = r.rank_na == rank
    coupled = [] if exact else _coupled_angles(a, na_idx, beta)
    if len(coupled) > max_lsq_angles:
        raise ClosedFormTooLargeError(
            f"robot '{robot.name}': the least-squares closed form for ({', '.join(assigned) or 'nothing'}) couples "
            f"{len(coupled)} steering angles ({', '.join(coupled)}), more than max_lsq_angles = {max_lsq_angles}: "
            "it would take minutes to hours; use the numeric models ('wmrkit kinematics') or the generated code")
    if not exact and gears and gear_rows(robot).rows:
        raise GearedLeastSquaresError(
            f"robot '{robot.name}': ({name_list(assigned) or 'nothing'}) is not an assignable set of the motions its "
            f"gears allow (mobility m = {a.cols - rank}): no exact closed form, and a least-squares one would "
            "weigh the gear rows against slip; gears=False gives the wheels' least squares, 'wmrkit ik' holds the gear")
    m, residual = closed_form(a, na_idx, a_idx, exact, values, points)
    return SymbolicModel(
        robot_name=robot.name, assigned=assigned, solved=solved,
        matrix=sp.ImmutableMatrix(m), residual=sp.ImmutableMatrix(residual),
        exact=exact, steering=beta, rank=rank, mobility=a.cols - rank,
    )


def _coupled_angles(a: sp.MatrixBase, na_idx: list[int], beta: tuple[sp.Expr, ...]) -> list[str]:
    """Names of the steering symbols in the rows of the largest block of unknowns solved together (the cost of
    its least-squares closed form)."""
    steering = set().union(*(b.free_symbols for b in beta))
    blocks = [set().union(*(a.row(i).free_symbols for i in rows)) & steering for rows, _ in _components(a[:, na_idx])]
    return sorted(s.name for s in max(blocks, key=len, default=set()))


# ---- default assignments and printing --------------------------------------------------------------------
def sensed_rates(robot: Robot) -> tuple[str, ...]:
    """Inputs of the direct model: the sensed joint rates (``wheel.joint`` columns of A).

    Sensed steering angles of centred wheels are configuration (``beta``), not rates. With no sensed rates
    declared, every wheel joint rate (spins, castor steering; never a free roller).
    """
    columns = set(robot.velocity_names)
    sensed = tuple(n for n in robot.sensed if n in columns)
    return sensed or tuple(f"{w.name}.{j}" for w in robot.wheels for j in w.kind.rates if j in w.kind.joints)


def twist_assignment(robot: Robot) -> tuple[str, ...]:
    """Inputs of the inverse model: the first assignable (4.10) subset of ``(vx, vy, omega)`` with m members (less
    the double wheels' steering rates no twist determines, always assigned: the numeric inverse model's at generic
    steering, :func:`~.models.generic_inputs`), else the whole twist (wheel rates by least squares, as a controller
    computes them); then those steering rates."""
    free, dof = generic_inputs(robot)
    m = dof - len(free)
    for subset in itertools.combinations(TWIST_NAMES, m) if 0 < m <= 3 else ():
        try:
            if symbolic_model(robot, subset + free).exact:
                return subset + free
        except (SingularError, ClosedFormTooLargeError):  # not exact: the next subset
            continue
    return TWIST_NAMES + free


def held_model(robot: Robot, names: Sequence[str]) -> tuple[SymbolicModel, tuple[str, ...]]:
    """The closed form of `names` holding the robot's gears, and the gears it does not hold: none for the exact one;
    when none is exact (:class:`GearedLeastSquaresError`), the least squares holding the gears that set a double
    wheel's steering rate not in `names` (:func:`~._symbolic_held.held_gears`, by substitution), else the wheels'."""
    try:
        return symbolic_model(robot, names), ()
    except GearedLeastSquaresError:
        pass
    held = held_gears(robot, names)
    model = _substituted_model(robot, tuple(names), held) if held else symbolic_model(robot, names, gears=False)
    return model, tuple(c.channel_name for c in robot.couplings if c.kind == "gear" and c not in held)


@functools.lru_cache(maxsize=32)
def _substituted_model(robot: Robot, names: tuple[str, ...], held: tuple) -> SymbolicModel:
    """:func:`~._symbolic_held.substituted_form` at symbolic steering, the robot's geometry; a least-squares form
    coupling more than :data:`MAX_LSQ_ANGLES` steering angles is refused before its derivation."""
    key = _geometry_key(robot, "numeric")
    beta = _steering_values(robot, None, None, key)
    a = constraint(robot, beta, key)

    def guard(system: sp.Matrix, na: list[int], exact: bool) -> None:
        coupled = [] if exact else _coupled_angles(system, na, beta)
        if len(coupled) > MAX_LSQ_ANGLES:
            raise ClosedFormTooLargeError(
                f"robot '{robot.name}': the least-squares closed form for ({', '.join(names)}) couples "
                f"{len(coupled)} steering angles ({', '.join(coupled)}), more than max_lsq_angles = "
                f"{MAX_LSQ_ANGLES}: it would take minutes to hours; use the numeric models or the generated code")

    solved, matrix, residual, exact = substituted_form(robot, names, a, held, guard)
    dof = generic_inputs(robot)[1]
    return SymbolicModel(robot_name=robot.name, assigned=names, solved=solved, matrix=sp.ImmutableMatrix(matrix),
                         residual=sp.ImmutableMatrix(residual), exact=exact, steering=beta, rank=a.cols - dof,
                         mobility=dof)


def default_sets(robot: Robot) -> list[tuple[str, tuple[str, ...]]]:
    """The titled sets :func:`format_symbolic` shows by default: the direct (sensed) and the inverse model's; nothing
    assigned for a robot that :func:`cannot_move` (its exact form: every velocity is zero)."""
    if cannot_move(robot):
        return [("direct model (sensed)", ()), ("inverse model", ())]
    return [("direct model (sensed)", sensed_rates(robot)), ("inverse model", twist_assignment(robot))]


def cannot_move(robot: Robot) -> bool:
    """Whether every velocity is zero at every steering, gears held: m = 0 generically, and the rows that do not
    depend on the steering (wheels that do not steer, gears) hold the twist at zero, ``rank R = 3 + rank R_joints``
    (4.10); a steered wheel's rates are then zero too (a double wheel's self-motion would make m > 0 generically).
    Generic m = 0 alone does not say it: a car whose front wheels steer independently moves once they are
    coordinated, and its least-squares forms are the extended solutions (4.82)."""
    key = _geometry_key(robot, "numeric")
    try:
        ranked = _ranked(robot, (), _steering_values(robot, None, None, key), key, True)
    except SingularError:  # assigning nothing leaves velocities free: m > 0
        return False
    steering = set(steering_symbols(robot))
    rows = [i for i in range(ranked.a.rows) if not ranked.a.row(i).free_symbols & steering]
    fixed = ranked.values[0][rows]
    return bool(rows) and int(matrix_rank(fixed)) == 3 + int(matrix_rank(fixed[:, 3:]))


def unheld_gears(robot: Robot) -> list[str]:
    """One sentence per default closed form (:func:`default_sets`) that does not hold the robot's gears (the wheels'
    least squares, :func:`held_model`); a form not determined or too large says so in its own line, not here."""
    gears = tuple(c.channel_name for c in robot.couplings if c.kind == "gear")
    out = []
    for title, names in default_sets(robot) if gears else ():
        try:
            unheld = held_model(robot, names)[1]
        except (SingularError, ClosedFormTooLargeError):
            continue
        alone = "is of the wheels alone, not holding" if unheld == gears else "does not hold"
        if unheld:
            words = name_list([coupling_words(robot.couplings, g) for g in unheld])
            out.append(f"the closed-form {title} ({', '.join(names)}) {alone} {words}: it may give rates "
                       "they forbid (check a twist with 'wmrkit ik')")
    return out


def format_symbolic(robot: Robot, assigned: Sequence[str] | None = None, *, latex: bool = False) -> str:
    """The closed forms of the direct (sensed) and inverse models of `robot`, or of one `assigned` set.

    Plain text (``name = expression``, velocity names as in ``robot.velocity_names``, steering angles
    ``beta_<wheel>`` [rad], geometry exact from the robot's numbers), or LaTeX ``aligned`` blocks. Each model
    says whether it is exact (4.5)/(4.11) or least squares (4.11)/(4.82), whose residual ``A q`` is slip, and,
    on a robot with a ``gear``, whether it holds the gears (:func:`held_model`).
    """
    sets = [("model", as_names(assigned, "assigned", error=AssignmentError))] if assigned is not None else (
        default_sets(robot))
    comment = "% " if latex else ""
    lines = [f"{comment}{robot.name}: no-slip kinematic models in closed form (thesis ch. 4)",
             f"{comment}  velocities: {', '.join(robot.velocity_names)}",
             f"{comment}  steering [rad]: {_steering_note(robot)}; geometry: the robot's numbers, exact (m, rad)"]
    gears = [c.channel_name for c in robot.couplings if c.kind == "gear"]
    if gears:
        named = ", ".join(coupling_words(robot.couplings, g, short=True) for g in gears)
        lines.append(f"{comment}  gears: {named}, q_j = ratio_j * u (rows q_i/ratio_i - q_j/ratio_j = 0 "
                     "under A): held by every form below that does not say otherwise")
    for title, names in sets:
        lines.append("")
        lines.append(f"{comment}{title}, assigned: {', '.join(names) or 'nothing'}")
        try:
            model, unheld = held_model(robot, names)
        except SingularError as err:
            lines.append(f"{comment}  not determined: {err}")
            continue
        except ClosedFormTooLargeError as err:
            lines.append(f"{comment}  not derived: {err}")
            continue
        if model.exact and not names and cannot_move(robot):
            how = (f"exact (4.5)/(4.11): the robot cannot move (m = 0 at every steering, rank A = {model.rank}): every "
                   "velocity is zero")
        elif model.exact:
            how = f"exact (4.5)/(4.11): assignable set, generic rank A = {model.rank}, mobility m = {model.mobility}"
        else:
            how = (f"least squares (4.11)/(4.82): {len(names)} assigned for mobility m = {model.mobility}; "
                   "a residual A q != 0 is slip")
        if unheld and len(unheld) == len(gears):
            how += "; of the wheels alone, the gears not held (no exact form holds them: check with 'wmrkit ik')"
        elif unheld:
            how += (f"; holding the gears that set double wheels' steering rates, not "
                    f"{name_list([coupling_words(robot.couplings, g) for g in unheld])} (no exact "
                    "form holds them: check with 'wmrkit ik')")
        lines.append(f"{comment}  {how}")
        lines += _latex_block(model) if latex else [f"    {n} = {_linear_form(model, i)}" for i, n in
                                                    enumerate(model.solved)]
    if latex:  # a Python-built name with a line break would end its comment line
        lines = [printable(line) if line.startswith(comment) else line for line in lines]
    return "\n".join(lines)


def _steering_note(robot: Robot) -> str:
    """``beta_<wheel> = heading_<wheel> + offset`` per steering wheel: the thesis's angle of the closed forms in
    terms of the users' heading (``beta = heading + pi/2 - delta``, :meth:`Robot.beta_of_heading`)."""
    if not robot.steer_names:
        return "none"
    offsets = robot.beta_of_heading([0.0] * len(robot.steer_names)).tolist()
    terms = []
    for beta, name, offset in zip(steering_symbols(robot), robot.steer_names, offsets, strict=True):
        exact = _nice_number(offset, "angle")
        heading = sp.Symbol(f"heading_{name}") + (sp.Float(offset, 15) if exact is None else exact)
        terms.append(f"{beta} = {sp.sstr(heading)}")
    return (", ".join(terms) + " (the thesis's axle angle; heading 0 = rolling straight ahead, counter-clockwise "
            "positive)")


def _linear_form(model: SymbolicModel, i: int, names: Mapping[str, str] | None = None) -> str:
    """Row i of ``q_na = M q_a`` as ``(c1)*q1 + (c2)*q2``: text, or LaTeX when `names` maps symbols to LaTeX."""
    terms = [(c, n) for c, n in zip(model.matrix.row(i), model.assigned, strict=True) if c != 0]
    if not terms:
        return "0"
    if names is None:
        parts = [n if c == 1 else f"-{n}" if c == -1 else f"{c}*{n}" if c.is_Number else f"({sp.sstr(c)})*{n}"
                 for c, n in terms]
    else:
        symbols = {s: names.get(s.name, sp.latex(s)) for c, _ in terms for s in c.free_symbols}
        parts = [names[n] if c == 1 else f"-{names[n]}" if c == -1 else f"{sp.latex(c)} {names[n]}" if c.is_Number
                 else rf"\left({sp.latex(c, symbol_names=symbols)}\right) {names[n]}" for c, n in terms]
    return " + ".join(parts).replace("+ -", "- ")


#: LaTeX's special characters in a name, as math-mode text (a Python-built wheel may be called 'l%' or 'a&b': '%'
#: commented the rest of the row out, '&' added an alignment column)
_LATEX_SPECIAL = {"\\": r"\backslash{}", "{": r"\{", "}": r"\}", "$": r"\$", "&": r"\&", "#": r"\#", "%": r"\%",
                  "_": r"\_", "^": r"\hat{}", "~": r"\sim{}"}


def printable(text: str) -> str:
    """`text` on one printable line: line breaks, control and format characters and lone surrogates escaped as in a
    Python string (``"a\\nb"``), so that a name can neither end a comment nor break the encoding."""
    return "".join(c if c.isprintable() else repr(c)[1:-1] for c in text)


def _latex_text(text: str) -> str:
    """`text` inside ``\\mathrm{}``: printable, LaTeX's special characters escaped."""
    return "".join(_LATEX_SPECIAL.get(c, c) for c in printable(text))


def latex_name(name: str) -> str:
    """LaTeX for a velocity or steering name: ``vx -> v_x``, ``left.spin -> \\dot{\\varphi}_{\\mathrm{left}}``."""
    twist = {"vx": "v_x", "vy": "v_y", "omega": r"\omega"}
    if name in twist:
        return twist[name]
    if name.startswith("beta_"):
        return r"\beta_{\mathrm{" + _latex_text(name[5:]) + "}}"
    wheel, _, joint = name.rpartition(".")
    wheel = r"\mathrm{" + _latex_text(wheel) + "}"
    if joint == "steer":
        return rf"\dot{{\beta}}_{{{wheel}}}"
    sub = {"roller": "r,", "spin": ""}.get(joint, f"{joint[4:]},")  # spin1 -> phi_{1,wheel}
    return rf"\dot{{\varphi}}_{{{sub}{wheel}}}"


def _latex_block(model: SymbolicModel) -> list[str]:
    names = {n: latex_name(n) for n in (*model.assigned, *model.solved)}
    names.update({str(s): latex_name(str(s)) for e in model.steering for s in e.free_symbols})
    rows = [f"  {names[n]} &= {_linear_form(model, i, names)}" for i, n in enumerate(model.solved)]
    return [r"\begin{aligned}", " \\\\\n".join(rows), r"\end{aligned}"]
