"""Camera model of the thesis §9.2.1.D, eqs. (9.1)-(9.4), with the true rotation R' of the digest (errata 9.3).

Frames (thesis Figs. 9.2-9.4):

- ground frame **W** (``_w``): ``X_w`` across the followed line, to its right, ``Y_w`` along it, ``Z_w`` up; the
  followed line is ``x_w = 0`` and parallel lines are ``x_w = n d`` (9.8);
- camera frame **C** (``_c``): ``Z_c`` the optical axis, ``X_c`` right and ``Y_c`` down in the image;
- image plane (``_u``): ``(x_u, y_u)`` in pixels from the image centre, ``y_u`` downward (9.1)-(9.2) with
  ``d_x = d_y = 1`` (the focal length is in pixels);
- wmrkit's **line frame L** (REP-103, ``pose_line_robot``): ``x`` along the line, ``y`` to its left, so
  ``x_w = -y_L``, ``y_w = x_L``. A robot at ``(x, y, theta)`` in L sees ``psi = -theta`` and ``h = y`` (9.25).

The camera is mounted on the robot looking straight ahead, its lens at height `height` and ``z_p`` from the
tracked point P (the robot origin) along the optical axis: the lens is ``z_p sin(tilt)`` behind P horizontally.
Lens distortion (option) is one radial term: ``x_d = x_u (1 + k1 r^2)``, ``r^2 = (x_u^2 + y_u^2) / f^2``. Its
inverse is a cubic in r, solved in closed form (:func:`undistort`); with ``k1 < 0`` the model folds over at
``r = 1 / sqrt(-3 k1)`` (:func:`fold_radius`), and a camera whose image reaches the fold is refused.
"""

from __future__ import annotations

import math
import numbers
from dataclasses import asdict, dataclass, fields
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from .._shapes import as_angle_array, as_reals, as_vectors, check_kind
from ..documents import LineOf, read_document, read_file, write_document
from ..errors import DescriptionError, WmrkitError
from ..limits import MAX_SIZE
from ..units import UnitError, parse_quantity

__all__ = ["Camera", "CameraError", "CameraFileError", "camera_coordinates", "check_lens_image", "distort",
           "extrinsics", "fold_radius", "ground_from_image", "project", "rotation", "undistort"]


class CameraError(WmrkitError, ValueError):
    """A camera description, image or measurement that cannot be used; the message names the field."""


class CameraFileError(DescriptionError, CameraError):
    """A camera (or points) file that cannot be used, located as a description's errors are: file, line and field
    (``wmrkit --json`` reports them; before, ``field`` and mostly ``line`` were null)."""


#: Largest image side [px]: the synthetic camera holds several float arrays of the image's size.
MAX_PIXELS = 4096


#: Smallest focal length [px]: below it a pixel subtends more than 53 deg (a 1e-300 px camera file positioned a line
#: 2.3e284 m away, exit 0).
MIN_FOCAL_PX = 1.0
#: Largest focal length [px]: beyond it a pixel subtends less than 1e-7 rad (0.02 arcsec, finer than a space
#: telescope resolves; a 1 um pixel behind a 10 m lens): a camera file with 1e308 px was accepted and positioned
#: lines from an image spanning 1e-305 rad.
MAX_FOCAL_PX = 1e7


#: The unit kind of each camera field (:func:`wmrkit.units.parse_quantity`); the others are plain numbers.
_FIELD_KINDS = {"tilt": "angle", "height": "length"}


@dataclass(frozen=True, slots=True)
class Camera:
    """A calibrated camera looking at the ground (§9.2.1.D-E). Frozen.

    - ``focal_px`` f [px] (9.1)-(9.2) with unit pixel size, in ``[MIN_FOCAL_PX, MAX_FOCAL_PX]``; ``tilt`` phi
      [rad], from the vertical (9.3);
    - ``height`` v [m], of the lens above the ground (9.7), at most ``limits.MAX_SIZE``; ``width``, ``rows``:
      image size [px];
    - ``k1``: radial distortion coefficient (0: an ideal pinhole).
    """

    focal_px: float
    tilt: float
    height: float
    width: int = 640
    rows: int = 480
    k1: float = 0.0

    def __post_init__(self) -> None:
        for name in ("focal_px", "tilt", "height", "width", "rows", "k1"):
            value = getattr(self, name)
            if name in ("width", "rows"):
                if isinstance(value, bool) or not isinstance(value, numbers.Integral):
                    raise CameraError(f"camera: {name}: expected a whole number of pixels (an integer), got {value!r}")
                object.__setattr__(self, name, int(value))
            else:
                if isinstance(value, bool) or not isinstance(value, numbers.Real):
                    raise CameraError(f"camera: {name}: expected a number, got {value!r}")
                object.__setattr__(self, name, float(value))
        checks = {"focal_px": (MIN_FOCAL_PX <= self.focal_px <= MAX_FOCAL_PX,
                               f"a number in [{MIN_FOCAL_PX:g}, {MAX_FOCAL_PX:g}] px"),
                  "tilt": (0 < self.tilt < math.pi / 2, "an angle in (0, 90 deg) from the vertical"),
                  "height": (0 < self.height <= MAX_SIZE, f"a length in (0, {MAX_SIZE:g}] m"),
                  "width": (8 <= self.width <= MAX_PIXELS, f"[8, {MAX_PIXELS}] px"),
                  "rows": (8 <= self.rows <= MAX_PIXELS, f"[8, {MAX_PIXELS}] px"),
                  "k1": (abs(self.k1) < 1, "a finite number in (-1, 1)")}
        for name, (ok, expected) in checks.items():
            value = getattr(self, name)
            if not ok or not math.isfinite(value):
                shown = f"{value} rad ({math.degrees(value):.4g} deg)" if name == "tilt" else f"{value}"
                raise CameraError(f"camera: {name}: out of range, got {shown} (expected {expected})")
        check_lens_image(self.k1, self.focal_px, self.width, self.rows, "camera")

    @property
    def centre(self) -> tuple[float, float]:
        """Image centre (C_x, C_y) [px] of (9.2), in pixel-centre coordinates."""
        return (self.width - 1) / 2, (self.rows - 1) / 2

    def to_dict(self) -> dict[str, Any]:
        """Plain SI numbers, the camera file's fields."""
        return asdict(self)

    @classmethod
    def from_dict(cls, data: Any, *, source: str = "<camera>", line_of: LineOf | None = None) -> Camera:
        """A camera from a mapping (a camera file's content; `line_of`: its fields' lines); unknown fields are
        refused. Errors are :class:`CameraFileError` naming `source`, the field and its line when known."""

        def fail(message: str, name: str | None = None) -> CameraFileError:
            loc = () if name is None else (name,)
            return CameraFileError(message, source=source, loc=loc, line=line_of(loc) if line_of and loc else None)

        if not isinstance(data, dict):
            raise fail("expected a mapping of camera fields")
        allowed = {f.name for f in fields(cls)}
        unknown = sorted(set(data) - allowed, key=str)
        if unknown:
            raise fail(f"unknown field (camera fields: {', '.join(sorted(allowed))})", str(unknown[0]))
        missing = [n for n in ("focal_px", "tilt", "height") if n not in data]
        if missing:
            raise fail("missing field (a camera file needs focal_px, tilt and height)", missing[0])
        values: dict[str, Any] = {}
        for name, value in data.items():  # units as in descriptions: '60 deg', '30 cm', '1e-7' (YAML 1.1 reads a str)
            try:
                number = parse_quantity(value, _FIELD_KINDS.get(name, "number"))
            except UnitError as err:
                raise fail(str(err), name) from None
            if name in ("width", "rows") and not number.is_integer():
                raise fail(f"expected a whole number of pixels, got {value!r}", name)
            values[name] = int(number) if name in ("width", "rows") else number
        try:
            return cls(**values)
        except CameraError as err:  # "camera: NAME: message" (Camera's checks name their field so)
            name, _, message = str(err).removeprefix("camera: ").partition(": ")
            raise (fail(message, name) if name in allowed else fail(str(err).removeprefix("camera: "))) from None

    @classmethod
    def from_file(cls, path: str | Path) -> Camera:
        """Read a camera file (YAML, as ``wmrkit vision calibrate --out`` writes)."""
        data, line_of = read_located(path, "camera file", "yaml", lines=True)
        return cls.from_dict(data, source=str(path), line_of=line_of)

    def to_file(self, path: str | Path) -> None:
        """Write the camera file, plain SI numbers: JSON for a ``.json`` file, else YAML (``.yaml``, ``.yml``; other
        extensions are refused: ``--out camera.png`` wrote YAML into a picture's name), replacing it in one step."""
        path = Path(path)
        suffix = path.suffix.lower()
        if suffix not in (".yaml", ".yml", ".json"):
            raise CameraError(f"{path}: a camera file is .yaml, .yml or .json, not '{suffix or 'no extension'}'")
        try:
            write_document(path, self.to_dict())
        except OSError as err:
            raise CameraError(f"{path}: cannot write the camera file ({err.strerror or err})") from None


def check_type(value: object, kind: type, argument: str, advice: str) -> None:
    """Raise :class:`CameraError` naming `argument` unless `value` is a `kind` (:func:`wmrkit._shapes.check_kind`)."""
    check_kind(value, kind, argument, advice, CameraError)


def read_located(path: str | Path, what: str, fmt: str, *, lines: bool = False) -> Any:
    """The data of a YAML or JSON file read as :func:`wmrkit.documents.read_file` and ``read_document`` do
    (bounded size, safe YAML, duplicate keys refused), with `lines` ``(data, line_of)``; their located errors as
    :class:`CameraFileError` (file, line and field kept)."""
    try:
        got = read_document(read_file(path, what), str(path), fmt)
    except DescriptionError as err:
        raise CameraFileError(err.message, source=err.source, loc=err.loc, line=err.line) from None
    return got if lines else got[0]


def rotation(psi: ArrayLike, tilt: ArrayLike) -> np.ndarray:
    """Ground-to-camera rotation R' (eq. 9.3 corrected: the printed matrix is not a rotation).

    ``(...), (...) -> (..., 3, 3)``.

    Rows are the camera axes in W: ``X_c = (c psi, -s psi, 0)``, ``Y_c = (-s psi c phi, -c psi c phi, -s phi)``,
    ``Z_c = (s psi s phi, c psi s phi, -c phi)`` (the optical axis, tilted down by phi from the vertical).
    """
    # the Python API reads no units: psi='1' was read as 1 rad; NaN gave a matrix of NaN
    psi, tilt = np.broadcast_arrays(as_angle_array(psi, "psi"), as_angle_array(tilt, "tilt"))
    cp, sp, cf, sf = np.cos(psi), np.sin(psi), np.cos(tilt), np.sin(tilt)
    z = np.zeros_like(psi)
    return np.stack([np.stack([cp, -sp, z], -1), np.stack([-sp * cf, -cp * cf, -sf], -1),
                     np.stack([sp * sf, cp * sf, -cf], -1)], -2)


def camera_coordinates(points_w: ArrayLike, psi: ArrayLike, tilt: ArrayLike, t: ArrayLike) -> np.ndarray:
    """``(x_c, y_c, z_c) = R' (x_w, y_w, z_w) + t``, eq. (9.3) corrected.

    ``(..., 3), (...), (...), (..., 3) -> (..., 3)``.
    """
    p = as_vectors(points_w, 3, "points_w")
    return (rotation(psi, tilt) @ p[..., None])[..., 0] + as_vectors(t, 3, "t")


def _focal(focal_px: ArrayLike, where: str) -> np.ndarray:
    """`focal_px` as a float array, or :class:`CameraError` naming it unless every value is finite and > 0 (f = 0
    put every point at the centre, f < 0 mirrored the image)."""
    f = as_reals(focal_px, f"{where}: focal_px")  # '1' was read as 1 px
    bad = ~((f > 0) & (f < math.inf))  # NaN included
    if bad.any():
        raise CameraError(f"{where}: focal_px: expected finite numbers > 0 [px], got {float(f[bad].flat[0])}")
    return f


def project(points_w: ArrayLike, psi: ArrayLike, tilt: ArrayLike, t: ArrayLike, focal_px: ArrayLike) -> np.ndarray:
    """Image coordinates ``(x_u, y_u)`` [px] of ground-frame points, eqs. (9.1) and (9.4) with R'.

    ``(..., 3) -> (..., 2)``. Points behind the camera (``z_c <= 0``) give NaN; `focal_px` must be finite and > 0.
    """
    f = _focal(focal_px, "project")
    c = camera_coordinates(points_w, psi, tilt, t)
    zc = c[..., 2:3]
    safe = np.where(zc > 0, zc, np.nan)
    return f[..., None] * c[..., :2] / safe


def extrinsics(pose_line_robot: ArrayLike, camera: Camera, z_p: ArrayLike = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """``(psi (...), t (..., 3))`` of (9.3) for a robot at `pose_line_robot` ``(x, y, theta)`` in the line frame L.

    ``psi = -theta`` (9.25); the lens is at height ``camera.height``, ``z_p sin(tilt)`` behind the robot origin P.
    """
    check_type(camera, Camera, "camera", "Camera.from_file(path) or Camera(focal_px, tilt, height)")
    pose = as_vectors(pose_line_robot, 3, "pose_line_robot")
    x, y, theta = pose[..., 0], pose[..., 1], pose[..., 2]
    z_p = as_reals(z_p, "z_p")  # '1' was read as 1 m
    bad = ~(np.abs(z_p) <= MAX_SIZE)  # NaN included: it gave a translation of NaN
    if bad.any():
        raise CameraError(f"z_p: expected lengths in [-{MAX_SIZE:g}, {MAX_SIZE:g}] m, got {float(z_p[bad].flat[0])}")
    back = z_p * math.sin(camera.tilt)
    lens_w = np.stack(np.broadcast_arrays(-(y - back * np.sin(theta)), x - back * np.cos(theta),
                                          np.full_like(x, camera.height)), -1)
    psi = -theta
    t = -(rotation(psi, camera.tilt) @ lens_w[..., None])[..., 0]
    return psi, t


def ground_from_image(xy_u: ArrayLike, psi: ArrayLike, tilt: ArrayLike, t: ArrayLike,
                      focal_px: ArrayLike) -> np.ndarray:
    """Ground points ``(x_w, y_w)`` seen at undistorted image points: eq. (9.4) inverted on ``z_w = 0``.

    ``(..., 2) -> (..., 2)``. Rays that do not meet the ground ahead (above the horizon) give NaN; `focal_px` must
    be finite and > 0.
    """
    f = _focal(focal_px, "ground_from_image")
    xy = as_vectors(xy_u, 2, "xy_u")
    r = rotation(psi, tilt)
    ray_c = np.concatenate([xy, np.broadcast_to(f[..., None], xy[..., :1].shape)], -1)
    ray_w = (np.swapaxes(r, -1, -2) @ ray_c[..., None])[..., 0]
    lens_w = -(np.swapaxes(r, -1, -2) @ as_vectors(t, 3, "t")[..., None])[..., 0]
    down = -ray_w[..., 2]
    s = np.where(down > 1e-12, lens_w[..., 2] / np.where(down > 1e-12, down, 1.0), np.nan)
    return lens_w[..., :2] + s[..., None] * ray_w[..., :2]


def _lens(k1: float, focal_px: float, where: str) -> tuple[float, float]:
    """`k1` and `focal_px` as floats, or :class:`CameraError` naming the one that is not finite (or f <= 0)."""
    try:
        k, f = float(k1), float(focal_px)
    except (TypeError, ValueError):
        raise CameraError(f"{where}: k1 and focal_px must be numbers, got {k1!r}, {focal_px!r}") from None
    if not math.isfinite(k):
        raise CameraError(f"{where}: k1: expected a finite number, got {k}")
    if not 0 < f < math.inf:
        raise CameraError(f"{where}: focal_px: expected a finite number > 0, got {f}")
    return k, f


def fold_radius(k1: float, focal_px: float) -> tuple[float, float]:
    """Where the radial model folds over: ``(r_u, r_d)`` [px] from the image centre.

    ``r_d = r_u (1 + k1 r_u^2 / f^2)`` grows with r_u up to ``r_u = f / sqrt(-3 k1)`` when ``k1 < 0``, where it
    reaches ``r_d = 2/3 r_u``; farther points would be imaged nearer the centre again (the model, not a lens).
    Both are ``inf`` for ``k1 >= 0`` (always invertible).
    """
    return _fold(*_lens(k1, focal_px, "fold_radius"))


def _fold(k1: float, f: float) -> tuple[float, float]:
    if k1 >= 0:
        return math.inf, math.inf
    r_u = f / math.sqrt(-3 * k1)
    return r_u, 2 * r_u / 3


def check_lens_image(k1: float, focal_px: float, width: int, rows: int, where: str) -> None:
    """Refuse (:class:`CameraError` naming `k1`) a distortion that folds over inside a ``width x rows`` image:
    its corners (pixel edges, ``hypot(width, rows) / 2`` from the centre) must be nearer than :func:`fold_radius`'s
    ``r_d``, so that every pixel has one undistorted position."""
    k1, focal_px = _lens(k1, focal_px, where)
    _, r_d = _fold(k1, focal_px)
    corner = math.hypot(width, rows) / 2
    if not corner < r_d:
        least = -4 * focal_px**2 / (27 * corner**2)  # k1 at which r_d reaches the corner
        raise CameraError(f"{where}: k1: {k1:g} folds the distortion model over inside the {width} x {rows} image "
                          f"(focal {focal_px:g} px): it is invertible out to {r_d:.1f} px from the centre, the "
                          f"corners are {corner:.1f} px away; k1 must be > {least:.4g} for this image")


def distort(xy_u: ArrayLike, k1: float, focal_px: float) -> np.ndarray:
    """Radial distortion of the image points of (9.1)-(9.2) (wmrkit extension): ``x_d = x_u (1 + k1 r^2)``,
    ``r^2 = |x_u|^2 / f^2``. ``(..., 2) -> (..., 2)``.

    Points beyond the fold of a ``k1 < 0`` model (``|x_u| > f / sqrt(-3 k1)``, :func:`fold_radius`) give NaN: the
    model would image them where nearer points are, a lens does not.
    """
    xy = as_vectors(xy_u, 2, "xy_u")
    k1, f = _lens(k1, focal_px, "distort")
    if k1 == 0:
        return xy
    r2 = np.sum(xy * xy, axis=-1, keepdims=True) / f**2
    out = xy * (1 + k1 * r2)
    return np.where(-3 * k1 * r2 > 1, np.nan, out) if k1 < 0 else out


def undistort(xy_d: ArrayLike, k1: float, focal_px: float) -> np.ndarray:
    """Inverse of :func:`distort`, exact: the cubic ``k1 r^3 + r - r_d = 0`` (radii over f) in closed form.

    ``(..., 2) -> (..., 2)``. With ``s = sqrt(3 |k1|)`` and ``u = 3 s r_d / 2``, the physical root (the one on the
    increasing branch, ``r -> r_d`` as ``k1 -> 0``) is ``r = (2 / s) sinh(asinh(u) / 3)`` for ``k1 > 0`` (the only
    real root) and ``r = (2 / s) sin(asin(u) / 3)`` for ``k1 < 0``. A ``k1 < 0`` model reaches no farther than
    :func:`fold_radius`'s ``r_d`` (``u = 1``): points beyond it have no undistorted position, :class:`CameraError`
    names them.
    """
    xy_d = as_vectors(xy_d, 2, "xy_d")
    k1, f = _lens(k1, focal_px, "undistort")
    if k1 == 0:
        return xy_d
    s = math.sqrt(3 * abs(k1))
    u = 1.5 * s * np.hypot(xy_d[..., 0], xy_d[..., 1]) / f
    if k1 > 0:
        r = (2 / s) * np.sinh(np.arcsinh(u) / 3)
    else:
        beyond = u > 1 + 1e-12  # round-off of a point distorted exactly at the fold is let through
        if beyond.any():
            bad = xy_d[beyond]
            shown = ", ".join(f"({x:.6g}, {y:.6g})" for x, y in bad[:3]) + (" ..." if len(bad) > 3 else "")
            raise CameraError(f"undistort: xy_d: {len(bad)} point(s) {shown} px lie beyond {2 * f / (3 * s):.1f} px "
                              f"from the centre, where the model with k1 = {k1:g} folds over: they have no "
                              "undistorted position")
        r = (2 / s) * np.sin(np.arcsin(np.minimum(u, 1.0)) / 3)
    return xy_d / (1 + k1 * r * r)[..., None]
