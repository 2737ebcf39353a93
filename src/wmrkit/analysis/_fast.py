"""Component-major kernels for maps over millions of configurations (private).

Arrays are laid out ``(component..., N)`` with the configurations on the last, contiguous axis, and processed
in cache-sized chunks, so every operation is a long elementwise loop or one small BLAS product. The maths is
that of :mod:`.lines` (slip rows 3.10), :mod:`.isotropy` (condition number 5.28 on the admissible twists) and
:mod:`.singularity` (lines 6.17); the public functions there are the reference, tests compare the two.
"""

from __future__ import annotations

import numpy as np

from ._sym import eigvalsh2_entries, eigvalsh3_entries

CHUNK = 4096  # configurations per chunk: the working set stays in cache
FEW = 64  # configurations up to which LAPACK's SVD is used (accurate to eps) instead of closed-form Gram eigenvalues


def _columns(x) -> np.ndarray:
    """Per-wheel or per-element values ``(K,)`` as a column ``(K, 1)``, or ``(K, N)`` (one per configuration) as they
    are."""
    a = np.asarray(x, dtype=float)
    return a[:, None] if a.ndim == 1 else a


def element_rows_cm(p, beta: np.ndarray) -> np.ndarray:
    """Slip-row twist columns ``(2E, 3, N)`` for configurations `beta` ``(N, n_steer)``; `p`: line_parameters, its
    per-wheel and per-element values one each ``(W,)``/``(E,)`` or one per configuration ``(W, N)``/``(E, N)`` (the
    sweep's designs)."""
    n = beta.shape[0]
    n_el = len(p.element_wheel)
    wheel_beta = np.broadcast_to(_columns(p.beta_described), (len(p.beta_described), n)).copy()  # (W, N)
    wheel_beta[p.steer_wheels] = beta.T
    theta = wheel_beta[p.element_wheel] + _columns(p.theta_offset)  # every element at once: (E, N)
    c, s = np.cos(theta), np.sin(theta)
    lc, ls, lsn, dc, ds = map(_columns, (p.l_c_alpha, p.l_s_alpha, p.l_s_alpha_neg, p.d_c, p.d_s))
    out = np.empty((n_el, 2, 3, n))
    out[:, 0, 0], out[:, 0, 1] = c, s
    out[:, 0, 2] = lsn * c + lc * s - dc
    out[:, 1, 0], out[:, 1, 1] = -s, c
    out[:, 1, 2] = lc * c + ls * s + ds
    return out.reshape(2 * n_el, 3, n)


def combine(coefficients: np.ndarray, rows: np.ndarray) -> np.ndarray:
    """``coefficients (L, 2E) @ rows (2E, 3, N)`` -> ``(L, 3, N)``."""
    return (coefficients @ rows.reshape(rows.shape[0], -1)).reshape(coefficients.shape[0], 3, rows.shape[-1])


def combine_rates(coefficients: np.ndarray, rows: np.ndarray) -> np.ndarray:
    """Joint rates per unit twist, ``coefficients (J, 2E) @ rows (2E, 3, N)`` -> ``(J, 3, N)``, each entry that is
    round-off (1e-12) of the terms ``|coefficients| @ |rows|`` that formed it zeroed: a castor mounted at the origin
    spins for no turn rate (its steering takes the turn), but its rows' cancellation left 1e-16, which outweighed
    the turn rate a wheel 3e-13 m off the origin gave, and kappa 1.62 came out 1.6203, 1.6193 or 1.6179 as the
    frame was turned, mirrored or scaled."""
    rates = combine(coefficients, rows)
    return np.where(np.abs(rates) <= 1e-12 * combine(np.abs(coefficients), np.abs(rows)), 0.0, rates)


def cancel_roundoff(lam: np.ndarray, terms: np.ndarray, axis: int) -> np.ndarray:
    """Zero the lines `lam` (components on `axis`) that are round-off (1e-12) of the `terms` ``|coefficients| @
    |rows|`` that formed them: a line through a coupling vanishes where its wheels' rows cancel (two identical castors
    at one angle), and its round-off, normalised, was a spurious unit line (6.17)."""
    small = np.abs(lam).max(axis=axis, keepdims=True) <= 1e-12 * terms.max(axis=axis, keepdims=True)
    return np.where(small, 0.0, lam)


def combine_lines(cl, rows: np.ndarray) -> np.ndarray:
    """The constraint lines of `cl` (:class:`.lines.ConstraintLines`) at `rows` ``(2E, 3, N)`` -> ``(L, 3, N)``, not
    normalised; a line that is round-off is zeroed (:func:`cancel_roundoff`) as ``cl.lines`` does. Only a line
    through a coupling can be (a wheel's own line keeps the length of its direction as it steers), so the check
    runs only for those."""
    lam = combine(cl.coefficients, rows)
    if cl.coupled:
        lam = cancel_roundoff(lam, combine(np.abs(cl.coefficients), np.abs(rows)), axis=1)
    return lam + cl.constant[:, :, None]


def normalize_cm(lines: np.ndarray) -> np.ndarray:
    """Rows ``(L, 3, N)`` scaled to a unit direction (or unit d for the line at infinity), eq. (6.18)."""
    n = np.hypot(lines[:, 0], lines[:, 1])
    scale = np.where(n > 1e-12 * np.maximum(np.abs(lines[:, 2]), 1.0), n, np.abs(lines[:, 2]))
    return lines / np.where(scale > 0, scale, 1.0)[:, None, :]


def gram3(h: np.ndarray) -> tuple[np.ndarray, ...]:
    """The six entries ``(g11, g22, g33, g12, g13, g23)`` of ``H^T H`` for ``h (J, 3, N)``."""
    return (np.einsum("jn,jn->n", h[:, 0], h[:, 0]), np.einsum("jn,jn->n", h[:, 1], h[:, 1]),
            np.einsum("jn,jn->n", h[:, 2], h[:, 2]), np.einsum("jn,jn->n", h[:, 0], h[:, 1]),
            np.einsum("jn,jn->n", h[:, 0], h[:, 2]), np.einsum("jn,jn->n", h[:, 1], h[:, 2]))


def kappa_cm(mobility: int, rates: np.ndarray, lines: np.ndarray, length: float) -> np.ndarray:
    """Condition number (5.28) of joint rates ``(J, 3, N)`` over the admissible scaled twists ``(N,)``.

    `lines` ``(R, 3, N)`` are the normalised axle lines; see isotropy._motion_basis for the bases used.
    """
    n = rates.shape[-1]
    if mobility == 3:
        h = rates * np.array([1.0, 1.0, 1.0 / length])[None, :, None]
        if n <= FEW:
            return _condition_svd(np.moveaxis(h, -1, 0))
        small, _, large = _eig3(gram3(h))
        return ratio(small, large)
    if mobility == 2:
        a, b, ok = columns_m2(rates, lines)
        b = b / length
        if n <= FEW:
            return np.where(ok, _condition_svd(np.stack([a.T, b.T], axis=-1)), np.nan)
        small, large = eigvalsh2_entries(np.einsum("jn,jn->n", a, a), np.einsum("jn,jn->n", a, b),
                                         np.einsum("jn,jn->n", b, b))
        return np.where(ok, ratio(small, large), np.nan)
    if mobility == 1:
        g0 = lines[0]
        cross = np.stack([g0[1] * lines[:, 2] - g0[2] * lines[:, 1], g0[2] * lines[:, 0] - g0[0] * lines[:, 2],
                          g0[0] * lines[:, 1] - g0[1] * lines[:, 0]], axis=1)  # (R, 3, N)
        norms = np.sqrt(np.einsum("rcn,rcn->rn", cross, cross))
        best = np.argmax(norms, axis=0)
        nv = cross[best, :, np.arange(n)].T  # (3, N)
        size = norms[best, np.arange(n)]
        nv = nv / np.where(size > 0, size, 1.0)
        ok = (size > 1e-9) & np.all(np.abs(np.einsum("rcn,cn->rn", lines, nv)) < 1e-6, axis=0)
        h = np.einsum("jcn,cn->jn", rates, nv)
        return np.where(ok, np.where(np.einsum("jn,jn->n", h, h) > 1e-24, 1.0, np.inf), np.nan)
    return np.full(n, np.nan)


def columns_m2(rates: np.ndarray, lines: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Joint rates ``(J, N)`` per unit speed normal to the common axle at the foot P of the perpendicular from the
    origin, and per unit rotation about P (the thesis's (v, omega) pairs, 5.47, and eta of 5.64); and where the
    axles really are one line (m = 2 there). A constraint at infinity (omega = 0) gives the two translations.
    """
    lx, ly, d = lines[0]
    gx, gy, gd = lines[:, 0], lines[:, 1], lines[:, 2]  # every axle must be the same line (rank 1)
    ok = np.all(np.abs(gy * d - gd * ly) + np.abs(gd * lx - gx * d) + np.abs(gx * ly - gy * lx) < 1e-6, axis=0)
    finite = np.hypot(lx, ly) > 1e-9
    px, py = d * ly, -d * lx  # foot of the perpendicular (6.18)
    a = np.where(finite, -ly * rates[:, 0] + lx * rates[:, 1], rates[:, 0])
    b = np.where(finite, py * rates[:, 0] - px * rates[:, 1] + rates[:, 2], rates[:, 1])
    return a, b, ok


def distance_cm(lines: np.ndarray, length: float) -> np.ndarray:
    """``sigma_min / sigma_max`` of the lines ``(L, 3, N)`` with d scaled by 1/length and unit rows, (6.17)."""
    g = lines * np.array([1.0, 1.0, 1.0 / length])[None, :, None]
    norm = np.sqrt(np.einsum("lcn,lcn->ln", g, g))
    g = g / np.where(norm > 0, norm, 1.0)[:, None, :]  # a line through a coupling can vanish at some configurations
    if g.shape[-1] <= FEW:  # SVD: accurate to eps (the Gram route bottoms out at sqrt(eps))
        sv = np.linalg.svd(np.moveaxis(g, -1, 0), compute_uv=False)
        return sv[:, 2] / np.where(sv[:, 0] > 0, sv[:, 0], 1.0)
    small, _, large = eigvalsh3_entries(*gram3(g))
    return np.sqrt(np.maximum(small, 0.0) / np.where(large > 0, large, 1.0))


def _eig3(entries: tuple[np.ndarray, ...]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Closed form for big chunks; LAPACK (accurate to eps * lambda_max) for a few configurations."""
    if entries[0].size > FEW:
        return eigvalsh3_entries(*entries)
    g11, g22, g33, g12, g13, g23 = entries
    g = np.stack([np.stack([g11, g12, g13], -1), np.stack([g12, g22, g23], -1), np.stack([g13, g23, g33], -1)], -2)
    w = np.linalg.eigvalsh(g)
    return w[..., 0], w[..., 1], w[..., 2]


def _condition_svd(h: np.ndarray) -> np.ndarray:
    """``sigma_max / sigma_min`` of ``h (N, J, k)`` by SVD, accurate to eps (the Gram route of :func:`ratio` bottoms
    out at sqrt(eps): a condition number above 1e7 read as infinite); the threshold of
    :func:`.isotropy.condition_number`."""
    from .isotropy import condition_number

    return condition_number(h)


def ratio(small: np.ndarray, large: np.ndarray) -> np.ndarray:
    """``sqrt(large / small)``: a condition number from Gram eigenvalues; inf where small vanishes."""
    tiny = np.maximum(small, 0.0) <= 1e-14 * np.maximum(large, 1e-300)
    return np.where(tiny, np.inf, np.sqrt(large / np.where(tiny, 1.0, small)))
