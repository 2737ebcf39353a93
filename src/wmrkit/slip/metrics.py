"""Accuracy indices of thesis §7.5: J (7.78) of a slip model against the dynamic model, J_k (7.80) of closed paths."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import ArrayLike

from .._shapes import as_reals, as_vectors
from ..errors import ShapeError, WmrkitError
from ..odometry.model import wrap_angle


def j_model(twist_reference: ArrayLike, twist_model: ArrayLike) -> float:
    """(7.78): mean absolute twist error over samples and the three components, ``(N, 3), (N, 3) -> float``.

    Mixes m/s and rad/s as the thesis does; the thesis reports it in percent (times 100).
    """
    ref, mod = as_reals(twist_reference, "twist_reference"), as_reals(twist_model, "twist_model")  # text refused
    if ref.shape != mod.shape or ref.ndim != 2 or ref.shape[1] != 3:
        raise ShapeError(f"j_model: expected two (N, 3) twist arrays, got {ref.shape} and {mod.shape}")
    if not len(ref) or not (np.isfinite(ref).all() and np.isfinite(mod).all()):
        raise ShapeError(f"j_model: expected at least one sample, every twist finite, got {len(ref)} samples")
    return float(np.mean(np.abs(ref - mod)))


def closure_error(poses: ArrayLike, truth_final: ArrayLike | None = None) -> tuple[float, float]:
    """One closed run's two terms of (7.80): final position error over the distance travelled and final heading
    error (wrapped to ``(-pi, pi]``) over the rotation travelled, both measured on the estimated path ``(N, 3)``.

    The error is against the start pose (a closed manoeuvre, as in the thesis's experiments) or, with
    `truth_final` ``(3,)``, against the true final pose (synthetic runs, whose open-loop paths do not close).
    """
    p = as_vectors(poses, 3, "poses")
    if p.ndim != 2 or len(p) < 2:
        raise ShapeError(f"closure_error: poses must be a path of at least 2 poses (N, 3), got shape {p.shape}")
    if not np.isfinite(p).all():  # it said 'the path neither moves nor turns'
        raise ShapeError(f"closure_error: poses must be finite, pose {int(np.argmin(np.isfinite(p).all(axis=1)))} "
                          "is not")
    goal = p[0] if truth_final is None else as_vectors(truth_final, 3, "truth_final").reshape(3)
    if not np.isfinite(goal).all():  # the heading term was nan
        raise ShapeError(f"closure_error: truth_final: must be finite, got {goal.tolist()}")
    steps = np.diff(p, axis=0)
    distance = float(np.sum(np.hypot(steps[:, 0], steps[:, 1])))
    rotation = float(np.sum(np.abs(wrap_angle(steps[:, 2]))))
    if distance <= 0 or rotation <= 0:  # each term of (7.80) divides by one of them
        what = "neither moves nor turns" if distance <= 0 and rotation <= 0 else \
            "does not move (distance 0 m)" if distance <= 0 else "does not turn (rotation 0 rad)"
        raise WmrkitError(f"closure_error: the path {what}: (7.80) divides the position error by the distance "
                          "travelled and the heading error by the rotation")
    pos = float(np.hypot(*(p[-1, :2] - goal[:2])))
    head = float(abs(wrap_angle(p[-1, 2] - goal[2])))
    return pos / distance, head / rotation


def j_closure(runs: Sequence[ArrayLike], truth_finals: Sequence[ArrayLike] | None = None) -> float:
    """(7.80): ``1/(2 N_e) sum (position error / distance + heading error / rotation)`` over runs (closed, or
    against `truth_finals` as in :func:`closure_error`)."""
    runs = list(runs)
    if not runs:
        raise ShapeError("j_closure: no runs")
    finals = [None] * len(runs) if truth_finals is None else list(truth_finals)
    if len(finals) != len(runs):  # zip() said 'argument 2 is shorter than argument 1'
        raise ShapeError(f"j_closure: {len(runs)} runs and {len(finals)} true final poses: expected one per run")
    return float(sum(sum(closure_error(p, f)) for p, f in zip(runs, finals, strict=True)) / (2 * len(runs)))
