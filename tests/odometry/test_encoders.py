"""Encoders: counts to radians, counter wrap-around, absolute steering encoders, the forklift's catalog data."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from wmrkit.errors import UnknownNameError
from wmrkit.odometry.encoders import (
    AbsoluteEncoder,
    EncoderError,
    IncrementalEncoder,
    catalog_encoders,
    encoders_for,
)


def test_forklift_encoders_are_the_thesis_values():
    enc = catalog_encoders("forklift")  # thesis §7.5.1: 8290 pulses per wheel revolution, 1.4118 deg
    assert enc["right_drive.spin"].radians_per_count == pytest.approx(2 * math.pi / 8290, rel=1e-15)
    assert enc["left_drive.spin"].counts_per_rev == 8290
    assert math.degrees(enc["steer.steer"].resolution) == pytest.approx(1.4118, abs=1e-12)
    assert 360 / 255 == pytest.approx(1.4118, abs=1e-4)  # the digest's reading: an 8-bit absolute encoder
    with pytest.raises(UnknownNameError, match="no encoder data for robot 'diff-drive'"):
        catalog_encoders("diff-drive")


def test_counts_to_angle_with_gearing_and_sign():
    enc = IncrementalEncoder(counts_per_rev=512, gear_ratio=4.0, sign=-1)
    # one wheel revolution = 4 motor revolutions = 2048 counts, counting down for a positive spin
    np.testing.assert_allclose(enc.angle_increments([0, -2048, -1024]), [2 * math.pi, -math.pi], rtol=1e-15)


@pytest.mark.parametrize(("bits", "signed"), [(8, False), (16, False), (16, True), (32, True)])
def test_wrap_around_of_fixed_width_counters(bits, signed):
    rng = np.random.default_rng(bits)
    steps = rng.integers(-(1 << (bits - 2)), 1 << (bits - 2), size=500)  # less than half the range per sample
    cumulative = np.concatenate([[12345 % (1 << (bits - 1))], steps]).cumsum()
    enc = IncrementalEncoder(counts_per_rev=1000, bits=bits, signed=signed)
    shown = enc.wrap(cumulative)
    low = -(1 << (bits - 1)) if signed else 0
    assert shown.min() >= low and shown.max() < low + (1 << bits)
    assert np.any(np.diff(shown) != steps)  # the counter really wrapped in this run
    np.testing.assert_array_equal(enc.count_increments(shown), steps)


@settings(max_examples=400)
@given(st.integers(2, 63), st.booleans(), st.lists(st.integers(-(1 << 60), 1 << 60), min_size=2, max_size=30))
def test_unwrap_recovers_any_steps_below_half_the_range(bits, signed, raw):
    half = 1 << (bits - 1)
    steps = np.array([s % half - half // 2 if bits > 1 else 0 for s in raw], dtype=np.int64)
    enc = IncrementalEncoder(counts_per_rev=1, bits=bits, signed=signed)
    shown = enc.wrap(np.cumsum(steps))
    np.testing.assert_array_equal(enc.count_increments(shown), np.diff(np.cumsum(steps)))


def test_bad_counts_are_refused_with_the_column_name():
    enc = IncrementalEncoder(counts_per_rev=100, bits=16)
    with pytest.raises(EncoderError, match=r"left: count 65536 outside the 16-bit unsigned counter range \[0, 65536\)"):
        enc.count_increments([0, 65536], name="left")
    with pytest.raises(EncoderError, match="whole numbers"):
        IncrementalEncoder(100).count_increments(np.array([0.0, 1.5]))
    with pytest.raises(EncoderError, match="finite"):
        IncrementalEncoder(100).count_increments(np.array([0.0, np.nan]))
    with pytest.raises(EncoderError, match="2\\*\\*53"):
        IncrementalEncoder(100).count_increments(np.array([0.0, 2.0**54]))


def test_64_bit_counters_of_the_header_widths():
    # a header's 'counts:u64' / 'counts:s64' (widths 8 to 64) was refused: "bits must be between 2 and 62"
    signed = IncrementalEncoder(counts_per_rev=100, bits=64, signed=True)
    np.testing.assert_array_equal(signed.count_increments(np.array([(1 << 63) - 2, -(1 << 63) + 3])), [5])
    np.testing.assert_array_equal(signed.wrap(np.array([-5, 7])), [-5, 7])
    unsigned = IncrementalEncoder(counts_per_rev=100, bits=64)
    np.testing.assert_array_equal(unsigned.count_increments(np.array([0.0, 5.0, 2.0])), [5, -3])
    with pytest.raises(EncoderError, match="outside the 63-bit unsigned counter range"):
        IncrementalEncoder(counts_per_rev=100, bits=63).count_increments(np.array([-1, 0]))


@pytest.mark.parametrize("kwargs", [dict(counts_per_rev=0), dict(counts_per_rev=10, gear_ratio=-1),
                                    dict(counts_per_rev=10, bits=1), dict(counts_per_rev=10, bits=65),
                                    dict(counts_per_rev=10, sign=2), dict(counts_per_rev=10, bits=2.5)])
def test_bad_incremental_settings(kwargs):
    with pytest.raises(EncoderError):  # bits=2.5 wrapped counts modulo 2**2.5
        IncrementalEncoder(**kwargs)


@pytest.mark.parametrize("offset", [math.nan, math.inf])
def test_absolute_encoder_offset_must_be_finite(offset):
    with pytest.raises(EncoderError, match="offset must be a finite angle"):  # gave NaN / infinite angles
        AbsoluteEncoder(resolution=0.01, offset=offset)


def test_fractional_absolute_counts_are_refused():
    enc = AbsoluteEncoder(resolution=math.radians(1.4118))  # -25.17 (degrees in a counts column) was read as counts
    with pytest.raises(EncoderError, match=r"steer: counts must be whole numbers, got -25\.17 \(an angle in degrees"):
        enc.angle(np.array([-25.0, -25.17]), name="steer")
    assert enc.angle(np.array([-25.0]))[0] == pytest.approx(math.radians(-25 * 1.4118), rel=1e-15)


def test_quantize_is_the_floor_of_the_count():
    enc = IncrementalEncoder(counts_per_rev=8290)
    res = 2 * math.pi / 8290
    np.testing.assert_array_equal(enc.quantize([0.0, 0.5 * res, 1.999 * res, -0.5 * res]), [0, 0, 1, -1])


def test_absolute_encoder_rounds_to_its_resolution():
    enc = AbsoluteEncoder(resolution=math.radians(1.4118), offset=math.radians(-90))
    angles = np.radians([-90.0, -89.3, -88.5, 0.0, 45.0])
    rounded = enc.round(angles)
    assert np.all(np.abs(rounded - angles) <= enc.resolution / 2 + 1e-15)
    np.testing.assert_allclose(enc.angle(enc.quantize(angles)), rounded, rtol=0, atol=0)
    assert enc.quantize(math.radians(-90.0)) == 0
    with pytest.raises(EncoderError):
        AbsoluteEncoder(resolution=0.0)


def test_encoders_for_takes_settings_or_the_catalog():
    got = dict(encoders_for("forklift", ["right_drive.spin", "steer.steer"], bits=16))
    assert got["right_drive.spin"] == IncrementalEncoder(8290, bits=16)
    assert got["steer.steer"] == catalog_encoders("forklift")["steer.steer"]
    got = dict(encoders_for("x", ["a.spin", "b.steer"], counts_per_rev=100, gear_ratio=2, steer_resolution=0.01))
    assert got == {"a.spin": IncrementalEncoder(100, 2.0), "b.steer": AbsoluteEncoder(0.01)}
    with pytest.raises(EncoderError, match=r"joint .a\.spin. of robot .x.: no encoder data; give the counts per"):
        encoders_for("x", ["a.spin"])
