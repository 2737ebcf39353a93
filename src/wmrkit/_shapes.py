"""Shape contracts of batched functions: batch axes lead, core axes trail."""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping

import numpy as np
from numpy.typing import ArrayLike

from .errors import ShapeError


def finite_number(value: object) -> bool:
    """Whether `value` is one finite real number (Python, NumPy scalar); False for NaN, infinities, text, None."""
    try:
        return math.isfinite(value)  # type: ignore[arg-type]
    except TypeError:
        return False


def real_number(value: object) -> bool:
    """Whether `value` is one finite real number and not a boolean (Python, NumPy scalar): a scalar argument of the
    Python API, which reads no units (``"1"`` and ``True`` are refused, as :func:`as_vectors` refuses them)."""
    return not isinstance(value, bool | np.bool_) and finite_number(value)


def as_vectors(x: ArrayLike, n: int, name: str, *, angles: bool = False) -> np.ndarray:
    """Return `x` as a float array of shape ``(..., n)``, or raise :class:`ShapeError` naming `name`.

    Real numbers only (Python or NumPy, any precision): text, booleans, complex numbers, mappings and ragged
    nested lists are refused, since the Python API reads no units (``"30 deg"``, or ``"30"`` as 30 rad).
    """
    a = x if isinstance(x, np.ndarray) and x.dtype == float else _real_array(x, name, angles)
    if a.shape[-1:] != (n,):
        raise ShapeError(f"{name}: expected shape (..., {n}), got {a.shape}")
    return a


def as_reals(x: ArrayLike, name: str) -> np.ndarray:
    """Return `x` as a float array of any shape, refusing what :func:`as_vectors` refuses (text, booleans, ...)."""
    return x if isinstance(x, np.ndarray) and x.dtype == float else _real_array(x, name, False)


def as_real(x: object, name: str) -> float:
    """`x` as one Python float, refusing what :func:`as_vectors` refuses (text, booleans, ...) and arrays, with a
    :class:`ShapeError` naming `name`; NaN and infinities pass (the callers' range checks name them). The
    predicate for a caller's own message: :func:`real_number`."""
    if type(x) is float:  # the common case, without building an array
        return x
    a = _real_array(x, name, False)
    if a.ndim:
        raise ShapeError(f"{name}: expected one real number, got an array of shape {a.shape}")
    return float(a)


def as_angles(x: ArrayLike, n: int, name: str) -> np.ndarray:
    """:func:`as_vectors` for angles [rad]: also raise :class:`ShapeError` naming `name` for NaN, infinities and
    angles beyond :data:`wmrkit.units.MAX_ANGLE` (1e6 turns), whose sine and cosine are round-off."""
    from .units import MAX_ANGLE, MAX_TURNS

    a = as_vectors(x, n, name, angles=True)
    bad = ~(np.abs(a) <= MAX_ANGLE)  # NaN included
    if bad.any():
        value = float(a[np.unravel_index(int(np.argmax(bad)), a.shape)])
        raise ShapeError(f"{name}: angles must be finite numbers of at most {MAX_TURNS:g} turns [rad], got {value!r}")
    return a


def as_angle_array(x: ArrayLike, name: str) -> np.ndarray:
    """Angles of any shape ``(...)`` [rad], refused as :func:`as_angles` refuses them."""
    a = x if isinstance(x, np.ndarray) and x.dtype == float else _real_array(x, name, True)
    return as_angles(a[..., None], 1, name)[..., 0]


def as_names(names: object, argument: str, what: str = "names", error: type[Exception] = ShapeError) -> tuple[str, ...]:
    """`names` (joints, velocities, wheels) as a tuple of strings, or `error` naming `argument`.

    The one door for every sequence of names the Python API takes: a lone string is refused, since iterating it
    reads one name per letter (``"o1.spin"`` gave "no velocity 'o'"), as is anything that is not an iterable of
    strings. `what` says what the names are, for the message (``"'wheel.joint' names"``).
    """
    if isinstance(names, str):
        raise error(f"{argument}: expected a sequence of {what}, got the string '{names}'")
    items = tuple(names) if isinstance(names, Iterable) and not isinstance(names, Mapping) else None
    if items is None or not all(isinstance(n, str) for n in items):
        raise error(f"{argument}: expected a sequence of {what}, got {names!r}")
    return items


def check_kind(value: object, kind: type, argument: str, advice: str, error: type[Exception] = ShapeError) -> None:
    """Raise `error` naming `argument` unless `value` is a `kind` (a name or a dict where an object goes raised an
    AttributeError deep inside); `advice` says how to build one."""
    if not isinstance(value, kind):
        raise error(f"{argument}: expected a {kind.__name__} ({advice}), got {type(value).__name__} {value!r:.60}")


def matvec(m: np.ndarray, v: np.ndarray, name: str) -> np.ndarray:
    """``m @ v`` over leading batch axes, ``(..., r, n), (..., n) -> (..., r)``, or :class:`ShapeError` naming `name`
    when the two batch shapes do not broadcast (numpy's message named neither)."""
    batch_shape(v.shape, m.shape[:-2], name)
    return (m @ v[..., None])[..., 0]


def batch_shape(shape: tuple[int, ...], steering_batch: tuple[int, ...], name: str) -> tuple[int, ...]:
    """The batch shape of `name` ``(..., n)`` (its `shape`) broadcast with the steering configurations' batch, or
    :class:`ShapeError` naming both (numpy's message named neither)."""
    try:
        return np.broadcast_shapes(shape[:-1], steering_batch)
    except ValueError:
        raise ShapeError(f"{name} {shape} and the steering configurations {steering_batch}: their batch shapes (all "
                         "but the last axis) do not broadcast") from None


#: What an array of each refused dtype kind holds, for :func:`_real_array`'s message.
_REFUSED_KINDS = {"b": "booleans", "c": "complex numbers", "U": "text", "S": "bytes", "M": "dates", "m": "durations"}


def _real_array(x: object, name: str, angles: bool) -> np.ndarray:
    """`x` as a float array, or :class:`ShapeError` naming `name` and saying what it got."""
    if isinstance(x, str | Mapping):
        got = f"the text {x!r}" if isinstance(x, str) else \
            f"a {type(x).__name__} (a mapping: pass the values as an array, in the order the function documents)"
    else:
        try:
            a = np.asarray(x)
            if a.dtype.kind in "fiu":
                return a.astype(float, copy=False)
            text = next((v for v in a.flat if isinstance(v, str | bytes)), None) if a.dtype.kind == "O" else None
            if a.dtype.kind == "O" and text is None:
                return a.astype(float)  # Fraction, Decimal; None reads as NaN, which the callers' checks refuse
            got = _REFUSED_KINDS.get(a.dtype.kind, f"values of type {a.dtype}")
            if text is not None:  # [Fraction(1, 10), "30"] was read as 30 rad: text among numbers of an object array
                got = f"the text {text!r}"
            if a.dtype.kind == "U":
                got = f"the text {str(next((v for v in a.flat if not reads_as_number(v)), a.flat[0]))!r}"
        except (TypeError, ValueError, OverflowError):  # a ragged nested list, an element that is no number
            got = f"a {type(x).__name__} of values that are no numbers, or of rows of different lengths"
    unit = "radians (e.g. math.radians(30))" if angles else "SI units (m, rad, m/s, rad/s)"
    if got.startswith("the text"):
        raise ShapeError(f"{name}: got {got}, but the Python API reads no units: pass real numbers in {unit}")
    raise ShapeError(f"{name}: expected real numbers in {unit}, got {got}")


def reads_as_number(text: str) -> bool:
    """Whether `text` reads as a number (``float(text)``: '1e3', 'nan', '-inf')."""
    try:
        float(text)
    except ValueError:
        return False
    return True


def readonly(a: np.ndarray) -> np.ndarray:
    """Mark `a` read-only and return it (values handed out are never written into)."""
    a.setflags(write=False)
    return a
