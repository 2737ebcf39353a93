"""The thesis's reference vehicles of §5.5 / §6.5, in the thesis's own frames and numbering (digest §4).

Built with ``Robot.from_dict`` from the digest's parameters (radians, metres); gamma = 90 deg, delta = 0 unless
given. Wheel names: f (fixed), o (orientable = steerable), s (Swedish), c (castor) + the thesis's number.
"""

from __future__ import annotations

import math

from wmrkit import Robot

DEG = math.pi / 180


def _w(name: str, type_: str, l: float, alpha: float, beta: float = 0.0, *, r: float = 0.1, d: float = 0.05,
       gamma: float = math.pi / 2, delta: float = 0.0, r_r: float = 0.02) -> dict:
    w = {"name": name, "type": type_, "l": l, "alpha": alpha, "beta": beta, "r": r}
    if type_ == "castor":
        w.update(d=d, delta=delta)
    if type_ == "swedish":
        w.update(gamma=gamma, r_r=r_r)
    return w


def robot(name: str, *wheels: dict) -> Robot:
    return Robot.from_dict({"name": name, "wheels": list(wheels)})


def omni_swedish(L: float = 0.7, r: float = 0.1, gamma: float = math.pi / 2, offset: float = 0.0) -> Robot:
    """Fig. 5.1 / (5.34)-(5.37): alpha = (0, 120, 240) deg, beta_i = alpha_i + offset, l_i = L."""
    a = [0.0, 120 * DEG, 240 * DEG]
    return robot("omni-swedish", *(_w(f"s{i + 1}", "swedish", L, ai, ai + offset, r=r, gamma=gamma)
                                   for i, ai in enumerate(a)))


def omni_castor(L: float = 1.0, d: float = 0.2, r: float = 0.2, betas=(0.0, 0.0, 0.0), delta: float = 0.0) -> Robot:
    """Fig. 5.2 / (5.39)-(5.41): castors at alpha = (0, 120, 240) deg, l_i = L."""
    a = [0.0, 120 * DEG, 240 * DEG]
    return robot("omni-castor", *(_w(f"c{i + 1}", "castor", L, ai, b, r=r, d=d, delta=delta)
                                  for i, (ai, b) in enumerate(zip(a, betas, strict=True))))


def differential(l12: float = 0.5, r1: float = 0.1, r2: float = 0.1, third: str = "swedish", l3: float = 0.6,
                 alpha3: float = -90 * DEG, beta3: float = 0.3, r3: float = 0.1, d: float = 0.05) -> Robot:
    """Figs. 5.3/5.5: fixed wheels at (+-l12, 0) with axle along X, wheel 3 Swedish or castor."""
    kind = {"swedish": "s3", "castor": "c3"}[third]
    return robot("differential", _w("f1", "fixed", l12, 0.0, 0.0, r=r1), _w("f2", "fixed", l12, math.pi, 0.0, r=r2),
                 _w(kind, third, l3, alpha3, beta3, r=r3, d=d))


def type3(l2: float = 1.2, a2: float = -120 * DEG, l3: float = 1.0, a3: float = -50 * DEG, omni: str = "swedish",
          beta1: float = 0.2, beta2: float = 0.4, beta3: float = 1.3, r: float = 0.1, r2: float | None = None,
          r3: float | None = None, d: float = 0.05) -> Robot:
    """Figs. 5.7/5.9: orientable wheel 1 at the origin (l1 = 0), omni wheels 2 and 3."""
    p = "s" if omni == "swedish" else "c"
    return robot("type3", _w("o1", "steerable", 0.0, 0.0, beta1, r=r),
                 _w(f"{p}2", omni, l2, a2, beta2, r=r2 or r, d=d), _w(f"{p}3", omni, l3, a3, beta3, r=r3 or r, d=d))


def tricycle(l12: float = 0.5, l3: float = 1.0, r: float = 0.1, beta3: float = 0.3) -> Robot:
    """Fig. 5.11 / (5.71)-(5.72): fixed wheels at (+-l12, 0), axle X; orientable wheel 3 at alpha3 = 90 deg."""
    return robot("tricycle", _w("f1", "fixed", l12, 0.0, 0.0, r=r), _w("f2", "fixed", l12, math.pi, 0.0, r=r),
                 _w("o3", "steerable", l3, 90 * DEG, beta3, r=r))


def bicycle(l2: float = 1.0, third: str = "swedish", l3: float = 0.8, a3: float = 30 * DEG, beta2: float = 0.3,
            beta3: float = 0.7, r: float = 0.1, d: float = 0.05) -> Robot:
    """Fig. 5.12 / (5.73)-(5.76): fixed wheel 1 at the origin (axle X), orientable wheel 2 at (0, l2)."""
    kind = {"swedish": "s3", "castor": "c3"}[third]
    return robot("bicycle", _w("f1", "fixed", 0.0, 0.0, 0.0, r=r), _w("o2", "steerable", l2, 90 * DEG, beta2, r=r),
                 _w(kind, third, l3, a3, beta3, r=r, d=d))


def type5(l12: float = 0.5, third: str = "swedish", l3: float = 1.0, a3: float = 90 * DEG, beta1: float = 0.3,
          beta2: float = 0.7, beta3: float = 0.2, r: float = 0.1, d: float = 0.05) -> Robot:
    """Fig. 5.13 / (5.77)-(5.80): orientable wheels at (+-l12, 0), wheel 3 Swedish or castor."""
    kind = {"swedish": "s3", "castor": "c3"}[third]
    return robot("type5", _w("o1", "steerable", l12, 0.0, beta1, r=r), _w("o2", "steerable", l12, math.pi, beta2, r=r),
                 _w(kind, third, l3, a3, beta3, r=r, d=d))
