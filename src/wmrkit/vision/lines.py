"""Line extraction from an image, thesis §9.2.1.C, with OpenCV (the 'vision' extra, imported lazily).

1. pixels of interest: the reference itself (``mode="threshold"``: Otsu binarisation of the bright paint or
   plants) or its contour (``mode="gradient"``: Canny edges), already binary;
2. the normalised (rho, theta) Hough transform of those pixels (OpenCV, run on the transposed image so that
   lines running up the image, the ones a follower sees, sit away from the theta = 0/pi wrap);
3. peaks: the strongest cell, then the **mean cell** of the adjacent high-vote cells around it (a wide stripe
   votes for a plateau: its mean is the stripe's axis, not a diagonal), then cells adjacent or too close to an
   accepted line are suppressed before the next peak;
4. refinement (wmrkit extension): the pixels within a band of each line are undistorted (``k1``) and fitted by
   least squares with one trimming pass (clutter), giving sub-pixel lines even where the lens bends the stripes.

Lines are returned as ``x_u = x0 + slope * y_u`` in undistorted image coordinates [px] from the image centre,
y down, sorted left to right at the centre row.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from types import ModuleType

import numpy as np
from numpy.typing import ArrayLike

from .._shapes import as_real
from ..errors import WmrkitError
from .camera import CameraError, check_lens_image, distort, undistort

__all__ = ["DetectedLine", "cv2_module", "extract_lines", "interest_mask"]


def cv2_module() -> ModuleType:
    """OpenCV, or a :class:`WmrkitError` naming the extra to install."""
    try:
        import cv2
    except ImportError:
        raise WmrkitError("the 'vision' extra is needed: pip install 'wmrkit[vision]'") from None
    return cv2


@dataclass(frozen=True, slots=True)
class DetectedLine:
    """A line ``x_u = x0 + slope * y_u`` [px] (undistorted, from the image centre, y down), with its Hough votes."""

    x0: float
    slope: float
    votes: int
    n_pixels: int

    def x_at(self, y_u: float) -> float:
        """The line's x_u [px] on image row `y_u` [px]."""
        return self.x0 + self.slope * y_u

    def points(self, rows_a: float) -> np.ndarray:
        """Its two points on rows ``-A`` and ``+A``: ``[[x, -A], [x, +A]]`` [px], input of (9.10)."""
        return np.array([[self.x_at(-rows_a), -rows_a], [self.x_at(rows_a), rows_a]])

    def intersection(self, other: DetectedLine) -> tuple[float, float] | None:
        """Where two lines meet (the vanishing point of parallel ground lines), or None when parallel."""
        ds = self.slope - other.slope
        if abs(ds) < 1e-12:
            return None
        y = (other.x0 - self.x0) / ds
        return self.x_at(y), y


def _grey(image: ArrayLike) -> np.ndarray:
    """A grey or BGR image of 0-255 levels as a 2-D uint8 grey image, or :class:`CameraError` naming what it is not.

    Levels of another type are taken as they are, not rescaled: levels outside 0-255 (a 16-bit image) and a
    float image of levels within [0, 1] are refused (clipped, the first read as white, the second as black).
    """
    img = np.asarray(image)
    if not (img.ndim == 2 or (img.ndim == 3 and img.shape[2] == 3)) or img.size == 0:
        raise CameraError(f"image: expected a grey or BGR image, got shape {img.shape}")
    if img.dtype != np.uint8:
        if not np.issubdtype(img.dtype, np.number) or not np.all(np.isfinite(img)):  # NaN became 0 with a warning
            raise CameraError(f"image: expected finite grey levels, got {img.dtype} values"
                              + ("" if not np.issubdtype(img.dtype, np.number) else " that are not finite"))
        lo, hi = float(img.min()), float(img.max())
        if lo < 0 or hi > 255:
            raise CameraError(f"image: {img.dtype} grey levels from {lo:g} to {hi:g}, outside 0-255: give 8-bit levels "
                              "(a 16-bit image divided by 257)")
        if np.issubdtype(img.dtype, np.floating) and lo < hi <= 1:
            raise CameraError(f"image: {img.dtype} grey levels from {lo:g} to {hi:g}: wmrkit reads levels 0-255 "
                              "(multiply an image of levels in [0, 1] by 255)")
        img = img.astype(np.uint8)  # BGR conversion (OpenCV) takes 8-bit images only
    if img.ndim == 3:
        img = cv2_module().cvtColor(np.ascontiguousarray(img), cv2_module().COLOR_BGR2GRAY)
    return img


def interest_mask(image: ArrayLike, mode: str = "threshold", *, min_contrast: float = 20.0) -> np.ndarray:
    """Binary uint8 mask (255 = of interest) of a grey or BGR image, steps 1-2 of §9.2.1.C.

    An image whose grey levels span less than `min_contrast` has none.
    """
    cv2 = cv2_module()
    if mode not in ("threshold", "gradient"):
        raise CameraError(f"mode must be 'threshold' or 'gradient', got {mode!r}")
    img = _grey(image)
    lo, hi, _, _ = cv2.minMaxLoc(img)
    if hi - lo < min_contrast:  # a blank image has no pixels of interest
        return np.zeros(img.shape, np.uint8)
    if mode == "threshold":
        _, mask = cv2.threshold(img, 0, 255, cv2.THRESH_BINARY | cv2.THRESH_OTSU)
        return mask
    median = float(np.median(img))
    return cv2.Canny(cv2.GaussianBlur(img, (5, 5), 1.0), max(10.0, 0.66 * median), max(30.0, 1.33 * median))


def _bright_side(grey: np.ndarray, line: DetectedLine, k1: float, focal_px: float, offset: float = 2.0) -> float:
    """Mean grey level `offset` px right of `line` minus left of it, over the image's lower half: > 0 on the left
    contour of a bright reference, < 0 on its right one (``mode="gradient"``: Canny's edges have no sign)."""
    rows, width = grey.shape
    cx, cy = (width - 1) / 2, (rows - 1) / 2
    ys = np.arange(0.0, cy, 2.0)
    pts = np.stack([line.x_at(ys), ys], -1)  # undistorted, as fitted: back to the image's pixels
    pts = distort(pts, k1, focal_px) + np.array([cx, cy])
    ok = np.all(np.isfinite(pts), axis=1)
    x, y = pts[ok, 0], pts[ok, 1]
    ok[ok] = (x >= offset) & (x <= width - 1 - offset) & (y >= 0) & (y <= rows - 1)
    if not ok.any():
        return 0.0
    r = np.rint(pts[ok, 1]).astype(np.intp)
    right = grey[r, np.rint(pts[ok, 0] + offset).astype(np.intp)].astype(float)
    left = grey[r, np.rint(pts[ok, 0] - offset).astype(np.intp)].astype(float)
    return float(np.mean(right - left))


def _run_around(row: np.ndarray, x: float, search: float) -> tuple[float, float] | None:
    """Extent ``(lo, hi)`` [px, column index] of the run of mask pixels on `row` at or nearest to column `x`."""
    on = np.flatnonzero(row)
    if on.size == 0:
        return None
    j = int(np.argmin(np.abs(on - x)))
    if abs(on[j] - x) > search:
        return None
    breaks = np.flatnonzero(np.diff(on) > 1)  # run boundaries
    first = on[breaks[breaks < j].max() + 1] if np.any(breaks < j) else on[0]
    last = on[breaks[breaks >= j].min()] if np.any(breaks >= j) else on[-1]
    return float(first), float(last)


def _peaks(cells: np.ndarray, votes: np.ndarray, mask: np.ndarray, n_lines: int, plateau: float,
           min_sep: float) -> list[tuple[float, float, int]]:
    """Mean cells of up to `n_lines` non-adjacent Hough peaks, as ``(x0, slope, votes)``.

    `cells` ``(M, 2)``: each above-threshold cell's line ``x = x0 + slope y`` [px from the centre]. A peak's
    stripe is measured on two rows of the lower part of its visible segment (the run of mask pixels it crosses);
    the cells whose lines stay, on both rows, inside the stripe widened by half its width (or within `min_sep`
    px) are its plateau: their vote-weighted mean among those above `plateau` x peak is the line (the thesis's
    mean cell), and all of them are suppressed before the next peak (§9.2.1.C: not adjacent, not too close).
    """
    rows, width = mask.shape
    cx, cy = (width - 1) / 2, (rows - 1) / 2
    alive = votes > 0
    out = []
    for _ in range(n_lines):
        if not alive.any():
            break
        i = int(np.argmax(np.where(alive, votes, -1)))
        x0, slope = cells[i]
        lo_y, hi_y = -cy, cy  # rows where the line is inside the image
        if abs(slope) > 1e-9:
            ends = sorted(((-cx - x0) / slope, (cx - x0) / slope))
            lo_y, hi_y = max(lo_y, ends[0]), min(hi_y, ends[1])
        if hi_y <= lo_y:
            lo_y, hi_y = 0.0, 0.8 * cy
        ys = np.array([lo_y + 0.5 * (hi_y - lo_y), lo_y + 0.9 * (hi_y - lo_y)])
        xs = cells[:, :1] + cells[:, 1:] * ys  # (M, 2): every cell's line on the two rows
        lo, hi = xs[i] - min_sep, xs[i] + min_sep
        for r in range(2):
            run = _run_around(mask[round(cy + ys[r])] > 0, xs[i, r] + cx, min_sep)
            if run is not None:  # the stripe, and as much again: lines crossing it diagonally are its plateau
                margin = 2 + (run[1] - run[0]) / 2
                lo[r], hi[r] = min(lo[r], run[0] - cx - margin), max(hi[r], run[1] - cx + margin)
        inside = alive & np.all((xs >= lo) & (xs <= hi), axis=1)
        top = inside & (votes >= plateau * votes[i])
        w = votes[top].astype(float)
        mean = (w[:, None] * cells[top]).sum(axis=0) / w.sum()
        out.append((float(mean[0]), float(mean[1]), int(votes[i])))
        alive &= ~inside
        alive[i] = False
    return out


#: Least grey-level step [grey levels] across a contour line (``mode="gradient"``, :func:`_bright_side`): real
#: contours of the test scenes show 55-140; a fit drawn onto a reference's axis (fewer lines asked than in view) ~1.
CONTOUR_CONTRAST = 10.0
#: Contour lines (``mode="gradient"``) nearer than this [px] on the near rows are one line: the fit leaves out rows
#: where two lines are nearer (``_fit_lines``' `min_gap`), so a second peak there, a contour's duplicate or a line
#: crossing the stripe from one contour to the other, took the real contour's rows and its fit failed.
GRADIENT_MIN_GAP_PX = 8.0


def _fit_lines(runs: np.ndarray, lines: list[tuple[float, float]], max_band: float,
               min_gap: float = GRADIENT_MIN_GAP_PX, passes: int = 4) -> list[tuple[float, float, int] | None]:
    """Least-squares ``x = x0 + slope y`` of each line over its own pixels, `passes` passes.

    `runs` ``(M, 3)``: ``(x_left, x_right, y)`` [px] of the runs of mask pixels along the rows (pixel edges).
    Each run goes to its nearest line and is clipped to the line's band (at most `max_band` px, then three
    standard deviations of the pixels about the line) and to half the gap to the next line on its row; rows
    where two lines are closer than `min_gap` px (near the vanishing point) are left out. A clipped run
    contributes exactly what its pixels would (they share y), so this is the fit over every pixel in the bands,
    made with ten times fewer numbers; clutter touching a stripe adds only the pixels inside the band, and
    from the second pass on each run is weighted down (Tukey's biweight) by how far its middle lies from the line.
    """
    k_lines = len(lines)
    if k_lines == 0 or len(runs) == 0:
        return [None] * k_lines
    left, right, y = runs[:, 0], runs[:, 1], runs[:, 2]
    mid = (left + right) / 2
    line = np.array(lines, dtype=float)  # (K, 2): x0, slope
    y_lo = math.floor(float(y.min()))
    yi = np.rint(y - y_lo).astype(np.intp)  # row of each run in the per-row tables
    y_rows = y_lo + np.arange(int(yi.max()) + 1, dtype=float)
    band = np.full(k_lines, max_band)
    fits: list[tuple[float, float, int] | None] = [None] * k_lines
    rows = np.arange(len(y))
    scale: np.ndarray | None = None  # robust scale of the runs' middles about each line [px], after a pass
    for _ in range(passes):
        table = line[:, 0] + line[:, 1] * y_rows[:, None]  # (rows, K): each line's x on each row
        at = table[yi]
        k = np.argmin(np.abs(mid[:, None] - at), axis=1)
        centre = at[rows, k]
        if k_lines > 1:
            gap_table = np.abs(table[:, :, None] - table[:, None, :])  # (rows, K, K)
            gap_table[:, np.arange(k_lines), np.arange(k_lines)] = np.inf
            gap = gap_table.min(axis=2)[yi, k]
        else:
            gap = np.full(len(k), np.inf)
        half = np.minimum(band[k], 0.5 * gap)
        lo, hi = np.maximum(left, centre - half), np.minimum(right, centre + half)
        length = np.where(gap >= min_gap, hi - lo, 0.0)
        ok = length > 0
        kk, ys, ls = k[ok], y[ok], length[ok]
        xs = (lo[ok] + hi[ok]) / 2
        if scale is not None:  # Tukey weights on the runs' middles: rows where weeds touch the stripe count less
            u = (xs - centre[ok]) / (4.685 * scale[kk])
            ls = ls * np.where(np.abs(u) < 1, (1 - u * u) ** 2, 0.0)
        count = np.bincount(kk, ls, minlength=k_lines)
        sums = [np.bincount(kk, ls * v, minlength=k_lines)
                for v in (xs, ys, xs * ys, ys * ys, xs * xs + ls * ls / 12)]
        with np.errstate(invalid="ignore", divide="ignore"):
            mx, my, mxy, myy, mxx = (v / count for v in sums)
            var_y = myy - my * my
            slope = (mxy - mx * my) / var_y
            x0 = mx - slope * my
            resid_var = np.maximum(mxx - mx * mx - slope * slope * var_y, 0.0)
        good = (count >= 10) & (var_y > 4.0)
        line = np.where(good[:, None], np.stack([x0, slope], -1), line)
        band = np.where(good, np.minimum(band, np.maximum(3.0, 3.0 * np.sqrt(resid_var))), band)
        fits = [(float(line[i, 0]), float(line[i, 1]), int(count[i])) if good[i] else None for i in range(k_lines)]
        resid = np.abs(xs - (line[kk, 0] + line[kk, 1] * ys))
        scale = np.array([max(0.5, 1.4826 * float(np.median(resid[kk == i]))) if np.any(kk == i) else max_band
                          for i in range(k_lines)])
    return fits


#: Most runs of pixels of interest per image row (median over the rows that have any), per 32 px of width, and at
#: least: references (painted lines, crop rows, with weeds) make one or two per reference crossing a row (measured:
#: 1-5 in the tests' scenes); binarised noise makes one every 4 px (an image too noisy for the threshold).
SPECKLE_RUNS_PER_32_PX, SPECKLE_MIN_RUNS = 1.0, 8.0


def _check_not_speckle(run_row: np.ndarray, rows: int, width: int) -> None:
    """Refuse pixels of interest that are noise, not references: Hough finds lines in any dense speckle (image
    noise of 20 grey levels defeats the threshold of a thin line; a follower then steered to random lines)."""
    per_row = np.bincount(run_row, minlength=rows)
    per_row = per_row[per_row > 0]
    limit = max(SPECKLE_MIN_RUNS, SPECKLE_RUNS_PER_32_PX * width / 32)
    if per_row.size and np.median(per_row) > limit:
        raise CameraError(f"image: too noisy to find lines, {np.median(per_row):g} runs of pixels of interest a row "
                          f"(median; references make a few, at most {limit:g}): reduce the image noise")


def _runs(mask: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Every run of mask pixels along a row: ``(row, first column, middle column, length)``.

    The row's transitions (OpenCV, raster order) alternate start, end because the row is padded with zeros.
    """
    cv2 = cv2_module()
    padded = cv2.copyMakeBorder((mask > 0).astype(np.uint8), 0, 0, 1, 1, cv2.BORDER_CONSTANT, value=0)
    edges = cv2.findNonZero(cv2.absdiff(padded[:, 1:], padded[:, :-1]))
    if edges is None:
        empty = np.zeros(0, dtype=np.intp)
        return empty, empty, empty.astype(float), empty
    xy = edges.reshape(-1, 2)
    r0, c0, c1 = xy[0::2, 1], xy[0::2, 0], xy[1::2, 0]
    return r0, c0, (c0 + c1 - 1) / 2, c1 - c0


def extract_lines(image: ArrayLike, *, n_lines: int = 1, mode: str = "threshold", k1: float = 0.0,
                  focal_px: float | None = None, max_angle: float = math.radians(70), min_votes: int | None = None,
                  min_separation_px: int = 12, max_band_px: float = 40.0, hough_scale: float | None = None,
                  mask: np.ndarray | None = None) -> tuple[DetectedLine, ...]:
    """Up to `n_lines` lines of a grey/BGR `image` (§9.2.1.C), sorted left to right; fewer if the image has fewer.

    `image`: at least 8 px a side; `max_angle` [rad]: the largest angle from the image's vertical searched, in
    ``(0, pi/2]``; `min_votes`: Hough threshold, an integer >= 1 (default a fifth of the shorter image side);
    `min_separation_px` (> 0): peaks closer than this (and 3 deg) are one line; `max_band_px` (> 0): the widest
    band of pixels fitted around a line; `k1`, `focal_px`: the lens distortion undone before the fit (module
    docstring; refused where the model folds over inside the image, :func:`.camera.check_lens_image`);
    `hough_scale`: the Hough transform runs on the mask resized by this factor in ``(0, 1]`` (default 0.5 for
    images wider than 400 px, else 1); `mask`: a precomputed :func:`interest_mask`.
    """
    cv2 = cv2_module()
    if isinstance(n_lines, bool) or not isinstance(n_lines, int | np.integer) or n_lines < 1:
        raise CameraError(f"n_lines must be an integer >= 1, got {n_lines!r}")
    # the Python API reads no units: text ('1' raised a bare TypeError, k1='1' was read as 1) and booleans
    k1, max_angle, max_band_px, min_separation_px = (as_real(v, f"extract_lines: {name}") for name, v in (
        ("k1", k1), ("max_angle", max_angle), ("max_band_px", max_band_px), ("min_separation_px", min_separation_px)))
    focal_px, hough_scale = (None if v is None else as_real(v, f"extract_lines: {name}") for name, v in (
        ("focal_px", focal_px), ("hough_scale", hough_scale)))  # focal_px was ignored, whatever it was, when k1 = 0
    if not 0 < max_angle <= math.pi / 2:  # NaN included: OpenCV raised its own error
        raise CameraError(f"extract_lines: max_angle: expected an angle in (0, pi/2] rad, got {max_angle}")
    for name, value in (("max_band_px", max_band_px), ("min_separation_px", min_separation_px)):
        if not 0 < value < math.inf:  # NaN included: a band or separation of no pixel found no line, silently
            raise CameraError(f"extract_lines: {name}: expected a finite number > 0 [px], got {value:g}")
    if min_votes is not None and (isinstance(min_votes, bool) or not isinstance(min_votes, int | np.integer)
                                  or min_votes < 1):
        raise CameraError(f"extract_lines: min_votes: expected an integer >= 1, got {min_votes!r}")
    binary = interest_mask(image, mode) if mask is None else mask
    rows, width = binary.shape
    if min(rows, width) < 8:  # a camera's least side; OpenCV's resize raised on one row wider than 400 px
        raise CameraError(f"image: {width} x {rows} px, smaller than 8 px a side")
    f = focal_px if focal_px is not None else float(max(rows, width))
    if k1 != 0:  # every pixel must have one undistorted position (camera.check_lens_image)
        check_lens_image(k1, f, width, rows, "extract_lines")
    scale = hough_scale if hough_scale is not None else (0.5 if width > 400 else 1.0)
    if not (0 < scale <= 1 and min(rows, width) * scale >= 1):  # > 1: slower, not finer (100 took 9 s)
        raise CameraError(f"extract_lines: hough_scale: expected a factor in (0, 1] that leaves at least a pixel of "
                          f"the {width} x {rows} px image, got {scale}")
    run_row, run_first, run_mid, run_len = _runs(binary)
    _check_not_speckle(run_row, rows, width)
    if mode == "threshold":  # wide references vote as thin lines: the middle pixel of each run
        voters = np.zeros_like(binary)
        voters[run_row, np.floor(run_mid).astype(np.intp)] = 255
    else:
        voters = binary
    if scale != 1:  # a cell of the small image votes if any of its pixels does
        voters = (cv2.resize(voters, None, fx=scale, fy=scale, interpolation=cv2.INTER_AREA) > 0).astype(np.uint8)
    small = cv2.transpose(np.ascontiguousarray(voters))  # x' = y, y' = x
    theta_step = math.radians(1.0)
    theta_min, theta_max = math.pi / 2 - max_angle, math.pi / 2 + max_angle
    votes = min_votes if min_votes is not None else max(10, int(min(rows, width) * scale / 5))
    found = cv2.HoughLinesWithAccumulator(small, 1, theta_step, votes, min_theta=theta_min, max_theta=theta_max)
    if found is None:
        return ()
    cells = found.reshape(-1, 3).astype(float)
    cx, cy = (width - 1) / 2, (rows - 1) / 2
    # transposed image: y_p cos(theta) + x_p sin(theta) = rho  ->  x = (rho - (y + cy) cos) / sin - cx
    rho, sin_t, cos_t = cells[:, 0] / scale, np.sin(cells[:, 1]), np.cos(cells[:, 1])
    lines_xs = np.stack([(rho - cy * cos_t) / sin_t - cx, -cos_t / sin_t], -1)
    sep = float(min_separation_px if mode == "threshold" else GRADIENT_MIN_GAP_PX)
    lines = _peaks(lines_xs, cells[:, 2], binary, n_lines * (1 if mode == "threshold" else 2), 0.7, sep)
    whole = (run_first > 0) & (run_first + run_len < width)  # runs cut by the image border are off-centre
    runs = np.stack([run_first[whole] - 0.5 - cx, run_first[whole] + run_len[whole] - 0.5 - cx,
                     run_row[whole] - cy], -1).astype(float)
    if mode == "gradient":  # strongest first, a contour peak is kept if every kept line still fits with it: a
        # spurious peak near a contour (a diagonal across the stripe, a line sharing its far end) took its rows
        kept: list[tuple[float, float, int]] = []
        for peak in lines:
            if all(_fit_lines(runs, [(x0, s) for x0, s, _ in (*kept, peak)], max_band_px, passes=2)):
                kept.append(peak)
        lines = kept
    if k1 != 0:  # fit on the undistorted runs: distortion bends the stripes, the ground lines are straight
        fits = _fit_lines(runs, [(x0, s) for x0, s, _ in lines], max_band_px)
        rough = [(fit[0], fit[1]) if fit else (x0, s) for fit, (x0, s, _) in zip(fits, lines, strict=True)]
        ends = undistort(np.stack([runs[:, [0, 2]], runs[:, [1, 2]]], 1), k1, f)  # (M, 2 ends, 2)
        runs = np.stack([ends[:, 0, 0], ends[:, 1, 0], ends[:, :, 1].mean(axis=1)], -1)
        fits = _fit_lines(runs, rough, max_band_px)
    else:
        fits = _fit_lines(runs, [(x0, s) for x0, s, _ in lines], max_band_px)
    result = sorted((DetectedLine(fit[0], fit[1], v, fit[2]) for fit, (_, _, v) in zip(fits, lines, strict=True)
                     if fit), key=lambda ln: ln.x0)
    if mode == "gradient":  # the two contour lines of each reference: their middle line (§9.2.1.C, step 1)
        # a left contour (brighter on its right) then a right one: taken in turn, contours of two neighbouring
        # references made a line between them where there is none
        grey = _grey(image)
        side = [_bright_side(grey, ln, k1, f) for ln in result]
        pairs, i = [], 0
        while i + 1 < len(result):
            if side[i] > CONTOUR_CONTRAST and side[i + 1] < -CONTOUR_CONTRAST:
                pairs.append((result[i], result[i + 1]))
                i += 2
            else:
                i += 1
        result = [DetectedLine((a.x0 + b.x0) / 2, (a.slope + b.slope) / 2, min(a.votes, b.votes),
                               a.n_pixels + b.n_pixels) for a, b in pairs]
    return tuple(result)
