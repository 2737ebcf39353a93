"""Positioning relative to a line from image points, thesis §9.2.1.D "Particularización", eqs. (9.5)-(9.11).

Two image points on a line known to lie at ``x_w = n d`` (9.8) give the camera's yaw psi and lateral offset t_x
in closed form (9.10), and the distance h of the tracked point P to the followed line (9.11). Several lines
(a road's two lines, three crop rows) each give one estimate; the result is their mean.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from .._shapes import as_real, as_reals, as_vectors
from ..errors import ShapeError
from ..limits import MAX_SIZE
from .camera import Camera, CameraError, check_type, read_located

__all__ = ["SPACING_TOLERANCE", "LineFix", "Positioning", "check_spacing", "line_position", "locate_points",
           "read_points"]


def line_position(points_u: ArrayLike, n: ArrayLike, *, focal_px: float, tilt: float, height: float,
                  spacing: float = 0.0, z_p: float = 0.0) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(psi, t_x, h)`` from two undistorted image points of one line, eqs. (9.10)-(9.11).

    ``(..., 2, 2), (...) -> 3 x (...)``.

    `points_u`: ``[[x_u1, y_u1], [x_u2, y_u2]]`` [px] from the image centre, y down; `n` the line's index (9.8)
    at ``x_w = n * spacing`` [m]; `height` v [m]; `tilt` phi [rad]; `z_p` [m] from the lens to P along the optical
    axis. ``psi`` [rad] is the yaw of the camera relative to the line (the robot's heading is ``-psi``, (9.25)),
    ``h`` [m] the signed distance from P to the followed line, positive when P is left of it (``h = -x_w(P)``).
    Points on one image row (``y_u1 = y_u2``) give NaN; non-finite points or `n` are refused (:class:`ShapeError`).
    """
    p = as_reals(points_u, "points_u")  # the Python API reads no units: text raised numpy's ValueError, n='1' was 1
    if p.shape[-2:] != (2, 2):
        raise ShapeError(f"points_u: expected shape (..., 2, 2), got {p.shape}")
    if not np.all(np.isfinite(p)):
        raise ShapeError("points_u: expected finite image coordinates [px], got "
                         f"{float(p[~np.isfinite(p)].flat[0])}")
    n_arr = as_reals(n, "n")
    focal_px, tilt, height, spacing, z_p = (as_real(v, name) for name, v in (  # text: a bare TypeError
        ("focal_px", focal_px), ("tilt", tilt), ("height", height), ("spacing", spacing), ("z_p", z_p)))
    if not np.all(np.isfinite(n_arr)):
        raise ShapeError(f"n: expected finite line indices, got {float(n_arr[~np.isfinite(n_arr)].flat[0])}")
    for name, value in (("focal_px", focal_px), ("height", height)):
        if not 0 < value < math.inf:  # NaN included
            raise ShapeError(f"{name}: expected a finite number > 0, got {value}")
    if not (math.isfinite(tilt) and math.isfinite(z_p) and math.isfinite(spacing)):
        raise ShapeError(f"tilt, z_p, spacing: expected finite numbers, got {tilt}, {z_p}, {spacing}")
    x1, y1, x2, y2 = p[..., 0, 0], p[..., 0, 1], p[..., 1, 0], p[..., 1, 1]
    cf, sf = math.cos(tilt), math.sin(tilt)
    dy = y1 - y2
    safe = np.where(dy != 0, dy, np.nan)
    psi = np.arctan(cf * (x1 - x2) / safe + (sf / focal_px) * (y2 * x1 - y1 * x2) / safe)
    t_x = (height / (focal_px * cf)) * (y1 * x2 - y2 * x1) / safe - n_arr * spacing / np.cos(psi)
    h = math.tan(tilt) * (height - z_p * cf) * np.sin(psi) + t_x * np.cos(psi)
    return psi, t_x, h


@dataclass(frozen=True, slots=True)
class LineFix:
    """The position given by one line: its index n (9.8), its two image points [px], psi [rad], h [m]."""

    n: int
    points: tuple[tuple[float, float], tuple[float, float]]
    psi: float
    h: float

    def to_dict(self) -> dict[str, Any]:
        """``{"n", "points", "psi", "h"}``, one entry of the ``lines`` list."""
        return {"n": self.n, "points": [list(p) for p in self.points], "psi": self.psi, "h": self.h}


@dataclass(frozen=True, slots=True)
class Positioning:
    """Heading psi [rad] and distance h [m] of P to the followed line (9.10)-(9.11): the mean over `lines`."""

    psi: float
    h: float
    lines: tuple[LineFix, ...]

    def to_dict(self) -> dict[str, Any]:
        """``{"psi": rad, "h": m, "lines": [...]}``, the ``wmrkit vision locate --json`` output."""
        return {"psi": self.psi, "h": self.h, "lines": [f.to_dict() for f in self.lines]}


def locate_points(camera: Camera, lines: Sequence[tuple[int, ArrayLike]], *, spacing: float = 0.0,
                  z_p: float = 0.0) -> Positioning:
    """Position from ``(n, [[x_u1, y_u1], [x_u2, y_u2]])`` per line (pixels from the image centre, y down).

    Points are taken as measured on the camera's (possibly distorted) image and undistorted with ``camera.k1``
    (exactly, :func:`.camera.undistort`; points beyond the fold of a ``k1 < 0`` model are refused, and so are
    points at or above the horizon, row ``y_u = -f / tan(tilt)``, where no ground is seen).
    A line with ``n != 0`` needs `spacing` d > 0 [m]; `spacing` and ``|z_p|`` are at most ``limits.MAX_SIZE``.
    The mean psi is taken on the circle.
    """
    from .camera import undistort

    check_type(camera, Camera, "camera", "Camera.from_file(path) or Camera(focal_px, tilt, height)")
    if isinstance(lines, str | Mapping | np.ndarray) or not isinstance(lines, Sequence) or \
            not all(isinstance(ln, Sequence) and not isinstance(ln, str) and len(ln) == 2 for ln in lines):
        raise CameraError(f"lines: expected a sequence of (n, [[xu, yu], [xu, yu]]), got {type(lines).__name__} "
                          f"{lines!r:.60}")  # a number or a list of points raised TypeError, 'abc' unpacked letters
    if not lines:
        raise CameraError("points: no lines given")
    check_placement(spacing, z_p)
    horizon = -camera.focal_px / math.tan(camera.tilt)  # image row of the horizon [px, y down]
    fixes = []
    for i, (n, pts) in enumerate(lines):
        pts = as_reals(pts, f"points: lines[{i}]")
        if pts.shape != (2, 2) or not np.all(np.isfinite(pts)):
            raise CameraError(f"points: lines[{i}]: expected two finite points [[xu, yu], [xu, yu]]")
        if isinstance(n, bool) or n not in (-1, 0, 1):  # True == 1: read as the line right of the followed one
            raise CameraError(f"points: lines[{i}].n: must be -1, 0 or 1, got {n!r}")
        if n != 0 and not spacing > 0:
            raise CameraError(f"points: lines[{i}]: n = {n} needs the line spacing (--spacing D > 0)")
        if np.any(np.abs(pts) > [camera.width, camera.rows]):  # outside the image (by more than its size)
            raise CameraError(f"points: lines[{i}]: a point {pts.tolist()} lies outside the {camera.width} x "
                              f"{camera.rows} image (pixels from its centre)")
        if abs(pts[0, 1] - pts[1, 1]) < 1e-9:  # after the bound: 1e308 - -1e308 overflowed with a numpy warning
            raise CameraError(f"points: lines[{i}]: the two points are on one image row (y_u1 = y_u2)")
        if any(n == other for other, _ in lines[:i]):  # two lines said to be the same one would be averaged
            raise CameraError(f"points: lines[{i}].n: line n = {n} given twice")
        try:  # points outside the image may lie beyond the fold of a k1 < 0 model
            und = undistort(pts, camera.k1, camera.focal_px)
        except CameraError as err:
            raise CameraError(f"points: lines[{i}]: {str(err).removeprefix('undistort: xy_d: ')}") from None
        if not np.all(und[:, 1] > horizon):  # no ground there: a line through it gave a distance of metres, exit 0
            raise CameraError(f"points: lines[{i}]: a point {pts.tolist()} lies above the horizon (row y_u = "
                              f"{horizon:.1f} px for this camera's tilt and focal length), where no ground is seen")
        psi, _, h = line_position(und, n, focal_px=camera.focal_px, tilt=camera.tilt, height=camera.height,
                                  spacing=spacing, z_p=z_p)
        fixes.append(LineFix(int(n), (tuple(pts[0].tolist()), tuple(pts[1].tolist())), float(psi), float(h)))
    check_spacing(fixes, spacing)
    psi_mean = math.atan2(sum(math.sin(f.psi) for f in fixes), sum(math.cos(f.psi) for f in fixes))
    return Positioning(psi_mean, float(np.mean([f.h for f in fixes])), tuple(fixes))


#: Largest relative difference between the line spacing the image shows and the one given (the thesis's chufa field,
#: real image points, shows 0.569 m for rows sown 0.60 m apart: 5 %).
SPACING_TOLERANCE = 0.25


def check_placement(spacing: float, z_p: float, names: tuple[str, str] = ("spacing", "z_p")) -> None:
    """Refuse (:class:`CameraError` naming it by `names`) a `spacing` outside ``[0, limits.MAX_SIZE]`` m or a `z_p`
    beyond ``limits.MAX_SIZE`` m, NaN included (a negative spacing was read as none, one line, silently). Text
    and booleans are refused (:func:`~wmrkit._shapes.as_real`: '1' raised a bare TypeError, True was 1 m)."""
    spacing, z_p = as_real(spacing, names[0]), as_real(z_p, names[1])
    if not 0 <= spacing <= MAX_SIZE:
        raise CameraError(f"{names[0]}: expected a length in [0, {MAX_SIZE:g}] m (0: one line), got {spacing:g}")
    if not abs(z_p) <= MAX_SIZE:
        raise CameraError(f"{names[1]}: expected a length in [-{MAX_SIZE:g}, {MAX_SIZE:g}] m, got {z_p:g}")


def check_spacing(fixes: Sequence[LineFix], spacing: float) -> None:
    """Refuse a line spacing the image contradicts. Each line n gives ``h_n = h + n (d_image - d)`` (9.10)-(9.11):
    with the right spacing d the lines agree on h; their disagreement is the spacing the image shows through the
    camera model, ``d_image = d + (h_i - h_j) / (n_i - n_j)`` (outermost lines). A wrong camera height scales it
    too. More than :data:`SPACING_TOLERANCE` apart (relative), or not positive: :class:`CameraError`."""
    ns = [f.n for f in fixes]
    if not spacing > 0 or len(set(ns)) < 2:
        return
    lo, hi = fixes[ns.index(min(ns))], fixes[ns.index(max(ns))]
    seen = spacing + (lo.h - hi.h) / (lo.n - hi.n)
    if not (seen > 0 and abs(seen - spacing) <= SPACING_TOLERANCE * spacing):
        raise CameraError(f"spacing: the lines n = {lo.n:+d} and {hi.n:+d} are {seen:.4g} m apart through the camera "
                          f"model (their h: {lo.h:.4g} m and {hi.h:.4g} m), --spacing says {spacing:.4g} m: more "
                          f"than {SPACING_TOLERANCE:.0%} apart; check --spacing, the lines' n and the camera's height, "
                          "tilt and focal length")


def read_points(path: str | Path) -> list[tuple[int, np.ndarray]]:
    """A points file: JSON ``{"lines": [{"n": -1|0|1, "points": [[xu, yu], [xu, yu]]}]}``.

    Points in pixels from the image centre, y down.
    """
    path = Path(path)
    data = read_located(path, "points file", "json")
    if not isinstance(data, dict) or not isinstance(data.get("lines"), list) or not data["lines"]:
        raise CameraError(f"{path}: expected {{\"lines\": [{{\"n\": ..., \"points\": [[xu, yu], [xu, yu]]}}]}}")
    if set(data) != {"lines"}:  # a misspelt or extra field was ignored
        raise CameraError(f"{path}: unknown field '{sorted(set(data) - {'lines'})[0]}' (the only field is 'lines')")
    out = []
    for i, line in enumerate(data["lines"]):
        if not isinstance(line, dict) or set(line) - {"n", "points"} or "points" not in line:
            raise CameraError(f"{path}: lines[{i}]: expected the fields 'n' and 'points'")
        n = line.get("n", 0)
        if isinstance(n, bool) or not isinstance(n, int):
            raise CameraError(f"{path}: lines[{i}].n: must be -1, 0 or 1, got {n!r}")
        pts = line["points"]
        ok = (isinstance(pts, list) and len(pts) == 2
              and all(isinstance(p, list) and len(p) == 2 for p in pts)
              and all(isinstance(c, int | float) and not isinstance(c, bool) for p in pts for c in p))
        if not ok:
            raise CameraError(f"{path}: lines[{i}].points: expected [[xu, yu], [xu, yu]] (numbers)")
        out.append((n, as_vectors(pts, 2, f"lines[{i}].points")))
    return out
