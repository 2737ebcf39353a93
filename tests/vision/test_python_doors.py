"""The Python doors of `wmrkit.vision` read no units (docs/conventions.md): text, booleans and arrays where one number
goes are refused naming the argument, as are a camera's name where a Camera goes and NaN where it would give NaN.
Before, each of these raised a bare TypeError/AttributeError/IndexError from deep inside, or read '1' as 1 rad."""

from __future__ import annotations

import math
import re

import numpy as np
import pytest

from wmrkit import catalog
from wmrkit.errors import WmrkitError
from wmrkit.vision import (
    Camera,
    Scene,
    calibrate,
    calibrate_image,
    extract_lines,
    extrinsics,
    follow_line,
    line_following_twist,
    line_position,
    locate_image,
    locate_points,
    project,
    render,
    rotation,
)

CAMERA = Camera(150.0, math.radians(60), 0.3, 64, 48)
ROBOT = catalog.load("line-follower")
IMAGE = np.full((48, 64), 70, np.uint8)
IMAGE[:, 28:36] = 215  # one bright stripe down the middle
POINTS = [[10.0, 0.0], [11.0, 10.0]]
TEXT = "got the text '1', but the Python API reads no units"
BOOLEANS = r"expected real numbers in (SI units|radians) \(.*\), got booleans$"


@pytest.mark.parametrize(("call", "message"), [
    (lambda v: calibrate(v, 100.0, 60.0, 0.1, 0.5), "x1: "),
    (lambda v: calibrate(200.0, 100.0, 60.0, 0.1, v), "row_distance: "),
    (lambda v: calibrate_image(IMAGE, v, 0.1, 0.5), "rows_a: "),
    (lambda v: rotation(v, 0.5), "psi: "),
    (lambda v: rotation(0.1, v), "tilt: "),
    (lambda v: project([[1.0, 0.0, 0.0]], 0.1, 0.5, [0.0, 0.0, 0.5], v), "project: focal_px: "),
    (lambda v: extrinsics([0.0, 0.1, 0.0], CAMERA, v), "z_p: "),
    (lambda v: line_position(POINTS, v, focal_px=150.0, tilt=1.0, height=0.3), "n: "),
    (lambda v: line_position(POINTS, 0, focal_px=v, tilt=1.0, height=0.3), "focal_px: "),
    (lambda v: line_position(POINTS, 0, focal_px=150.0, tilt=v, height=0.3), "tilt: "),
    (lambda v: line_position(POINTS, 0, focal_px=150.0, tilt=1.0, height=0.3, z_p=v), "z_p: "),
    (lambda v: locate_points(CAMERA, [(0, POINTS)], spacing=v), "spacing: "),
    (lambda v: locate_points(CAMERA, [(0, POINTS)], z_p=v), "z_p: "),
    (lambda v: render(CAMERA, [0.0, 0.0, 0.0], Scene(), noise=v), "render: noise: "),
    (lambda v: render(CAMERA, [0.0, 0.0, 0.0], Scene(), blur=v), "render: blur: "),
    (lambda v: render(CAMERA, [0.0, 0.0, 0.0], Scene(), z_p=v), "render: z_p: "),
    (lambda v: extract_lines(IMAGE, k1=v), "extract_lines: k1: "),
    (lambda v: extract_lines(IMAGE, focal_px=v), "extract_lines: focal_px: "),
    (lambda v: extract_lines(IMAGE, max_angle=v), "extract_lines: max_angle: "),
    (lambda v: extract_lines(IMAGE, max_band_px=v), "extract_lines: max_band_px: "),
    (lambda v: extract_lines(IMAGE, hough_scale=v), "extract_lines: hough_scale: "),
    (lambda v: locate_image(CAMERA, IMAGE, spacing=v), "spacing: "),
    (lambda v: locate_image(CAMERA, IMAGE, z_p=v), "z_p: "),
    (lambda v: locate_image(CAMERA, IMAGE, rows_a=v), "rows_a: "),
    (lambda v: follow_line(ROBOT, CAMERA, z_p=v), "follow-line: z_p: "),
    (lambda v: follow_line(ROBOT, CAMERA, image_noise=v), "follow-line: image_noise: "),
    (lambda v: follow_line(ROBOT, CAMERA, blur=v), "follow-line: blur: "),
])
def test_text_and_booleans_where_a_number_goes_are_refused_naming_the_argument(call, message):
    """'1' raised a bare TypeError from a comparison (or was read as 1 rad, 1 px, 1 m: rotation, project,
    extrinsics, line_position's n, extract_lines' k1 and focal_px); True was 1, or reached OpenCV (blur)."""
    with pytest.raises(WmrkitError, match=f"^{re.escape(message + TEXT)}"):
        call("1")
    with pytest.raises(WmrkitError, match=f"^{re.escape(message)}{BOOLEANS}"):
        call(True)


@pytest.mark.parametrize(("call", "message"), [
    (lambda: rotation(math.nan, 0.5), "psi: angles must be finite numbers"),
    (lambda: project([[1.0, 0.0, 0.0]], 0.1, math.inf, [0.0, 0.0, 0.5], 150.0), "tilt: angles must be finite"),
    (lambda: extrinsics([0.0, 0.1, 0.0], CAMERA, math.nan), "z_p: expected lengths in [-1000, 1000] m, got nan"),
    (lambda: render(CAMERA, [0.0, 0.0, 0.0], Scene(), seed="1"), "render: seed must be an integer >= 0, got '1'"),
    (lambda: render(CAMERA, [0.0, 0.0, 0.0], Scene(), seed=1.5), "render: seed must be an integer >= 0, got 1.5"),
    (lambda: render(CAMERA, [0.0, 0.0, 0.0], Scene(), clutter=True), "render: clutter must be an integer"),
    (lambda: render(CAMERA, [0.0, 0.0, 0.0], "paint"), "render: scene: expected a Scene (Scene(ns=(0,), "),
    (lambda: render("cam.yaml", [0.0, 0.0, 0.0], Scene()), "camera: expected a Camera (Camera.from_file(path)"),
    (lambda: locate_image("cam.yaml", IMAGE), "camera: expected a Camera"),
    (lambda: locate_image(CAMERA, IMAGE, ns=0), "ns: expected a sequence of line indices n such as (-1, 0, 1)"),
    (lambda: locate_points(CAMERA, [1.0]), "lines: expected a sequence of (n, [[xu, yu], [xu, yu]]), got list"),
    (lambda: locate_points(CAMERA, 3), "lines: expected a sequence of (n, [[xu, yu], [xu, yu]]), got int"),
    (lambda: locate_points(CAMERA, [(0, [["1 m", 0.0], [1.0, 10.0]])]), "points: lines[0]: got the text '1 m'"),
    (lambda: calibrate_image(3, 10.0, 0.1, 0.5), "image: expected a grey or BGR image, got shape ()"),
    (lambda: follow_line(ROBOT, {"focal_px": 150.0}), "follow-line: camera: expected a Camera"),
    (lambda: follow_line("line-follower", CAMERA), "follow-line: robot: expected a Robot (wmrkit.catalog.load"),
    (lambda: line_following_twist("line-follower", 0.0, 0.1, 0.3, 0.1), "line_following_twist: robot: expected a "
                                                                         "Robot"),
])
def test_values_that_gave_a_bare_error_or_nan_are_named(call, message):
    """rotation, project and extrinsics gave NaN for NaN; a float seed raised numpy's TypeError, clutter=True its
    own; a camera's, scene's or robot's name raised AttributeError, a list of points 'cannot unpack non-iterable
    float', an image that is a number IndexError."""
    with pytest.raises(WmrkitError, match=f"^{re.escape(message)}"):
        call()


def test_real_numbers_of_any_type_are_still_taken():
    np.testing.assert_array_equal(rotation(np.float32(0.25), 1), rotation(0.25, 1.0))
    a = line_position(POINTS, np.int64(0), focal_px=np.float32(150.0), tilt=1.0, height=0.3)
    b = line_position(POINTS, 0, focal_px=150.0, tilt=1.0, height=0.3)
    np.testing.assert_array_equal(a, b)
    image = render(CAMERA, [0.0, 0.0, 0.0], Scene(), noise=np.float64(2.0), seed=np.int64(3))
    np.testing.assert_array_equal(image, render(CAMERA, [0.0, 0.0, 0.0], Scene(), noise=2, seed=3))
