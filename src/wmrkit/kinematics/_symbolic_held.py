"""Least-squares closed forms that hold the gears setting double wheels' steering rates (private).

A double wheel whose steering rate is not an input (its gears set it from the twist: ``models._free_steering``) is
determined only with those gears. They are held exactly by substitution, ``q = F x + K q_a`` (the unknowns of
:func:`wmrkit.couplings.gear_unknowns`, as ``linalg.geared_solve`` for ``fk``), and the slip rows alone are fitted
(4.11), in m/s: no gear row is weighed against slip. The other gears are not held (the wheels' least squares, as
``ik`` gives them); the closed forms and the generated code say so.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np
import sympy as sp

from ..couplings import Coupling, gear_free, gear_unknowns
from ..errors import SingularError, name_list
from ..robot import Robot
from ._exact_linalg import closed_form, generic_ranks
from ._symbolic_matrix import exact_number
from .linalg import free_columns


def held_gears(robot: Robot, inputs: Sequence[str]) -> tuple[Coupling, ...]:
    """The gears turning a joint of a double wheel whose steering rate is not one of the `inputs`."""
    steered = {n.rpartition(".")[0] for n in robot.free_steering if n not in inputs}
    return tuple(c for c in robot.couplings
                 if c.kind == "gear" and any(j.rpartition(".")[0] in steered for j in c.joints))


def combine(a: sp.MatrixBase, m: np.ndarray) -> sp.Matrix:
    """``a @ m`` for a numeric `m` of gear ratios, 0 and 1 (its entries made exact, ``0.4 -> 2/5``), summing only
    the nonzero terms: a column selecting one column of `a` is that column, as it is."""
    cols = []
    for c in m.T:
        terms = [a[:, j] if v == 1 else a[:, j] * exact_number(v, "length") for j, v in enumerate(c) if v != 0]
        cols.append(sum(terms[1:], terms[0]) if terms else sp.zeros(a.rows, 1))
    return sp.Matrix.hstack(*cols) if cols else sp.zeros(a.rows, 0)


def substituted_form(robot: Robot, inputs: tuple[str, ...], a: sp.MatrixBase, held: tuple[Coupling, ...],
                     guard: Callable[[sp.Matrix, list[int], bool], None] | None = None,
                     ) -> tuple[tuple[str, ...], sp.Matrix, sp.Matrix, bool]:
    """The velocities not in `inputs`, ``M`` with ``q_solved = M q_inputs``, the slip ``A q`` per input (`a`'s
    rows) and whether the form is exact, `held` gears held by substitution, `a` the slip matrix (3.22) without gear
    rows. :class:`SingularError` naming the unknowns the inputs leave free; `guard(system, unknown columns, exact)`
    may refuse before the derivation."""
    names = robot.velocity_names
    given = tuple(names.index(n) for n in inputs)
    free, known = gear_unknowns(held, names, given)
    system = sp.Matrix.hstack(combine(a, free), combine(a, known))
    na, assigned = list(range(free.shape[1])), list(range(free.shape[1], system.cols))
    points, values, rank, ranks_na = generic_ranks(system, na)
    if max(ranks_na) < len(na):
        unknown = gear_free(held, names, given)[1]
        left = free_columns(values[int(np.argmax(ranks_na))][:, na])
        raise SingularError(f"robot '{robot.name}': assigning ({name_list(inputs)}) does not determine "
                            f"({name_list([n for n, f in zip(unknown, left, strict=True) if f])}) with "
                            f"{name_list([c.words() for c in held])} held")
    exact = max(ranks_na) == rank
    if guard is not None:
        guard(system, na, exact)
    x, residual = closed_form(system, na, assigned, exact, values, points)
    q = combine(sp.eye(len(names)), free) * x + combine(sp.eye(len(names)), known)
    solved = [j for j in range(len(names)) if j not in given]
    return tuple(names[j] for j in solved), q.extract(solved, list(range(len(given)))), residual, exact
