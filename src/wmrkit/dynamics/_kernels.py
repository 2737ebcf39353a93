"""Compiled kernels of the dynamic model (thesis §7.2): slip matrix, mass matrix, contact forces, loads, steps.

Imported lazily (numba takes a moment to import). No formula is written twice: the wheel rows are
:func:`wmrkit.wheels.slip_row_entries` compiled as they are, the tyre kernels are those of
:mod:`wmrkit.dynamics.tyres` compiled in a namespace where their helpers are compiled too.

The model is passed as a tuple ``pack`` of arrays built by :func:`wmrkit.dynamics.model.DynamicModel.pack`:

``el (E, 10)``: per contact element ``l, alpha, d, delta, gamma, r, r_r, beta_fixed, I_spin, I_roller``;
``el_steer (E,)`` int: index of the steering angle the element follows, -1 for none; ``rate_map (E, 3, nr)``;
``code (E,)`` int and ``tp (E, 4)``: tyre model and parameters; ``steer_col (S,)`` int: column of each steering
rate in the velocity vector; ``steer_kind (S,)`` int: 0 centred (its z-inertia in I_T, (7.17)), 1 castor unit;
``steer_prm (S, 5)``: ``I_s, m, l, alpha, d``; ``diag_I (n,)``: spin/roller inertia per column; ``carry (n,)``:
1 for the columns that carry the wheel (twist, steering rates), 0 for rolling ones; ``body (6,)``: ``M, I, cx, cy,
h, g``; ``pinv (E, 3)``: static load map when the contacts do not move (``fixed_loads``), ``fixed_loads (1,)``;
``group (n,)`` int: the differential coupling of each column (-1: none) and ``ratio (n,)`` its ratio there;
``loaded (E,)``: 1 for the contacts loaded at rest; ``basis (n, p)``: the motions the gear and linkage couplings
allow, ``nu = basis @ p`` (``model.gear_basis`` less the linkages' followers, whose rows depend on the state:
:func:`hold_linkages`; ``(n, 0)`` without a coupling to hold); ``linkages (L, 10)``: :mod:`wmrkit.dynamics.linkages`.
"""

from __future__ import annotations

import math
import types
from pathlib import Path

from .._jit import __file__ as jit_file
from .._jit import compile_cached, disk_cached, drop_stale_cache
from ..kinematics import linkage_law
from ..wheels import __file__ as wheels_file
from ..wheels import slip_row_entries
from . import linkages, tyres

#: Fast-math flags of the dynamics kernels: no NaN or infinity reaches them (the simulator checks the state between
#: chunks) and the sign of zero does not matter, but no contraction into fused multiply-adds and no reassociation:
#: those depend on what the compiler inlines, which differs with the order the kernels were compiled and cached in,
#: and closed loops through the dynamics amplify the last bits (a fresh install that ran the test suite printed a
#: skid steer's cross-track error 19 % off a clean compile's). With these flags every compilation gives the same bits,
#: at the same speed.
FASTMATH = ("nnan", "ninf", "nsz")


def _compile(fn, inline: str = "never", nrt: bool = True):
    """``numba.njit`` with the :data:`FASTMATH` flags, cached on disk where possible, without the C-callable wrapper
    numba adds for a kernel passed as a first-class function value (none is): the wrapper unboxes every argument,
    and for the step loop's tuples of arrays it was as large as the loop (docs/limits.md, "First run on a machine")."""
    return compile_cached(fn, fastmath=set(FASTMATH), inline=inline, _nrt=nrt, no_cfunc_wrapper=True)


def _inline(fn):
    """Compiled and inlined into its callers (no call boundary: the model's arrays are not re-counted per call)."""
    return _compile(fn, inline="always")


def _called(fn):
    """Compiled once and called, not inlined, without reference counting (it allocates nothing): for the large parts
    of the model that :func:`wmrkit.dynamics._integrate.assemble` calls. Numba inlines at the IR level, copying the
    callee's blocks into every call site and compiling each copy anew: called, ``mass_matrix`` and ``normal_loads``
    cut the first compile of ``wmrkit simulate`` by a third (docs/limits.md); a call passes its arrays by value and
    counts no references (callgrind: 1.25 % more instructions a step, the loads then taking the whole model)."""
    return _compile(fn, nrt=False)


def _njit(fn, nrt: bool = True):
    """Compiled for the types of its first call (:func:`_compile`). ``nrt=False`` compiles without numba's reference
    counting: for the time-stepping loops, which allocate nothing and would otherwise count references to every model
    and work array at every step (half the cost of a step)."""
    return _compile(fn, nrt=nrt)


def _identity(x):
    return x


def _pair(a, b):
    return (a, b)


def _compiled_namespace():
    """The tyre kernels compiled, each calling compiled helpers (same source, numba globals)."""
    g = dict(vars(tyres))
    g["_asarray"] = _njit(_identity)
    g["TyreForces"] = _njit(_pair)
    names = ("slip_ratio", "slip_angle", "magic_formula", "lu_longitudinal_coefficients", "lu_lateral_coefficients",
             "lu_longitudinal", "lu_lateral", "delft_combined", "linear_forces", "coulomb_forces", "dugoff_forces",
             "pacejka_speed_terms", "pacejka_at_speed", "pacejka_forces", "coulomb_grip", "dugoff_grip",
             "pacejka_grip")
    for name in names:
        fn = getattr(tyres, name)
        g[name] = _njit(types.FunctionType(fn.__code__, g, name, fn.__defaults__, fn.__closure__))
    return g


_STEPS = [str(Path(__file__).with_name(f)) for f in ("_integrate.py", "_newton.py")]  # step kernels
drop_stale_cache([__file__, *_STEPS, tyres.__file__],
                 [wheels_file, linkages.__file__, linkage_law.__file__, jit_file])  # _jit: runtime_value
_NS = _compiled_namespace()
_linear, _coulomb, _dugoff, _pacejka = (_NS[n] for n in ("linear_forces", "coulomb_forces", "dugoff_forces",
                                                          "pacejka_forces"))
_pacejka_speed, _pacejka_at = _NS["pacejka_speed_terms"], _NS["pacejka_at_speed"]
_grip_coulomb, _grip_dugoff, _grip_pacejka = (_NS[n] for n in ("coulomb_grip", "dugoff_grip", "pacejka_grip"))
_rows = compile_cached(slip_row_entries, None)
_law = _inline(linkages.law)


@_inline
def hold_linkages(s, pack, t, c, project):
    """Set each linkage's entry of the basis `t` (the model's, ``pack[16]``, elsewhere) to ``f'`` and its
    velocity-product acceleration ``c = f'' beta_i'^2`` at the state `s` (:mod:`.linkages`); with `project`, first
    set its follower in `s` from its leader (angle ``f(beta_i)``, rate ``f' beta_i'``: the constraint held to
    round-off). Nothing without a linkage."""
    table = pack[17]
    n = s.shape[0] // 2
    for r in range(table.shape[0]):
        j, i = int(table[r, 0]), int(table[r, 1])
        f, slope, curvature = _law(table[r], s[i])
        if project:
            s[j], s[n + j] = f, slope * s[n + i]
        t[j, int(table[r, 2])] = slope
        c[j] = curvature * s[n + i] * s[n + i]


@_inline
def tyre(code, p, fz, vl, vg, vw, vr):
    """Force ``(F_lat, F_long)`` of tyre model `code` (see ``tyres.TYRES``) on one contact."""
    if code == 0:
        return _linear(p[0], p[1], p[2], p[3], fz, vl, vg, vw, vr)
    if code == 1:
        return _coulomb(p[0], p[1], p[2], p[3], fz, vl, vg, vw, vr)
    if code == 2:
        return _dugoff(p[0], p[1], p[2], p[3], fz, vl, vg, vw, vr)
    return _pacejka(p[0], p[1], p[2], p[3], fz, vl, vg, vw, vr)


@_inline
def grip(code, p, fz):
    """Largest ``(|F_lat|, |F_long|)`` of tyre model `code` at load `fz` (``TyreKind.grip``); ``(-1, -1)`` for the
    linear model, which has no limit (no infinity reaches the kernels: :data:`FASTMATH`)."""
    if code == 0:
        return -1.0, -1.0
    if code == 1:
        return _grip_coulomb(p[0], p[1], p[2], p[3], fz)
    if code == 2:
        return _grip_dugoff(p[0], p[1], p[2], p[3], fz)
    return _grip_pacejka(p[0], p[1], p[2], p[3], fz)


@_inline
def tyre_and_jacobian(code, p, fz, vl, vg, vw, h):
    """:func:`tyre` at ``(vl, vg)``, ``(vl + h, vg)`` and ``(vl, vg + h)`` (rolling speed ``vg - vw``): the forward
    differences of the Jacobian. Pacejka's speed terms are computed once: the wheel speed `vw` is the same."""
    if code == 3:
        terms = _pacejka_speed(p[0], p[2], vw)
        return (_pacejka_at(terms, p[1], p[2], fz, vl, vg, vw, vg - vw),
                _pacejka_at(terms, p[1], p[2], fz, vl + h, vg, vw, vg - vw),
                _pacejka_at(terms, p[1], p[2], fz, vl, vg + h, vw, vg + h - vw))
    return (tyre(code, p, fz, vl, vg, vw, vg - vw), tyre(code, p, fz, vl + h, vg, vw, vg - vw),
            tyre(code, p, fz, vl, vg + h, vw, vg + h - vw))


@_inline
def slip_matrix(beta, pack, n, a, steer_only):
    """Fill ``a (2E, n)``: the rows of (3.22) in frame Ē over the velocity vector (extra columns zero, as given);
    with `steer_only`, only the rows of the steering wheels (the others do not change)."""
    el, el_steer, rate_map = pack[0], pack[1], pack[2]
    nr = rate_map.shape[2]
    for e in range(el.shape[0]):
        if steer_only and el_steer[e] < 0:
            continue  # a wheel that does not steer: its rows are already in `a`
        be_e = el[e, 7] + (beta[el_steer[e]] if el_steer[e] >= 0 else 0.0)
        rows = _rows(be_e, el[e, 0], el[e, 1], el[e, 2], el[e, 3], el[e, 4], el[e, 5], el[e, 6])
        for i in range(2):
            row = rows[i]
            a[2 * e + i, 0], a[2 * e + i, 1], a[2 * e + i, 2] = row[0], row[1], row[2]
            for c in range(nr):
                a[2 * e + i, 3 + c] = row[3] * rate_map[e, 0, c] + row[4] * rate_map[e, 1, c] \
                    + row[5] * rate_map[e, 2, c]


@_called
def mass_matrix(beta, pack, n, m, dm):
    """Fill the mass matrix ``m (n, n)`` of (7.17) and its derivatives ``dm (S, n, n)`` along the steering angles."""
    steer_col, steer_kind, steer_prm, diag_i, body = pack[5], pack[6], pack[7], pack[8], pack[10]
    m[:] = 0.0
    dm[:] = 0.0
    mb, ib, cx, cy = body[0], body[1], body[2], body[3]
    m[0, 0] += mb
    m[1, 1] += mb
    m[0, 2] -= mb * cy
    m[2, 0] -= mb * cy
    m[1, 2] += mb * cx
    m[2, 1] += mb * cx
    m[2, 2] += ib + mb * (cx * cx + cy * cy)
    for j in range(n):
        m[j, j] += diag_i[j]
    for k in range(steer_col.shape[0]):
        c, i_s, ms = steer_col[k], steer_prm[k, 0], steer_prm[k, 1]
        m[c, c] += i_s
        m[c, 2] += i_s
        m[2, c] += i_s
        if steer_kind[k] == 0:
            continue  # centred: I_os (b'^2 + 2 b' w) / 2, its I_os w^2 / 2 being in I_T (7.17)
        m[2, 2] += i_s  # castor unit: I_cs (b' + w)^2 / 2 and M_c |v_cm|^2 / 2, CM at the wheel centre (7.18)
        ll, al, d, b = steer_prm[k, 2], steer_prm[k, 3], steer_prm[k, 4], beta[k]
        px, py = ll * math.cos(al) - d * math.sin(b), ll * math.sin(al) + d * math.cos(b)
        # the wheel centre's velocity rows over the columns (0, 1, 2, c), and their derivatives along beta
        cols = (0, 1, 2, c)
        jx, jy = (1.0, 0.0, -py, -d * math.cos(b)), (0.0, 1.0, px, -d * math.sin(b))
        djx, djy = (0.0, 0.0, d * math.sin(b), d * math.sin(b)), (0.0, 0.0, -d * math.cos(b), -d * math.cos(b))
        for i in range(4):
            for j in range(4):
                m[cols[i], cols[j]] += ms * (jx[i] * jx[j] + jy[i] * jy[j])
                dm[k, cols[i], cols[j]] += ms * (djx[i] * jx[j] + jx[i] * djx[j] + djy[i] * jy[j] + jy[i] * djy[j])


@_inline
def bias(nu, beta_rate, m, dm, steer_col, steer_kind, out):
    """Velocity terms of the Lagrange-Poincaré equations: ``ad*_xi p`` (SE(2)), ``-M' nu`` and ``nu' dM nu / 2``."""
    n = nu.shape[0]
    p0, p1 = 0.0, 0.0
    for j in range(n):
        p0 += m[0, j] * nu[j]
        p1 += m[1, j] * nu[j]
    out[:] = 0.0
    out[0] = nu[2] * p1
    out[1] = -nu[2] * p0
    out[2] = nu[1] * p0 - nu[0] * p1
    for k in range(steer_col.shape[0]):
        if steer_kind[k] == 0:
            continue  # a centred steering unit: dM/dbeta = 0
        quad = 0.0
        for i in range(n):
            row = 0.0
            for j in range(n):
                row += dm[k, i, j] * nu[j]
            out[i] -= beta_rate[k] * row
            quad += nu[i] * row
        out[steer_col[k]] += 0.5 * quad


@_inline
def contact_forces(a, nu, pack, fz, f, g, vw, jac):
    """Tyre forces ``f (E, 2)`` on the slips ``a @ nu``; with `jac`, ``g (E, 2, 2) = dF/dv_slip`` (forward diff.)."""
    _contacts(a, nu, pack[3], pack[4], pack[9], fz, f, g, vw, jac)


@_called
def _contacts(a, nu, code, tp, carry, fz, f, g, vw, jac):
    """:func:`contact_forces` on the arrays of `pack` it reads. Called, not inlined: the step loop, the records and
    the step's re-linearisation at the grip (:mod:`._newton`) share one compiled copy of the four tyre models."""
    for e in range(code.shape[0]):
        vl, vg, w = 0.0, 0.0, 0.0
        for c in range(nu.shape[0]):
            vl += a[2 * e, c] * nu[c]
            vg += a[2 * e + 1, c] * nu[c]
            w += a[2 * e + 1, c] * nu[c] * carry[c]
        vw[e] = w
        if jac:
            h = 1e-7 * (1.0 + abs(vl) + abs(vg))
            (fl, fg), (fl2, fg2), (fl3, fg3) = tyre_and_jacobian(code[e], tp[e], fz[e], vl, vg, w, h)
            f[e, 0], f[e, 1] = fl, fg
            g[e, 0, 0], g[e, 1, 0] = (fl2 - fl) / h, (fg2 - fg) / h
            g[e, 0, 1], g[e, 1, 1] = (fl3 - fl) / h, (fg3 - fg) / h
        else:
            f[e, 0], f[e, 1] = tyre(code[e], tp[e], fz[e], vl, vg, w, vg - w)


@_inline
def normal_loads(beta, nu, acc, pack, out):
    """Normal loads (7.64) generalised: static + inertial transfer (h_CM) + spin-momentum rate; least norm.

    ``sum F_N = m g``, ``sum dx F_N = -h m a_x``, ``sum dy F_N = -h m a_y + sum I phi'' u_x`` about the centre of
    mass (a: its acceleration in body axes from `acc`, the velocity derivative); negative loads are set to 0.
    """
    _loads(beta, nu, acc, pack[0], pack[1], pack[2], pack[6], pack[7], pack[10], pack[11], pack[12], out)


@_called
def _loads(beta, nu, acc, el, el_steer, rate_map, steer_kind, steer_prm, body, pinv, fixed, out):
    """:func:`normal_loads` on the arrays of `pack` it reads (the call passes them, not the whole tuple)."""
    mb, cx, cy, h, grav = body[0], body[2], body[3], body[4], body[5]
    mt, mx, my = mb, mb * cx, mb * cy
    for k in range(steer_kind.shape[0]):
        if steer_kind[k] == 1:
            d, b = steer_prm[k, 4], beta[k]
            mt += steer_prm[k, 1]
            mx += steer_prm[k, 1] * (steer_prm[k, 2] * math.cos(steer_prm[k, 3]) - d * math.sin(b))
            my += steer_prm[k, 1] * (steer_prm[k, 2] * math.sin(steer_prm[k, 3]) + d * math.cos(b))
    gx, gy = mx / mt, my / mt
    w = nu[2]
    ax = acc[0] - w * nu[1] - acc[2] * gy - w * w * gx
    ay = acc[1] + w * nu[0] + acc[2] * gx - w * w * gy
    hx, hy = 0.0, 0.0
    nr = rate_map.shape[2]
    for e in range(el.shape[0]):
        be_e = el[e, 7] + (beta[el_steer[e]] if el_steer[e] >= 0 else 0.0)
        spin_acc, roll_acc = 0.0, 0.0
        for c in range(nr):
            spin_acc += rate_map[e, 1, c] * acc[3 + c]
            roll_acc += rate_map[e, 2, c] * acc[3 + c]
        t_l, t_e = be_e + el[e, 3], be_e + el[e, 3] + el[e, 4]
        if el[e, 9] != 0.0:  # a roller's inertia
            hx += el[e, 8] * spin_acc * math.cos(t_l) + el[e, 9] * roll_acc * math.cos(t_e)
            hy += el[e, 8] * spin_acc * math.sin(t_l) + el[e, 9] * roll_acc * math.sin(t_e)
        else:
            hx += el[e, 8] * spin_acc * math.cos(t_l)
            hy += el[e, 8] * spin_acc * math.sin(t_l)
    r0, r1, r2 = mt * grav, -h * mt * ax - hy, -h * mt * ay + hx
    if fixed[0] == 1:
        for e in range(el.shape[0]):
            out[e] = max(pinv[e, 0] * r0 + pinv[e, 1] * r1 + pinv[e, 2] * r2, 0.0)
        return
    # contacts that move with the steering (castors): the least-norm loads G' (G G')^-1 r, G = rows (1, dx, dy)
    s00, s01, s02, s11, s12, s22 = 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
    for e in range(el.shape[0]):
        dx, dy = _contact_offset(beta, el, el_steer, e, gx, gy)
        s00, s01, s02, s11, s12, s22 = s00 + 1.0, s01 + dx, s02 + dy, s11 + dx * dx, s12 + dx * dy, s22 + dy * dy
    c00, c01, c02 = s11 * s22 - s12 * s12, s02 * s12 - s01 * s22, s01 * s12 - s02 * s11
    det = s00 * c00 + s01 * c01 + s02 * c02
    if abs(det) <= 1e-12 * (s00 * s11 * s22 + 1e-300):  # contacts on a line: the moment about it is not carried
        y0, y1, y2 = r0 / s00, 0.0, 0.0
    else:
        c11, c12, c22 = s00 * s22 - s02 * s02, s01 * s02 - s00 * s12, s00 * s11 - s01 * s01
        y0 = (c00 * r0 + c01 * r1 + c02 * r2) / det
        y1 = (c01 * r0 + c11 * r1 + c12 * r2) / det
        y2 = (c02 * r0 + c12 * r1 + c22 * r2) / det
    for e in range(el.shape[0]):
        dx, dy = _contact_offset(beta, el, el_steer, e, gx, gy)
        out[e] = max(y0 + dx * y1 + dy * y2, 0.0)


@_inline
def _contact_offset(beta, el, el_steer, e, gx, gy):
    """Position of contact `e` relative to the centre of mass ``(gx, gy)`` (body axes)."""
    be = el[e, 7] + (beta[el_steer[e]] if el_steer[e] >= 0 else 0.0)
    return (el[e, 0] * math.cos(el[e, 1]) - el[e, 2] * math.sin(be) - gx,
            el[e, 0] * math.sin(el[e, 1]) + el[e, 2] * math.cos(be) - gy)


@_called
def solve_in_place(a, x):
    """Gaussian elimination with partial pivoting (small dense systems; no LAPACK call overhead): `x` becomes
    ``a^-1 x``; `a` is overwritten. Called, not inlined: the geared solve has two call sites, each inlined copy
    compiled anew in the step loop (docs/limits.md, "First run on a machine")."""
    n = x.shape[0]
    for i in range(n):
        p = i
        for r in range(i + 1, n):
            if abs(a[r, i]) > abs(a[p, i]):
                p = r
        if p != i:
            for c in range(n):
                a[i, c], a[p, c] = a[p, c], a[i, c]
            x[i], x[p] = x[p], x[i]
        piv = a[i, i]
        for r in range(i + 1, n):
            f = a[r, i] / piv
            if f != 0.0:
                for c in range(i, n):
                    a[r, c] -= f * a[i, c]
                x[r] -= f * x[i]
    for i in range(n - 1, -1, -1):
        s = x[i]
        for c in range(i + 1, n):
            s -= a[i, c] * x[c]
        x[i] = s / a[i, i]


def first_compile() -> bool:
    """Whether the dynamics kernels are about to be compiled rather than loaded from numba's disk cache: neither the
    normal loads (a model's first kernel) nor the tyre forces (every run's) are there. A first run on a machine, which
    compiles them for about 20 s (the CLI says so as it starts)."""
    return [disk_cached(kernel) for kernel in (normal_loads, _contacts)] == [False, False]
