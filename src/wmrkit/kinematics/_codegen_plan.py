"""The plan of generated code (:mod:`wmrkit.kinematics.codegen`): symbols, the constraint matrix (3.22), the inverse
closed form, the forward model's unknowns with the robot's gears held, and the common-subexpression printer."""

from __future__ import annotations

import keyword
import math
import re
from collections.abc import Sequence

import numpy as np
import sympy as sp
from sympy.printing.c import C99CodePrinter
from sympy.printing.numpy import NumPyPrinter

from .._shapes import as_names
from ..couplings import gear_free, gear_unknowns
from ..errors import SingularError, WmrkitError, name_list
from ..robot import TWIST_NAMES, Robot
from ._symbolic_held import combine, held_gears, substituted_form
from .gear_check import gear_table, steer_gears
from .linalg import centroid, characteristic_length, free_columns, matrix_rank, nondimensional
from .linkage_check import _plan as linkage_plan
from .models import generic_inputs
from .symbolic import sensed_rates, symbolic_constraint_matrix, symbolic_model

C_KEYWORDS = frozenset(
    "auto break case char const continue default do double else enum extern float for goto if inline int long "
    "register restrict return short signed sizeof static struct switch typedef union unsigned void volatile while "
    "_Bool _Complex _Imaginary".split()
)



class CodegenError(WmrkitError, ValueError):
    """A code-generation request that cannot be met (unknown language, sensed set, directory, existing file)."""


def identifier(name: str) -> str:
    """A C and Python identifier from a robot name: ``"diff-drive 2" -> "diff_drive_2"``, never a keyword."""
    ident = re.sub(r"\W", "_", name, flags=re.ASCII).strip("_") or "robot"
    if ident[0].isdigit():
        ident = f"robot_{ident}"
    return f"{ident}_" if ident in C_KEYWORDS or keyword.iskeyword(ident) else ident


class Plan:
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
        # q = free @ x + known @ q_sensed: a gear's joints filled from its sensed ones, a gear none of whose joints
        # is sensed one unknown (its turn), as fk solves them (linalg.geared_solve); without a gear, the columns
        self.geared = any(c.kind == "gear" for c in robot.couplings)
        names, given = robot.velocity_names, tuple(self.sensed_cols)
        self.free, self.known = gear_unknowns(robot.couplings, names, given)
        self.unknown_names = gear_free(robot.couplings, names, given)[1]
        self._check_forward()
        self.decide = self._decision_transform()
        # the double wheels' steering rates no twist determines: inputs besides the twist, as the inverse model's
        self.free_steer = generic_inputs(robot)[0]
        self.steer_rate = tuple(sp.Symbol(f"s{i}", real=True) for i in range(len(self.free_steer)))
        self.rates, matrix, self.inverse_exact = self._inverse_form(TWIST_NAMES + self.free_steer)
        self.inverse = [e for e in matrix * sp.Matrix(self.twist + self.steer_rate)]
        # the gears over the rates then the steering rates (gear_check's tables: ik's check), and their names
        self.gear_table = gear_table(robot, (*self.rates, *self.free_steer))
        self.gear_names = tuple(robot.couplings[i].channel_name for i in self.gear_table.coupling)
        # the held linkages (linkage_check's flat plan: ik's check of the headings) and their names
        self.links = linkage_plan(robot)
        self.linkage_names = tuple(robot.couplings[int(i)].channel_name for i in self.links.coupling)
        # the gears between steering joints (gear_check's flat tables: ik's out_of_steer_gear) and their names
        self.steer_gears = steer_gears(robot)
        self.steer_gear_names = tuple(robot.couplings[i].channel_name for i in self.steer_gears.table.coupling)

    def _check_forward(self) -> None:
        beta = np.random.default_rng(7).uniform(-math.pi, math.pi, (3, len(self.robot.steer_names)))
        # on the nondimensional robot, as the numeric models decide ranks: raw, a 1 um robot's 1 nm castor was lost
        a = nondimensional(self.robot).constraint_matrix(beta)
        a_na = a @ self.free
        ranks = matrix_rank(a_na)
        if int(ranks.max()) < len(self.unknown_names):  # name the rates left free, not every unknown
            free = free_columns(a_na[int(np.argmax(ranks))])
            names = name_list([n for n, f in zip(self.unknown_names, free, strict=True) if f])
            raise SingularError(f"robot '{self.robot.name}': the sensed rates ({name_list(self.sensed)}) do not "
                                f"determine ({names}); sense more joints (the wheels' 'sensed' field of the "
                                "description, or sensed= in Python)")

    def _decision_transform(self) -> np.ndarray:
        """``S`` ``(p, p)``: ``A_na @ S`` is the library's decision matrix of the forward model's unknowns
        (:func:`~.linalg.decision_matrix`: lengths over ``L``, the twist of the wheels' centroid; gears as
        :func:`~.linalg.geared_twist_determined` holds them), on which the generated code decides "twist not
        determined" with :data:`~.linalg.RANK_RTOL` and solves; ``S @ y`` the unknowns of ``A_na``. The twist is
        the first three unknowns (the sensed rates are joints)."""
        p = len(self.unknown_names)
        if not np.array_equal(self.free[:3, :3], np.eye(3)) or np.any(self.free[:3, 3:]):
            raise CodegenError("the forward model's unknowns do not start with the twist")  # sensed are joints
        size = characteristic_length(self.robot)
        cx, cy = centroid(self.robot)
        out = np.eye(p) / size
        out[0, 0] = out[1, 1] = 1.0  # vx, vy: / (1 / L) / L
        out[0, 2], out[1, 2] = cy / size, -cx / size  # the centroid's twist (linalg.centred)
        return out

    def _inverse_form(self, inputs: tuple[str, ...]) -> tuple[tuple[str, ...], sp.Matrix, bool]:
        """The rates not in `inputs`, ``M`` with ``rates = M @ inputs``, and whether it is exact: least squares per
        wheel (4.11), as ``ik``; the gears that set a double wheel's steering rate held exactly (``_symbolic_held``),
        the others left to ``in_gear``."""
        held = held_gears(self.robot, inputs)
        if not held:
            model = symbolic_model(self.robot, inputs, self.beta, gears=False)
            return model.solved, model.matrix, model.exact
        solved, matrix, _, exact = substituted_form(self.robot, inputs, self.a, held)
        return solved, matrix, exact

    def forward_exprs(self) -> tuple[list[sp.Expr], list[sp.Expr]]:
        """Entries of ``A_na = A F`` (row-major) and of ``b = -A K q_s``, ``F, K`` :attr:`free`, :attr:`known`
        (made exact: without a gear, the unknown and the sensed columns of ``A``)."""
        a_na = combine(self.a, self.free)
        b = -combine(self.a, self.known) * sp.Matrix(self.q)
        return list(a_na), list(b)


def _c_numbers(e: sp.Expr) -> sp.Expr:
    table: dict[sp.Expr, sp.Expr] = {sp.pi: sp.Float(math.pi, 20)}
    for n in e.atoms(sp.Rational):
        if abs(n.p) > 2**31 or abs(n.q) > 2**31:
            table[n] = sp.Float(n, 20)
    return e.xreplace(table)


def cse(exprs: list[sp.Expr], printer: C99CodePrinter | NumPyPrinter) -> tuple[list[str], list[str]]:
    """Common subexpressions ``t0, t1...`` as ``name = code`` lines, and the reduced expressions, printed."""
    if isinstance(printer, C99CodePrinter):  # C: no M_PI in strict C99, no integer literal beyond 64 bits
        exprs = [_c_numbers(e) for e in exprs]
    replacements, reduced = sp.cse(exprs, symbols=sp.numbered_symbols("t"), optimizations="basic")
    lines = [f"{sym} = {printer.doprint(value)}" for sym, value in replacements]
    return lines, [printer.doprint(e) for e in reduced]
