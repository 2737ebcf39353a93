"""Hypothesis strategies for random regular wheels and robots (``from strategies import wheels, robots``).

The test root is put on ``sys.path`` by ``tests/conftest.py``, so every test folder can import this module.
"""

from __future__ import annotations

import math

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
