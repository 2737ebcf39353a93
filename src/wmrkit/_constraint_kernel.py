"""Compiled filling of the constraint matrix (3.22): the wheel kernel (3.10) of :mod:`wmrkit.wheels`, compiled.

Imported on the first call of :meth:`wmrkit.Robot.constraint_matrix` (numba takes a moment to import). The
formula is not repeated here: :func:`wmrkit.wheels.slip_row_entries` is compiled as it is.
"""

from __future__ import annotations

import numba

from . import wheels
from ._jit import compile_cached, drop_stale_cache, jit
from .wheels import slip_row_entries

drop_stale_cache([__file__], [wheels.__file__])
_entries = compile_cached(slip_row_entries, None)

_IN1 = numba.types.Array(numba.float64, 1, "A", readonly=True)
_IN2 = numba.types.Array(numba.float64, 2, "A", readonly=True)
_IN3 = numba.types.Array(numba.float64, 3, "A", readonly=True)
_OUT4 = numba.float64[:, :, :, ::1]


@jit((_IN2, _IN1, _IN1, _IN1, _IN1, _IN1, _IN1, _IN1, _IN3, _OUT4))
def fill_constraint_rows(beta, l, alpha, d, delta, gamma, r, r_r, rate_map, out):
    """Rows of every contact element into `out` ``(B, E, 2, 3 + n_rates)`` for element angles `beta` ``(B, E)``.

    Columns: the twist, then the wheel rates through each element's ``rate_map`` ``(E, 3, n_rates)``.
    """
    n_rates = rate_map.shape[2]
    for b in range(beta.shape[0]):
        for e in range(beta.shape[1]):
            rows = _entries(beta[b, e], l[e], alpha[e], d[e], delta[e], gamma[e], r[e], r_r[e])
            for i in range(2):
                row = rows[i]
                out[b, e, i, 0] = row[0]
                out[b, e, i, 1] = row[1]
                out[b, e, i, 2] = row[2]
                for c in range(n_rates):
                    out[b, e, i, 3 + c] = row[3] * rate_map[e, 0, c] + row[4] * rate_map[e, 1, c] \
                        + row[5] * rate_map[e, 2, c]
