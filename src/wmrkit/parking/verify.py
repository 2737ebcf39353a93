"""Exact geometric check of a plan, independent of the planner's formulas: car polygons against the scene (shapely).

The scene (world frame of :mod:`wmrkit.parking.path`): the front obstacle ``x >= 0``, the rear one
``x <= -H`` (both between the curb and the side line ``y = 0``), and the curb ``y <= -J``. The car's rectangle is
placed at P_f's poses sampled so densely that no corner moves more than `corner_step` between samples (the
swept area between two samples then lies within ``corner_step^2 / (8 r)`` of their union, r the corner's radius).
Touching is allowed; a collision is an overlap deeper than `tol`. By default both are in units of the car's size
``max(a1 + b1, c1)`` (:data:`CORNER_STEP`, :data:`TOL`: 2 mm and 0.1 um for example 1's 2 m car), and so are the
obstacles' depths: in metres, a 2 mm car was checked at 7 poses and its path cutting 50 um into the front car was
"collision-free". Needs the ``parking`` extra (shapely).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .._shapes import as_vectors
from ..errors import ShapeError, WmrkitError
from ..wheels import wrap_angle
from .geometry import Space, Vehicle, footprint
from .path import Segment, sample_count, sample_poses

#: Most poses one check tests (about 25 us each here: under a minute). A longer path (a pass of hundreds of
#: metres, a car hundreds of metres long) is refused before anything is allocated: 1e7 poses took over 4 GB.
MAX_CHECK_POSES = 2_000_000
#: Poses tested at a time (their shapely polygons take about 1 kB each).
CHUNK = 50_000
#: Default largest corner motion between checked poses, and default overlap tolerance, in car sizes.
CORNER_STEP, TOL = 1e-3, 5e-8
#: Depth of the parked cars and of the curb in the scene, in car sizes (20 m and 5 m for example 1).
DEPTH, CURB_DEPTH = 10.0, 2.5


@dataclass(frozen=True, eq=False)
class CollisionReport:
    """Result of :func:`check_plan`: ``poses`` ``(N, 3)`` checked, ``colliding`` ``(N,)`` bool, ``what`` the first
    obstacle hit (``""`` if none), ``min_clearance`` [m] to the obstacles and curb over the motion (0 if touching),
    ``inside`` whether the final footprint lies in the slot."""

    poses: np.ndarray
    colliding: np.ndarray
    what: str
    min_clearance: float
    inside: bool

    @property
    def collision_free(self) -> bool:
        """No pose overlaps an obstacle or the curb."""
        return not bool(self.colliding.any())

    @property
    def n_collisions(self) -> int:
        """Number of sampled poses that overlap something."""
        return int(self.colliding.sum())


def shapely_module():
    """Import shapely, or a :class:`WmrkitError` naming the extra."""
    try:
        import shapely
    except ImportError:  # pragma: no cover - the extra is installed in the test environment
        raise WmrkitError("the 'parking' extra is needed for exact collision checks: "
                          "pip install 'wmrkit[parking]'") from None
    return shapely


def scene(space: Space, depth: float = 20.0, curb_depth: float = 5.0) -> dict[str, object]:
    """The obstacles as shapely polygons: ``front``, ``rear`` (parked cars `depth` long) and ``curb`` (`curb_depth`
    deep) [m]."""
    shapely = shapely_module()
    H, J = space.H, space.J
    return {"front": shapely.box(0.0, -J, depth, 0.0), "rear": shapely.box(-H - depth, -J, -H, 0.0),
            "curb": shapely.box(-H - depth, -J - curb_depth, depth, -J)}


def _unit(vehicle: Vehicle) -> float:
    """The car's size ``max(a1 + b1, c1)`` [m], the unit of the defaults."""
    return max(vehicle.length, vehicle.c1)


def footprints(vehicle: Vehicle, poses: np.ndarray):
    """Car rectangles at P_f's poses ``(N, 3)``: an array of N shapely polygons."""
    shapely = shapely_module()
    corners = np.array(footprint(vehicle))  # (4, 2) in the vehicle frame
    c, s = np.cos(poses[:, 2]), np.sin(poses[:, 2])
    x = poses[:, None, 0] + c[:, None] * corners[:, 0] - s[:, None] * corners[:, 1]
    y = poses[:, None, 1] + s[:, None] * corners[:, 0] + c[:, None] * corners[:, 1]
    return shapely.polygons(np.stack([x, y], axis=-1))


def _corner_reach(vehicle: Vehicle) -> float:
    """The largest distance [m] from P_f to a corner of the car's body: a corner moves at most this much per
    radian turned."""
    return math.hypot(max(vehicle.a1, vehicle.b1), vehicle.c1 / 2)


def dense_poses(vehicle: Vehicle, segments: tuple[Segment, ...] | list[Segment],
                corner_step: float | None = None) -> np.ndarray:
    """P_f's poses along the path with no body corner moving more than `corner_step` [m] (default
    :data:`CORNER_STEP` car sizes) between samples."""
    corner_step = CORNER_STEP * _unit(vehicle) if corner_step is None else corner_step
    reach = _corner_reach(vehicle)
    steps = [corner_step / (1 + reach * abs(seg.curvature)) for seg in segments]  # corner speed / P_f speed
    check_count(1 + sum(sample_count(seg.length, step, None) for seg, step in zip(segments, steps, strict=True)),
                 corner_step)
    chunks = []
    for k, (seg, step) in enumerate(zip(segments, steps, strict=True)):
        chunk = sample_poses([seg], step, cap=None)  # no per-segment cap: a 1 km pass was checked every 5 mm
        chunks.append(chunk if k == 0 else chunk[1:])
    return np.concatenate(chunks) if chunks else np.zeros((0, 3))


def densify(vehicle: Vehicle, poses: np.ndarray, corner_step: float | None = None) -> np.ndarray:
    """P_f's `poses` ``(N, 3)`` (an executed path) with poses interpolated linearly between neighbours so that no
    body corner moves more than `corner_step` [m] (default :data:`CORNER_STEP` car sizes) between samples. Between
    samples the motion is taken as the chord: within ``ds^2 kappa / 8`` of the arc (0.06 mm for 2.5 cm steps on a
    1.4 m radius)."""
    corner_step = CORNER_STEP * _unit(vehicle) if corner_step is None else corner_step
    poses = _pose_rows(poses)
    if len(poses) < 2:
        return poses
    step = np.diff(poses, axis=0)
    step[:, 2] = wrap_angle(step[:, 2])  # the short way round
    moved = np.hypot(step[:, 0], step[:, 1]) + _corner_reach(vehicle) * np.abs(step[:, 2])  # a corner's bound
    parts = np.maximum(1, np.ceil(moved / corner_step))
    check_count(1 + float(parts.sum()), corner_step)
    parts = parts.astype(int)
    k = np.repeat(np.arange(len(step)), parts)
    frac = (np.arange(len(k)) - np.repeat(np.cumsum(parts) - parts, parts)) / np.repeat(parts, parts)
    return np.concatenate([poses[k] + frac[:, None] * step[k], poses[-1:]])


def _pose_rows(poses: np.ndarray) -> np.ndarray:
    """`poses` as finite ``(N, 3)`` rows ``(x, y, theta)`` (one pose ``(3,)`` is one row), or :class:`ShapeError`:
    ``(N, 2)`` positions were reshaped into other poses (six points read as four poses mixing x, y and theta),
    and NaN raised a GEOS traceback."""
    rows = as_vectors(poses, 3, "poses")
    rows = rows[None] if rows.ndim == 1 else rows
    if rows.ndim != 2:
        raise ShapeError(f"poses: expected shape (N, 3), rows (x, y, theta) of P_f, got {rows.shape}")
    if not np.isfinite(rows).all():
        raise ShapeError(f"poses: row {int(np.argmax(~np.isfinite(rows).all(axis=1)))} is not finite")
    return rows


def check_count(n: float, corner_step: float | None = None) -> None:
    """Refuse a check of more than :data:`MAX_CHECK_POSES` poses, before they are made."""
    if n > MAX_CHECK_POSES:
        spacing = "" if corner_step is None else f" (no corner moving more than {corner_step:.3g} m between them)"
        raise WmrkitError(f"the exact check would test {n:.3g} poses{spacing}, at most {MAX_CHECK_POSES}: the path "
                          "is too long to check; plan a shorter one (a pass nearer the parked cars, a smaller car)")


def check_plan(vehicle: Vehicle, space: Space, segments: tuple[Segment, ...] | list[Segment], *,
               corner_step: float | None = None, tol: float | None = None) -> CollisionReport:
    """Check every pose of `segments` against the scene of `space` with exact polygon tests (shapely); the
    defaults of `corner_step` and `tol` [m] are :data:`CORNER_STEP` and :data:`TOL` car sizes."""
    return check_poses(vehicle, space, dense_poses(vehicle, segments, corner_step), tol=tol)


def check_poses(vehicle: Vehicle, space: Space, poses: np.ndarray, *, tol: float | None = None) -> CollisionReport:
    """Check P_f's `poses` ``(N, 3)`` (any planner's, sampled densely by the caller) against the scene; an overlap
    deeper than `tol` [m] (default :data:`TOL` car sizes) is a collision."""
    shapely = shapely_module()
    unit = _unit(vehicle)
    tol = TOL * unit if tol is None else tol
    poses = _pose_rows(poses)
    check_count(len(poses))
    obstacles = {name: (ob, ob.buffer(-tol, join_style="mitre"))
                 for name, ob in scene(space, DEPTH * unit, CURB_DEPTH * unit).items()}
    colliding = np.zeros(len(poses), dtype=bool)
    hit_any = dict.fromkeys(obstacles, False)
    clearance = math.inf
    for lo in range(0, len(poses), CHUNK):  # bounded memory: CHUNK polygons at a time
        cars = footprints(vehicle, poses[lo:lo + CHUNK])
        for name, (obstacle, core) in obstacles.items():
            hit = shapely.intersects(cars, core)
            hit_any[name] |= bool(hit.any())
            colliding[lo:lo + CHUNK] |= hit
            clearance = min(clearance, float(np.min(shapely.distance(cars, obstacle))))
    what = next((name for name, hit in hit_any.items() if hit), "")  # the first obstacle of the scene hit
    inside = False
    if len(poses):
        slot = shapely.box(-space.H, -space.J, 0.0, 0.0).buffer(tol, join_style="mitre")
        inside = bool(shapely.within(footprints(vehicle, poses[-1:])[0], slot))
    return CollisionReport(poses, colliding, what, clearance, inside)
