"""Synthetic camera: what the camera on the robot sees of painted lines or crop rows (§9.2.1, Figs. 9.5-9.10).

Every pixel is traced back to the ground through the camera model (:mod:`.camera`, eqs. (9.1)-(9.4) with R'),
after the lens distortion when ``camera.k1 != 0``; the ground's brightness there is the scene's. Edges are
anti-aliased with each pixel's footprint on the ground, so line positions are exact to a fraction of a pixel.
Options add Gaussian noise, blur and clutter (bright blobs lying on the ground). Pure NumPy; blur uses OpenCV.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from .._shapes import as_real, as_vectors, real_number
from ..limits import MAX_SIZE, MIN_SIZE, check_seed
from .camera import Camera, CameraError, check_type, extrinsics, ground_from_image, undistort

__all__ = ["Scene", "render"]

#: Grey levels of the ground and of the paint (or plants).
GROUND, PAINT = 70.0, 215.0
#: Largest blur sigma [px] (wider blurs a camera image to a uniform grey) and most clutter blobs per image (each
#: costs a pass over the image).
MAX_BLUR, MAX_CLUTTER = 50.0, 100
#: Largest image noise: a standard deviation of the whole grey range.
MAX_NOISE = 255.0
#: Most stripes in a scene (``ns`` and ``extra``): each is one pass over the image.
MAX_STRIPES = 1000


@dataclass(frozen=True, slots=True)
class Scene:
    """Parallel lines on the ground at ``x_w = n * spacing`` (9.8), ``n`` in `ns`; `width` [m] of each; `spacing`
    in ``[0, limits.MAX_SIZE]`` m.

    ``style="paint"``: uniform painted stripes; ``"crops"``: rows of plants whose width and density vary along
    the row (chufa field, Fig. 9.10), on textured soil. `extra` lists further lateral positions x_w [m] of
    stripes (e.g. the calibration stripes, which are not at multiples of a spacing).
    """

    ns: tuple[int, ...] = (0,)
    spacing: float = 0.0
    width: float = 0.02
    style: str = "paint"
    extra: tuple[float, ...] = ()

    def __post_init__(self) -> None:
        if self.style not in ("paint", "crops"):
            raise CameraError(f"scene: style must be 'paint' or 'crops', got {self.style!r}")
        # real numbers only (the Python API reads no units: width="0.02" raised a bare TypeError), in the lengths
        # wmrkit handles (1e-320 m overflowed the coverage; a NaN spacing rendered garbage with a numpy warning)
        if not (real_number(self.width) and MIN_SIZE <= self.width <= MAX_SIZE):
            raise CameraError(f"scene: width must be in [{MIN_SIZE:g}, {MAX_SIZE:g}] m, got {self.width!r}")
        if not (real_number(self.spacing) and 0 <= self.spacing <= MAX_SIZE):
            raise CameraError(f"scene: spacing must be in [0, {MAX_SIZE:g}] m, got {self.spacing!r}")
        if not (isinstance(self.ns, tuple | list) and all(isinstance(n, int | np.integer) and not isinstance(n, bool)
                                                           for n in self.ns)):
            raise CameraError(f"scene: ns must be a tuple of whole numbers (stripe n at n * spacing), got {self.ns!r}")
        if not (isinstance(self.extra, tuple | list)
                and all(real_number(x) and abs(x) <= MAX_SIZE for x in self.extra)):
            raise CameraError(f"scene: extra must be a tuple of real numbers within {MAX_SIZE:g} m of the line "
                              f"(lateral positions of further stripes), got {self.extra!r}")
        if len(self.ns) + len(self.extra) > MAX_STRIPES:
            raise CameraError(f"scene: at most {MAX_STRIPES} stripes (ns and extra; each is a pass over the image), "
                              f"got {len(self.ns) + len(self.extra)}")

    @property
    def offsets(self) -> np.ndarray:
        """Lateral positions x_w [m] of every stripe (thesis ground frame: to the right of the followed line)."""
        return np.array([n * self.spacing for n in self.ns] + list(self.extra), dtype=float)


def _pixel_grid(camera: Camera) -> np.ndarray:
    """Undistorted image coordinates ``(rows, width, 2)`` [px] of every pixel centre."""
    cx, cy = camera.centre
    xs = np.arange(camera.width, dtype=float) - cx
    ys = np.arange(camera.rows, dtype=float) - cy
    grid = np.stack(np.meshgrid(xs, ys), -1)
    return undistort(grid, camera.k1, camera.focal_px)


def _coverage(dist: np.ndarray, half: np.ndarray | float, footprint: np.ndarray) -> np.ndarray:
    """Fraction of a pixel of ground size `footprint` covered by a stripe of half-width `half` at `dist`: the overlap
    of ``[|dist| - footprint / 2, |dist| + footprint / 2]`` with ``[-half, half]``, over the footprint. (Its edge alone,
    ``0.5 + (half - |dist|) / footprint``, painted half of a pixel a stripe thinner than it crossed at its centre,
    whatever the stripe's width.)"""
    d = np.abs(dist)
    overlap = np.minimum(d + footprint / 2, half) - np.maximum(d - footprint / 2, -half)
    return np.clip(overlap / footprint, 0.0, 1.0)


def render(camera: Camera, pose_line_robot: ArrayLike, scene: Scene, *, z_p: float = 0.0, noise: float = 0.0,
           blur: float = 0.0, clutter: int = 0, seed: int | None = 0) -> np.ndarray:
    """Grey image ``(rows, width)`` uint8 seen by `camera` on a robot at `pose_line_robot` ``(x, y, theta)``.

    The pose is in the line frame L (x along the followed line, y to its left, REP-103); `z_p` [m] places the
    lens on the optical axis behind P (:func:`.camera.extrinsics`). `noise`: standard deviation of added
    Gaussian noise [grey levels]; `blur`: Gaussian blur sigma [px]; `clutter`: number of bright blobs scattered
    on the ground in view (drawn anew for each image); `seed` makes noise and clutter reproducible.
    """
    # the Python API reads no units: text ('1' raised a bare TypeError) and booleans (blur=True reached OpenCV)
    noise, blur = as_real(noise, "render: noise"), as_real(blur, "render: blur")
    if not (0 <= noise <= MAX_NOISE and 0 <= blur <= MAX_BLUR):  # NaN fails both
        raise CameraError(f"render: image noise must be in [0, {MAX_NOISE:g}] grey levels and blur in [0, "
                          f"{MAX_BLUR:g}] px, got {noise:g}, {blur:g}")
    if isinstance(clutter, bool) or not (isinstance(clutter, int | np.integer) and 0 <= clutter <= MAX_CLUTTER):
        raise CameraError(f"render: clutter must be an integer in [0, {MAX_CLUTTER}] blobs, got {clutter!r}")
    check_type(scene, Scene, "render: scene", "Scene(ns=(0,), width=0.02)")
    pose = as_vectors(pose_line_robot, 3, "render: pose_line_robot")
    z_p = z_p if np.ndim(z_p) else as_real(z_p, "render: z_p")
    if pose.shape != (3,) or np.ndim(z_p):  # one image: (2, 3) poses or an array z_p raised numpy's ValueError
        raise CameraError(f"render: one pose (x, y, theta) and one z_p make an image, got shapes {pose.shape} and "
                          f"{np.shape(z_p)}")
    if not (np.all(np.isfinite(pose)) and np.isfinite(z_p)):  # NaN: a blank image
        raise CameraError(f"render: pose and z_p must be finite, got {pose_line_robot!r}, {z_p!r}")
    if seed is not None:  # '1' or 1.5 raised numpy's TypeError
        check_seed(seed, CameraError, "render: seed")
    rng = np.random.default_rng(seed)
    psi, t = extrinsics(pose, camera, z_p)
    ground = ground_from_image(_pixel_grid(camera), psi, camera.tilt, t, camera.focal_px)
    xw, yw = ground[..., 0], ground[..., 1]
    visible = np.isfinite(xw)
    # ground size of a pixel across the stripes (the anti-aliasing width), from neighbouring pixels
    fx = np.abs(np.gradient(np.where(visible, xw, 0.0), axis=1))
    fy = np.abs(np.gradient(np.where(visible, xw, 0.0), axis=0))
    footprint = np.maximum(np.hypot(fx, fy), 1e-6)
    footprint = np.where(np.isfinite(footprint) & (footprint < 10 * scene.width + 1), footprint, 10 * scene.width)
    xw0, yw0 = np.where(visible, xw, 1e9), np.where(visible, yw, 0.0)
    cover = np.zeros_like(xw0)
    for i, x0 in enumerate(scene.offsets):
        half: np.ndarray | float = scene.width / 2
        if scene.style == "crops":  # plants: width varying along the row, the same field in every image
            phase = np.random.default_rng(1000 + i).uniform(0, 2 * np.pi, 2)
            half = scene.width / 2 * (0.75 + 0.15 * np.sin(yw0 / 0.13 + phase[0]) + 0.1 * np.sin(yw0 / 0.047
                                                                                                  + phase[1]))
        cover = np.maximum(cover, _coverage(xw0 - x0, half, footprint))
    if scene.style == "crops":
        cover *= 0.8 + 0.2 * np.sin(yw0 / 0.021 + 3 * np.sin(xw0 / 0.05)) ** 2
    if clutter:  # bright discs lying on the ground, centred on random visible pixels
        idx = rng.choice(np.flatnonzero(visible), size=clutter)
        for cx0, cy0 in zip(xw0.flat[idx], yw0.flat[idx], strict=True):
            radius = rng.uniform(0.3, 1.0) * scene.width
            cover = np.maximum(cover, 0.8 * _coverage(np.hypot(xw0 - cx0, yw0 - cy0), radius, footprint))
    soil = GROUND
    if scene.style == "crops":
        fade = np.clip(1.0 - footprint / 0.006, 0.0, 1.0)  # texture finer than a pixel is averaged away
        soil = GROUND + 12 * fade * np.sin(xw0 / 0.011) * np.sin(yw0 / 0.017)
    img = np.where(visible, soil + (PAINT - soil) * cover, GROUND)
    if blur > 0:
        from .lines import cv2_module

        img = cv2_module().GaussianBlur(img, (0, 0), blur)
    if noise > 0:
        img = img + rng.normal(0.0, noise, img.shape)
    return np.clip(np.rint(img), 0, 255).astype(np.uint8)
