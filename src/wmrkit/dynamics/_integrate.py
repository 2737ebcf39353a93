"""Compiled time stepping of the dynamic model: joint inputs, the equations of motion, fixed-step integrators.

State ``s (2n,)``: pose ``(x, y, theta)`` in the world, the joint positions of the columns ``3..n-1`` of the
velocity vector (so the steering angle of column c is ``s[c]``), then the velocity vector ``nu (n,)``.
Inputs ``inp``: ``(tk (K,), tau (K, n), rate_ref (K, n), rate_gain (n,), tau_max (n,), beta_ref (K, S), kp (S,),
kd (S,), steer_max (S,))``, linear in time between the knots ``tk``, held outside them: feed-forward torques,
wheel-rate servos ``tau += rate_gain (rate_ref - rate)`` saturated at ``tau_max``, steering servos ``u = kp
wrap(beta_ref - beta) - kd beta_dot``, saturated smoothly as ``steer_max tanh(u / steer_max)`` where ``steer_max >
0``: the damping stays in the implicit matrix, so a saturated servo does not chatter between its limits.

Speed (issue 10): the kernels of a step are inlined into :func:`run_semi_implicit`, which is compiled without numba's
reference counting (nothing in it allocates), but for the mass matrix, the normal loads, the tyre forces, the linear
solve and a record's row, called (compiled once: :func:`wmrkit.dynamics._kernels._called`); a record reuses the
assembly of the step that starts at its time.
The first compile (docs/limits.md, "First run on a machine"): the step is written in the loop, not inlined from
nested functions (:func:`_semi_implicit_kernel`), and every kernel is compiled for one set of argument types.
"""

from __future__ import annotations

import math

import numpy as np

from .._jit import runtime_value
from ._kernels import (
    _called,
    _inline,
    _njit,
    bias,
    contact_forces,
    hold_linkages,
    mass_matrix,
    normal_loads,
    slip_matrix,
    solve_in_place,
)
from ._newton import GRIP_ITERATIONS, beyond_grip, line_search, loads_moved, newton_matrix, relinearise


@_inline
def _segment(tk, t):
    k = np.searchsorted(tk, t) - 1
    if k < 0:
        return 0, 0, 0.0
    if k >= tk.shape[0] - 1:
        return tk.shape[0] - 1, tk.shape[0] - 1, 0.0
    return k, k + 1, (t - tk[k]) / (tk[k + 1] - tk[k])


@_inline
def _interp(values, k, k1, w, out):
    for j in range(out.shape[0]):
        out[j] = (1 - w) * values[k, j] + w * values[k1, j]


@_inline
def assemble(t, s, acc, pack, inp, jac, w):
    """Everything at state `s`, time `t`, into the work arrays `w` (see :func:`work_arrays`); returns nothing.

    ``w = (a, m, dm, fz, f, g, vw, tau, kdiag, rhs, beta, beta_rate, rate_ref, beta_ref, mat, filled, lift, red, y,
    basis, c)`` (``lift``: 1, the time and the contact of the first lift-off, see
    :func:`wmrkit.dynamics.runs.check_lift_off`; ``basis``, ``c``: :func:`solve_held`). `s` holds the linkages
    (its callers set it on them: :func:`~._kernels.hold_linkages`; writing `s` here cost the fixed-step loop of a
    robot without a linkage 7 %);
    ``rhs = tau + A' F + bias`` so that
    ``m nu' = rhs``; ``kdiag`` holds the servo terms of ``d rhs / d nu``.
    """
    a, m, dm, fz, f, g, vw, tau, kdiag, rhs, beta, beta_rate = w[:12]
    n = rhs.shape[0]
    steer_col = pack[5]
    nu = s[n:]
    for k in range(steer_col.shape[0]):
        beta[k], beta_rate[k] = s[steer_col[k]], nu[steer_col[k]]
    filled = w[15][0] == 1.0
    slip_matrix(beta, pack, n, a, filled)
    castors = False
    for k in range(steer_col.shape[0]):
        castors = castors or pack[6][k] == 1
    if not filled or castors:  # without castor units M does not depend on the configuration
        mass_matrix(beta, pack, n, m, dm)
    w[15][0] = 1.0
    normal_loads(beta, nu, acc, pack, fz)
    lift = w[16]
    if lift[0] == 0.0:  # the first contact loaded at rest whose load is clipped to 0: it lifts off
        for e in range(fz.shape[0]):
            if fz[e] <= 0.0 and pack[15][e] > 0.0:
                lift[0], lift[1], lift[2] = 1.0, t, e
                break
    contact_forces(a, nu, pack, fz, f, g, vw, jac)
    tk, tff, rref, rgain, tmax, bref, kp, kd, smax = inp
    k0, k1, wt = _segment(tk, t)
    rr, br = w[12], w[13]
    _interp(tff, k0, k1, wt, tau)
    _interp(rref, k0, k1, wt, rr)
    _interp(bref, k0, k1, wt, br)
    kdiag[:] = 0.0
    group, ratio = pack[13], pack[14]
    met, err, total = -1, 0.0, 1.0
    for c in range(n):
        if rgain[c] > 0:
            if group[c] < 0:
                met, err, total, slope = -1, rr[c] - nu[c], 1.0, 1.0
            else:  # a differential: one servo on the carrier's rate error (model._differentials), summed once
                if group[c] != met:
                    met, err, total = group[c], 0.0, 0.0
                    for d in range(n):
                        if group[d] == met:
                            err += ratio[d] * (rr[d] - nu[d])
                            total += ratio[d]
                slope = ratio[c]  # d tau_c / d nu_d = -k ratio_d for every member d
            k = rgain[c] / total  # a differential's: the joint's own stiffness while the others keep pace
            u = tau[c] + k * err
            if abs(u) > tmax[c]:
                u = math.copysign(tmax[c], u)
            else:
                kdiag[c] = -k * slope
            tau[c] = u
    for k in range(steer_col.shape[0]):
        c = steer_col[k]
        err = br[k] - beta[k]
        err = err - 2 * math.pi * math.floor((err + math.pi) / (2 * math.pi))
        u = kp[k] * err - kd[k] * nu[c]
        if smax[k] > 0.0:  # u -> smax tanh(u / smax): d/d nu = -kd (1 - tanh^2)
            th = math.tanh(u / smax[k])
            tau[c] += smax[k] * th
            kdiag[c] -= kd[k] * (1.0 - th * th)
        else:
            tau[c] += u
            kdiag[c] -= kd[k]
    bias(nu, beta_rate, m, dm, steer_col, pack[6], rhs)
    for c in range(n):
        acc_c = tau[c]
        for e in range(f.shape[0]):
            acc_c += a[2 * e, c] * f[e, 0] + a[2 * e + 1, c] * f[e, 1]
        rhs[c] += acc_c


def work_arrays(n: int, n_el: int, n_steer: int, n_geared: int = 0) -> tuple:
    """Scratch arrays of :func:`assemble`, of :func:`solve_geared` (`n_geared`: the columns of the model's gear
    basis, ``pack[16]``) and of the step's Newton iterations at the grip and the loads (``w[21:40]``:
    :mod:`._newton`)."""
    return (np.zeros((2 * n_el, n)), np.zeros((n, n)), np.zeros((n_steer, n, n)), np.zeros(n_el),
            np.zeros((n_el, 2)), np.zeros((n_el, 2, 2)), np.zeros(n_el), np.zeros(n), np.zeros(n), np.zeros(n),
            np.zeros(n_steer), np.zeros(n_steer), np.zeros(n), np.zeros(n_steer), np.zeros((n, n)),
            np.zeros(1), np.zeros(3), np.zeros((n_geared, n_geared)), np.zeros(n_geared), np.zeros((n, n_geared)),
            np.zeros(n), np.zeros(n), np.zeros(n), np.zeros((n_el, 2)), np.zeros(n), np.zeros(n_el),
            np.zeros(1), np.zeros((n_el, 2)), np.zeros(n_el), np.zeros((n, n)), np.zeros((n_el, 2)),
            np.zeros(n_el), np.zeros((n_el, 2)), np.zeros(n), np.zeros(n), np.zeros(n), np.zeros(n), np.zeros(n),
            np.zeros(n), np.zeros(n))


def model_work_arrays(model) -> tuple:
    """:func:`work_arrays` of a :class:`wmrkit.dynamics.model.DynamicModel` (its basis copied in: the linkages'
    entries of it change with the state)."""
    w = work_arrays(model.n, len(model.contacts), len(model.steer_columns), model.pack[16].shape[1])
    w[19][:] = model.pack[16]
    return w


@_inline
def solve_geared(mat, rhs, t, red, y):
    """`rhs` becomes ``mat^-1 rhs`` with the gears held: ``T (T' mat T)^-1 T' rhs`` for the gear basis ``t (n, p)``
    (``model.gear_basis``; the plain solve when ``p = 0``, no gear); `mat` is overwritten, `red` ``(p, p)`` and
    `y` ``(p,)`` are scratch."""
    n, p = t.shape
    if p == 0:
        solve_in_place(mat, rhs)
        return
    for i in range(p):
        acc = 0.0
        for k in range(n):
            acc += t[k, i] * rhs[k]
        y[i] = acc
    for k in range(n):  # mat <- mat T, in its first p columns
        for i in range(p):
            acc = 0.0
            for l in range(n):
                acc += mat[k, l] * t[l, i]
            rhs[i] = acc  # rhs is free once y holds T' rhs: a row of (mat T)
        for i in range(p):
            mat[k, i] = rhs[i]
    for i in range(p):
        for j in range(p):
            acc = 0.0
            for k in range(n):
                acc += t[k, i] * mat[k, j]
            red[i, j] = acc
    solve_in_place(red, y)
    for k in range(n):
        acc = 0.0
        for i in range(p):
            acc += t[k, i] * y[i]
        rhs[k] = acc


@_inline
def solve_held(mat, rhs, pack, w):
    """:func:`solve_geared` with the linkages held too: ``nu' = T p' + c`` with the state's basis ``T = w[19]`` and
    velocity-product accelerations ``c = w[20]`` (filled by :func:`assemble`), so ``rhs`` becomes ``T (T' mat
    T)^-1 T' (rhs - mat c) + c``; without a linkage exactly :func:`solve_geared` on the model's basis."""
    linked, c, n = pack[17].shape[0] > 0, w[20], rhs.shape[0]
    if linked:
        for i in range(n):
            acc = 0.0
            for j in range(n):
                acc += mat[i, j] * c[j]
            rhs[i] -= acc
    solve_geared(mat, rhs, w[19] if linked else pack[16], w[17], w[18])  # one copy of the solve, inlined
    if linked:
        for i in range(n):
            rhs[i] += c[i]


#: :func:`assemble` compiled once and called, for the records (:func:`observe`, the last one of a run) and the explicit
#: derivative: its own source compiled (inlined into each of them the model was compiled once more per caller, 100 s
#: of CPU the first time ``wmrkit simulate`` ran, against 60 s; inlined into a wrapper, once more for the wrapper).
#: The step loop keeps its own inlined copy: called, the model's and work arrays are passed by value at every step
#: (measured up to 10 % more a step, under load).
assembled = _njit(assemble.py_func, nrt=False)


@_njit
def derivative(t, s, acc, pack, inp, w):
    """``ds/dt`` (explicit form): pose rate from the twist (3.15), joint rates, ``nu' = M^-1 rhs``; `s` is not
    changed (a copy is set on the linkages)."""
    if pack[17].shape[0] > 0:
        s = s.copy()
        hold_linkages(s, pack, w[19], w[20], True)
    assembled(t, s, acc, pack, inp, runtime_value(False), w)
    n = w[9].shape[0]
    out = np.empty(2 * n)
    th = s[2]
    out[0] = math.cos(th) * s[n] - math.sin(th) * s[n + 1]
    out[1] = math.sin(th) * s[n] + math.cos(th) * s[n + 1]
    out[2:n] = s[n + 2:2 * n]
    out[n:] = w[9]
    solve_held(w[1].copy(), out[n:], pack, w)
    acc[:] = out[n:]
    return out


@_inline
def _implicit_matrix(a, m, g, kdiag, pack, dt, mat):
    """``mat = M - dt (A' G A + servo terms)``: the matrix of the linearly implicit step (tyre Jacobian `g`)."""
    n = mat.shape[0]
    for i in range(n):
        for j in range(n):
            mat[i, j] = m[i, j]
    for e in range(g.shape[0]):
        for i in range(n):
            a0, a1 = a[2 * e, i], a[2 * e + 1, i]
            if a0 == 0.0 and a1 == 0.0:
                continue
            g00, g01 = a0 * g[e, 0, 0] + a1 * g[e, 1, 0], a0 * g[e, 0, 1] + a1 * g[e, 1, 1]
            for j in range(n):
                b0, b1 = a[2 * e, j], a[2 * e + 1, j]
                if b0 == 0.0 and b1 == 0.0:
                    continue
                mat[i, j] -= dt * (g00 * b0 + g01 * b1)
    group, ratio = pack[13], pack[14]
    for c in range(n):
        mat[c, c] -= dt * kdiag[c]
        if group[c] >= 0 and kdiag[c] != 0.0:  # a differential's servo couples its joints: -k ratio_d
            for d in range(n):
                if d != c and group[d] == group[c]:
                    mat[c, d] -= dt * kdiag[c] * ratio[d] / ratio[c]


@_njit
def step_rk4(t, s, dt, acc, pack, inp, w):
    """One classical Runge-Kutta step (explicit; for smooth, non-stiff cases such as frictionless checks)."""
    k1 = derivative(t, s, acc, pack, inp, w)
    k2 = derivative(t + dt / 2, s + dt / 2 * k1, acc, pack, inp, w)
    k3 = derivative(t + dt / 2, s + dt / 2 * k2, acc, pack, inp, w)
    k4 = derivative(t + dt, s + dt * k3, acc, pack, inp, w)
    s += dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
    hold_linkages(s, pack, w[19], w[20], True)


@_inline
def _observe(t, s, acc, pack, inp, w, rec, i):
    assembled(t, s, acc, pack, inp, runtime_value(False), w)
    _store(t, s, w, rec, i)


@_inline
def _store(t, s, w, rec, i):
    """Row `i` of the records from the state `s` at time `t` and its assembly `w` (:func:`_row`)."""
    _row(t, s, w[0], w[7], w[3], w[4], w[6], rec, i)


@_called
def _row(t, s, a, tau, fz, f, vw, rec, i):
    """:func:`_store` on the work arrays it reads. Called, not inlined: the step loop and the last record share one
    compiled copy (a record is a row in every tenth step or fewer; inlined twice it was a tenth of the loop's code)."""
    r_t, r_s, r_f, r_fz, r_v, r_vw, r_tau = rec
    n = tau.shape[0]
    r_t[i] = t
    for c in range(2 * n):
        r_s[i, c] = s[c]
    for c in range(n):
        r_tau[i, c] = tau[c]
    for e in range(r_v.shape[1]):
        r_fz[i, e], r_vw[i, e] = fz[e], vw[e]
        for k in range(2):
            v = 0.0
            for c in range(n):
                v += a[2 * e + k, c] * s[n + c]
            r_v[i, e, k], r_f[i, e, k] = v, f[e, k]


@_njit
def _hold(s, pack, w):
    hold_linkages(s, pack, w[19], w[20], True)


def observe(t, s, acc, pack, inp, w, rec, i):
    """Store the state's outputs in the record arrays ``rec`` at row `i`, `s` first set on the linkages (an
    adaptive run's states: the solver integrates the followers too). Calls from Python into kernels the step loop
    compiles anyway (:func:`assembled`) or small ones, and :func:`_store`'s few products as Python (the same
    arithmetic): compiled as one kernel, they took 2.5 s of a first run to compile."""
    if pack[17].shape[0] > 0:
        _hold(s, pack, w)
    assembled(t, s, acc, pack, inp, False, w)
    _row.py_func(t, s, w[0], w[7], w[3], w[4], w[6], rec, i)


def _semi_implicit_kernel(linked: bool):
    """:func:`run_semi_implicit` compiled with `linked` a constant of its closure: for a robot without a linkage the
    linkages' code is compiled out of its loop (in it, not taken, it cost 5-7 %).

    The step is written in the loop rather than inlined from shared functions: numba inlines a function by copying
    its IR block by block, each block with a copy of every variable of the function, a cost that grows with the
    square of its size and again at each level of nesting; the loop and the step, each inlined, took 60 % of the
    first compile of ``wmrkit simulate`` (docs/limits.md, "First run on a machine")."""

    def run_semi_implicit(s, k0, dt, n_steps, every, jac_every, jac_phase, acc, pack, inp, w, rec, i0):
        """`n_steps` linearly implicit Euler steps from `s` (changed in place) at step `k0` (``t = k0 dt``); a record
        every `every` steps from row `i0`; returns the next row. Compiled without reference counting (it allocates
        nothing).

        Each step assembles the model (:func:`assemble`), then takes the friction and servo Jacobians implicit and
        the positions with the new velocity. The tyre Jacobian ``dF/dv_slip`` is refreshed at the steps ``k =
        jac_phase (mod jac_every)`` and reused otherwise (a W-method). A step whose linearised tyre forces exceed
        their grip, or whose acceleration transfers loads that move them, is linearised again where it arrived, at
        those loads, and solved again: Newton iterations of the implicit step in the forces and the loads
        (:mod:`._newton`, a line search along each), at most ``GRIP_ITERATIONS``; the next step then refreshes the
        Jacobian. One loop solves them all: one copy of the solve to compile (docs/limits.md)."""
        a, m, fz, f, g, kdiag, rhs, mat = w[0], w[1], w[3], w[4], w[5], w[8], w[9], w[14]
        n = rhs.shape[0]
        i = i0
        for j in range(n_steps):
            k = k0 + j
            assemble(k * dt, s, acc, pack, inp, (k - jac_phase) % jac_every == 0 or w[26][0] == 1.0, w)
            if j > 0 and k % every == 0 and i < rec[0].shape[0]:  # the step's assembly is the record at t = k dt
                _store(k * dt, s, w, rec, i)
                i += 1
            for c in range(n):
                w[21][c] = rhs[c]
                w[24][c] = 0.0
            if linked:
                hold_linkages(s, pack, w[19], w[20], False)  # the linkages' basis at the step's start
            w[26][0] = 0.0
            basis = w[19] if linked else pack[16]
            it, lam = 0, 1.0
            while True:
                _implicit_matrix(a, m, g, kdiag, pack, dt, mat)
                if it > 0:  # the loads' share of the Newton matrix, the residual where the iteration was linearised
                    newton_matrix(mat, rhs, w[29], w[24], basis, w[34])
                solve_held(mat, rhs, pack, w)  # (M - dt K) dnu/dt = rhs: rhs becomes dnu/dt, gears, linkages held
                if it > 0:
                    lam = line_search(s, dt, w, pack, basis)  # a Newton step that does not reduce the residual
                beyond = beyond_grip(a, rhs, w[24], w[23] if it > 0 else f, g, fz, pack, dt, w[27])
                moved = loads_moved(s, rhs, w[10], fz, w[28], w[27], pack)
                if it == 0:
                    at_grip = beyond
                    for c in range(n):
                        w[33][c] = rhs[c]  # the step at the previous step's loads
                if it == GRIP_ITERATIONS or (it == 0 and not beyond and not moved):
                    if it > 0 and not at_grip:  # the loads' iterations did not converge: the previous loads' step
                        for c in range(n):
                            rhs[c] = w[33][c]
                    break
                w[26][0] = 1.0  # `g` becomes the Jacobian where the step arrived: the next step refreshes it
                if relinearise(s, dt, w, pack, lam < 1.0):
                    break
                it += 1
            dnu = rhs
            for c in range(n):
                acc[c] = dnu[c]
                s[n + c] += dt * dnu[c]
            th = s[2] + 0.5 * dt * s[n + 2]
            s[0] += dt * (math.cos(th) * s[n] - math.sin(th) * s[n + 1])
            s[1] += dt * (math.sin(th) * s[n] + math.cos(th) * s[n + 1])
            for c in range(2, n):
                s[c] += dt * s[n + c]
            if linked:
                hold_linkages(s, pack, w[19], w[20], True)  # the followers set from their leaders (no drift)
        k = k0 + n_steps
        if n_steps > 0 and k % every == 0 and i < rec[0].shape[0]:
            _observe(k * dt, s, acc, pack, inp, w, rec, i)
            i += 1
        return i

    return _njit(run_semi_implicit, nrt=False)


run_semi_implicit = _semi_implicit_kernel(False)
#: :func:`run_semi_implicit` holding the linkages (``pack[17]``): each step sets the followers from their leaders;
#: compiled at its first use, by a robot with a linkage.
run_semi_implicit_linked = _semi_implicit_kernel(True)


@_njit
def run_rk4(s, k0, dt, n_steps, every, acc, pack, inp, w, rec, i0):
    """`n_steps` RK4 steps from `s` (changed in place) at step `k0`; records as :func:`run_semi_implicit`."""
    i = i0
    for j in range(n_steps):
        k = k0 + j
        step_rk4(k * dt, s, dt, acc, pack, inp, w)
        if (k + 1) % every == 0 and i < rec[0].shape[0]:
            _observe((k + 1) * dt, s, acc, pack, inp, w, rec, i)
            i += 1
    return i


def run(s, k0, dt, n_steps, every, method, jac_every, acc, pack, inp, w, rec, i0, jac_phase=0):
    """`n_steps` fixed steps from `s` (changed in place) at step `k0` (``t = k0 dt``); a record every `every` steps
    from row `i0`. Running in chunks gives the same result as one run.

    `method` 0: semi-implicit, refreshing the tyre Jacobian every `jac_every` steps (from step `jac_phase`); 1: RK4.
    A state that overflows (the compiled kernels then raise ZeroDivisionError) comes back as NaN, for the caller's
    divergence check.
    """
    if pack[17].shape[0]:  # a state changed in between (Stepper.state is the caller's) starts on the linkages
        _hold(s, pack, w)
    try:
        if method == 0:
            steps = run_semi_implicit_linked if pack[17].shape[0] else run_semi_implicit
            return steps(s, k0, dt, n_steps, every, jac_every, jac_phase, acc, pack, inp, w, rec, i0)
        return run_rk4(s, k0, dt, n_steps, every, acc, pack, inp, w, rec, i0)
    except ZeroDivisionError:
        s[:] = math.nan
        return i0

