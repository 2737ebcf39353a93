"""Pose references for the kinematic loop (thesis §8.2, high-level loop of Fig. 8.1): built-in shapes and files.

A :class:`Reference` is a sampled trajectory ``p_ref(t) = (x, y, theta)`` in the world frame with its velocity and
acceleration (exact for the built-in shapes, finite differences for files). The built-ins start at the origin
heading along +x, except the two forklift examples of §8.6.2, which are placed as the thesis describes them
(``docs/control.md``). Files: TUM (8 columns) or CSV with a ``t,x,y,theta`` header (``time`` accepted).
"""

from __future__ import annotations

import csv
import math
import os
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .._numbers import number_problem
from .._shapes import as_real, readonly
from ..errors import UnknownNameError, WmrkitError
from ..limits import MAX_COORDINATE, MAX_SPEED, check_table_size
from ..units import BARE_ANGLE_LIMIT

__all__ = ["BUILTIN", "CORNER_RECOVERY", "TIGHTEST_TURN", "TURN_MARGIN", "Reference", "ReferenceError",
           "builtin_reference", "default_size", "load_reference", "reference_from_samples", "resolve_reference"]


class ReferenceError(WmrkitError, ValueError):
    """A reference file or name that cannot be used (located, one line)."""


@dataclass(frozen=True, eq=False)
class Reference:
    """A sampled pose reference. Frozen; arrays read-only. ``eq=False``: array fields.

    ``t`` ``(n,)`` [s], increasing; ``pose`` ``(n, 3)`` ``(x [m], y [m], theta [rad])`` world frame, theta
    continuous (unwrapped); ``velocity`` ``(n, 3)`` its time derivative (world frame, the ``G p_dot_ref`` of
    (8.2)); ``acceleration`` ``(n, 3)``. ``breaks``: times where the shape is known to be discontinuous.
    """

    name: str
    t: np.ndarray
    pose: np.ndarray
    velocity: np.ndarray
    acceleration: np.ndarray
    breaks: tuple[float, ...] = ()

    @property
    def duration(self) -> float:
        """Time span [s]."""
        return float(self.t[-1] - self.t[0])

    def at(self, t: float) -> tuple[np.ndarray, np.ndarray]:
        """``(pose (3,), velocity (3,))`` at time `t`: cubic Hermite between samples (pose from pose and velocity,
        velocity from velocity and acceleration; exact to ``O(dt^4)``); after the end the last pose at rest (at the
        last sample its own velocity: a run ends there, and its last step must not see the reference stop)."""
        ts = self.t
        if t > ts[-1]:
            return self.pose[-1].copy(), np.zeros(3)
        k = min(max(int(ts.searchsorted(t, side="right")) - 1, 0), len(ts) - 2)
        t0, t1 = ts[k:k + 2].tolist()
        h = t1 - t0
        corner = next((b for b in self.breaks if t0 < b <= t1), None) if self.breaks else None
        if corner is not None:  # a corner inside the interval: Taylor from the sample on t's side of it
            j = k if t < corner else k + 1
            dt = t - ts[j]
            p, v, a = self.pose[j], self.velocity[j], self.acceleration[j]
            return p + dt * v + (0.5 * dt * dt) * a, v + dt * a
        u = min(max((t - t0) / h, 0.0), 1.0)
        u2, u3 = u * u, u * u * u
        h00, h10, h01, h11 = 2 * u3 - 3 * u2 + 1, u3 - 2 * u2 + u, -2 * u3 + 3 * u2, u3 - u2
        # in floats, the operations of the arrays' (a few µs instead of tens: the loop asks it at every evaluation)
        (p0, p1), (v0, v1), (a0, a1) = (x[k:k + 2].tolist() for x in (self.pose, self.velocity, self.acceleration))
        pose = [h00 * p0[i] + (h10 * h) * v0[i] + h01 * p1[i] + (h11 * h) * v1[i] for i in range(3)]
        vel = [h00 * v0[i] + (h10 * h) * a0[i] + h01 * v1[i] + (h11 * h) * a1[i] for i in range(3)]
        return np.array(pose), np.array(vel)

    def sample(self, t: np.ndarray) -> np.ndarray:
        """Poses at times `t` ``(m,) -> (m, 3)`` (linear interpolation, held after the end)."""
        t = np.asarray(t, dtype=float)
        if not np.isfinite(t).all():
            raise ReferenceError(f"{self.name}: sample times must be finite")
        return np.stack([np.interp(t, self.t, self.pose[:, j]) for j in range(3)], axis=-1)


def reference_from_samples(name: str, t: np.ndarray, pose: np.ndarray) -> Reference:
    """A reference from sampled poses ``(n,), (n, 3)``: velocities and accelerations by finite differences."""
    t = np.asarray(t, dtype=float)
    pose = np.asarray(pose, dtype=float).copy()
    if t.ndim != 1 or pose.shape != (len(t), 3) or len(t) < 3:
        raise ReferenceError(f"{name}: expected at least 3 samples of (t, x, y, theta), got {pose.shape}")
    bad = ~np.isfinite(np.column_stack([t, pose]))
    if bad.any():
        k, c = (int(i) for i in np.argwhere(bad)[0])
        value = float(t[k] if c == 0 else pose[k, c - 1])
        raise ReferenceError(f"{name}: sample {k + 1}: {('t', 'x', 'y', 'theta')[c]} {value!r} is not a finite "
                             "number (times and poses must be)")
    if np.abs(pose[:, :2]).max() > MAX_COORDINATE:
        k = int(np.argmax(np.abs(pose[:, :2]).max(axis=1) > MAX_COORDINATE))  # the first, as for NaN above
        raise ReferenceError(f"{name}: sample {k + 1}: position ({pose[k, 0]:g}, {pose[k, 1]:g}) m is beyond "
                             f"{MAX_COORDINATE:g} m")
    if np.any(np.diff(t) <= 0):
        k = int(np.argmax(np.diff(t) <= 0))
        raise ReferenceError(f"{name}: times must increase (sample {k + 2}: {t[k + 1]} after {t[k]})")
    _check_radians(name, pose[:, 2])
    pose[:, 2] = np.unwrap(pose[:, 2])
    # second-order differences at the ends too: first-order ones put a false curvature jump at the first and last
    # samples of a reference that starts or ends turning
    step = np.hypot(*np.diff(pose[:, :2], axis=0).T) / np.diff(t)
    if step.max() > MAX_SPEED:  # a wrong time unit (ms, ns read as s) or positions: nothing a robot follows
        k = int(np.argmax(step))
        raise ReferenceError(f"{name}: samples {k + 1}-{k + 2} move at {step[k]:.3g} m/s, beyond {MAX_SPEED:g} m/s "
                             "(times are seconds, positions metres)")
    with np.errstate(over="ignore", invalid="ignore"):  # numpy's warnings on stderr: refused below instead
        vel = np.gradient(pose, t, axis=0, edge_order=2)
        acc = np.gradient(vel, t, axis=0, edge_order=2)
    if not (np.isfinite(vel).all() and np.isfinite(acc).all()):  # samples 1e-300 s apart: an acceleration of inf
        k = int(np.argmax(~(np.isfinite(vel).all(axis=1) & np.isfinite(acc).all(axis=1))))
        raise ReferenceError(f"{name}: sample {k + 1}: the velocity or acceleration by finite differences overflows "
                             "(samples too close in time, or too far apart: times are seconds)")
    return Reference(name, readonly(t), readonly(pose), readonly(vel), readonly(acc))


def _check_radians(name: str, theta: np.ndarray) -> None:
    """Headings are radians: wrapped ones stay within a turn, unwrapped ones move less than half a turn a sample.
    Beyond a turn with larger jumps they are degrees (or nothing a robot can follow): refused."""
    jumps = np.abs(np.diff(theta))
    if np.abs(theta).max() > BARE_ANGLE_LIMIT and jumps.max() > math.pi:
        k = int(np.argmax(jumps)) + 1
        raise ReferenceError(f"{name}: sample {k + 1}: theta {theta[k]:g} rad, {jumps[k - 1]:g} rad from the sample "
                             "before: headings are radians and go beyond a turn only when unwrapped (less than half "
                             f"a turn a sample); degrees? {theta[k]:g} deg = {math.radians(theta[k]):.6g} rad")


def _plain_csv(path: Path) -> np.ndarray | None:
    """The rows of a CSV reference whose header starts ``t,x,y,theta`` and whose every row is as many plain numbers,
    by numpy's reader; None for anything else (quotes, blank fields, a bad row, a value that is not finite), which
    the row-by-row reader refuses with its line. A 64 MiB file read as Python lists took 1.1 GB."""
    with open(path, encoding="utf-8-sig", newline="") as f:
        header = [h.strip().lower() for h in f.readline().strip("\r\n").split(",")]
        if header[:1] == ["time"]:
            header[0] = "t"
        if header[:4] != ["t", "x", "y", "theta"]:
            return None
        try:
            with warnings.catch_warnings():  # "input contained no data": a header alone, refused below
                warnings.simplefilter("ignore")
                data = np.loadtxt(f, delimiter=",", ndmin=2, comments=None, dtype=float)
        except ValueError:
            return None
    ok = len(data) and data.shape[1] == len(header) and np.isfinite(data[:, :4]).all()
    return data if ok else None  # 'nan', 'inf', '1e400' (read as inf): named with their line by the row reader


def load_reference(path: str | os.PathLike[str]) -> Reference:
    """A reference from a TUM file (``t x y z qx qy qz qw``) or a CSV with header ``t,x,y,theta``."""
    path = Path(path)
    if not path.exists():
        raise ReferenceError(f"{path}: no such file")
    check_table_size(path, ReferenceError, "reference")
    try:
        with open(path, encoding="utf-8") as f:
            first = f.readline()
        if "," in first:
            data = _plain_csv(path)
            if data is not None:
                return reference_from_samples(str(path), data[:, 0], data[:, 1:4])
            with open(path, encoding="utf-8-sig", newline="") as f:  # -sig: a spreadsheet's byte-order mark
                rows = list(csv.reader(f))
            header = [h.strip().lower() for h in rows[0]]
            if header[:1] == ["time"]:
                header[0] = "t"
            if header[:4] != ["t", "x", "y", "theta"]:
                raise ReferenceError(f"{path}:1: expected the columns t,x,y,theta, got {','.join(rows[0])}")
            data = []
            for line, row in enumerate(rows[1:], start=2):
                if row and len(row) != len(header):
                    raise ReferenceError(f"{path}:{line}: expected {len(header)} fields, got {len(row)}")
                for name, field in zip(header[:4], row[:4], strict=False):
                    problem = number_problem(field)
                    if problem is not None:
                        raise ReferenceError(f"{path}:{line}: column '{name}': {problem}")
                data += [[float(v) for v in row[:4]]] if row else []
            data = np.array(data, dtype=float).reshape(-1, 4)
            return reference_from_samples(str(path), data[:, 0], data[:, 1:4])
        from ..odometry.trajectories import read_tum

        try:
            t, pose = read_tum(path)
        except WmrkitError as err:  # its message names the file and the line already
            raise ReferenceError(str(err)) from None
    except ReferenceError:
        raise
    except (ValueError, IndexError, UnicodeDecodeError, WmrkitError) as err:
        raise ReferenceError(f"{path}: cannot read the reference ({str(err).splitlines()[0]})") from None
    except OSError as err:  # a directory, no permission
        raise ReferenceError(f"{path}: cannot read the reference ({err.strerror or err})") from None
    return reference_from_samples(str(path), t, pose)


# ---- built-in shapes ------------------------------------------------------------------------------------
def _line(t: np.ndarray, v: float, size: float) -> tuple[np.ndarray, np.ndarray, np.ndarray, tuple[float, ...]]:
    z = np.zeros_like(t)
    return np.stack([v * t, z, z], -1), np.stack([v + z, z, z], -1), np.zeros((len(t), 3)), ()


def _circle(t, v, size):
    w = v / size
    th = w * t
    pose = np.stack([size * np.sin(th), size * (1 - np.cos(th)), th], -1)
    vel = np.stack([v * np.cos(th), v * np.sin(th), np.full_like(t, w)], -1)
    acc = np.stack([-v * w * np.sin(th), v * w * np.cos(th), 0 * t], -1)
    return pose, vel, acc, ()


def _figure_eight(t, v, size):
    # Gerono lemniscate x = A sin(w t), y = (A / 2) sin(2 w t); w set so the mean speed is about v.
    w = v / (1.2 * size)
    s, c = np.sin(w * t), np.cos(w * t)
    s2, c2 = np.sin(2 * w * t), np.cos(2 * w * t)
    x, y = size * s, 0.5 * size * s2
    dx, dy = size * w * c, size * w * c2
    ddx, ddy = -size * w * w * s, -2 * size * w * w * s2
    dddx, dddy = -size * w**3 * c, -4 * size * w**3 * c2
    chi = np.unwrap(np.arctan2(dy, dx))
    num, den = dx * ddy - dy * ddx, dx * dx + dy * dy
    chi_dot = num / den
    chi_ddot = ((dx * dddy - dy * dddx) * den - num * 2 * (dx * ddx + dy * ddy)) / den**2
    return (np.stack([x, y, chi], -1), np.stack([dx, dy, chi_dot], -1), np.stack([ddx, ddy, chi_ddot], -1), ())


def _polyline(t, v, corners):
    """Constant speed `v` along straight legs through `corners` ``(k, 2)``; heading jumps at each corner."""
    legs = np.diff(corners, axis=0)
    lengths = np.hypot(legs[:, 0], legs[:, 1])
    ends = np.concatenate([[0.0], np.cumsum(lengths)]) / v
    i = np.clip(np.searchsorted(ends, t, side="right") - 1, 0, len(legs) - 1)
    u = legs[i] / lengths[i, None]
    xy = corners[i] + u * (v * (t - ends[i]))[:, None]
    chi = np.unwrap(np.arctan2(legs[:, 1], legs[:, 0]))[i]
    pose = np.column_stack([xy, chi])
    vel = np.column_stack([v * u, np.zeros_like(t)])
    return pose, vel, np.zeros((len(t), 3)), tuple(float(e) for e in ends[1:-1])


def _square(t, v, size):
    c = np.array([[0, 0], [size, 0], [size, size], [0, size], [0, 0]], dtype=float)
    return _polyline(t, v, c)


def _corner(t, v, size):
    # §8.6.2 example 2: a reference with a tangent-angle discontinuity, from the origin (shape not given): an L,
    # first along -y (behind a truck facing +y, hence the initial manoeuvre), then along +x.
    return _polyline(t, v, np.array([[0, 0], [0, -size], [size, -size]], dtype=float))


def _arc_line(t, v, size):
    # §8.6.2 example 1: a half turn (arc of radius `size`) then a straight line; starts at the origin heading -y.
    w = v / size
    t1 = math.pi / w
    on_arc = t < t1
    th = np.where(on_arc, w * t, math.pi)
    chi = th - math.pi / 2
    x = np.where(on_arc, size * (1 - np.cos(th)), 2 * size)
    y = np.where(on_arc, -size * np.sin(th), v * (t - t1))
    vel = np.stack([v * np.cos(chi), v * np.sin(chi), np.where(on_arc, w, 0.0)], -1)
    acc = np.stack([-v * np.sin(chi) * np.where(on_arc, w, 0), v * np.cos(chi) * np.where(on_arc, w, 0), 0 * t], -1)
    return np.stack([x, y, chi], -1), vel, acc, (t1,)


#: Built-in references: name -> (shape function, default speed [m/s], default size [m], duration(speed, size) [s]).
BUILTIN = {
    "line": (_line, 0.5, 1.0, lambda v, size: 20.0),
    "circle": (_circle, 0.5, 3.0, lambda v, size: 2 * math.pi * size / v),
    "figure-eight": (_figure_eight, 0.5, 6.0, lambda v, size: 2 * math.pi * 1.2 * size / v),
    "square": (_square, 0.5, 6.0, lambda v, size: 4 * size / v),
    "arc-line": (_arc_line, 0.5, 1.5, lambda v, size: math.pi * size / v + 10.0),
    "corner": (_corner, 0.5, 3.0, lambda v, size: 2 * size / v),
}

#: The tightest turn of each built-in shape whose curvature scales with its size: its smallest radius of curvature
#: per metre of size (the circle's is its radius, the arc-line's its arc's; Gerono's lemniscate of half width A,
#: the figure-eight, turns on 0.2087557 A at its tightest, where cos^2(w t) = 0.38643: rounded down here, so the
#: sized shape's turn is never below the margin). The line and the polylines (square, corner) have straight legs
#: only: their corners are tangent jumps at any size (Table 8.1), sized by :data:`CORNER_RECOVERY` instead.
TIGHTEST_TURN = {"circle": 1.0, "arc-line": 1.0, "figure-eight": 0.208755}
#: A robot's default size of such a shape makes its tightest turn at least this many times the robot's minimum
#: turning radius (a car's steering stops), rounded up to a metre.
TURN_MARGIN = 1.5
#: The legs of a polyline (square, corner) for a robot that turns on R [m] at least are R plus this [m], rounded up
#: to a metre: after each corner (a heading jump, Table 8.1) such a car turns with its wheels at their stops while
#: about R of the reference passes, then the P law (8.2) closes its error e-fold every speed / gain (0.5 m at the
#: defaults, 0.5 m/s and 1/s): 4 m more brings it back within 1 mm before the next corner (measured 2.5-2.8 m after
#: the stops for R from 2.7 to 6.6 m; a faster speed or a softer gain needs longer legs, --size).
CORNER_RECOVERY = 4.0


def default_size(name: str, turning_radius: float = 0.0) -> float | None:
    """The default size [m] of built-in reference `name` (None for ``line``, which has none) for a robot that turns
    on `turning_radius` [m] at least (0: on the spot): the shape's own (:data:`BUILTIN`), or, when larger, for a
    shape of :data:`TIGHTEST_TURN` the smallest whole metre whose tightest turn is :data:`TURN_MARGIN` times
    `turning_radius`, so that the robot can drive it, and for the square and the corner legs of `turning_radius`
    plus :data:`CORNER_RECOVERY` rounded up to a metre, so that it recovers from each corner within the next leg."""
    if name == "line":
        return None
    size = BUILTIN[name][2]
    if turning_radius > 0 and name in TIGHTEST_TURN:
        size = max(size, math.ceil(TURN_MARGIN * turning_radius / TIGHTEST_TURN[name]))
    elif turning_radius > 0:  # the polylines: straight legs between corners
        size = max(size, math.ceil(turning_radius + CORNER_RECOVERY))
    return size


def builtin_reference(name: str, *, speed: float | None = None, size: float | None = None,
                      duration: float | None = None, dt: float = 0.01) -> Reference:
    """A built-in reference by name (:data:`BUILTIN`), sampled every `dt` [s], with exact derivatives.

    `speed` [m/s] along the path, `size` [m] (circle radius, square side, figure-eight half width, arc radius,
    leg length of ``corner``; ``line`` has none, and refuses one), `duration` [s] (default: one lap); defaults
    per shape in :data:`BUILTIN`.
    """
    if not isinstance(name, str):
        raise ReferenceError(f"reference: expected a built-in reference's name ({', '.join(BUILTIN)}), got {name!r}")
    speed, size, duration, dt = (None if v is None else as_real(v, what) for what, v in
                                 (("speed", speed), ("size", size), ("duration", duration), ("dt", dt)))
    if name not in BUILTIN:
        import difflib

        close = difflib.get_close_matches(name, BUILTIN, n=1)
        hint = f" (did you mean '{close[0]}'?)" if close else ""
        raise UnknownNameError(f"no built-in reference '{name}'{hint} (built-in: {', '.join(BUILTIN)}; or a file)")
    if name == "line" and size is not None:  # its shape has no size: it would be ignored
        raise ReferenceError("reference 'line' has no size (the x axis, followed at the speed for 20 s); a size "
                             f"applies to {', '.join(n for n in BUILTIN if n != 'line')}")
    fn, v0, s0, d0 = BUILTIN[name]
    v, size = (v0 if speed is None else speed), (s0 if size is None else size)
    for what, value in (("speed", v), ("size", size), ("dt", dt)):
        if not (math.isfinite(value) and value > 0):
            raise ReferenceError(f"reference '{name}': {what} must be a positive number, got {value}")
    dur = d0(v, size) if duration is None else duration
    if duration is None and not math.isfinite(dur):  # 'duration must be a positive number, got inf': not given
        raise ReferenceError(f"reference '{name}': speed (--speed) {v:g} m/s: one lap of size {size:g} m would never "
                             "end; give a higher speed")
    for what, value in (("duration", dur),):
        if not (math.isfinite(value) and value > 0):
            raise ReferenceError(f"reference '{name}': {what} must be a positive number, got {value}")
    n = math.floor(dur / dt + 1e-9) + 1
    if n < 3 or n > 10_000_000:
        lap = " (one lap at this speed and size)" if duration is None else ""
        raise ReferenceError(f"reference '{name}' at {v:g} m/s, size {size:g} m: {dur:.4g} s{lap} sampled every "
                             f"{dt:g} s gives {n if n < 10**9 else f'{n:.4g}'} samples (3 to 10^7 allowed)")
    t = np.arange(n) * dt
    pose, vel, acc, breaks = fn(t, v, size)
    return Reference(name, readonly(t), readonly(np.ascontiguousarray(pose, dtype=float)),
                     readonly(np.ascontiguousarray(vel, dtype=float)), readonly(np.ascontiguousarray(acc, dtype=float)),
                     tuple(b for b in breaks if b < dur))


def resolve_reference(spec: str, *, speed: float | None = None, size: float | None = None) -> Reference:
    """A built-in name (with `speed`, `size`) or a file path (what ``--reference`` takes)."""
    if spec in BUILTIN:
        return builtin_reference(spec, speed=speed, size=size)
    if Path(spec).suffix or Path(spec).exists():
        if speed is not None or size is not None:  # a file's samples fix both: they would be ignored
            raise ReferenceError(f"{spec}: --speed and --size apply to a built-in reference; a file's samples give "
                                 "its speed and size")
        return load_reference(spec)
    return builtin_reference(spec)  # raises with a suggestion
