"""The semi-implicit step at the tyres' grip: when to re-linearise, and one Newton iteration's forces.

The step linearises the tyre forces at its start, ``F + dt G A dnu``, and a tyre's slope does not saturate: from
rest (zero slip) the first step would grip at many times ``mu Fz`` and the next step's load transfer would empty the
drive wheels (docs/dynamics.md, "a start from rest"). A step whose linearised force exceeds the tyre's grip
(:func:`~._kernels.grip`, :func:`beyond_grip`) is linearised again where it arrived (:func:`relinearise`) and
solved again (:func:`wmrkit.dynamics._integrate.run_semi_implicit`), until its forces are those its
linearisation predicted. The re-linearisation is rare: it is compiled once and called, not inlined into the step
loop, and its tyre forces are the compiled copy the step and the records call (:func:`~._kernels.contact_forces`).

Work arrays (:func:`~._integrate.work_arrays`): ``w[21]`` the step's right-hand side ``rhs``, ``w[22]`` the
velocity of the re-linearisation, ``w[23]`` its forces, ``w[24]`` the velocity change it was taken at, ``w[25]``
its wheel speeds, ``w[26]`` 1 after a re-linearisation (the next step refreshes the tyre Jacobian), ``w[27]`` the
forces the linearisation predicts.
"""

from __future__ import annotations

from .._jit import runtime_value
from ._kernels import _called, _inline, contact_forces, grip

#: Newton iterations at most in a semi-implicit step whose linearised tyre forces exceed their grip.
GRIP_ITERATIONS = 8
#: How far (relative) a linearised tyre force may exceed the tyre's grip before the step is re-linearised.
GRIP_SLACK = 1e-3


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


@_called
def relinearise(s, dt, w, pack):
    """One Newton iteration of the implicit step in the tyre forces; True when it has converged.

    Linearise the forces at the velocity the step reached, ``nu + dt dnu`` (``dnu`` in ``w[9]``): converged when
    they are the predicted ones (``w[27]``), ``w[9]`` then holding ``dnu`` again; otherwise ``w[9]`` becomes the
    right-hand side of the next solve, ``rhs + A' (F_i - F - dt G_i A dnu)`` with the matrix ``M - dt A' G_i A - dt
    K`` (``G_i`` left in ``w[5]``)."""
    a, fz, f0, g, rhs = w[0], w[3], w[4], w[5], w[9]
    rhs0, nu_i, f_i, d_lin, vw = w[21], w[22], w[23], w[24], w[25]
    n = rhs.shape[0]
    for c in range(n):
        d_lin[c] = rhs[c]
        nu_i[c] = s[n + c] + dt * rhs[c]
    contact_forces(a, nu_i, pack, fz, f_i, g, vw, runtime_value(True))  # one compiled _contacts
    if _converged(f_i, w[27], fz, pack):
        return True
    for c in range(n):
        rhs[c] = rhs0[c]
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
