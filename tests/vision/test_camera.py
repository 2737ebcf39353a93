"""Camera model (9.1)-(9.4): the corrected rotation R', projection, pose of the camera on the robot, distortion."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from wmrkit.errors import WmrkitError
from wmrkit.vision.camera import (
    Camera,
    CameraError,
    camera_coordinates,
    check_lens_image,
    distort,
    extrinsics,
    fold_radius,
    ground_from_image,
    project,
    rotation,
    undistort,
)

angles = st.floats(-1.4, 1.4)
tilts = st.floats(0.2, 1.4)


def printed_9_3(psi: float, phi: float) -> np.ndarray:
    """The matrix of (9.3) exactly as 001 prints it."""
    cp, sp, cf, sf = math.cos(psi), math.sin(psi), math.cos(phi), math.sin(phi)
    return np.array([[cp, sp, 0], [sp * cf, -cp * cf, -sf], [sp * sf, cp * sf, -cf]])


@settings(max_examples=300)
@given(angles, tilts)
def test_errata_9_3_printed_matrix_is_not_a_rotation_r_prime_is(psi, phi):
    r = rotation(psi, phi)
    np.testing.assert_allclose(r @ r.T, np.eye(3), atol=1e-12)
    assert np.linalg.det(r) == pytest.approx(1.0)
    printed = printed_9_3(psi, phi)
    # the printed determinant is 1 - 2 sin^2(phi) sin^2(psi) (digest §2.2)
    assert np.linalg.det(printed) == pytest.approx(1 - 2 * math.sin(phi) ** 2 * math.sin(psi) ** 2, abs=1e-12)
    if abs(math.sin(psi) * math.sin(phi)) > 0.1:
        assert not np.allclose(printed @ printed.T, np.eye(3), atol=1e-3)
    # at psi = 0 the two coincide (digest: the versions agree when psi = 0)
    np.testing.assert_allclose(rotation(0.0, phi), printed_9_3(0.0, phi), atol=1e-15)


@settings(max_examples=300)
@given(angles, tilts, st.floats(-1, 1), st.floats(-1, 1), st.floats(0.5, 2))
def test_projection_is_9_4_with_r_prime_numerators(psi, phi, tx, ty, tz):
    cp, sp, cf, sf = math.cos(psi), math.sin(psi), math.cos(phi), math.sin(phi)
    f = 400.0
    p = np.array([0.3, 1.7, 0.1])
    xw, yw, zw = p
    den = sf * (sp * xw + cp * yw) - cf * zw + tz
    if den < 0.05:
        return
    expected = [f * (cp * xw - sp * yw + tx) / den, f * (-cf * (sp * xw + cp * yw) - sf * zw + ty) / den]
    np.testing.assert_allclose(project(p, psi, phi, [tx, ty, tz], f), expected, rtol=1e-10, atol=1e-9)


def test_optical_axis_and_image_axes_in_the_ground_frame():
    phi = math.radians(50)
    r = rotation(0.0, phi)
    np.testing.assert_allclose(r[2], [0, math.sin(phi), -math.cos(phi)], atol=1e-15)  # forward and down
    assert r[1, 1] < 0 and r[1, 2] < 0  # image y (down) points back towards the vehicle and down
    np.testing.assert_allclose(np.cross(r[0], r[1]), r[2], atol=1e-15)  # right-handed


@settings(max_examples=300)
@given(st.floats(-2, 2), st.floats(-0.5, 0.5), angles, st.floats(0, 1.0))
def test_extrinsics_place_the_lens_at_height_v_behind_p(x, y, theta, z_p):
    cam = Camera(300, 1.0, 0.4)
    psi, t = extrinsics([x, y, theta], cam, z_p)
    assert psi == pytest.approx(-theta)
    lens_w = -rotation(psi, cam.tilt).T @ t
    back = z_p * math.sin(cam.tilt)
    # line frame L (x along, y left) -> ground frame W (x_w = -y, y_w = x)
    np.testing.assert_allclose(lens_w, [-(y - back * math.sin(theta)), x - back * math.cos(theta), 0.4], atol=1e-12)
    # the point at z_p along the optical axis is above P
    p_w = lens_w + z_p * rotation(psi, cam.tilt)[2]
    np.testing.assert_allclose(p_w[:2], [-y, x], atol=1e-12)


@settings(max_examples=300)
@given(st.floats(-300, 300), st.floats(-200, 200))
def test_ground_from_image_inverts_projection(xu, yu):
    cam = Camera(320, 0.9, 0.5)
    psi, t = extrinsics([0.2, -0.1, 0.3], cam)
    g = ground_from_image([xu, yu], psi, cam.tilt, t, cam.focal_px)
    if not np.all(np.isfinite(g)):  # above the horizon: the ray is not pointing down
        ray = rotation(psi, cam.tilt).T @ [xu, yu, cam.focal_px]
        assert ray[2] >= -1e-9
        return
    np.testing.assert_allclose(project([g[0], g[1], 0.0], psi, cam.tilt, t, cam.focal_px), [xu, yu], atol=1e-7)
    assert camera_coordinates([g[0], g[1], 0.0], psi, cam.tilt, t)[2] > 0


@settings(max_examples=300)
@given(st.floats(-300, 300), st.floats(-240, 240), st.floats(-0.2, 0.2))
def test_undistort_inverts_distort(x, y, k1):
    d = distort([x, y], k1, 400.0)
    np.testing.assert_allclose(undistort(d, k1, 400.0), [x, y], atol=1e-9)


def test_undistort_is_exact_for_the_audits_points():
    """The fixed-point iteration stopped after 8 steps without converging: k1 = -0.5 gave (295.8, 217.0) for
    (300, 220), k1 = 0.5 (300.10, 220.08); k1 = -0.7 gave (251.7, 184.6), but (300, 220) lies beyond that model's
    fold (r = 372 px > f / sqrt(2.1) = 345 px): distort now says so (NaN) and no camera of that image is accepted."""
    for k1 in (-0.5, 0.5, 0.9):
        np.testing.assert_allclose(undistort(distort([[300.0, 220.0]], k1, 500.0), k1, 500.0), [[300.0, 220.0]],
                                   atol=1e-9)
    assert np.all(np.isnan(distort([[300.0, 220.0]], -0.7, 500.0)))
    with pytest.raises(CameraError, match=r"camera: k1: -0.7 folds the distortion model over inside the 640 x 480 "
                                          r"image .* k1 must be > -0.2315 for this image"):
        Camera(500.0, 0.5, 1.0, k1=-0.7)


def _grid(width: int, rows: int, step: int = 7) -> np.ndarray:
    """Image points [px from the centre] every `step` px and on the image's edges and corners."""
    xs = np.unique(np.r_[np.arange(-width / 2, width / 2, step), width / 2])
    ys = np.unique(np.r_[np.arange(-rows / 2, rows / 2, step), rows / 2])
    return np.stack(np.meshgrid(xs, ys), -1).reshape(-1, 2)


@pytest.mark.parametrize("k1", np.r_[np.linspace(-0.999, 0.999, 25), -1e-9, 1e-9, 1e-12])
def test_undistort_round_trips_over_the_whole_image_across_the_accepted_k1(k1):
    """Every image point (pixel edges included) of cameras with k1 across (-1, 1): the exact inverse, checked
    against the forward model both ways. For k1 < 0 the focal length puts the image's corners at 98 % of the
    fold radius (near the hardest camera accepted) and at 30 %."""
    width, rows = 640, 480
    corner = math.hypot(width, rows) / 2
    focals = [500.0, 2000.0] if k1 >= 0 else [corner * 1.5 * math.sqrt(-3 * k1) / c for c in (0.98, 0.3)]
    k1 = float(k1)
    for f in focals:
        # accepted by the lens check (a Camera's; for k1 = -1e-9 these focal lengths are below its MIN_FOCAL_PX)
        check_lens_image(k1, f, width, rows, "test")
        d = _grid(width, rows)
        u = undistort(d, k1, f)
        np.testing.assert_allclose(distort(u, k1, f), d, atol=1e-9)
        # the physical root: |u| below the fold, growing with |d| along each ray
        assert np.all(np.hypot(*u.T) <= fold_radius(k1, f)[0] * (1 + 1e-12))
        np.testing.assert_allclose(undistort(distort(u, k1, f), k1, f), u, atol=1e-8)
        ray = np.linspace(0, 1, 200)[:, None] * d[np.argmax(np.hypot(*d.T))]
        assert np.all(np.diff(np.hypot(*undistort(ray, k1, f).T)) > 0)


@settings(max_examples=600)
@given(st.floats(-0.999, 0.999), st.floats(50, 3000), st.integers(8, 1024), st.integers(8, 1024),
       st.floats(-0.5, 0.5), st.floats(-0.5, 0.5))
def test_undistort_inverts_distort_on_every_accepted_camera(k1, f, width, rows, a, b):
    try:
        cam = Camera(f, 0.8, 0.5, width, rows, k1)
    except CameraError as err:  # refused only where the model folds over inside the image
        assert "folds the distortion model over" in str(err)
        assert math.hypot(width, rows) / 2 >= fold_radius(k1, f)[1]
        return
    p = np.array([a * width, b * rows])  # a point of the image
    u = undistort(p, cam.k1, f)
    np.testing.assert_allclose(distort(u, cam.k1, f), p, atol=1e-9)
    np.testing.assert_allclose(undistort(distort(u, cam.k1, f), cam.k1, f), u, atol=1e-8)


def test_undistort_refuses_points_beyond_the_fold_and_distort_does_not_fold_back():
    r_u, r_d = fold_radius(-0.3, 400.0)
    assert (r_u, r_d) == (pytest.approx(400 / 0.9**0.5), pytest.approx(2 / 3 * 400 / 0.9**0.5))
    assert fold_radius(0.3, 400.0) == (math.inf, math.inf)
    # the fold itself, where dr_u/dr_d is infinite: round-off eps in r_d moves r_u by sqrt(eps), not eps
    np.testing.assert_allclose(undistort([r_d, 0.0], -0.3, 400.0), [r_u, 0.0], rtol=2 * np.finfo(float).eps ** 0.5)
    with pytest.raises(CameraError, match=r"undistort: xy_d: 1 point\(s\) \(0, 290\) px lie beyond 281.1 px"):
        undistort([[0.0, 10.0], [0.0, 290.0]], -0.3, 400.0)
    # beyond the fold the model would image points where nearer points are: NaN, not a second image
    d = distort([[r_u * 0.999, 0.0], [r_u * 1.5, 0.0]], -0.3, 400.0)
    assert np.isfinite(d[0]).all() and np.isnan(d[1]).all()


@pytest.mark.parametrize(("call", "message"), [
    (lambda: distort([1.0, 2.0], math.nan, 400.0), "distort: k1: expected a finite number, got nan"),
    (lambda: undistort([1.0, 2.0], 0.1, 0.0), r"undistort: focal_px: expected a finite number > 0, got 0.0"),
    (lambda: undistort([1.0, 2.0], 0.1, -400.0), r"undistort: focal_px: expected a finite number > 0, got -400.0"),
    (lambda: fold_radius(-0.1, math.inf), r"fold_radius: focal_px: expected a finite number > 0, got inf"),
])
def test_the_distortion_functions_refuse_their_inputs_by_name(call, message):
    with pytest.raises(CameraError, match=message):
        call()


@pytest.mark.parametrize(("args", "message"), [
    ((500.0, 0.5, 1.0, "640"), r"camera: width: expected a whole number of pixels \(an integer\), got '640'"),
    ((500.0, 0.5, 1.0, 640.5), r"camera: width: expected a whole number of pixels \(an integer\), got 640.5"),
    ((500.0, 0.5, 1.0, 640, 480.0), r"camera: rows: expected a whole number of pixels \(an integer\), got 480.0"),
    ((500.0, 0.5, 1.0, True), r"camera: width: expected a whole number of pixels \(an integer\), got True"),
    (("500", 0.5, 1.0), r"camera: focal_px: expected a number, got '500'"),
    ((500.0, None, 1.0), r"camera: tilt: expected a number, got None"),
    ((500.0, 0.5, 1.0, 640, 480, "0.1"), r"camera: k1: expected a number, got '0.1'"),
    ((math.inf, 0.5, 1.0), r"camera: focal_px: out of range, got inf"),
    ((-500.0, 0.5, 1.0), r"camera: focal_px: out of range, got -500.0"),
    # 'focal_px: 1e-300' was accepted: locate printed a line 2.3e284 m away
    ((1e-300, 0.5, 1.0), r"^camera: focal_px: out of range, got 1e-300 \(expected a number in \[1, 1e\+07\] px\)$"),
    ((500.0, 0.5, math.nan), r"camera: height: out of range, got nan"),
    # a height of 1e308 m was accepted: locate printed a NaN spacing and a numpy warning
    ((500.0, 0.5, 1e308), r"^camera: height: out of range, got 1e\+308 \(expected a length in \(0, 1000\] m\)$"),
    # the range was not said, nor the value in degrees of a tilt given as '100 deg'
    ((500.0, math.radians(100), 1.0), r"^camera: tilt: out of range, got 1.745\d* rad \(100 deg\) \(expected an "
                                      r"angle in \(0, 90 deg\) from the vertical\)$"),
])
def test_camera_fields_are_checked_by_name(args, message):
    """Camera(500., .5, 1., "640") raised a bare TypeError and width=640.5 was accepted."""
    with pytest.raises(CameraError, match=message):
        Camera(*args)


def test_camera_numbers_are_stored_as_python_numbers(tmp_path):
    cam = Camera(np.float64(400.0), np.float32(0.75), 1, np.int64(320), np.int32(240))
    assert [type(v) for v in cam.to_dict().values()] == [float, float, float, int, int, float]
    cam.to_file(tmp_path / "cam.yaml")  # numpy scalars are not YAML
    assert Camera.from_file(tmp_path / "cam.yaml") == cam


@pytest.mark.parametrize("focal", [0.0, -400.0, math.nan, math.inf, [400.0, 0.0]])
def test_project_and_ground_from_image_refuse_a_focal_length_that_is_not_positive(focal):
    """focal_px = 0 put every point at the image centre, a negative one mirrored the image."""
    psi, t = extrinsics([0.0, 0.0, 0.0], Camera(400.0, 0.8, 0.5))
    with pytest.raises(CameraError, match=r"^project: focal_px: expected finite numbers > 0 \[px\], got "):
        project([0.0, 2.0, 0.0], psi, 0.8, t, focal)
    with pytest.raises(CameraError, match=r"^ground_from_image: focal_px: expected finite numbers > 0"):
        ground_from_image([0.0, 10.0], psi, 0.8, t, focal)


def test_a_camera_file_is_written_as_its_extension_says(tmp_path):
    """'--out cam.json' wrote YAML (not JSON) and '--out cam.png' YAML into a picture's name."""
    cam = Camera(325.7, math.radians(45), 0.134, 320, 240, 0.05)
    cam.to_file(tmp_path / "cam.json")
    assert json.loads((tmp_path / "cam.json").read_text()) == cam.to_dict()
    assert Camera.from_file(tmp_path / "cam.json") == cam
    for name in ("cam.png", "cam"):
        with pytest.raises(CameraError, match=rf"{name}: a camera file is .yaml, .yml or .json"):
            cam.to_file(tmp_path / name)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["cam.json"]


def test_camera_file_round_trip_and_errors(tmp_path):
    cam = Camera(325.7, math.radians(45), 0.134, 320, 240, 0.05)
    path = tmp_path / "cam.yaml"
    cam.to_file(path)
    assert Camera.from_file(path) == cam
    (tmp_path / "bad.yaml").write_text("focal_px: 300\ntilt: 0.8\nheigth: 0.2\n")
    with pytest.raises(CameraError, match=r"bad.yaml:3: heigth: unknown field \(camera fields: focal_px, "):
        Camera.from_file(tmp_path / "bad.yaml")
    (tmp_path / "neg.yaml").write_text("focal_px: 300\ntilt: 2.0\nheight: 0.2\n")
    with pytest.raises(WmrkitError, match=r"neg.yaml:2: tilt: out of range"):
        Camera.from_file(tmp_path / "neg.yaml")
    with pytest.raises(CameraError, match="cannot read"):
        Camera.from_file(tmp_path / "missing.yaml")
    (tmp_path / "twice.yaml").write_text("focal_px: 300\ntilt: 0.8\nheight: 0.2\ntilt: 0.9\n")
    with pytest.raises(CameraError, match=r"twice.yaml:4: tilt: field 'tilt' given twice"):  # not the last one kept
        Camera.from_file(tmp_path / "twice.yaml")


def test_camera_files_read_numbers_and_units_as_descriptions_do(tmp_path):
    """'k1: 1e-7' is a string to YAML 1.1 and was refused ("expected a number, got '1e-7'"); units are read as in
    robot descriptions, and a bare tilt beyond a turn (degrees meant) is refused."""
    from wmrkit.vision.camera import Camera, CameraError

    path = tmp_path / "cam.yaml"
    path.write_text("focal_px: 1.5e2\ntilt: 60 deg\nheight: 30 cm\nwidth: 320\nrows: 240\nk1: 1e-7\n")
    cam = Camera.from_file(path)
    assert (cam.focal_px, cam.height, cam.k1) == (150.0, pytest.approx(0.3), 1e-7)
    assert cam.tilt == pytest.approx(math.radians(60))
    path.write_text("focal_px: 150\ntilt: 60\nheight: 0.3\n")
    with pytest.raises(CameraError, match="tilt: a bare angle is read in radians, and 60 rad is more than a turn"):
        Camera.from_file(path)
