"""Calibration (9.12)-(9.24): closed forms against synthetic projections and synthetic images; the thesis's example."""

from __future__ import annotations

import math
import re

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from wmrkit.vision.calibration import calibrate, calibrate_image, calibration_kernel
from wmrkit.vision.camera import Camera, CameraError, camera_coordinates, extrinsics, ground_from_image, project
from wmrkit.vision.render import Scene, render


def calibration_setup(cam: Camera, rows_a: float, x1_px: float) -> tuple[float, float, float, float]:
    """Half-separation x_w putting the stripes at +-x1_px on row +A, the ground distance y_w between rows +-A,
    and the exact (x1, x2) of (9.17), all from the camera model in the calibration pose (9.12)."""
    psi, t = extrinsics([0, 0, 0], cam)
    g = ground_from_image(np.array([[0.0, rows_a], [0.0, -rows_a]]), psi, cam.tilt, t, cam.focal_px)
    zc = camera_coordinates([0.0, g[0, 1], 0.0], psi, cam.tilt, t)[2]
    x_w = x1_px * zc / cam.focal_px
    uv = project(np.array([[x_w, g[0, 1], 0], [x_w, g[1, 1], 0]]), psi, cam.tilt, t, cam.focal_px)
    return x_w, float(g[1, 1] - g[0, 1]), float(uv[0, 0]), float(uv[1, 0])


@settings(max_examples=300)
@given(st.floats(200, 900), st.floats(0.4, 1.3), st.floats(0.05, 2.0), st.floats(20, 200))
def test_closed_forms_recover_the_camera_from_exact_projections(f, phi, v, a):
    assume(phi + math.atan(a / f) < math.radians(85))  # the far row -A sees the ground
    cam = Camera(f, phi, v)
    x_w, y_w, x1, x2 = calibration_setup(cam, a, 0.5 * a + 30)
    tilt, focal, height = calibration_kernel(x1, x2, a, x_w, y_w)
    assert float(tilt) == pytest.approx(phi, abs=1e-9)
    assert float(focal) == pytest.approx(f, rel=1e-9)
    assert float(height) == pytest.approx(v, rel=1e-9)


def test_errata_9_24_printed_height_lacks_the_factor_2():
    """The digest's synthetic check: phi 45 deg, f 325.7, v 0.134 -> the printed (9.24) gives 0.067."""
    for f, phi, v in ((325.7, math.radians(45), 0.134), (545.0, math.radians(76), 1.42)):
        x_w, y_w, x1, x2 = calibration_setup(Camera(f, phi, v), 93.0, 120.0)
        printed = math.sin(phi) * 93.0 * x_w / (x1 - x2)
        assert printed == pytest.approx(v / 2, rel=1e-9)
        assert calibrate(x1, x2, 93.0, x_w, y_w).height == pytest.approx(v, rel=1e-9)


def quantisation_tolerance(x1, x2, a, x_w, y_w, delta=0.5):
    """How much (tilt, f, v) move when x1 and x2 each move by `delta` px (the pixel quantisation)."""
    base = np.array(calibration_kernel(x1, x2, a, x_w, y_w))
    d1 = np.abs(np.array(calibration_kernel(x1 + delta, x2, a, x_w, y_w)) - base)
    d2 = np.abs(np.array(calibration_kernel(x1, x2 + delta, a, x_w, y_w)) - base)
    return d1 + d2


@settings(max_examples=36)
@given(st.floats(250, 700), st.floats(math.radians(35), math.radians(68)), st.floats(0.1, 1.5),
       st.floats(0.2, 0.35), st.integers(0, 10_000))
def test_calibration_from_synthetic_images_recovers_random_cameras(f, phi, v, spread, seed):
    assume(phi + math.atan(120 / f) < math.radians(80))
    cam = Camera(f, phi, v, 640, 480)
    a = 120.0
    x_w, y_w, x1, x2 = calibration_setup(cam, a, spread * 640)
    img = render(cam, [0, 0, 0], Scene(ns=(), extra=(-x_w, x_w), width=0.12 * x_w), noise=2, seed=seed)
    cal = calibrate_image(img, a, x_w, y_w)
    tol = quantisation_tolerance(x1, x2, a, x_w, y_w)
    assert abs(cal.tilt - phi) <= tol[0]
    assert abs(cal.focal_px - f) <= tol[1]
    assert abs(cal.height - v) <= tol[2]


def test_thesis_calibration_example_fig_9_7():
    """§9.2.1.F: 13.4 cm, 45 deg, 325.7 px (metric tools: 13.5 cm, 45 deg), stripes slightly bent by the lens.

    A camera with those values renders two stripes 7 cm apart (the Fig. 9.9 lines are 3.5 cm apart) with a
    little barrel/pincushion distortion that the calibration ignores, as the thesis's did; the calibration
    gives back the height within 1 mm (the thesis's 13.4 against 13.5 cm), the tilt within 0.5 deg, f within 1 %.
    """
    for k1 in (0.0, 0.03, -0.03):
        cam = Camera(325.7, math.radians(45), 0.134, 320, 240, k1)
        x_w = 0.035
        psi, t = extrinsics([0, 0, 0], cam)
        g = ground_from_image(np.array([[0.0, 60.0], [0.0, -60.0]]), psi, cam.tilt, t, cam.focal_px)
        img = render(cam, [0, 0, 0], Scene(ns=(), extra=(-x_w, x_w), width=0.008), noise=2, blur=0.7)
        cal = calibrate_image(img, 60.0, x_w, float(g[1, 1] - g[0, 1]))
        assert cal.height == pytest.approx(0.134, abs=0.001)
        assert math.degrees(cal.tilt) == pytest.approx(45.0, abs=0.5)
        assert cal.focal_px == pytest.approx(325.7, rel=0.01)
        assert cal.camera(width=320, rows=240).focal_px == cal.focal_px


def test_calibration_refuses_what_is_no_calibration():
    with pytest.raises(CameraError, match=r"x1 .* must exceed x2"):
        calibrate(50, 60, 60, 0.035, 0.1)
    with pytest.raises(CameraError, match=r"cos\(tilt\)"):
        calibrate(70, 50, 60, 0.035, 0.001)
    with pytest.raises(CameraError, match="half-separation must be > 0"):
        calibrate(70, 50, 60, -1, 0.1)
    cam = Camera(325.7, math.radians(45), 0.134, 320, 240)
    turned = render(cam, [0, 0, 0.15], Scene(ns=(), extra=(-0.035, 0.035), width=0.008))
    with pytest.raises(CameraError, match="not the calibration pose"):
        calibrate_image(turned, 60.0, 0.035, 0.2)
    blank = np.full((240, 320), 70, np.uint8)
    with pytest.raises(CameraError, match="two stripes"):
        calibrate_image(blank, 60.0, 0.035, 0.2)


@pytest.mark.parametrize("x1, x2, rows_a, x_w, y_w, height", [
    (60, 59.9999999, 60, 0.035, 0.1022, "3.06e+07"),  # stripes that look parallel: focal 7.7e10 px, exit 0
    (60, 30, 1e-300, 0.035, 1e-300, "2.333e-303"),  # printed 'focal = 0.00 px, height = 0.00000 m'
])
def test_calibration_refuses_an_impossible_camera_height(x1, x2, rows_a, x_w, y_w, height):
    with pytest.raises(CameraError, match=rf"camera height of {re.escape(height)} m, outside the lengths"):
        calibrate(x1, x2, rows_a, x_w, y_w)


@pytest.mark.parametrize(("x_w", "y_w", "message"), [
    (1e300, 1e301, "half-separation must be at most 1000 m (the lengths wmrkit handles), got 1e+300 m"),
    (0.035, 1001, "row distance must be at most 1000 m (the lengths wmrkit handles), got 1001 m"),
])
def test_calibration_refuses_ground_lengths_beyond_those_wmrkit_handles(x_w, y_w, message):
    """1e300 m was refused as a camera height of 3.8e300 m, and '--half-separation 1e300' as a tilt's cosine of
    7e300, naming neither length."""
    with pytest.raises(CameraError, match=f"^calibration: {re.escape(message)}$"):
        calibrate(60, 30, 60, x_w, y_w)


@pytest.mark.parametrize("third", [-0.02, 0.01])
def test_calibration_image_with_a_third_stripe_is_refused(third):
    """The two strongest lines were taken: with a third stripe at -2 cm the camera came out 37.6 deg, 251 px,
    12.96 cm (truth 45 deg, 325.7 px, 13.4 cm), exit 0; at +1 cm 'cos(tilt) = 1.98'."""
    cam = Camera(325.7, math.radians(45), 0.134, 320, 240)
    image = render(cam, [0, 0, 0], Scene(ns=(), extra=(-0.035, 0.035, third), width=0.008))
    with pytest.raises(CameraError, match=r"^calibration: the image shows more than two stripes \(lines at x = "):
        calibrate_image(image, 60.0, 0.035, 0.10221)


def test_calibration_image_refuses_rows_too_close_to_measure_the_convergence():
    """Rows +-0.01 px gave tilt 89.99 deg, focal 2.8e6 px, height 0.19 m, exit 0 (x1 - x2 = 0.004 px)."""
    cam = Camera(325.7, math.radians(45), 0.134, 320, 240)
    image = render(cam, [0, 0, 0], Scene(ns=(), extra=(-0.035, 0.035), width=0.008))
    with pytest.raises(CameraError, match=r"differ by less than 1 px, too little to measure: .* \(A = 0.01 px\)$"):
        calibrate_image(image, 0.01, 0.035, 0.10221)
    assert calibrate_image(image, 5.0, 0.035, 0.00823).tilt == pytest.approx(math.radians(45), abs=1e-3)  # 1.8 px


def test_calibration_of_underflowing_measurements_is_refused_not_a_traceback():
    # x1 * x2 underflows to 0: the cos(tilt) of the message divided by zero (ZeroDivisionError, a traceback);
    # (9.18) is A (x_w / y_w) (x1 + x2) / (x1 x2) = 1e-300 (0.035 / 0.1022) 1.1e301 = 3.767
    with pytest.raises(CameraError, match=r"cos\(tilt\) = 3.767, not in \(0, 1\)"):
        calibrate(1e-300, 1e-301, 1e-300, 0.035, 0.1022)



@pytest.mark.parametrize("x1, x2, rows_a", [(0.002, 0.001, 0.001), (2e-5, 1e-5, 1e-5)])
def test_calibration_refuses_a_focal_length_no_camera_has(x1, x2, rows_a):
    # (9.21) gave f = 0.005 px, printed with exit 0 (without --out; with it the camera file named only focal_px)
    _, focal, height = calibration_kernel(x1, x2, rows_a, 0.035, 0.1022)
    assert focal < 1 and 1e-6 <= height <= 1e3  # the height check let it through
    with pytest.raises(CameraError, match=rf"^calibration: the measurements give a focal length of {focal:.4g} px, "
                                          r"below 1 px"):
        calibrate(x1, x2, rows_a, 0.035, 0.1022)


def test_calibration_image_refuses_a_far_row_beyond_the_vanishing_point_naming_rows_a():
    # the stripes cross at their vanishing point (row -f / tan(tilt), the horizon): on row -A above it their
    # half-distance is negative, and 'vision calibrate IMAGE --rows 100' said "x2 must be > 0", an option of the
    # other mode
    cam = Camera(325.7, math.radians(75), 0.134, 320, 240)
    horizon = cam.focal_px / math.tan(cam.tilt)  # 87.3 px above the centre
    image = render(cam, [0, 0, 0], Scene(ns=(), extra=(-0.035, 0.035), width=0.008))
    with pytest.raises(CameraError, match=r"^calibration: rows A \(100 px\): row -A is above where the stripes "
                                          r"meet \(row -87\.\d px\), take A below 87\.\d px$"):
        calibrate_image(image, 100.0, 0.035, 0.1)
    assert horizon == pytest.approx(87.3, abs=0.05)
