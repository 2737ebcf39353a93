"""Pose uncertainty: noise models of the increments and covariance propagation through any integration scheme.

Paper 003 (14)-(17): ``X(k+1) = f(X(k), U(k)) + v(k)``, with Crowley's input covariance ``Q(k) = diag(K_D |dD|,
K_Dtheta |dD| + K_theta |dtheta|)`` (typical K_D = 0.001 m^2/m, K_Dtheta = 0.003 rad^2/m, K_theta = 0.001
rad^2/rad; papers-odometry.md B.4; (17) is [RECONSTRUCTED] there). The first-order (EKF prediction) recursion

    ``P_k = F_k P_(k-1) F_k^T + G_k Q_k G_k^T``,  ``F = J_pose_pose``, ``G = J_pose_increment``,

is evaluated for all samples at once: ``F_k = I + E(p_k - p_(k-1))`` with ``E(d) = (-d_y, d_x, 0) e_3^T``, and
``E(a) E(b) = 0``, so ``F_n ... F_(k+1) = I + E(p_n - p_k)`` and ``P_n = sum_k Phi(n, k) C_k Phi(n, k)^T`` with
``C_0 = P_0`` expands into prefix sums of ``C_k``, ``C_k e_3``, ``p_k`` and ``p_k p_k^T`` [DERIVED]. No Python
loop; positions are taken relative to the first pose to keep the sums well conditioned.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields

import numpy as np
from numpy.typing import ArrayLike

from .._shapes import as_reals, as_vectors
from ..errors import ShapeError, WmrkitError
from .integrators import HEADING_FRACTION, Method, _finite, check_batches, check_method, sinc, sinc_derivative


@dataclass(frozen=True, slots=True)
class CrowleyNoise:
    """Crowley's odometry error model, 003 eq. (17) with the typical values of 003 (Crowley 1992).

    ``k_d`` [m^2/m], ``k_dtheta`` [rad^2/m], ``k_theta`` [rad^2/rad].
    """

    k_d: float = 0.001
    k_dtheta: float = 0.003
    k_theta: float = 0.001

    def __post_init__(self) -> None:
        _check_coefficients(self)

    def input_covariance(self, delta_d: ArrayLike, delta_theta: ArrayLike) -> np.ndarray:
        """Covariance of ``U = (dD, dtheta)``, 003 eqs. (15)-(17): ``(...), (...) -> (..., 2, 2)``."""
        dd, dth = (np.abs(_finite(as_reals(v, name), name)) for v, name in ((delta_d, "delta_d"),
                                                                             (delta_theta, "delta_theta")))
        try:
            dd, dth = np.broadcast_arrays(dd, dth)
        except ValueError:  # numpy's 'shape mismatch' named neither
            raise ShapeError(f"delta_d {dd.shape} and delta_theta {dth.shape}: their shapes do not broadcast") from None
        q = np.zeros((*dd.shape, 2, 2))
        q[..., 0, 0] = self.k_d * dd
        q[..., 1, 1] = self.k_dtheta * dd + self.k_theta * dth
        return q

    def increment_covariance(self, increments_robot: ArrayLike) -> np.ndarray:
        """Covariance of body increments ``(dx, dy, dtheta)`` for any robot, 003 (17) generalised [DERIVED].

        ``(..., 3) -> (..., 3, 3)``: ``K_D |dD|`` along the direction of travel ``(dx, dy) / dD`` (``dD`` the
        length of the body displacement), ``K_Dtheta |dD| + K_theta |dtheta|`` on the heading, no cross terms.
        For a differential drive (``dy = 0``) this is exactly (17) on ``(dD, dtheta)``.
        """
        inc = _finite(as_vectors(increments_robot, 3, "increments_robot"), "increments_robot")
        dd = np.hypot(inc[..., 0], inc[..., 1])
        safe = np.where(dd > 0, dd, 1.0)
        u = inc[..., :2] / safe[..., None]
        q = np.zeros((*inc.shape[:-1], 3, 3))
        q[..., :2, :2] = self.k_d * dd[..., None, None] * u[..., :, None] * u[..., None, :]
        q[..., 2, 2] = self.k_dtheta * dd + self.k_theta * np.abs(inc[..., 2])
        return q


@dataclass(frozen=True, slots=True)
class JointNoise:
    """Independent noise on each sensed joint increment, propagated through the robot's own kinematics.

    Variance of a joint's increment over an interval: ``per_rad * |dq| + per_sample`` [rad^2], with ``per_rad``
    [rad^2/rad] (rolling noise growing with the distance turned, the per-wheel analogue of Crowley's model)
    and ``per_sample`` [rad^2] (e.g. quantisation: two readings at resolution ``res`` give ``res^2 / 6``).
    """

    per_rad: float = 0.0
    per_sample: float = 0.0

    def __post_init__(self) -> None:
        _check_coefficients(self)

    def increment_covariance(self, twist_map: ArrayLike, rate_increments: ArrayLike) -> np.ndarray:
        """Covariance of body increments, ``S_t diag(sigma^2) S_t^T`` (first order in the ranks solution (4.11)).

        ``(..., 3, n_a), (..., n_a) -> (..., 3, 3)``: `twist_map` maps sensed joint increments to the body
        increment (:meth:`wmrkit.odometry.model.OdometryModel.matrices`, first three rows).
        """
        s = np.asarray(twist_map, dtype=float)
        var = self.per_rad * np.abs(np.asarray(rate_increments, dtype=float)) + self.per_sample
        return (s * var[..., None, :]) @ np.swapaxes(s, -1, -2)


class NoiseError(WmrkitError, ValueError):
    """A noise coefficient or a covariance that cannot be one: negative, not finite, not symmetric positive
    semi-definite. The message names the argument."""


def _check_coefficients(noise) -> None:
    """Every coefficient of a noise model finite and >= 0 (a negative variance gave negative covariances)."""
    for f in fields(noise):
        value = getattr(noise, f.name)
        if not (isinstance(value, int | float | np.floating) and not isinstance(value, bool)
                and math.isfinite(value) and value >= 0):
            raise NoiseError(f"{type(noise).__name__}.{f.name}: a noise coefficient must be finite and >= 0, "
                             f"got {value!r}")


def check_covariance(c: ArrayLike, what: str, *, definite: bool = False) -> np.ndarray:
    """`c` ``(3, 3)`` as floats, or :class:`NoiseError` naming `what` unless it is finite, symmetric (to 1e-9 of
    its largest entry; not averaged: an asymmetric matrix is a mistake) and positive semi-definite (`definite`:
    positive definite)."""
    c = np.asarray(c, dtype=float)
    if c.shape != (3, 3) or not np.isfinite(c).all():
        raise NoiseError(f"{what}: expected a finite (3, 3) matrix, got shape {c.shape}")
    scale = float(np.abs(c).max())
    if np.abs(c - c.T).max() > 1e-9 * scale:
        raise NoiseError(f"{what}: a covariance is symmetric, got {c.tolist()}")
    low = float(np.linalg.eigvalsh(c)[0])
    if low < -1e-12 * scale or (definite and not low > 1e-12 * scale):
        raise NoiseError(f"{what}: a covariance must be positive {'definite' if definite else 'semi-definite'}, "
                         f"its least eigenvalue is {low:.6g}")
    return c


def step_jacobians(pose_world_robot: ArrayLike, increment_robot: ArrayLike,
                   method: Method = "exact") -> tuple[np.ndarray, np.ndarray]:
    """Jacobians ``(J_pose_pose, J_pose_increment)`` of one step of :func:`~.integrators.step` (003 (14), (20)-(26)).

    ``(..., 3), (..., 3) -> (..., 3, 3), (..., 3, 3)``; derivatives of the new pose with respect to the old pose
    and to the body increment ``(dx, dy, dtheta)``. For Crowley's input ``(dD, dtheta)`` of a differential drive
    take columns 0 and 2 of ``J_pose_increment``.
    """
    check_method(method)
    pose = _finite(as_vectors(pose_world_robot, 3, "pose_world_robot"), "pose_world_robot")
    inc = _finite(as_vectors(increment_robot, 3, "increment_robot"), "increment_robot")
    check_batches(pose, "pose_world_robot", inc, "increment_robot")
    return _step_jacobians(pose, inc, method)


def _step_jacobians(pose: np.ndarray, inc: np.ndarray, method: Method) -> tuple[np.ndarray, np.ndarray]:
    """:func:`step_jacobians` on arrays already checked."""
    batch = np.broadcast_shapes(pose.shape[:-1], inc.shape[:-1])
    frac, dth = HEADING_FRACTION[method], inc[..., 2]
    head = pose[..., 2] + frac * dth
    c, s = np.cos(head), np.sin(head)
    if method == "exact":
        f, df = sinc(dth / 2), 0.5 * sinc_derivative(dth / 2)
    else:
        f, df = np.ones_like(dth), np.zeros_like(dth)
    rx, ry = c * inc[..., 0] - s * inc[..., 1], s * inc[..., 0] + c * inc[..., 1]  # Rot(head) (dx, dy)
    j_pp = np.broadcast_to(np.eye(3), (*batch, 3, 3)).copy()
    j_pp[..., 0, 2] = -f * ry
    j_pp[..., 1, 2] = f * rx
    j_pi = np.zeros((*batch, 3, 3))
    j_pi[..., 0, 0], j_pi[..., 1, 0] = f * c, f * s
    j_pi[..., 0, 1], j_pi[..., 1, 1] = -f * s, f * c
    j_pi[..., 0, 2] = df * rx - frac * f * ry
    j_pi[..., 1, 2] = df * ry + frac * f * rx
    j_pi[..., 2, 2] = 1.0
    return j_pp, j_pi


def propagate_covariance(poses_world_robot: ArrayLike, increments_robot: ArrayLike, increment_covariance: ArrayLike,
                         method: Method = "exact", *, initial: ArrayLike | None = None) -> np.ndarray:
    """Pose covariance after every step, first order, all steps at once (003 (14)-(17); module docstring).

    ``(N + 1, 3), (N, 3), (N, 3, 3) -> (N, 3, 3)``: `poses_world_robot` from the start pose to the last one
    (as integrated with `method`), the body increments and their covariance (e.g.
    :meth:`CrowleyNoise.increment_covariance`); `initial` ``(3, 3)`` is the start pose's covariance (default 0).
    Equal to the recursion ``P = F P F^T + G Q G^T`` to round-off.
    """
    # the Python API reads no units: text raised numpy's ValueError; a number as increments IndexError
    poses, inc, q = (as_reals(v, name) for name, v in (("poses_world_robot", poses_world_robot),
                                                       ("increments_robot", increments_robot),
                                                       ("increment_covariance", increment_covariance)))
    n = len(inc) if inc.ndim else 0
    if poses.shape != (n + 1, 3) or inc.shape != (n, 3) or q.shape != (n, 3, 3):
        raise WmrkitError(f"propagate_covariance: expected shapes (N + 1, 3), (N, 3), (N, 3, 3); got {poses.shape}, "
                          f"{inc.shape}, {q.shape}")
    _finite(poses, "poses_world_robot"), _finite(inc, "increments_robot")
    p0 = np.zeros((3, 3)) if initial is None else check_covariance(initial, "initial")
    scale = np.abs(q).max(initial=0.0)
    if not (np.isfinite(q).all() and (np.diagonal(q, axis1=-2, axis2=-1) >= 0).all()
            and np.abs(q - np.swapaxes(q, -1, -2)).max(initial=0.0) <= 1e-9 * scale):
        raise NoiseError("increment_covariance: every matrix must be finite and symmetric, with variances >= 0")
    low = np.linalg.eigvalsh(q)[:, 0] if n else np.zeros(0)
    if (low < -1e-12 * scale).any():
        k = int(np.argmax(low < -1e-12 * scale))
        raise NoiseError(f"increment_covariance: matrix {k} is not positive semi-definite (least eigenvalue "
                         f"{low[k]:.6g}): a covariance cannot be")
    return propagate_checked(poses, inc, q, method, p0)


def propagate_checked(poses: np.ndarray, inc: np.ndarray, q: np.ndarray, method: Method,
                      p0: np.ndarray) -> np.ndarray:
    """:func:`propagate_covariance` on arrays already checked (the pipeline's own, chunk after chunk: its
    overflows are located where they happen, not refused as input)."""
    _, g = _step_jacobians(poses[:-1], inc, method)
    c = np.concatenate([p0[None], g @ q @ np.swapaxes(g, -1, -2)])  # C_0 = P_0, C_k = G Q G^T
    rel = poses[:, :2] - poses[0, :2]
    b = np.stack([-rel[:, 1], rel[:, 0]], axis=-1)  # J p_k, 2-D part of (-y, x, 0)
    ck = c[:, :, 2]  # C_k e_3
    c33 = c[:, 2, 2]
    s_c = np.cumsum(c, axis=0)[1:]
    s_col = np.cumsum(ck, axis=0)[1:]
    s_bc = np.cumsum(b[:, :, None] * ck[:, None, :], axis=0)[1:]  # sum b_k c_k^T, (N, 2, 3)
    s_33 = np.cumsum(c33)[1:]
    s_b33 = np.cumsum(c33[:, None] * b, axis=0)[1:]
    s_bb = np.cumsum(c33[:, None, None] * b[:, :, None] * b[:, None, :], axis=0)[1:]
    a = b[1:]  # J p_n
    out = s_c.copy()
    cross = a[:, :, None] * s_col[:, None, :] - s_bc  # sum (a - b_k) c_k^T, (N, 2, 3)
    out[:, :2, :] += cross
    out[:, :, :2] += np.swapaxes(cross, -1, -2)
    out[:, :2, :2] += (s_33[:, None, None] * a[:, :, None] * a[:, None, :] - a[:, :, None] * s_b33[:, None, :]
                       - s_b33[:, :, None] * a[:, None, :] + s_bb)
    return 0.5 * (out + np.swapaxes(out, -1, -2))
