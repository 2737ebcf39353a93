"""Line extraction (§9.2.1.C) on synthetic camera images: exact lines are the camera model's projections."""

from __future__ import annotations

import builtins
import math
import re
from pathlib import Path

import numpy as np
import pytest

from wmrkit.errors import WmrkitError
from wmrkit.vision import lines as lines_module
from wmrkit.vision.camera import Camera, CameraError, extrinsics, project
from wmrkit.vision.follow import locate_image
from wmrkit.vision.lines import extract_lines, interest_mask
from wmrkit.vision.render import Scene, render

FIGURES = Path(__file__).parents[2] / "docs" / "figures" / "vision"
CAMERA = Camera(325.7, math.radians(45), 0.134, 640, 480)
SCENE = Scene(ns=(-1, 0, 1), spacing=0.035, width=0.008)
POSE = (0.0, -0.058, math.radians(10))


def true_lines(cam: Camera, pose, scene: Scene) -> list[tuple[float, float]]:
    """``(x0, slope)`` of each ground line's image, by projecting two of its points."""
    psi, t = extrinsics(pose, cam)
    out = []
    for x_w in scene.offsets:
        uv = project(np.array([[x_w, pose[0] + 0.2, 0], [x_w, pose[0] + 0.6, 0]]), psi, cam.tilt, t, cam.focal_px)
        slope = (uv[1, 0] - uv[0, 0]) / (uv[1, 1] - uv[0, 1])
        out.append((uv[0, 0] - slope * uv[0, 1], slope))
    return out


@pytest.mark.parametrize("mode", ["threshold", "gradient"])
@pytest.mark.parametrize("options", [{}, {"noise": 6.0}, {"blur": 1.2}, {"noise": 4.0, "blur": 0.8}],
                         ids=["clean", "noise", "blur", "noise+blur"])
def test_lines_are_found_to_a_tenth_of_a_pixel(mode, options):
    img = render(CAMERA, POSE, SCENE, **options)
    found = extract_lines(img, n_lines=3, mode=mode)
    assert len(found) == 3
    for line, (x0, slope) in zip(found, true_lines(CAMERA, POSE, SCENE), strict=True):
        for y in (-120.0, 120.0):
            assert line.x_at(y) == pytest.approx(x0 + slope * y, abs=0.15)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_clutter_does_not_move_the_position_much(seed):
    img = render(CAMERA, POSE, SCENE, clutter=12, noise=4.0, seed=seed)
    fix = locate_image(CAMERA, img, spacing=0.035)
    assert fix.psi == pytest.approx(-POSE[2], abs=math.radians(0.3))
    assert fix.h == pytest.approx(POSE[1], abs=0.001)


def test_distorted_stripes_are_found_and_straightened_with_k1():
    cam = Camera(325.7, math.radians(45), 0.134, 640, 480, k1=0.08)
    img = render(cam, POSE, SCENE, noise=3.0)
    fix = locate_image(cam, img, spacing=0.035)  # k1 known: pixels undistorted before the fit
    assert fix.psi == pytest.approx(-POSE[2], abs=math.radians(0.05))
    assert fix.h == pytest.approx(POSE[1], abs=2e-4)
    ignorant = locate_image(Camera(325.7, math.radians(45), 0.134, 640, 480), img, spacing=0.035)
    assert abs(ignorant.h - POSE[1]) > 5 * abs(fix.h - POSE[1])  # the bent stripes are still found


def test_a_distortion_that_folds_over_inside_the_image_is_refused():
    """k1 = -0.5 with f = 325.7 px folds over 230 px from the centre, inside the 640 x 480 image: the pixels beyond
    have no undistorted position (the fixed-point iteration gave some without converging)."""
    img = render(CAMERA, POSE, SCENE)
    with pytest.raises(WmrkitError, match=r"^extract_lines: k1: -0.5 folds the distortion model over inside the "
                                          r"640 x 480 image \(focal 325.7 px\)"):
        extract_lines(img, n_lines=3, k1=-0.5, focal_px=325.7)
    with pytest.raises(WmrkitError, match=r"^extract_lines: k1: expected a finite number, got nan"):
        extract_lines(img, n_lines=3, k1=math.nan, focal_px=325.7)


def test_wide_stripe_gives_its_axis_not_a_diagonal():
    """A wide painted band (the mean cell of §9.2.1.C): the axis, not a line from corner to corner."""
    cam = Camera(300, math.radians(55), 0.3, 320, 240)
    scene = Scene(ns=(0,), width=0.25)
    pose = (0.0, 0.05, 0.1)
    fix = locate_image(cam, render(cam, pose, scene, noise=3.0), z_p=0.0)
    assert fix.h == pytest.approx(0.05, abs=0.002)
    assert fix.psi == pytest.approx(-0.1, abs=math.radians(0.3))


def test_thesis_fig_9_9_three_lines_synthetic():
    """Fig. 9.8-9.9 scene (calibrated camera, lines 3.5 cm apart, psi ~ -35.4 deg, h ~ -5.8 cm, z_P = 0):
    each line's position is within the thesis's stated maximum deviation (1.5 deg, 2.3 mm) of the truth."""
    cam = Camera(325.716, math.radians(45.063), 0.134, 320, 240)
    pose = (0.0, -0.0583, math.radians(35.434))
    img = render(cam, pose, Scene(ns=(-1, 0, 1), spacing=0.035, width=0.006), noise=3.0, blur=0.7)
    fix = locate_image(cam, img, spacing=0.035)
    for line in fix.lines:
        assert abs(math.degrees(line.psi) + 35.434) < 1.5
        assert abs(line.h - pose[1]) < 0.0023


def test_chufa_crop_rows_synthetic():
    """Figs. 9.10-9.11 setting: f 545 px, v 1.42 m, phi 76 deg, rows 60 cm apart, plants of varying width; five
    rows in view, the three central ones used. Clean: exact to 2 mm; with weeds (bright blobs up to the rows'
    width, touching them) within the thesis's field agreement, 0.3 deg and 2.5 cm (docs/vision.md: at most
    2.3 cm and 0.28 deg over 20 seeds)."""
    cam = Camera(545, math.radians(76), 1.42, 640, 480)
    scene = Scene(ns=(-2, -1, 0, 1, 2), spacing=0.6, width=0.25, style="crops")
    pose = (0.0, -0.05, math.radians(0.57))
    for seed in range(3):
        clean = locate_image(cam, render(cam, pose, scene, noise=6.0, blur=1.0, seed=seed), spacing=0.6)
        assert [f.n for f in clean.lines] == [-1, 0, 1]
        assert clean.psi == pytest.approx(-pose[2], abs=math.radians(0.05))
        assert clean.h == pytest.approx(pose[1], abs=0.002)
        weeds = locate_image(cam, render(cam, pose, scene, noise=6.0, blur=1.0, clutter=8, seed=seed), spacing=0.6)
        assert weeds.psi == pytest.approx(-pose[2], abs=math.radians(0.3))
        assert weeds.h == pytest.approx(pose[1], abs=0.025)


@pytest.mark.parametrize("turn_deg", [5.0, 10.0, 15.5, -15.5, 20.0])
@pytest.mark.parametrize("h", [0.009, 0.2, -0.25, 0.29])
def test_a_turned_robot_between_crop_rows_follows_the_nearest(turn_deg, h):
    """The lines centred in the image were taken as rows -1, 0, 1: turned 5 deg at 20 cm from its row, the robot was
    placed at -40 cm (one row over, 0.6 m apart), and would steer to the next row. Identical rows: the followed one
    is the one P is nearest (|h| <= spacing / 2); checked against the pose rendered."""
    cam = Camera(545, math.radians(76), 1.42, 640, 480)
    scene = Scene(ns=(-2, -1, 0, 1, 2), spacing=0.6, width=0.25, style="crops")
    fix = locate_image(cam, render(cam, (0.0, h, math.radians(turn_deg)), scene, noise=6.0, blur=1.0, seed=1),
                       spacing=0.6)
    assert fix.h == pytest.approx(h, abs=0.005)
    assert fix.psi == pytest.approx(-math.radians(turn_deg), abs=math.radians(0.05))


def test_road_with_two_lines_and_no_centre_line():
    """Fig. 9.5 (a): a road's two lines at n = -1 and +1, the followed centre line not painted."""
    cam = Camera(400, math.radians(70), 1.2, 640, 480)
    pose = (0.0, 0.3, 0.05)
    img = render(cam, pose, Scene(ns=(-1, 1), spacing=1.6, width=0.12), noise=4.0, clutter=6)
    fix = locate_image(cam, img, spacing=1.6, ns=(-1, 1))
    assert [f.n for f in fix.lines] == [-1, 1]
    assert fix.psi == pytest.approx(-0.05, abs=math.radians(0.1))
    assert fix.h == pytest.approx(0.3, abs=0.005)


def test_a_camera_whose_horizon_is_below_the_far_row_locates_from_rows_that_see_the_ground():
    """Tilt 85 deg: the horizon is row -47.7 px, above the far row -120 px would see no ground (points there are
    refused): the far point is taken halfway to the horizon, on the same image line."""
    cam = Camera(545.0, math.radians(85), 1.42, 640, 480)
    fix = locate_image(cam, render(cam, (0.0, -0.2, -0.1), Scene(width=0.05)))
    assert fix.psi == pytest.approx(0.1, abs=1e-3) and fix.h == pytest.approx(-0.2, abs=1e-3)
    assert fix.lines[0].points[0][1] == pytest.approx(-545.0 / math.tan(math.radians(85)) / 2)


@pytest.mark.parametrize(("image", "options", "message"), [
    # OpenCV's resize raised on a row wider than 400 px ('vision calibrate' printed its traceback)
    (np.tile(np.r_[np.full(100, 70), np.full(10, 220)], 10)[None].astype(np.uint8), {},
     "image: 1100 x 1 px, smaller than 8 px a side"),
    (np.zeros((240, 320), np.uint8), {"hough_scale": 0.0}, "extract_lines: hough_scale: expected a factor in (0, 1]"),
    (np.zeros((240, 320), np.uint8), {"hough_scale": 100.0}, "extract_lines: hough_scale: expected a factor"),
    (np.zeros((240, 320), np.uint8), {"max_angle": math.nan}, "extract_lines: max_angle: expected an angle in"),
    (np.zeros((240, 320), np.uint8), {"n_lines": 2.5}, "n_lines must be an integer >= 1, got 2.5"),
])
def test_extract_lines_refuses_what_opencv_failed_on(image, options, message):
    with pytest.raises(CameraError, match=re.escape(message)):
        extract_lines(image, **options)


def test_locate_image_refuses_an_image_that_is_not_the_camera_size():
    """A 420 x 340 px image (the camera's 320 x 240 padded) was positioned about the wrong centre: h = -1.5 mm,
    psi = 0.5 deg for a robot 0.1 m left of the line at psi = -5.7 deg, no error."""
    cam = Camera(150.0, math.radians(60), 0.3, 320, 240)
    img = render(cam, (0.0, 0.1, 0.1), Scene())
    with pytest.raises(CameraError, match=r"^image: 420 x 340 px, the camera's is 320 x 240$"):
        locate_image(cam, np.pad(img, 50))


def test_blank_image_has_no_lines_and_bad_input_is_refused():
    assert extract_lines(np.full((120, 160), 90, np.uint8)) == ()
    with pytest.raises(WmrkitError, match="expected a grey or BGR image"):
        interest_mask(np.zeros((4, 4, 2)))
    with pytest.raises(WmrkitError, match="mode must be"):
        interest_mask(np.zeros((8, 8)), "edges")
    with pytest.raises(WmrkitError, match="found 0 line"):
        locate_image(CAMERA, np.full((480, 640), 90, np.uint8))


def test_missing_opencv_names_the_extra(monkeypatch):
    real_import = builtins.__import__

    def no_cv2(name, *args, **kwargs):
        if name == "cv2":
            raise ImportError("no cv2")
        return real_import(name, *args, **kwargs)

    monkeypatch.setattr(builtins, "__import__", no_cv2)
    with pytest.raises(WmrkitError, match=r"the 'vision' extra is needed: pip install 'wmrkit\[vision\]'"):
        lines_module.cv2_module()


def test_runs_of_a_random_mask_match_a_loop():
    rng = np.random.default_rng(0)
    mask = (rng.random((40, 57)) < 0.4).astype(np.uint8) * 255
    mask[:, 0] = mask[:, -1] = 255  # runs touching both borders
    rows, first, middle, length = lines_module._runs(mask)
    expected = []
    for r in range(mask.shape[0]):
        c = 0
        while c < mask.shape[1]:
            if mask[r, c]:
                end = c
                while end < mask.shape[1] and mask[r, end]:
                    end += 1
                expected.append((r, c, (c + end - 1) / 2, end - c))
                c = end
            else:
                c += 1
    assert list(zip(rows.tolist(), first.tolist(), middle.tolist(), length.tolist(), strict=True)) == expected


@pytest.mark.parametrize("noise", [20.0, 40.0, 255.0])
def test_an_image_too_noisy_for_the_threshold_is_refused_not_read_as_lines(noise):
    """Image noise of 20 grey levels defeats Otsu's threshold of a thin line: 40 % of the pixels become of
    interest and Hough found a line in them wherever the speckle peaked (the follower steered to it, exit 0)."""
    cam = Camera(150, math.radians(60), 0.3, 320, 240)
    scene = Scene(ns=(0,), width=0.02)
    assert len(extract_lines(render(cam, (0, 0.3, 0), scene, noise=12.0, seed=1))) == 1  # below: found
    with pytest.raises(WmrkitError, match=r"image: too noisy to find lines, \d+ runs of pixels of interest a row"):
        extract_lines(render(cam, (0, 0.3, 0), scene, noise=noise, seed=1))
    with pytest.raises(WmrkitError, match="too noisy"):
        locate_image(cam, render(cam, (0, 0.3, 0), scene, noise=noise, seed=1))


def test_weeds_and_crop_rows_are_not_speckle():
    """The densest scenes of these tests (five crop rows with 100 weeds; 5 runs a row at most in the median)."""
    cam = Camera(545, math.radians(76), 1.42, 640, 480)
    scene = Scene(ns=(-2, -1, 0, 1, 2), spacing=0.6, width=0.25, style="crops")
    img = render(cam, (0.0, -0.05, 0.01), scene, noise=6.0, blur=1.0, clutter=100, seed=1)
    assert len(extract_lines(img, n_lines=5)) >= 3


@pytest.mark.parametrize(("pose", "z_p", "shapes"), [([[0.0, 0.1, 0.0], [1.0, 0.1, 0.0]], 0.0, "(2, 3) and ()"),
                                                     ((0.0, 0.1, 0.0), np.array([0.0, 0.1]), "(3,) and (2,)")])
def test_render_makes_one_image_of_one_pose(pose, z_p, shapes):
    """Two poses, or two z_p, raised numpy's ValueError (operands could not be broadcast; truth value of an array
    is ambiguous) from deep in the camera model."""
    with pytest.raises(CameraError, match=rf"^render: one pose \(x, y, theta\) and one z_p make an image, got "
                                          rf"shapes {re.escape(shapes)}$"):
        render(CAMERA, pose, Scene(), z_p=z_p)


@pytest.mark.parametrize(("pose", "z_p"), [((0.0, math.nan, 0.0), 0.0), ((0.0, 0.1, math.inf), 0.0),
                                           ((0.0, 0.1, 0.0), math.nan)])
def test_render_refuses_a_pose_that_is_not_finite(pose, z_p):
    """It rendered a blank image (ground only), which reads as 'no line in view'."""
    with pytest.raises(CameraError, match=r"^render: pose and z_p must be finite"):
        render(CAMERA, pose, Scene(), z_p=z_p)


@pytest.mark.parametrize(("kwargs", "message"), [
    ({"ns": (-1, 0, 1), "spacing": math.nan}, "scene: spacing must be in [0, 1000] m, got nan"),
    ({"ns": (-1, 0, 1), "spacing": -0.5}, "scene: spacing must be in [0, 1000] m, got -0.5"),
    ({"ns": (), "extra": (0.1, math.inf)}, "scene: extra must be a tuple of real numbers within 1000 m of the line "
                                           "(lateral positions of further stripes), got (0.1, inf)"),
])
def test_scene_refuses_stripe_positions_that_are_not_lengths(kwargs, message):
    """A NaN spacing rendered the image with a numpy 'invalid value' warning, the stripes nowhere."""
    with pytest.raises(CameraError, match=f"^{re.escape(message)}$"):
        Scene(**kwargs)


@pytest.mark.parametrize(("kwargs", "message"), [
    ({"width": "0.02"}, "scene: width must be in [1e-06, 1000] m, got '0.02'"),
    ({"width": True}, "scene: width must be in [1e-06, 1000] m, got True"),
    ({"ns": (-1, 1), "spacing": "0.5"}, "scene: spacing must be in [0, 1000] m, got '0.5'"),
    ({"ns": ("1",)}, "scene: ns must be a tuple of whole numbers (stripe n at n * spacing), got ('1',)"),
    ({"ns": (0.5,)}, "scene: ns must be a tuple of whole numbers (stripe n at n * spacing), got (0.5,)"),
    ({"extra": 0.3}, "scene: extra must be a tuple of real numbers within 1000 m of the line (lateral positions of "
                     "further stripes), got 0.3"),
    ({"ns": tuple(range(600)), "extra": (0.0,) * 401, "spacing": 0.1},
     "scene: at most 1000 stripes (ns and extra; each is a pass over the image), got 1001"),
])
def test_scene_refuses_values_that_are_not_numbers_of_its_kind(kwargs, message):
    """The Python API reads no units: width="0.02" raised a bare TypeError from a comparison, ns=("1",) one from
    "1" * spacing, extra=0.3 one from iterating a float; and a million stripes was a million passes over the image."""
    with pytest.raises(CameraError, match=f"^{re.escape(message)}$"):
        Scene(**kwargs)


def test_scene_takes_numpy_integers_and_a_list_of_stripes():
    scene = Scene(ns=[np.int64(-1), 0, 1], spacing=np.float32(0.5), extra=[0.2])
    np.testing.assert_allclose(scene.offsets, [-0.5, 0.0, 0.5, 0.2])


@pytest.mark.parametrize(("image", "message"), [
    (np.full((60, 80), np.nan), "image: expected finite grey levels, got float64 values that are not finite"),
    (np.full((60, 80), "a"), "image: expected finite grey levels, got <U1 values"),
])
def test_images_of_grey_levels_that_are_not_numbers_are_refused(image, message):
    """NaN grey levels were cast to 0 with a numpy warning (no line found); text raised a numpy UFuncTypeError."""
    with pytest.raises(CameraError, match=f"^{re.escape(message)}$"):
        extract_lines(image)


def _one_stripe() -> np.ndarray:
    img = np.full((60, 80), 60.0)
    img[:, 38:42] = 200.0
    return img


@pytest.mark.parametrize("dtype", [np.float64, np.int64, np.float32, np.uint16, np.int16])
def test_colour_images_of_any_number_type_with_levels_0_255_are_read_as_grey_ones(dtype):
    """A BGR image of float64 or int64 levels (numpy's defaults) raised OpenCV's cv2.error from its colour
    conversion, which takes 8-bit images only: a traceback from the Python API."""
    grey = _one_stripe()
    expected = extract_lines(grey.astype(np.uint8))
    assert len(expected) == 1 and expected[0].x0 == pytest.approx(0.0, abs=1e-9)
    assert extract_lines(np.stack([grey] * 3, -1).astype(dtype)) == expected
    assert extract_lines(grey.astype(dtype)) == expected


@pytest.mark.parametrize(("image", "message"), [
    (_one_stripe().astype(np.uint16) * 4, "image: uint16 grey levels from 240 to 800, outside 0-255: give 8-bit "
                                          "levels (a 16-bit image divided by 257)"),
    (_one_stripe() - 100, "image: float64 grey levels from -40 to 100, outside 0-255"),
    (_one_stripe() / 255, "image: float64 grey levels from 0.235294 to 0.784314: wmrkit reads levels 0-255 "
                          "(multiply an image of levels in [0, 1] by 255)"),
])
def test_grey_levels_outside_0_255_are_refused_not_clipped(image, message):
    """They were clipped to 0-255: a 16-bit image of ground 240 and paint 800 became all white and a float image
    of levels in [0, 1] all black, both read as showing no line ('found 0 line(s)'), with no word on why."""
    with pytest.raises(CameraError, match=f"^{re.escape(message)}"):
        extract_lines(image)


@pytest.mark.parametrize(("image", "camera", "spacing", "psi_deg", "h"), [
    ("three-lines.png", Camera(325.7, math.radians(45), 0.134, 320, 240), 0.035, -35.43, -0.0583),
    ("crop-rows.png", Camera(545.0, math.radians(76), 1.42, 640, 480), 0.60, -0.57, -0.05),
])
def test_gradient_mode_locates_the_docs_images(image, camera, spacing, psi_deg, h):
    """--mode gradient said 'found 2 line(s), expected 3' on both: asked for two more lines than expected, spurious
    peaks 2 px from a contour (or crossing the stripe) took its rows and its fit failed."""
    import cv2

    img = cv2.imread(str(FIGURES / image), 0)
    fix = locate_image(camera, img, spacing=spacing, mode="gradient")
    assert math.degrees(fix.psi) == pytest.approx(psi_deg, abs=0.05) and fix.h == pytest.approx(h, abs=0.005)


@pytest.mark.parametrize("mode", ["threshold", "gradient"])
def test_one_line_of_five_crop_rows_is_the_centred_one(mode):
    """Without a spacing the row nearest the image's centre is the followed line (n = 0); only the three strongest
    of the five rows were extracted, and a side row gave h = -0.65 m for -0.05 m, exit 0."""
    import cv2

    img = cv2.imread(str(FIGURES / "crop-rows.png"), 0)
    fix = locate_image(Camera(545.0, math.radians(76), 1.42, 640, 480), img, mode=mode)
    assert math.degrees(fix.psi) == pytest.approx(-0.57, abs=0.05) and fix.h == pytest.approx(-0.05, abs=0.005)


def test_gradient_mode_pairs_the_two_contours_of_one_reference():
    """Contours were paired in turn: asked for one line, the three-line image gave one at x0 = 77 px, between
    two stripes (a contour of each), where there is none."""
    import cv2

    img = cv2.imread(str(FIGURES / "three-lines.png"), 0)
    truth = [ln.x0 for ln in extract_lines(img, n_lines=3)]
    for n in (1, 2, 3, 4, 5):
        for line in extract_lines(img, n_lines=n, mode="gradient"):
            assert min(abs(line.x0 - x) for x in truth) < 1.0


def test_gradient_mode_finds_every_reference_when_asked_for_more_lines():
    """Asked for 7 lines (14 contour peaks), weak peaks near a contour (sharing its far end, or crossing the
    stripe) took its rows: the three-line image gave two lines of three, the five crop rows four (greedy fits)."""
    import cv2

    for image, count in (("three-lines.png", 3), ("crop-rows.png", 5)):
        img = cv2.imread(str(FIGURES / image), 0)
        truth = [ln.x0 for ln in extract_lines(img, n_lines=count)]
        found = extract_lines(img, n_lines=7, mode="gradient")
        assert len(found) == count
        assert max(abs(a.x0 - b) for a, b in zip(found, truth, strict=True)) < 1.5


@pytest.mark.parametrize(("options", "message"), [
    # each found no line in an image of one painted line, silently (the band or separation of no pixel)
    ({"max_band_px": -1.0}, "extract_lines: max_band_px: expected a finite number > 0 [px], got -1"),
    ({"max_band_px": math.nan}, "extract_lines: max_band_px: expected a finite number > 0 [px], got nan"),
    ({"min_separation_px": -5}, "extract_lines: min_separation_px: expected a finite number > 0 [px], got -5"),
    ({"min_votes": -5}, "extract_lines: min_votes: expected an integer >= 1, got -5"),
])
def test_extract_lines_refuses_settings_that_would_find_no_line(options, message):
    cam = Camera(150.0, math.radians(60), 0.3, 320, 240)
    image = render(cam, (0.0, 0.05, 0.2), Scene())
    assert len(extract_lines(image)) == 1
    with pytest.raises(CameraError, match=f"^{re.escape(message)}$"):
        extract_lines(image, **options)


@pytest.mark.parametrize("width", [1e-6, 5e-4, 0.02])
@pytest.mark.parametrize("shift_px", [0.0, 0.25, 0.5])
def test_the_synthetic_camera_paints_as_much_line_as_there_is(width, shift_px):
    """Conservation: over an image row, each pixel's share of paint times its ground size sums to the line's width,
    wherever the line falls on the pixels. A line thinner than a pixel, centred on one, covered half of it whatever
    its width: a 1 um line showed 1 mm of paint at 143 grey levels, and follow-line followed it."""
    from wmrkit.vision.camera import ground_from_image
    from wmrkit.vision.render import GROUND, PAINT

    cam = Camera(150.0, math.radians(60), 0.3, 320, 240)
    row = 200
    y_u = row - cam.centre[1]
    psi, t = extrinsics((0.0, 0.0, 0.0), cam)
    # pixel centres are at x_u = k + 0.5 (even width): put the line `shift_px` left of the one at x_u = 0.5
    ground = ground_from_image(np.array([[0.5 - shift_px, y_u], [1.5 - shift_px, y_u]]), psi, cam.tilt, t,
                               cam.focal_px)
    size = abs(ground[1, 0] - ground[0, 0])  # a pixel's ground width on that row [m], about 2 mm
    image = render(cam, (0.0, -ground[0, 0], 0.0), Scene(width=width))  # the line (x_w = 0) seen there
    paint = np.sum((image[row].astype(float) - GROUND) / (PAINT - GROUND)) * size
    # grey levels are whole numbers: at most half a level off on each of the (up to 3) pixels the line touches
    assert paint == pytest.approx(width, abs=1.5 / (PAINT - GROUND) * size, rel=0.01)
