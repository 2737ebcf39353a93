"""Calibration of tilt, focal length and height from one image of two parallel stripes, thesis §9.2.1.E.

In the calibration pose (9.12) ``psi = 0`` the stripes ``x_w = +-x_w`` run straight away from the camera. On two
image rows ``y_u = +A`` (near) and ``-A`` (far) their half-distances are ``x1 > x2``; with the real half-separation
``x_w`` and the real distance ``y_w`` along the stripes between the ground points seen on those rows:

- tilt (9.18): ``cos(phi) = A (x_w / y_w) (x1 + x2) / (x1 x2)``;
- focal length (9.21): ``f = tan(phi) A (x1 + x2) / (x1 - x2)``;
- height (9.24), corrected (errata): ``v = 2 x_w sin(phi) A / (x1 - x2)``; the printed form lacks the 2.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from .._shapes import as_real
from ..limits import MAX_SIZE, MIN_SIZE
from .camera import MAX_FOCAL_PX, MIN_FOCAL_PX, Camera, CameraError

__all__ = ["Calibration", "calibrate", "calibrate_image", "calibration_kernel"]

#: Least difference x1 - x2 [px] calibrate_image accepts: below a pixel, the convergence of the stripes between rows
#: +-A is not measured (rows +-0.01 px of the docs' image gave a tilt of 89.99 deg and a focal length of 2.8e6 px).
MIN_CONVERGENCE_PX = 1.0
#: Least rows A [px] calibrate accepts: rows +-A are rows of the image, a pixel apart at least (A = 0.001 px with
#: x1 = 80, x2 = 40 px gave a camera 1.75 um high at 89.999 deg, exit 0).
MIN_ROWS_PX = 1.0


def calibration_kernel(x1: ArrayLike, x2: ArrayLike, rows_a: ArrayLike, half_separation: ArrayLike,
                       row_distance: ArrayLike) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(tilt [rad], focal [px], height [m])`` by eqs. (9.18), (9.21) and (9.24) corrected. ``(...) -> 3 x (...)``.

    `x1`, `x2`: half-distances [px] between the stripes on rows ``+A`` and ``-A``; `rows_a` A [px];
    `half_separation` x_w [m]; `row_distance` y_w [m]. Out-of-domain inputs give NaN (check with :func:`calibrate`).
    """
    x1, x2, a = (np.asarray(v, dtype=float) for v in (x1, x2, rows_a))
    xw, yw = np.asarray(half_separation, dtype=float), np.asarray(row_distance, dtype=float)
    cos_tilt = a * (xw / yw) * (1 / x1 + 1 / x2)  # (x1 + x2) / (x1 x2), without the product (it can underflow)
    tilt = np.arccos(np.where((cos_tilt > 0) & (cos_tilt < 1), cos_tilt, np.nan))
    focal = np.tan(tilt) * a * (x1 + x2) / (x1 - x2)
    height = 2 * xw * np.sin(tilt) * a / (x1 - x2)
    return tilt, focal, height


@dataclass(frozen=True, slots=True)
class Calibration:
    """Result of §9.2.1.E: ``tilt`` phi [rad], ``focal_px`` f [px], ``height`` v [m], and the measurements used."""

    tilt: float
    focal_px: float
    height: float
    x1: float
    x2: float
    rows_a: float
    half_separation: float
    row_distance: float

    def to_dict(self) -> dict[str, Any]:
        """``{"tilt", "focal_px", "height"}`` plus the inputs, the ``wmrkit vision calibrate --json`` output."""
        return {"tilt": self.tilt, "focal_px": self.focal_px, "height": self.height,
                "inputs": {"x1": self.x1, "x2": self.x2, "rows_a": self.rows_a,
                           "half_separation": self.half_separation, "row_distance": self.row_distance}}

    def camera(self, *, width: int = 640, rows: int = 480, k1: float = 0.0) -> Camera:
        """The calibrated :class:`Camera` for images of ``width x rows`` pixels."""
        return Camera(self.focal_px, self.tilt, self.height, width, rows, k1)


def calibrate(x1: float, x2: float, rows_a: float, half_separation: float, row_distance: float) -> Calibration:
    """Calibrate from image measurements (x1, x2, A) [px] and ground ones (x_w, y_w) [m], (9.18)-(9.24).

    Raises :class:`CameraError` naming the measurement when they describe no camera (``x1 <= x2``, a half-separation
    or row distance above ``MAX_SIZE``, a tilt whose cosine is not in (0, 1), a height outside ``[MIN_SIZE,
    MAX_SIZE]`` of :mod:`wmrkit.limits`, a focal length outside :data:`.camera.MIN_FOCAL_PX` to
    :data:`.camera.MAX_FOCAL_PX`, rows A below :data:`MIN_ROWS_PX`).
    """
    # the Python API reads no units: text raised a bare TypeError from math.isfinite
    x1, x2, rows_a, half_separation, row_distance = (as_real(v, name) for name, v in (
        ("x1", x1), ("x2", x2), ("rows_a", rows_a), ("half_separation", half_separation),
        ("row_distance", row_distance)))
    for name, value in (("x1", x1), ("x2", x2), ("rows A", rows_a), ("half-separation", half_separation),
                        ("row distance", row_distance)):
        if not (math.isfinite(value) and value > 0):
            raise CameraError(f"calibration: {name} must be > 0, got {value}")
    for name, value in (("half-separation", half_separation), ("row distance", row_distance)):
        if value > MAX_SIZE:  # 1e300 m: refused as a tilt's cosine of 7e300, naming neither
            raise CameraError(f"calibration: {name} must be at most {MAX_SIZE:g} m (the lengths wmrkit handles), "
                              f"got {value:g} m")
    if x1 <= x2:
        raise CameraError(f"calibration: x1 (near row +A, {x1:g} px) must exceed x2 (far row -A, {x2:g} px)")
    with np.errstate(over="ignore", invalid="ignore"):  # an overflow gives NaN, refused below
        tilt, focal, height = (float(v) for v in calibration_kernel(x1, x2, rows_a, half_separation, row_distance))
        c = rows_a * (half_separation / row_distance) * (1 / x1 + 1 / x2)  # (x1 + x2) / (x1 x2): x1 x2 underflowed
    if not math.isfinite(tilt):
        raise CameraError(f"calibration: the measurements give cos(tilt) = {c:.4g}, not in (0, 1): check the "
                          f"half-separation and row distance")
    if not MIN_SIZE <= height <= MAX_SIZE:  # x1 close to x2 (stripes that look parallel), or lengths far off
        raise CameraError(f"calibration: the measurements give a camera height of {height:.4g} m, outside the "
                          f"lengths wmrkit handles ({MIN_SIZE:g} to {MAX_SIZE:g} m): check x1 and x2 (nearly equal "
                          "when the stripes look parallel), rows A and the half-separation")
    if not focal >= MIN_FOCAL_PX:  # rows A of a fraction of a pixel: printed 'focal = 0.01 px', exit 0
        raise CameraError(f"calibration: the measurements give a focal length of {focal:.4g} px, below "
                          f"{MIN_FOCAL_PX:g} px (no camera: see vision.camera.MIN_FOCAL_PX): check rows A, x1 and x2 "
                          "(pixels from the image's centre)")
    if not focal <= MAX_FOCAL_PX:
        raise CameraError(f"calibration: the measurements give a focal length of {focal:.4g} px, above "
                          f"{MAX_FOCAL_PX:g} px (no camera: see vision.camera.MAX_FOCAL_PX): check x1 and x2 (nearly "
                          "equal when the stripes look parallel) and rows A")
    if rows_a < MIN_ROWS_PX:
        raise CameraError(f"calibration: rows A must be at least {MIN_ROWS_PX:g} px from the image's centre (rows "
                          f"+-A are rows of the image), got {rows_a:g} px")
    return Calibration(tilt, focal, height, float(x1), float(x2), float(rows_a), float(half_separation),
                       float(row_distance))


def calibrate_image(image: ArrayLike, rows_a: float, half_separation: float, row_distance: float, *,
                    k1: float = 0.0, focal_guess: float | None = None, max_vanishing_px: float = 3.0,
                    mode: str = "threshold") -> Calibration:
    """Calibrate from an image of two parallel stripes in the calibration pose (9.12), §9.2.1.E.

    The two stripes are extracted (:func:`wmrkit.vision.lines.extract_lines`), their half-distances on rows
    ``+-A`` [px] measured (an image showing a third stripe is refused); `k1` with `focal_guess` undistorts the
    points when the distortion is known. The
    stripes' vanishing point must lie on the image's vertical centre line (``psi = 0``) within
    `max_vanishing_px`, else :class:`CameraError` says to turn the camera.
    """
    from .lines import _grey, extract_lines

    img = _grey(image)  # a number raised IndexError from its shape
    rows_a = as_real(rows_a, "rows_a")
    if not 0 < rows_a < img.shape[0] / 2:
        raise CameraError(f"calibration: rows A must be in (0, {img.shape[0] / 2:g}) px, got {rows_a:g}")
    lines = extract_lines(img, n_lines=3, mode=mode, k1=k1, focal_px=focal_guess or float(max(img.shape[:2])))
    if len(lines) < 2:
        raise CameraError("calibration: the image does not show two stripes")
    if len(lines) > 2:  # the two strongest were taken, whichever pair they were: a wrong camera, or cos(tilt) > 1
        raise CameraError(f"calibration: the image shows more than two stripes (lines at x = "
                          f"{', '.join(f'{ln.x0:.0f}' for ln in lines)} px on the centre row): the calibration pose "
                          "needs exactly two")
    left, right = sorted(lines, key=lambda ln: ln.x_at(0.0))
    near = (right.x_at(rows_a) - left.x_at(rows_a)) / 2
    far = (right.x_at(-rows_a) - left.x_at(-rows_a)) / 2
    vanish = left.intersection(right)
    if vanish is None or abs(vanish[0]) > max_vanishing_px:
        where = "at infinity" if vanish is None else f"at x = {vanish[0]:.1f} px"
        raise CameraError(f"calibration: not the calibration pose (psi = 0): the stripes meet {where}, not on the "
                          f"image's centre line; turn the camera until they do (tolerance {max_vanishing_px:g} px)")
    if not -rows_a > vanish[1]:  # beyond where the stripes cross, their half-distance is negative (x2 < 0)
        raise CameraError(f"calibration: rows A ({rows_a:g} px): row -A is above where the stripes meet (row "
                          f"{vanish[1]:.1f} px), take A below {-vanish[1]:.1f} px")
    if near - far < MIN_CONVERGENCE_PX:  # rows +-A so close that the stripes' convergence is below a pixel
        raise CameraError(f"calibration: the stripes' half-distances on rows +-A ({near:.4g} and {far:.4g} px) differ "
                          f"by less than {MIN_CONVERGENCE_PX:g} px, too little to measure: take rows A farther from "
                          f"the centre (A = {rows_a:g} px)")
    return calibrate(near, far, rows_a, half_separation, row_distance)
