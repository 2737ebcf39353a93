"""The generated C forward model of a robot without steering angles (Mecanum, omni, skid steer, fixed wheels): the
least squares of its decision matrix ``D`` (:mod:`.codegen`), constant, is then one linear map, decided and
factored when the code is generated, by the rule
the generated Python applies at run time (``numpy.linalg.svd`` of the same ``D``, singular values above
``RANK_RTOL * max(s_max, 1)`` kept, twist determined iff ``rank D = 3 + rank D_joints``). A call
is two small matrix products instead of a Jacobi SVD.

With ``D = U S V^T`` (the kept columns of U) the unknowns are ``y = V S^+ U^T b``, the twist ``T b`` with
``T = (_DECIDE V S^+ U^T)[:3]``, and the residual ``|b - U U^T b|`` (the part of ``b`` no kept column reaches).
"""

from __future__ import annotations

import numpy as np
import sympy as sp

from ._codegen_plan import Plan
from .linalg import matrix_rank, rank_cutoff


def fixed_decision_matrix(plan: Plan) -> np.ndarray | None:
    """``D`` ``(rows, unknowns)`` when no entry of it depends on a steering angle (a robot without any) and the
    rule determines the twist, else None (the Jacobi SVD decides at run time; the plan refuses sensing that never
    determines the twist, so that is a margin of the rule only)."""
    a_na, _ = plan.forward_exprs()
    if any(sp.sympify(e).free_symbols for e in a_na):
        return None
    d = np.array([float(e) for e in a_na]).reshape(plan.a.rows, len(plan.unknown_names))
    d = d @ np.array(plan.decide.tolist(), dtype=float)
    s = np.linalg.svd(d, compute_uv=False)
    return d if int(np.sum(s > rank_cutoff(s))) == 3 + int(matrix_rank(d[:, 3:])) else None


def _c_matrix(name: str, m: np.ndarray) -> str:
    values = ", ".join(repr(float(v)) for v in m.ravel()) or "0.0"
    return f"    static const double {name}[{max(m.size, 1)}] = {{{values}}};"


def c_fixed_forward(d: np.ndarray, decide: np.ndarray, p: str) -> list[str]:
    """The C lines after ``b`` is filled and ``status`` set by its check: the twist, ``*residual``, the status."""
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
        f"    for (int i = 0; i < 3; ++i) {{ /* the twist T b, T = (_DECIDE V S^+ U^T)[:3] */",
        "        twist[i] = 0.0;",
        f"        for (int j = 0; j < {p}_N_ROWS; ++j) twist[i] += T[i * {p}_N_ROWS + j] * b[j];",
        "    }",
        "    if (residual) { /* |b - U U^T b|, scaled by its largest entry */",
        f"        for (int j = 0; j < {k}; ++j) {{ /* c = U^T b, in the workspace */",
        "            c[j] = 0.0;",
        f"            for (int i = 0; i < {p}_N_ROWS; ++i) c[j] += U[i * {k} + j] * b[i];",
        "        }",
        "        double e_max = 0.0, r = 0.0;",
        f"        for (int i = 0; i < {p}_N_ROWS; ++i)",
        f"            e_max = fmax(e_max, fabs(unreached({k}, U + i * {k}, b[i], c)));",
        f"        if (e_max > 0.0) for (int i = 0; i < {p}_N_ROWS; ++i) {{",
        f"            const double e = unreached({k}, U + i * {k}, b[i], c) / e_max;",
        "            r += e * e;",
        "        }",
        "        *residual = e_max * sqrt(r);",
        "    }",
        "    return status;",
    ]
