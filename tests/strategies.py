"""Hypothesis strategies for random regular wheels and robots (``from strategies import wheels, robots``), and the
transformed robots of the invariance tests (:func:`moved`, :func:`mirrored`, :func:`scaled`), built field by field.

The test root is put on ``sys.path`` by ``tests/conftest.py``, so every test folder can import this module.
"""

from __future__ import annotations

import math
from dataclasses import replace

from hypothesis import strategies as st

from wmrkit import KINDS, Robot, Wheel

_angle = st.floats(-math.pi, math.pi)
_length = st.floats(0.01, 0.5)
_signed = st.sampled_from([-1.0, 1.0])

#: Ranges that keep every wheel regular: castor |delta| < 80 deg, Swedish 15 deg < |gamma| < 165 deg.
_FIELDS = {
    "beta": _angle, "r": _length, "b": _length, "r_r": st.floats(0.005, 0.1),
    "delta": st.floats(-1.4, 1.4),
    "d": st.builds(lambda s, x: s * x, _signed, _length),
    "gamma": st.builds(lambda s, x: s * x, _signed, st.floats(0.26, math.pi - 0.26)),
}


@st.composite
def wheels(draw, type_name: str | None = None, name: str = "w") -> Wheel:
    """A random regular wheel of `type_name` (any type if None) with only the fields its type uses."""
    type_name = type_name or draw(st.sampled_from(list(KINDS)))
    kind = KINDS[type_name]
    values = {key: draw(_FIELDS[key]) for key in (*kind.required, *kind.optional)}
    values.setdefault("beta", 0.0)
    if "r_r" in values:  # the rollers sit on the rim: r_r <= r (descriptions refuse more)
        values["r_r"] = min(values["r_r"], values["r"])
    in_order = lambda js: tuple(sorted(js, key=kind.joints.index))  # noqa: E731
    joints = st.lists(st.sampled_from(kind.joints), unique=True).map(in_order)
    return Wheel(name=name, type=type_name, l=draw(st.floats(0, 1.5)), alpha=draw(_angle),
                 actuated=draw(joints), sensed=draw(joints), **values)


@st.composite
def robots(draw, max_wheels: int = 4) -> Robot:
    """A random robot of 1..max_wheels random regular wheels named w0, w1, ..."""
    n = draw(st.integers(1, max_wheels))
    return Robot(name=draw(st.sampled_from(["r", "rover", "test-bot"])),
                 wheels=tuple(draw(wheels(name=f"w{i}")) for i in range(n)))


def moved(robot: Robot, c: tuple[float, float], phi: float) -> Robot:
    """`robot` described from a frame at `c` (in its frame) turned by `phi`: a wheel at p sits at R(-phi)(p - c) with
    its angles turned by -phi (3.8); a twist becomes R(-phi)(v + omega z x c), omega (:func:`moved_twist`)."""
    cos, sin = math.cos(phi), math.sin(phi)
    wheels = []
    for w in robot.wheels:
        x, y = w.l * math.cos(w.alpha) - c[0], w.l * math.sin(w.alpha) - c[1]
        x, y = cos * x + sin * y, -sin * x + cos * y
        beta = math.remainder(w.beta - phi, math.tau)
        wheels.append(replace(w, l=math.hypot(x, y), alpha=math.atan2(y, x), beta=beta))
    return replace(robot, wheels=tuple(wheels))


def moved_twist(twist, c: tuple[float, float], phi: float) -> tuple[float, float, float]:
    """The twist ``(vx, vy, omega)`` of the robot's origin as the twist of the frame of :func:`moved`."""
    vx, vy, w = (float(v) for v in twist)
    vx, vy = vx - w * c[1], vy + w * c[0]
    return (math.cos(phi) * vx + math.sin(phi) * vy, -math.sin(phi) * vx + math.cos(phi) * vy, w)


def mirrored(robot: Robot) -> Robot:
    """`robot` mirrored in y, each wheel rolling along its mirrored direction with the same spin sign (heading ->
    -heading), so beta -> pi - beta, delta -> -delta, gamma -> -gamma (the roller's axis line mirrored), d kept; a
    double unit's axle then points the other way (spin1 and spin2 swap sides); a twist becomes (vx, -vy, -omega)."""
    return replace(robot, wheels=tuple(replace(w, alpha=-w.alpha, beta=math.remainder(math.pi - w.beta, math.tau),
                                               delta=-w.delta, gamma=-w.gamma) for w in robot.wheels))


def scaled(robot: Robot, k: float) -> Robot:
    """`robot` with every length (l, r, r_r, d, b) times `k`."""
    return replace(robot, wheels=tuple(replace(w, l=w.l * k, r=w.r * k, r_r=w.r_r * k, d=w.d * k, b=w.b * k)
                                       for w in robot.wheels))
