"""Encoders: incremental counts (with fixed-width counter wrap-around) and absolute steering angles, to radians.

The conversion ``wheel angle = 2 pi counts / (counts_per_rev * gear_ratio)`` is [DERIVED] (neither paper gives it;
papers-odometry.md Part D.1); the wheel's travel is then ``r * angle`` through the robot's own kinematics. The
forklift of thesis §7.5.1 (8290 pulses per wheel revolution, absolute steering encoder of 1.4118 deg = 360/255 deg)
is in :data:`CATALOG_ENCODERS`. An absolute steering encoder reads the wheel's **heading** (0 when it rolls
straight ahead, counter-clockwise positive), as every steering angle in a log does (:mod:`.steering`).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from .._shapes import as_names, finite_number, real_number
from ..errors import UnknownNameError, WmrkitError


class EncoderError(WmrkitError, ValueError):
    """Encoder settings or counts that cannot be right (zero resolution, counts outside the counter's range).

    ``index``: for bad counts, the sample (index along the first axis of the readings) of the first one, which
    a log reader turns into the line (None for settings); ``joint``: the joint that has no encoder data, if that
    is the error (the log readers name its column)."""

    def __init__(self, message: str, index: int | None = None, joint: str | None = None) -> None:
        super().__init__(message)
        self.index, self.joint = index, joint


def _first(bad: np.ndarray) -> int:
    """The sample (first-axis index) of the first True of `bad`."""
    return int(np.argwhere(bad)[0][0])


#: Most counts per wheel revolution (counts per revolution x gear ratio): 2^53, where counts stop being exact.
MAX_COUNTS_PER_REV = 2.0**53


@dataclass(frozen=True, slots=True)
class IncrementalEncoder:
    """A wheel encoder counting pulses: ``counts_per_rev`` per revolution of the encoder shaft.

    ``gear_ratio``: encoder-shaft revolutions per wheel revolution (1 when the encoder is on the wheel).
    ``bits``: width of the hardware counter, which wraps around modulo ``2**bits`` (None: counts are already
    cumulative). ``signed``: the counter reads ``[-2**(bits-1), 2**(bits-1))`` instead of ``[0, 2**bits)``.
    ``sign``: +1, or -1 when the encoder counts down for a positive spin (right-hand rule about the axle).
    """

    counts_per_rev: float
    gear_ratio: float = 1.0
    bits: int | None = None
    signed: bool = False
    sign: int = 1

    def __post_init__(self) -> None:
        for name in ("counts_per_rev", "gear_ratio"):  # text raised a TypeError comparing it, True was 1
            value = getattr(self, name)
            if isinstance(value, bool) or not (finite_number(value) and value > 0):
                raise EncoderError(f"{name} must be a finite number > 0, got {value!r}")
        if self.bits is not None and not (isinstance(self.bits, int | np.integer) and 2 <= self.bits <= 64):
            raise EncoderError(f"bits must be a whole number between 2 and 64, got {self.bits}")
        if self.counts_per_rev * self.gear_ratio > MAX_COUNTS_PER_REV:  # a count below round-off, or 0 rad
            raise EncoderError(f"counts_per_rev x gear_ratio = {self.counts_per_rev * self.gear_ratio:g} counts per "
                               f"wheel revolution: at most {MAX_COUNTS_PER_REV:g}")
        if not (real_number(self.sign) and self.sign in (1, -1)):  # True was taken as +1, an array raised numpy's
            raise EncoderError(f"sign must be +1 or -1, got {self.sign!r}")

    @property
    def radians_per_count(self) -> float:
        """Wheel angle of one count [rad]."""
        return self.sign * 2.0 * math.pi / (self.counts_per_rev * self.gear_ratio)

    def count_increments(self, counts: ArrayLike, *, name: str = "counts") -> np.ndarray:
        """Count differences between consecutive samples, unwrapped. ``(N, ...) -> (N - 1, ...)``.

        With ``bits``, a difference is taken modulo ``2**bits`` into ``[-2**(bits-1), 2**(bits-1))``: correct
        as long as the wheel turns less than half the counter's range between two samples (an assumption no
        log can check). Counts outside the counter's range raise :class:`EncoderError` naming `name`.
        """
        c = np.asarray(counts)
        if not np.issubdtype(c.dtype, np.integer):
            c = _as_integer(c, name)
        if self.bits is None:
            return np.diff(c, axis=0)
        span = 1 << self.bits
        low = -(span >> 1) if self.signed else 0
        if c.size and (c.min() < low or c.max() >= low + span):
            k = _first((c < low) | (c >= low + span))
            bad = c[k][(c[k] < low) | (c[k] >= low + span)].reshape(-1)[0]
            raise EncoderError(f"{name}: count {bad} outside the {self.bits}-bit "
                               f"{'signed' if self.signed else 'unsigned'} counter range [{low}, {low + span})", k)
        shift = 64 - self.bits  # int64 differences wrap modulo 2**64; the shifts take them modulo 2**bits
        return (np.diff(c, axis=0) << shift) >> shift

    def angle_increments(self, counts: ArrayLike, *, name: str = "counts") -> np.ndarray:
        """Wheel angle increments [rad] between consecutive samples. ``(N, ...) -> (N - 1, ...)``."""
        return self.count_increments(counts, name=name) * self.radians_per_count

    def quantize(self, angle: ArrayLike) -> np.ndarray:
        """Counts an ideal encoder reports at wheel angle `angle` [rad] (floor, cumulative, no wrap). ``(...)``."""
        return np.floor(_counts_of(angle, self.radians_per_count)).astype(np.int64)

    def wrap(self, counts: ArrayLike) -> np.ndarray:
        """Cumulative counts as the fixed-width counter shows them (identity without ``bits``). ``(...)``."""
        c = np.asarray(counts, dtype=np.int64)
        if self.bits is None:
            return c
        shift = 64 - self.bits
        shown = (c << shift) >> shift  # the signed counter's reading
        if self.signed:
            return shown
        if self.bits == 64 and (c < 0).any():
            raise EncoderError("counts: a 64-bit unsigned counter's readings of negative counts exceed int64")
        return shown & ((1 << self.bits) - 1) if self.bits < 64 else c


@dataclass(frozen=True, slots=True)
class AbsoluteEncoder:
    """An absolute angle encoder (steering): ``angle = offset + sign * counts * resolution`` [rad].

    In a log the angle is the wheel's heading (0 = rolling straight ahead): ``offset`` is the heading at count 0,
    so an encoder that reads 0 straight ahead (the default) needs none."""

    resolution: float
    offset: float = 0.0
    sign: int = 1

    def __post_init__(self) -> None:
        if isinstance(self.resolution, bool) or not (finite_number(self.resolution) and self.resolution > 0):
            raise EncoderError(f"resolution must be a finite number > 0 [rad], got {self.resolution!r}")
        if isinstance(self.offset, bool) or not finite_number(self.offset):
            raise EncoderError(f"offset must be a finite angle [rad], got {self.offset!r}")
        if not (real_number(self.sign) and self.sign in (1, -1)):  # True was taken as +1, an array raised numpy's
            raise EncoderError(f"sign must be +1 or -1, got {self.sign!r}")

    def angle(self, counts: ArrayLike, *, name: str = "counts") -> np.ndarray:
        """Angles [rad] of raw readings `counts` (whole numbers, else :class:`EncoderError` naming `name`).
        ``(...) -> (...)``."""
        c = np.asarray(counts, dtype=float)
        if not np.isfinite(c).all():
            raise EncoderError(f"{name}: expected finite readings", _first(~np.isfinite(c)))
        if (c != np.round(c)).any():  # an angle written to a counts column
            raise EncoderError(f"{name}: counts must be whole numbers, got {float(c[c != np.round(c)][0])!r} "
                               "(an angle in degrees or radians?)", _first(c != np.round(c)))
        return self.offset + self.sign * c * self.resolution

    def quantize(self, angle: ArrayLike) -> np.ndarray:
        """The reading (nearest count) of an ideal encoder at `angle` [rad]. ``(...) -> (...)`` int."""
        return np.rint(self.sign * _counts_of(np.asarray(angle, dtype=float) - self.offset, self.resolution)
                       ).astype(np.int64)

    def round(self, angle: ArrayLike) -> np.ndarray:
        """`angle` [rad] rounded to what this encoder can report. ``(...) -> (...)``."""
        return self.angle(self.quantize(angle))


Encoder = IncrementalEncoder | AbsoluteEncoder


def _counts_of(angle: ArrayLike, per_count: float) -> np.ndarray:
    """``angle / per_count`` as counts, or :class:`EncoderError` when an angle is not finite or the count would not
    fit an int64 (NaN became -9223372036854775808 counts, silently)."""
    c = np.asarray(angle, dtype=float) / per_count
    if not (np.abs(c) < 2.0**62).all():
        raise EncoderError(f"angle: expected finite angles within {2.0**62 * per_count:.3g} rad of the encoder's zero")
    return c

#: Encoders of catalog robots, by robot then joint (thesis §7.5.1: 8290 pulses/rev, 1.4118 deg = 360/255 deg).
#: The forklift's steering encoder reads 0 when steered straight ahead, the general rule of steering encoders
#: (no offset), so straight is representable; the thesis does not say where its zero is.
CATALOG_ENCODERS: Mapping[str, Mapping[str, Encoder]] = {
    "forklift": {
        "right_drive.spin": IncrementalEncoder(counts_per_rev=8290),
        "left_drive.spin": IncrementalEncoder(counts_per_rev=8290),
        "steer.steer": AbsoluteEncoder(resolution=math.radians(1.4118)),
    },
}


def catalog_encoders(robot_name: str) -> Mapping[str, Encoder]:
    """Encoders of catalog robot `robot_name` by joint, or :class:`UnknownNameError`."""
    if not isinstance(robot_name, str) or robot_name not in CATALOG_ENCODERS:  # a list: "unhashable type"
        raise UnknownNameError(f"no encoder data for robot '{robot_name}' (known: {', '.join(CATALOG_ENCODERS)}); "
                               "give the counts per revolution")
    return CATALOG_ENCODERS[robot_name]


def _as_integer(c: np.ndarray, name: str) -> np.ndarray:
    """Float counts (as read from text) to int64, refusing fractions, NaN and values beyond 2**53."""
    c = np.asarray(c, dtype=float)
    if not np.all(np.isfinite(c)):
        raise EncoderError(f"{name}: counts must be finite", _first(~np.isfinite(c)))
    if np.any(np.abs(c) > 2.0**53):
        raise EncoderError(f"{name}: counts beyond 2**53 cannot be represented exactly (counter overflow?)",
                           _first(np.abs(c) > 2.0**53))
    if np.any(c != np.round(c)):
        raise EncoderError(f"{name}: counts must be whole numbers, got {float(c[c != np.round(c)][0])!r}",
                           _first(c != np.round(c)))
    return c.astype(np.int64)


def encoders_for(robot_name: str, joints: Sequence[str], *, counts_per_rev: float | None = None,
                 gear_ratio: float | None = None, bits: int | None = None, signed: bool = False,
                 steer_resolution: float | None = None) -> tuple[tuple[str, Encoder], ...]:
    """Encoders of `joints` for a counts log: the given settings, else the catalog's (:data:`CATALOG_ENCODERS`).

    Spin joints get an :class:`IncrementalEncoder` (`counts_per_rev`, `gear_ratio`, counter `bits`, `signed`; each
    given one replaces the catalog encoder's, a `gear_ratio` not given is the catalog's or 1),
    steer joints an :class:`AbsoluteEncoder` of `steer_resolution` [rad] reading 0 straight ahead (the rule of
    every steering encoder, catalog ones included). Raises :class:`EncoderError` when a
    joint has neither.
    """
    known = CATALOG_ENCODERS.get(robot_name, {})
    out = []
    for joint in as_names(joints, "joints", "joint names", EncoderError):
        if joint.endswith(".steer"):
            enc = AbsoluteEncoder(steer_resolution) if steer_resolution is not None else known.get(joint)
        elif counts_per_rev is not None:
            enc = IncrementalEncoder(counts_per_rev, 1.0 if gear_ratio is None else gear_ratio, bits, signed)
        else:
            enc = known.get(joint)
            if isinstance(enc, IncrementalEncoder) and (bits is not None or gear_ratio is not None):
                enc = IncrementalEncoder(enc.counts_per_rev, enc.gear_ratio if gear_ratio is None else gear_ratio,
                                         enc.bits if bits is None else bits, signed if bits is not None else enc.signed,
                                         enc.sign)
        if enc is None:
            what = ("steering resolution (steer_resolution; --steer-resolution)" if joint.endswith(".steer") else
                    "counts per revolution (counts_per_rev; --cpr)")
            raise EncoderError(f"joint '{joint}' of robot '{robot_name}': no encoder data; give the {what}",
                               joint=joint)
        out.append((joint, enc))
    return tuple(out)
