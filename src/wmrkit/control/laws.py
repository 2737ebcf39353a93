"""Position control of the kinematic loop (thesis §8.3): laws (8.1)-(8.3), the gated feedforward (8.53).

A law maps the reference ``(p_ref, p_dot_ref)`` and the estimated pose ``p`` (all in the world frame, G) to the
velocity to impose, ``p_dot_control``. With diagonal gains ``A_c = diag(a)`` and ``B_c = diag(b)`` [1/s, 1/s^2]:

- ``"point"`` (8.1): ``A_c (p_ref - p)``; constant error for ramps, rejected by the thesis.
- ``"p"`` (8.2): ``p_dot_ref + A_c (p_ref - p)``; error ``e(t) = e(0) exp(-a t)`` per coordinate (8.5).
- ``"pi"`` (8.3): ``p_dot_ref + A_c e + B_c int(e)``; second-order error (8.6), rejects a dead zone.

``gate`` [m] (8.53): the feedforward is applied only while the position error is at most ``gate`` (a binary switch:
the thesis warns that weighting it continuously leaves a steady-state error). Heading errors are wrapped to
``(-pi, pi]``. Reduced references (types 2, 4) use the first two coordinates only.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass
from typing import Literal

import numpy as np

from ..wheels import wrap_angle
from .points import ControlError, check_delay

__all__ = ["KINDS", "GateWarning", "PositionLaw", "SamplingWarning", "check_gate", "check_sampling", "fastest_pole",
           "law_velocity", "sampled_root"]

KINDS = ("point", "p", "pi")


class SamplingWarning(UserWarning):
    """The discrete loop breaks the rule 1/a >= 10 T (§8.3, §9.2.2)."""


class GateWarning(UserWarning):
    """The feedforward gate (8.53) is below the point-to-point lag ``v / a``: once open it never closes again."""


@dataclass(frozen=True)
class PositionLaw:
    """A position-control law of §8.3: ``kind`` in :data:`KINDS`, gains ``a`` [1/s] and ``b`` [1/s^2] per
    coordinate ``(x, y, theta)``, optional feedforward ``gate`` [m] (8.53). Frozen."""

    kind: Literal["point", "p", "pi"] = "p"
    a: tuple[float, float, float] = (1.0, 1.0, 1.0)
    b: tuple[float, float, float] = (0.0, 0.0, 0.0)
    gate: float | None = None

    def __post_init__(self) -> None:
        if self.kind not in KINDS:
            raise ControlError(f"unknown position law '{self.kind}' (laws: {', '.join(KINDS)})")
        for name, gains in (("a", self.a), ("b", self.b)):
            if len(gains) != 3 or not all(math.isfinite(g) and g >= 0 for g in gains):
                raise ControlError(f"gain {name}: expected three finite numbers >= 0, got {gains}")
        if self.gate is not None and not (self.gate > 0 and math.isfinite(self.gate)):
            raise ControlError(f"feedforward gate: expected a distance > 0 m, got {self.gate}")
        if self.gate is not None and self.kind == "point":
            raise ControlError("feedforward gate: the point-to-point law (8.1) has no feedforward to gate (it would be "
                               "ignored); use the p or pi law")

    @classmethod
    def uniform(cls, kind: Literal["point", "p", "pi"] = "p", a: float = 1.0, b: float = 0.0,
                gate: float | None = None) -> PositionLaw:
        """The same pole `a` (and `b`) on every coordinate."""
        return cls(kind, (a, a, a), (b, b, b), gate)


def pose_error(pose_ref: np.ndarray, pose: np.ndarray) -> np.ndarray:
    """``p_ref - p`` with the heading difference wrapped to (-pi, pi]. ``(..., 3), (..., 3) -> (..., 3)``."""
    e = np.asarray(pose_ref, dtype=float) - np.asarray(pose, dtype=float)
    e[..., 2] = wrap_angle(e[..., 2])
    return e


def law_velocity(law: PositionLaw, pose_ref: np.ndarray, velocity_ref: np.ndarray, pose: np.ndarray,
                 integral: np.ndarray) -> np.ndarray:
    """``p_dot_control`` [world frame] of (8.1)-(8.3)/(8.53) for one instant. ``(3,) x 4 -> (3,)``.

    `integral` is ``int (p_ref - p) dt`` (used by ``"pi"`` only).
    """
    e = pose_error(pose_ref, pose)
    out = np.asarray(law.a) * e
    if law.kind != "point":
        ff = 1.0
        if law.gate is not None and math.hypot(e[0], e[1]) > law.gate:
            ff = 0.0
        out = out + ff * np.asarray(velocity_ref, dtype=float)
    if law.kind == "pi":
        out = out + np.asarray(law.b) * integral
    return out


def fastest_pole(law: PositionLaw) -> float:
    """The largest modulus [1/s] of the continuous error dynamics' poles (8.5)/(8.6): ``a``, or under ``"pi"`` the
    roots of ``s^2 + a s + b`` (computed without squaring ``a``: finite for any finite gains)."""
    if law.kind != "pi":
        return max(law.a)
    out = 0.0
    for a, b in zip(law.a, law.b, strict=True):
        h, r = a / 2, math.sqrt(b)
        out = max(out, h + math.sqrt(h - r) * math.sqrt(h + r) if r <= h else r)
    return out


def sampled_root(a: float, b: float, period: float, delay: int = 0) -> complex:
    """The slowest root of the sampled error recursion of one coordinate (commands held for `period` ``T``, the pose
    measured `delay` samples late): ``e_{k+1} = e_k - T (a e_{k-d} + b I_k)``, ``I_{k+1} = I_k + T e_{k-d}``, whose
    characteristic polynomial is ``z^d (z - 1)^2 + a T (z - 1) + b T^2`` (``b = 0``: ``z^{d+1} - z^d + a T``,
    stable while ``a T < 2 sin(pi / (2 (2 d + 1)))``: 2 without delay, 1 with one sample). The loop oscillates when
    this root is complex or negative and diverges when its modulus reaches 1."""
    if b == 0:
        poly = np.zeros(delay + 2)
        poly[:2] = 1.0, -1.0
        poly[-1] += a * period
    else:
        poly = np.polyadd(np.r_[1.0, -2.0, 1.0, np.zeros(delay)], [a * period, b * period * period - a * period])
    return complex(max(np.roots(poly), key=abs))


def check_sampling(law: PositionLaw, period: float, *, delay: int = 0, factor: float = 10.0,
                   stacklevel: int = 2) -> bool:
    """Whether ``1/a >= factor * T`` for every pole (§8.3) and the sampled loop is stable (:func:`sampled_root`,
    with `delay` samples); warns :class:`SamplingWarning` when not, saying whether the loop oscillates or diverges."""
    check_delay(delay)
    fastest = max(law.a)
    ok = fastest == 0 or 1.0 / fastest >= factor * period * (1 - 1e-12)
    b = law.b if law.kind == "pi" else (0.0, 0.0, 0.0)
    root = max((sampled_root(ai, bi, period, delay) for ai, bi in zip(law.a, b, strict=True)), key=abs)
    samples = f"{delay} sample{'' if delay == 1 else 's'}"
    rule = "" if ok else f"1/a = {1 / fastest:.3g} s < {factor:g} T = {factor * period:.3g} s (thesis §8.3): "
    if abs(root) >= 1 - 1e-12:
        warnings.warn(f"discrete loop: {rule}unstable with a delay of {samples}: the error grows by "
                      f"{abs(root):.4g} times a sample; lower the gains or the period", SamplingWarning,
                      stacklevel=stacklevel)
        return False
    if not ok:
        shape = ("expect oscillation" if abs(root.imag) > 1e-12 or root.real < 0 else
                 "the sampled response departs from the continuous design")
        bound = (f"; unstable from a T = {2 * math.sin(math.pi / (2 * (2 * delay + 1))):.3g} with a delay of "
                 f"{samples}" if law.kind != "pi" else "")
        warnings.warn(f"discrete loop: {rule}{shape}{bound}", SamplingWarning, stacklevel=stacklevel)
    return ok


def check_gate(law: PositionLaw, velocity: np.ndarray, *, stacklevel: int = 2) -> bool:
    """Whether the feedforward gate ``d_max`` (8.53) of `law` exceeds the point-to-point lag ``|(v_x / a_x, v_y /
    a_y)|`` of the reference `velocity` ``(n, 2+)`` [m/s] (world frame) wherever it moves; warns
    :class:`GateWarning` when not. Beyond the gate the law is (8.1), whose error on a ramp tends to ``v / a``: an
    error that once exceeds a smaller gate (a start off the reference, a corner) settles at ``v / a`` instead of 0
    (docs/errata.md, (8.53)). No gate, or a law other than ``"p"``: True (``"point"`` has no feedforward to gate;
    ``"pi"``'s integral removes a ramp's error without it)."""
    if law.gate is None or law.kind != "p":
        return True
    v = np.asarray(velocity, dtype=float)[:, :2]
    moving = np.hypot(v[:, 0], v[:, 1]) > 0
    if not moving.any():
        return True
    with np.errstate(divide="ignore", invalid="ignore"):
        lags = np.hypot(*(v[moving] / np.asarray(law.a[:2])).T)
    k = int(np.argmax(lags))
    lag = float(lags[k])
    if lag < law.gate:
        return True
    speed = float(np.hypot(*v[moving][k]))
    if not math.isfinite(lag):  # a = 0: no feedback to bring the error back within the gate
        warnings.warn(f"feedforward gate {law.gate:g} m (8.53) with a pole a = 0: once the error exceeds the gate "
                      f"nothing moves the robot (the reference moves at up to {speed:.4g} m/s); give a gain > 0",
                      GateWarning, stacklevel=stacklevel)
        return False
    warnings.warn(f"feedforward gate {law.gate:g} m (8.53) is below the point-to-point lag v / a = {lag:.4g} m "
                  f"(reference speed {speed:.4g} m/s, a = {min(law.a[:2]):g} 1/s): once the error exceeds the gate "
                  "the feedforward stays off and the error settles at v / a instead of 0 (docs/errata.md, (8.53)); "
                  f"give a gate above {lag:.4g} m or a larger gain", GateWarning, stacklevel=stacklevel)
    return False
