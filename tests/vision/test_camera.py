"""Camera model (9.1)-(9.4): the corrected rotation R', projection, pose of the camera on the robot, distortion."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from wmrkit.errors import WmrkitError
from wmrkit.vision.camera import (
    Camera,
    CameraError,
    camera_coordinates,
    distort,
    extrinsics,
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


@given(st.floats(-300, 300), st.floats(-240, 240), st.floats(-0.2, 0.2))
def test_undistort_inverts_distort(x, y, k1):
    d = distort([x, y], k1, 400.0)
    np.testing.assert_allclose(undistort(d, k1, 400.0, iterations=40), [x, y], atol=1e-6)


def test_camera_file_round_trip_and_errors(tmp_path):
    cam = Camera(325.7, math.radians(45), 0.134, 320, 240, 0.05)
    path = tmp_path / "cam.yaml"
    cam.to_file(path)
    assert Camera.from_file(path) == cam
    (tmp_path / "bad.yaml").write_text("focal_px: 300\ntilt: 0.8\nheigth: 0.2\n")
    with pytest.raises(CameraError, match=r"bad.yaml: unknown field 'heigth'"):
        Camera.from_file(tmp_path / "bad.yaml")
    (tmp_path / "neg.yaml").write_text("focal_px: 300\ntilt: 2.0\nheight: 0.2\n")
    with pytest.raises(WmrkitError, match=r"neg.yaml: tilt: out of range"):
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
