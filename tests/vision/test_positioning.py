"""Positioning (9.5)-(9.11): exact recovery on synthetic points, the thesis's examples (Fig. 9.9, chufa field)."""

from __future__ import annotations

import json
import math
import re

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from wmrkit.vision.camera import Camera, CameraError, distort, extrinsics, project
from wmrkit.vision.positioning import line_position, locate_points, read_points


@st.composite
def setups(draw):
    cam = Camera(draw(st.floats(150, 900)), draw(st.floats(0.3, 1.35)), draw(st.floats(0.1, 2.0)))
    pose = (draw(st.floats(-5, 5)), draw(st.floats(-0.5, 0.5)), draw(st.floats(-0.6, 0.6)))
    z_p = draw(st.floats(0, 1)) * cam.height / math.cos(cam.tilt)
    spacing = draw(st.floats(0.05, 1.0))
    n = draw(st.sampled_from([-1, 0, 1]))
    return cam, pose, z_p, spacing, n


@settings(max_examples=500)
@given(setups(), st.floats(0.2, 5.0), st.floats(0.2, 5.0))
def test_projection_then_positioning_recovers_psi_and_h_exactly(setup, ahead1, gap):
    cam, (x, y, theta), z_p, d, n = setup
    # two ground points of line n ahead of the lens, projected with the camera model, then positioned
    psi, t = extrinsics([x, y, theta], cam, z_p)
    lens_y = x - z_p * math.sin(cam.tilt) * math.cos(theta)
    pts = np.array([[n * d, lens_y + ahead1 + 0.3, 0.0], [n * d, lens_y + ahead1 + 0.3 + gap, 0.0]])
    uv = project(pts, psi, cam.tilt, t, cam.focal_px)
    if not np.all(np.isfinite(uv)) or abs(uv[0, 1] - uv[1, 1]) < 1e-3:
        return  # behind the camera, or on one row
    got_psi, _, got_h = line_position(uv, n, focal_px=cam.focal_px, tilt=cam.tilt, height=cam.height,
                                      spacing=d, z_p=z_p)
    assert math.remainder(float(got_psi) - (-theta), 2 * math.pi) == pytest.approx(0, abs=1e-9)
    assert float(got_h) == pytest.approx(y, abs=1e-9 * (1 + abs(uv).max() / 100))


def test_batched_line_position_equals_loop():
    rng = np.random.default_rng(1)
    pts = rng.uniform(-100, 100, (4, 5, 2, 2))
    n = rng.integers(-1, 2, (4, 5))
    args = dict(focal_px=400.0, tilt=1.0, height=0.5, spacing=0.3, z_p=0.2)
    psi, tx, h = line_position(pts, n, **args)
    assert psi.shape == (4, 5)
    for idx in np.ndindex(4, 5):
        one = line_position(pts[idx], n[idx], **args)
        np.testing.assert_allclose([psi[idx], tx[idx], h[idx]], [float(v) for v in one], rtol=1e-14)


CHUFA = {"a": [(-10, -93), (-90, 93)], "b": [(4, -93), (-2, 93)], "c": [(18, -93), (83, 93)]}
CHUFA_CAMERA = Camera(545.0, math.radians(76), 1.42)


def test_thesis_chufa_field_with_the_digest_labels():
    """Figs. 9.10-9.11: psi -0.86, -0.55, -0.3 deg and h -2.4, -4.2, -8.5 cm with n = (-1, 0, 1) for (a, b, c)."""
    fix = locate_points(CHUFA_CAMERA, [(n, CHUFA[k]) for k, n in zip("abc", (-1, 0, 1), strict=True)],
                        spacing=0.60)
    psis = [math.degrees(f.psi) for f in fix.lines]
    np.testing.assert_allclose(psis, [-0.86, -0.55, -0.3], atol=0.01)
    np.testing.assert_allclose([f.h for f in fix.lines], [-0.024, -0.042, -0.085], atol=0.003)
    # the thesis's "maximum error relative to the mean": 0.3 deg holds
    assert max(abs(p - np.mean(psis)) for p in psis) == pytest.approx(0.3, abs=0.05)


def test_errata_chufa_printed_labels_give_nonsense():
    """With the printed n = (1, -1, 0) line a is 1.22 m from the centre line, not 2.4 cm; locate_points refuses
    such labels (lines b and a then lie -0.29 m apart: check_spacing)."""
    c = CHUFA_CAMERA
    h = [float(line_position(CHUFA[k], n, focal_px=c.focal_px, tilt=c.tilt, height=c.height, spacing=0.60)[2])
         for k, n in zip("abc", (1, -1, 0), strict=True)]
    assert h[0] == pytest.approx(-1.224, abs=0.001)
    assert abs(h[1] - h[0]) > 1.0
    with pytest.raises(CameraError, match=r"the lines n = -1 and \+1 are -0.29\d* m apart"):
        locate_points(CHUFA_CAMERA, [(n, CHUFA[k]) for k, n in zip("abc", (1, -1, 0), strict=True)], spacing=0.60)


def test_errata_fig_9_9_deviations_need_the_label_fix():
    """Fig. 9.9: each h relative to its own line, shifted to the centre with n = +1 'left', -1 'right'."""
    psi = np.radians([-35.447, -33.928, -36.927])
    h_own = np.array([-0.024, -0.056, -0.095])
    assert np.max(np.abs(np.degrees(psi - psi.mean()))) == pytest.approx(1.5, abs=0.02)
    h_c = h_own - np.array([1, 0, -1]) * 0.035  # h_own = h_centre + n d  (h = -x_w(P), line n at x_w = n d)
    assert np.max(np.abs(h_c - h_c.mean())) == pytest.approx(0.0023, abs=0.0001)
    wrong = h_own - np.array([-1, 0, 1]) * 0.035
    assert np.max(np.abs(wrong - wrong.mean())) > 0.03


def test_h_own_line_shift_is_n_times_spacing():
    """The relation used above: the same two points positioned as line n or as its own line (n = 0)."""
    pts = np.array([[-40.0, -60.0], [-75.0, 60.0]])
    args = dict(focal_px=325.7, tilt=math.radians(45), height=0.134, spacing=0.035)
    _, _, h_centre = line_position(pts, 1, **args)
    _, _, h_own = line_position(pts, 0, **args)
    assert float(h_own - h_centre) == pytest.approx(0.035, abs=1e-12)


def test_distorted_points_are_undistorted_with_the_camera_k1():
    cam = Camera(400, 1.0, 0.5, k1=0.1)
    psi, t = extrinsics([0, 0.05, 0.1], cam)
    uv = project(np.array([[0.0, 1.0, 0], [0.0, 2.5, 0]]), psi, cam.tilt, t, cam.focal_px)
    fix = locate_points(cam, [(0, distort(uv, cam.k1, cam.focal_px))])
    assert fix.h == pytest.approx(0.05, abs=1e-9) and fix.psi == pytest.approx(-0.1, abs=1e-9)


def test_points_beyond_the_fold_of_the_lens_model_are_refused_by_line():
    """Points may lie outside the image (up to its size); with k1 < 0 they can lie beyond the fold of the radial
    model, where no undistorted point exists: the fixed-point iteration returned one that did not converge."""
    cam = Camera(400.0, 1.0, 0.5, 320, 240, k1=-0.3)  # folds over 281.1 px from the centre
    with pytest.raises(CameraError, match=r"^points: lines\[1\]: 1 point\(s\) \(300, 200\) px lie beyond 281.1 px"):
        locate_points(cam, [(0, [[1.0, -50.0], [3.0, 50.0]]), (1, [[300.0, 200.0], [40.0, 50.0]])], spacing=0.5)


def test_points_above_the_horizon_are_refused_by_line():
    """The chufa camera's horizon is row -135.9 px: points on row -200 see no ground, and a line through them was
    positioned 13.3 m away at psi = 89 deg, exit 0."""
    with pytest.raises(CameraError, match=re.escape("points: lines[0]: a point [[300.0, -200.0], [-300.0, -199.0]] "
                                                    "lies above the horizon (row y_u = -135.9 px")):
        locate_points(CHUFA_CAMERA, [(0, [[300.0, -200.0], [-300.0, -199.0]])])
    with pytest.raises(CameraError, match=r"^points: lines\[0\]: a point .* lies above the horizon"):
        locate_points(CHUFA_CAMERA, [(0, [[4.0, -135.9], [-2.0, 93.0]])])  # 0.02 px above it
    locate_points(CHUFA_CAMERA, [(0, [[4.0, -135.8], [-2.0, 93.0]])])  # just below it: accepted


@pytest.mark.parametrize(("points", "n", "message"), [
    ([[math.nan, 40.0], [-5.0, 80.0]], 0, "points_u: expected finite image coordinates [px], got nan"),
    ([[10.0, 40.0], [-5.0, math.inf]], 0, "points_u: expected finite image coordinates [px], got inf"),
    ([[10.0, 40.0], [-5.0, 80.0]], math.nan, "n: expected finite line indices, got nan"),
])
def test_line_position_refuses_points_that_are_not_finite(points, n, message):
    """NaN points gave psi = h = NaN without a word."""
    from wmrkit.errors import ShapeError

    with pytest.raises(ShapeError, match=f"^{re.escape(message)}$"):
        line_position(points, n, focal_px=500.0, tilt=0.3, height=0.5, spacing=0.1)


def test_points_file_and_its_errors(tmp_path):
    good = tmp_path / "p.json"
    good.write_text(json.dumps({"lines": [{"n": 0, "points": [[1, -50], [3, 50]]}]}))
    (n, pts), = read_points(good)
    assert n == 0 and pts.shape == (2, 2)
    cases = {
        "notjson.json": ("{", r"notjson.json:1: malformed JSON"),
        "twice.json": ('{"lines": [{"n": 0, "n": 1, "points": [[1, 2], [3, 4]]}]}', r"twice.json:1: .*'n' given twice"),
        "empty.json": ('{"lines": []}', r"expected"),
        "field.json": ('{"lines": [{"n": 0, "pts": [[1, 2], [3, 4]]}]}', r"lines\[0\]: expected the fields"),
        "n.json": ('{"lines": [{"n": "x", "points": [[1, 2], [3, 4]]}]}', r"lines\[0\].n"),
        "pts.json": ('{"lines": [{"n": 0, "points": [[1, 2]]}]}', r"lines\[0\].points"),
        # an unknown top-level field was ignored
        "extra.json": ('{"lines": [{"n": 0, "points": [[1, -50], [3, 50]]}], "spacing": 0.6}',
                       r"extra.json: unknown field 'spacing' \(the only field is 'lines'\)$"),
    }
    for name, (text, message) in cases.items():
        (tmp_path / name).write_text(text)
        with pytest.raises(CameraError, match=message):
            read_points(tmp_path / name)
    cam = Camera(300, 1.0, 0.3)
    with pytest.raises(CameraError, match="needs the line spacing"):
        locate_points(cam, [(1, [[0, -10], [1, 10]])])
    with pytest.raises(CameraError, match="one image row"):
        locate_points(cam, [(0, [[0, 10], [1, 10]])])
    with pytest.raises(CameraError, match="must be -1, 0 or 1"):
        locate_points(cam, [(2, [[0, -10], [1, 10]])], spacing=0.1)
    # True (== 1) was positioned as line n = +1, as a points file's "n": true is refused
    with pytest.raises(CameraError, match=r"^points: lines\[0\]\.n: must be -1, 0 or 1, got True$"):
        locate_points(cam, [(True, [[0, -10], [1, 10]])], spacing=0.1)


@pytest.mark.parametrize(("spacing", "z_p", "message"), [
    (-0.035, 0.0, "spacing: expected a length in [0, 1000] m (0: one line), got -0.035"),
    (math.nan, 0.0, "spacing: expected a length in [0, 1000] m (0: one line), got nan"),
    (1e300, 0.0, "spacing: expected a length in [0, 1000] m (0: one line), got 1e+300"),
    (0.0, 1e300, "z_p: expected a length in [-1000, 1000] m, got 1e+300"),
])
def test_locate_points_refuses_a_spacing_or_z_p_out_of_range(spacing, z_p, message):
    """A negative spacing was read as none (one line, silently); z_p = 1e300 printed h = 4e299 m."""
    with pytest.raises(CameraError, match=f"^{re.escape(message)}$"):
        locate_points(Camera(300, 1.0, 0.3), [(0, [[0, -10], [1, 10]])], spacing=spacing, z_p=z_p)
