"""The semi-implicit step at the tyres' grip: when to re-linearise, and one Newton iteration's forces.

The step linearises the tyre forces at its start, ``F + dt G A dnu``, and a tyre's slope does not saturate: from
rest (zero slip) the first step would grip at many times ``mu Fz`` and the next step's load transfer would empty the
drive wheels (docs/dynamics.md, "a start from rest"). A step whose linearised force exceeds the tyre's grip
(:func:`~._kernels.grip`, :func:`beyond_grip`), or whose own acceleration transfers loads that move a force by more
than :data:`GRIP_SLACK` of its grip (:func:`loads_moved`: the step's forces take the loads of the previous step's
acceleration), is linearised again where it arrived, at the loads of its acceleration (:func:`relinearise`), and
solved again (:func:`wmrkit.dynamics._integrate.run_semi_implicit`), until its forces are those its
linearisation predicted; an iteration whose Newton step does not reduce the residual of the step's equations takes a
shorter one along it (:func:`line_search`: a tyre's force is steep across zero slip and flat beyond, and a step
linearised where the tyre slides jumps across the zero). The re-linearisation is rare: it is compiled once and
called, not inlined into the step loop, and its tyre forces and loads are the compiled copies the step and the
records call (:func:`~._kernels.contact_forces`, :func:`~._kernels.normal_loads`).

Work arrays (:func:`~._integrate.work_arrays`): ``w[21]`` the step's right-hand side ``rhs``, ``w[22]`` the
velocity of the re-linearisation, ``w[23]`` its forces, ``w[24]`` the velocity change it was taken at, ``w[25]``
its wheel speeds, ``w[26]`` 1 after a re-linearisation (the next step refreshes the tyre Jacobian), ``w[27]`` the
forces the linearisation predicts, ``w[28]`` the loads of the step's acceleration, ``w[29]`` the loads' share of
the Newton matrix, ``w[30:33]`` scratch (:func:`_load_terms`), ``w[33]`` the step at the previous step's loads
(kept when the loads' iterations do not converge), ``w[34:40]`` the line search's residual at the iteration's
start, its share of the step, the step, and scratch (:func:`line_search`).
"""

from __future__ import annotations

from .._jit import runtime_value
from ._kernels import _called, _inline, contact_forces, grip, normal_loads

#: Newton iterations at most in a semi-implicit step whose linearised tyre forces exceed their grip.
GRIP_ITERATIONS = 8
#: How far (relative) a linearised tyre force may exceed the tyre's grip before the step is re-linearised.
GRIP_SLACK = 1e-3


@_called
def loads_moved(s, dnu, beta, fz, new, pred, pack):
    """Whether the normal loads at the step's acceleration `dnu` (``w[9]``; steering angles `beta`, ``w[10]``; at
    the step's start, into `new`, ``w[28]``: :func:`~._kernels.normal_loads`) moved from those its tyre forces were
    taken at (`fz`, ``w[3]``, the previous step's acceleration) enough to move a force by more than
    :data:`GRIP_SLACK` of its grip: by that share of the load, times the share of its grip the force uses (`pred`,
    ``w[27]``, :func:`beyond_grip`; a tyre's forces scale with its load at most as its grip does). Linear tyres do
    not depend on the load. Given arrays rather than the work tuple (:func:`newton_matrix`)."""
    code, tp = pack[3], pack[4]
    n = dnu.shape[0]
    normal_loads(beta, s[n:], dnu, pack, new)
    for e in range(fz.shape[0]):
        if code[e] == 0 or new[e] == fz[e]:
            continue
        if fz[e] <= 0.0:
            return True
        lat, lon = grip(code[e], tp[e], fz[e])
        moved, tol = abs(new[e] - fz[e]), GRIP_SLACK * fz[e]
        if moved * abs(pred[e, 0]) > tol * lat or moved * abs(pred[e, 1]) > tol * lon:
            return True
    return False


@_inline
def beyond_grip(a, dnu, d_lin, f, g, fz, pack, dt, pred):
    """Whether a contact's linearised force ``f + dt g A (dnu - d_lin)`` (the step's, linearised at the velocity
    change ``dt d_lin``; stored in `pred`) exceeds the tyre's grip by more than :data:`GRIP_SLACK`."""
    code, tp = pack[3], pack[4]
    n = dnu.shape[0]
    beyond = False
    for e in range(code.shape[0]):
        if code[e] == 0:
            continue  # linear tyres: no grip, and the linearisation is exact
        dl, dg = 0.0, 0.0
        for c in range(n):
            dd = dnu[c] - d_lin[c]
            dl += a[2 * e, c] * dd
            dg += a[2 * e + 1, c] * dd
        fl = f[e, 0] + dt * (g[e, 0, 0] * dl + g[e, 0, 1] * dg)
        fg = f[e, 1] + dt * (g[e, 1, 0] * dl + g[e, 1, 1] * dg)
        pred[e, 0], pred[e, 1] = fl, fg
        lat, lon = grip(code[e], tp[e], fz[e])
        beyond = beyond or abs(fl) > lat * (1.0 + GRIP_SLACK) or abs(fg) > lon * (1.0 + GRIP_SLACK)
    return beyond


@_inline
def _converged(f, pred, fz, pack):
    """Whether the tyre forces `f` where the step arrived are those its linearisation predicted (`pred`), within
    :data:`GRIP_SLACK` of each tyre's grip."""
    code, tp = pack[3], pack[4]
    for e in range(code.shape[0]):
        if code[e] == 0:
            continue
        lat, lon = grip(code[e], tp[e], fz[e])
        if abs(f[e, 0] - pred[e, 0]) > GRIP_SLACK * lat or abs(f[e, 1] - pred[e, 1]) > GRIP_SLACK * lon:
            return False
    return True


#: Most trial steps of a line search (:func:`line_search`) besides the full step and the slips' zero crossings.
HALVINGS = 6


@_called
def newton_matrix(mat, rhs, lt, d_lin, t, r0):
    """An iteration's Newton matrix and the residual it starts from: ``mat`` (``M - dt A' G_i A - dt K``) less the
    loads' share `lt` (``T``, ``w[29]``: :func:`relinearise`), and the residual of ``mat d = rhs`` at the velocity
    change the iteration was linearised at, `d_lin` (``w[24]``), into `r0` (``w[34]``, for :func:`line_search`).
    Called from the step loop, not inlined, and given the arrays it reads rather than the work and model tuples (a
    kernel taking those compiles 0.4 s longer: docs/limits.md, "First run on a machine")."""
    n = rhs.shape[0]
    for i in range(n):
        for j in range(n):
            mat[i, j] -= lt[i, j]
    held_residual(mat, d_lin, rhs, t, r0)


@_inline
def held_residual(mat, d, rhs, t, r):
    """``r = mat d - rhs``, the residual of the step's linear system at `d`; returns its squared norm over the
    coordinates the gears and linkages leave free (:func:`_held_norm`)."""
    n = d.shape[0]
    for i in range(n):
        acc = -rhs[i]
        for j in range(n):
            acc += mat[i, j] * d[j]
        r[i] = acc
    return _held_norm(r, t)


@_inline
def _held_norm(r, t):
    """``|t' r|^2`` for the basis ``t (n, p)`` of the motions the gears and linkages allow (a coupling's reaction is
    no residual: :func:`~._integrate.solve_held`), ``|r|^2`` for ``p = 0`` (no coupling)."""
    n, p = t.shape
    total = 0.0
    if p == 0:
        for i in range(n):
            total += r[i] * r[i]
        return total
    for k in range(p):
        acc = 0.0
        for i in range(n):
            acc += t[i, k] * r[i]
        total += acc * acc
    return total


@_called
def line_search(s, dt, w, pack, t):
    """A step along the Newton direction of an iteration that does not reduce the residual: ``w[9]`` (the Newton
    step ``d``, from ``d_lin = w[24]``) becomes ``d_lin + lam (d - d_lin)``, the `lam` of least residual ``R(d) =
    (M - dt K) d - rhs - A' (F(nu + dt d, Fz(d)) - F)`` (over the coordinates the basis `t` leaves free:
    :func:`held_residual`) among the full step, the zero crossings of the contacts' slip velocities along it (a
    tyre's force is steep there and flat beyond: a step linearised where it slides jumps across the crossing, to the
    other side of the grip) and :data:`HALVINGS` halvings; returns `lam` (1: the full step reduced the residual).

    ``R`` along the step, from the residual ``R0 = w[34]`` at ``d_lin`` (:func:`held_residual`, unprojected) and
    the iteration's linearisation (forces ``F_i = w[23]``, Jacobian ``w[5]``, loads' share ``w[29]``):
    ``R0 + lam (M - dt K) p - A' (F(d) - F_i)``, ``p = d - d_lin``, ``(M - dt K) p = -R0 + dt A' G_i A p + T p``
    (the Newton matrix's ``J p = -R0``)."""
    a, g, d, d_lin, lt = w[0], w[5], w[9], w[24], w[29]
    r0, v, trial = w[34], w[35], w[36]
    code = pack[3]
    n = d.shape[0]
    for c in range(n):
        trial[c] = d[c] - d_lin[c]  # p
    for i in range(n):
        acc = -r0[i]
        for j in range(n):
            acc += lt[i, j] * trial[j]
        v[i] = acc
    for e in range(code.shape[0]):
        pl, pg = 0.0, 0.0
        for c in range(n):
            pl += a[2 * e, c] * trial[c]
            pg += a[2 * e + 1, c] * trial[c]
        ql = dt * (g[e, 0, 0] * pl + g[e, 0, 1] * pg)
        qg = dt * (g[e, 1, 0] * pl + g[e, 1, 1] * pg)
        for c in range(n):
            v[c] += a[2 * e, c] * ql + a[2 * e + 1, c] * qg
    target = _held_norm(r0, t) * (1.0 - 1e-4)  # a sufficient decrease from the step's start
    best, lam, half, m = 0.0, 1.0, 1.0, 2 * code.shape[0]
    for q in range(-1, m + HALVINGS):  # the full step, the slips' zero crossings along it, the halvings: one call
        if q < 0:  # of the trial's residual to compile (each inlined copy took a second of the first compile)
            x = 1.0
        elif q < m:  # slip velocity q // 2 (lateral, longitudinal) at both ends of the step
            if code[q // 2] == 0:
                continue
            v0, v1 = 0.0, 0.0
            for c in range(n):
                v0 += a[q, c] * (s[n + c] + dt * d_lin[c])
                v1 += a[q, c] * (s[n + c] + dt * d[c])
            if not v0 * v1 < 0.0:
                continue
            x = v0 / (v0 - v1)
        else:
            half *= 0.5
            x = half
        now = _trial_residual(s, dt, w, pack, t, x)
        if q < 0:
            if now <= target:
                break
            best = now
        elif now < best:
            best, lam = now, x
    return _take(d, d_lin, trial, lam)


@_inline
def _take(d, d_lin, p, lam):
    """``d = d_lin + lam p``; returns `lam`."""
    for c in range(d.shape[0]):
        d[c] = d_lin[c] + lam * p[c]
    return lam


@_inline
def _trial_residual(s, dt, w, pack, t, lam):
    """The squared residual of :func:`line_search` at ``d_lin + lam p`` (``p`` in ``w[36]``; the trial's loads,
    forces and residual in the scratch ``w[31]``, ``w[32]``, ``w[37]``, its velocity and velocity change in
    ``w[38]``, ``w[39]``; the re-linearisation's forces ``w[23]`` unchanged)."""
    a, d_lin, f_i, p, fz_t, f_t, r = w[0], w[24], w[23], w[36], w[31], w[32], w[37]
    r0, v, nu_t, d_t = w[34], w[35], w[38], w[39]
    n = d_lin.shape[0]
    for c in range(n):
        d_t[c] = d_lin[c] + lam * p[c]
        nu_t[c] = s[n + c] + dt * d_t[c]
    normal_loads(w[10], s[n:], d_t, pack, fz_t)
    contact_forces(a, nu_t, pack, fz_t, f_t, w[5], w[25], runtime_value(False))  # no `g` without the Jacobian
    for c in range(n):
        r[c] = r0[c] + lam * v[c]
    for c in range(n):
        for e in range(f_t.shape[0]):
            r[c] -= a[2 * e, c] * (f_t[e, 0] - f_i[e, 0]) + a[2 * e + 1, c] * (f_t[e, 1] - f_i[e, 1])
    return _held_norm(r, t)


@_called
def relinearise(s, dt, w, pack, damped):
    """One Newton iteration of the implicit step in the tyre forces and the normal loads; True when it has converged.

    Linearise the forces at the velocity the step reached, ``nu + dt dnu`` (``dnu`` in ``w[9]``), and at the loads
    of its acceleration, ``Fz(dnu)`` (``w[28]``, :func:`loads_moved`, which become ``w[3]``): converged when they
    are the predicted ones (``w[27]``), ``w[9]`` then holding ``dnu`` again; otherwise ``w[9]`` becomes the
    right-hand side of the next solve, ``rhs + A' (F_i - F - dt G_i A dnu) - T dnu`` with the matrix ``M - dt A' G_i
    A - dt K - T`` (``G_i`` left in ``w[5]``, ``T = A' dF/dFz dFz/dnu'`` in ``w[29]``: :func:`_load_terms`).
    A `damped` iteration (shortened by :func:`line_search`) has not converged: its linearisation's own residual is
    left."""
    a, fz, f0, g, rhs = w[0], w[3], w[4], w[5], w[9]
    rhs0, nu_i, f_i, d_lin, vw, lt = w[21], w[22], w[23], w[24], w[25], w[29]
    n = rhs.shape[0]
    for c in range(n):
        d_lin[c] = rhs[c]
        nu_i[c] = s[n + c] + dt * rhs[c]
    for e in range(fz.shape[0]):
        fz[e] = w[28][e]
    contact_forces(a, nu_i, pack, fz, f_i, g, vw, runtime_value(True))  # one compiled _contacts
    if not damped and _converged(f_i, w[27], fz, pack):
        return True
    _load_terms(s, w, pack)
    for c in range(n):
        rhs[c] = rhs0[c]
        for j in range(n):
            rhs[c] -= lt[c, j] * d_lin[j]
    for e in range(f_i.shape[0]):
        dl, dg = 0.0, 0.0
        for c in range(n):
            dl += a[2 * e, c] * d_lin[c]
            dg += a[2 * e + 1, c] * d_lin[c]
        r0 = f_i[e, 0] - f0[e, 0] - dt * (g[e, 0, 0] * dl + g[e, 0, 1] * dg)
        r1 = f_i[e, 1] - f0[e, 1] - dt * (g[e, 1, 0] * dl + g[e, 1, 1] * dg)
        for c in range(n):
            rhs[c] += a[2 * e, c] * r0 + a[2 * e + 1, c] * r1
    return False


@_inline
def _load_terms(s, w, pack):
    """``T = A' (dF/dFz) (dFz/dnu')`` into ``w[29]``: how the tyre forces at ``nu_i`` (``w[22]``, forces ``w[23]``)
    follow the step's acceleration ``d_lin`` (``w[24]``) through the loads it transfers (forward differences: the
    loads are affine in the acceleration until they clip at 0; scratch ``w[30:33]``)."""
    a, fz, g, d_lin, vw, lt = w[0], w[3], w[5], w[24], w[25], w[29]
    gz, fz_h, f_h = w[30], w[31], w[32]
    n = d_lin.shape[0]
    for e in range(fz.shape[0]):
        fz_h[e] = fz[e] + 1e-6 * (1.0 + fz[e])
    contact_forces(a, w[22], pack, fz_h, f_h, g, vw, runtime_value(False))  # no `g` written
    for e in range(fz.shape[0]):
        hz = fz_h[e] - fz[e]
        gz[e, 0], gz[e, 1] = (f_h[e, 0] - w[23][e, 0]) / hz, (f_h[e, 1] - w[23][e, 1]) / hz
    for c in range(n):
        h = 1e-6 * (1.0 + abs(d_lin[c]))
        keep = d_lin[c]
        d_lin[c] = keep + h
        normal_loads(w[10], s[n:], d_lin, pack, fz_h)
        d_lin[c] = keep
        for i in range(n):
            lt[i, c] = 0.0
        for e in range(fz.shape[0]):
            dz = (fz_h[e] - fz[e]) / h
            if dz == 0.0:
                continue
            for i in range(n):
                lt[i, c] += (a[2 * e, i] * gz[e, 0] + a[2 * e + 1, i] * gz[e, 1]) * dz
