"""The synthetic generator's and the encoders' number arguments: one real number each, refused by name otherwise."""

import numpy as np
import pytest

from wmrkit import catalog
from wmrkit.errors import WmrkitError
from wmrkit.odometry.encoders import AbsoluteEncoder, EncoderError, IncrementalEncoder
from wmrkit.odometry.synthetic import TwistProfile, simulate, square_path


@pytest.mark.parametrize(("call", "message"), [
    # text raised TypeError ("'<' not supported between instances of 'int' and 'str'"); True ran at 1 Hz
    (lambda: square_path("1"), "square_path: side must be a finite number > 0, got '1'"),
    (lambda: square_path(1.0, pause="0.5"), "square_path: pause must be a finite number >= 0 s, got '0.5'"),
    (lambda: simulate(catalog.load("diff-drive"), square_path(1.0), "10"), "rate: expected a finite number [Hz], "
                                                                          "got '10'"),
    (lambda: simulate(catalog.load("diff-drive"), square_path(1.0), True), "rate: expected a finite number [Hz], "
                                                                          "got True"),
    (lambda: simulate(catalog.load("diff-drive"), square_path(1.0), 10.0, spin_noise_per_rad="1e-3"),
     "spin_noise_per_rad: a noise must be a finite number >= 0, got '1e-3'"),
    # rows of 3 or 5 values were numpy's reshape ValueError; 8 values in one row were read as two segments
    (lambda: TwistProfile.from_segments([(1.0, 0.5, 0.0)]), "profile: expected (duration, vx, vy, omega) rows, got "
                                                            "shape (1, 3)"),
    (lambda: TwistProfile.from_segments([1.0, 0.5, 0.0, 0.0, 2.0, 0.0, 0.0, 0.5]),
     "profile: expected (duration, vx, vy, omega) rows, got shape (8,)"),
    (lambda: TwistProfile.from_segments([("1 s", 0.5, 0.0, 0.0)]), "profile: segments: "),
    (lambda: IncrementalEncoder("1000"), "counts_per_rev must be a finite number > 0, got '1000'"),
    (lambda: IncrementalEncoder(1000, gear_ratio=True), "gear_ratio must be a finite number > 0, got True"),
    (lambda: AbsoluteEncoder("0.01"), "resolution must be a finite number > 0 [rad], got '0.01'"),
    (lambda: AbsoluteEncoder(0.01, offset="90 deg"), "offset must be a finite angle [rad], got '90 deg'"),
])
def test_number_arguments_refuse_text_and_booleans_by_name(call, message):
    with pytest.raises(WmrkitError) as err:
        call()
    assert str(err.value).startswith(message), str(err.value)


def test_one_row_is_one_segment_and_numbers_of_any_kind_are_read():
    one = TwistProfile.from_segments((2.0, 0.5, 0.0, 0.0))
    assert one.durations.tolist() == [2.0] and one.twists.tolist() == [[0.5, 0.0, 0.0]]
    assert IncrementalEncoder(np.int64(1000), np.float32(2.0)).radians_per_count == pytest.approx(np.pi / 1000)
    with pytest.raises(EncoderError, match="counts_per_rev must be a finite number > 0, got nan"):
        IncrementalEncoder(float("nan"))
