"""The generated C forward model when its least squares is one linear map, factored when the code is generated:
a robot without steering angles (Mecanum, omni, skid steer), or one whose steered wheels' rows are all absorbed (a
diff drive's castor). A call is then two small matrix products instead of a Jacobi SVD of the decision matrix ``D``
(:mod:`.codegen`).

Absorbed rows: a set of unknown joint columns ``J`` nonzero only in rows ``R`` (a connected part of ``D``'s joint
columns, e.g. a castor's steering and spin rates, not sensed), as many rows as columns, with a constant invertible
block ``B = D[R, J]``: any twist leaves ``B v = b_R - Q u`` solvable, so the least squares is that of the other
rows ``P`` and columns alone (``Q = D[R, twist]``). With ``D`` of full column rank (the plan requires every unknown
determined) the twist is then ``P``'s, exactly, and the residual too. ``D`` itself depends on the headings through
``Q``; wmrkit's rule (singular values above ``RANK_RTOL * max(s_max, 1)``, twist determined iff ``rank D = 3 +
rank D_joints``) keeps every one at every heading when ``s_P s_B / (s_P + s_B + q)``, a lower bound of ``D``'s
least singular value (``s_P``, ``s_B`` the least of ``P`` and ``B``, ``q >= |Q|`` from its entries' coefficients,
``|sin|, |cos| <= 1``), lies above the cut-off with ``s_max`` bounded by ``|D|_F``: only then is the map used, and
``fk``'s rule and this code cannot disagree. Otherwise the Jacobi SVD decides at run time.

With ``P = U S V^T`` (decision units; the kept columns of U) the twist is ``T b_P``, ``T = (_DECIDE V S^+ U^T)[:3]``,
and the residual ``|b_P - U U^T b_P|``.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
import sympy as sp
from scipy.sparse.csgraph import connected_components

from ._codegen_plan import Plan
from .linalg import RANK_RTOL, matrix_rank, rank_cutoff

#: Margin of the bound over the cut-off: the run-time SVD's round-off (relative 1e-15) stays far below it.
MARGIN = 2.0


def _bound(e: sp.Expr) -> float | None:
    """An upper bound of ``|e|`` over every heading: the sum of its terms' coefficients' magnitudes, each term a
    number times sines and cosines (powers too); None for any other form."""
    total = 0.0
    for term in sp.Add.make_args(sp.expand(e)):
        if not term.free_symbols:  # a number
            total += abs(float(term))
            continue
        coeff, rest = term.as_independent(*term.free_symbols, as_Add=False)  # a number (sqrt(2)/2 too), the rest
        for f in sp.Mul.make_args(rest):
            base = f.base if isinstance(f, sp.Pow) and f.exp.is_positive and f.exp.is_integer else f
            if not (f == 1 or isinstance(base, sp.sin | sp.cos)):
                return None
        total += abs(float(coeff))
    return total


class FastForward(NamedTuple):
    """The forward model as one linear map: the rows of ``A_na`` kept, their decision matrix ``D_P`` ``(rows, kept
    unknowns)``, and ``_DECIDE``'s rows and columns of the kept unknowns (the twist first)."""

    rows: list[int]
    d: np.ndarray
    decide: np.ndarray


def fast_forward(plan: Plan) -> FastForward | None:
    """The forward model's least squares as one linear map when fk's rule keeps it whole at every heading (module
    docstring), else None."""
    a_na, _ = plan.forward_exprs()
    rows, na = plan.a.rows, len(plan.unknown_names)
    m = sp.Matrix(rows, na, a_na)
    decide = np.array(plan.decide.tolist(), dtype=float)
    nonzero = np.array([[m[i, j] != 0 for j in range(na)] for i in range(rows)])
    # joint columns and rows as one graph: a connected part is a set of joints and the rows they appear in
    graph = np.zeros((na + rows, na + rows), dtype=bool)
    graph[3:na, na:] = nonzero[:, 3:].T
    _, label = connected_components(graph, directed=False)
    absorbed_rows: list[int] = []
    absorbed_cols: list[int] = []
    s_b = np.inf
    for part in {int(label[j]) for j in range(3, na)}:
        cols = [j for j in range(3, na) if label[j] == part]
        part_rows = [i for i in range(rows) if label[na + i] == part]
        block = m.extract(part_rows, cols)
        if len(part_rows) != len(cols) or block.free_symbols:
            continue
        b = np.array(block.tolist(), dtype=float) @ decide[np.ix_(cols, cols)]
        least = float(np.linalg.svd(b, compute_uv=False)[-1])
        if least > 0:
            absorbed_rows += part_rows
            absorbed_cols += cols
            s_b = min(s_b, least)
    kept_rows = [i for i in range(rows) if i not in absorbed_rows]
    kept_cols = [j for j in range(na) if j not in absorbed_cols]
    p_sym = m.extract(kept_rows, kept_cols)
    if p_sym.free_symbols or len(kept_rows) < len(kept_cols):
        return None
    d_p = np.array(p_sym.tolist(), dtype=float).reshape(len(kept_rows), len(kept_cols))
    d_p = d_p @ decide[np.ix_(kept_cols, kept_cols)]
    fast = FastForward(kept_rows, d_p, decide[np.ix_(kept_cols, kept_cols)])
    if not absorbed_rows:  # D itself is constant: the rule decides it now as it would at run time
        return fast if int(matrix_rank(d_p)) == 3 + int(matrix_rank(d_p[:, 3:])) else None
    q_raw = [_bound(m[i, j]) for i in absorbed_rows for j in range(3)]
    if any(v is None for v in q_raw):
        return None
    q = float(np.linalg.norm(q_raw)) * float(np.linalg.norm(decide[:3, :3], 2))
    b_frob = float(np.linalg.norm(np.array(m.extract(absorbed_rows, absorbed_cols).tolist(), dtype=float)
                                  @ decide[np.ix_(absorbed_cols, absorbed_cols)]))
    s_max = float(np.sqrt(np.sum(d_p**2) + q**2 + b_frob**2))
    s_p = float(np.linalg.svd(d_p, compute_uv=False)[-1])
    least = s_p * s_b / (s_p + s_b + q)
    return fast if least > MARGIN * RANK_RTOL * max(s_max, 1.0) else None


def _c_matrix(name: str, m: np.ndarray) -> str:
    values = ", ".join(repr(float(v)) for v in m.ravel()) or "0.0"
    return f"    static const double {name}[{max(m.size, 1)}] = {{{values}}};"


def c_fixed_forward(fast: FastForward) -> list[str]:
    """The C lines after the kept rows' ``b`` are filled and ``status`` set by the inputs' check: the twist,
    ``*residual``, the status."""
    d, decide, rows = fast.d, fast.decide, len(fast.rows)
    u, s, vt = np.linalg.svd(d, full_matrices=False)
    keep = s > rank_cutoff(s)
    u_k = u[:, keep]
    w = (decide @ vt.T[:, keep] / s[keep])[:3]
    k = int(keep.sum())
    return [
        "    /* D = U S V^T factored when the code was generated (no entry of it depends on a steering angle) */",
        _c_matrix("T", w @ u_k.T), _c_matrix("U", u_k),
        "    if (status != 0) { for (int i = 0; i < 3; ++i) twist[i] = (double)NAN; "
        "if (residual) *residual = NAN; return status; }",
        "    for (int i = 0; i < 3; ++i) { /* the twist T b, T = (_DECIDE V S^+ U^T)[:3] */",
        "        twist[i] = 0.0;",
        f"        for (int j = 0; j < {rows}; ++j) twist[i] += T[i * {rows} + j] * b[j];",
        "    }",
        "    if (residual) { /* |b - U U^T b| */",
        f"        for (int j = 0; j < {k}; ++j) {{ /* c = U^T b, in the workspace */",
        "            c[j] = 0.0;",
        f"            for (int i = 0; i < {rows}; ++i) c[j] += U[i * {k} + j] * b[i];",
        "        }",
        f"        *residual = unreached_norm({rows}, {k}, U, b, c);",
        "    }",
        "    return status;",
    ]
