"""Drawings of a robot seen from above: body, wheels, axles, rollers, castor arms, joints, frame.

Every wheel is drawn from its contact elements (:meth:`wmrkit.Wheel.elements`, thesis eq. 3.8): an element's
wheel centre is the steering joint ``(l cos(alpha), l sin(alpha))`` plus ``d`` along the steering frame's S_y
axis ``(-sin(beta), cos(beta))``; its axle is at ``beta + delta`` and its contact rollers at
``beta + delta + gamma``. So castors, double wheels and double castors need no special geometry. Only
matplotlib's object API is used (no pyplot, no GUI backend, no global state).
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.patches import FancyArrow, Patch, Polygon
from numpy.typing import ArrayLike
from scipy.spatial import ConvexHull

from .._shapes import as_vectors
from ..errors import ShapeError
from ..robot import Robot
from ..wheels import Wheel
from .files import PlotError, check_figure_path, spread_indices

DRIVEN = "#f28e2b"  # actuated spin: orange wheel
PASSIVE = "#e6e6e6"  # passive wheel: light grey
SENSOR = "#1f77b4"  # sensed joint: blue mark
BODY = "#c9d6e3"
INK = "#222222"
ROLLED_TYPES = ("swedish", "ball", "orthogonal")
ARMED_TYPES = ("castor", "double_castor")


@dataclass(frozen=True)
class ElementGeometry:
    """One contact element of a wheel at one configuration, in robot coordinates [m]."""

    joint: np.ndarray  # (2,) steering joint / mount point
    centre: np.ndarray  # (2,) wheel centre (above the contact point)
    axle: float  # rad, direction of the axle
    roller: float | None  # rad, direction of the contact rollers' axes (None: no rollers)
    r: float
    spin_joint: str  # the wheel joint that spins this element ("spin", "spin1", "spin2")


def element_geometry(wheel: Wheel, beta: float) -> list[ElementGeometry]:
    """Where each contact element of `wheel` is drawn at steering angle `beta` (3.8), in robot coordinates."""
    joints = ("spin1", "spin2") if wheel.type in ("double", "double_castor") else ("spin", "spin")
    out = []
    for e, spin in zip(wheel.elements(), joints, strict=False):
        joint = np.array([e.l * math.cos(e.alpha), e.l * math.sin(e.alpha)])
        s_frame = beta + e.beta_offset
        centre = joint + e.d * np.array([-math.sin(s_frame), math.cos(s_frame)])
        axle = s_frame + e.delta
        roller = axle + e.gamma if wheel.type in ROLLED_TYPES else None
        out.append(ElementGeometry(joint, centre, axle, roller, e.r, spin))
    return out


#: Most steering configurations drawn over each other (about 10 ms each: 1000 took 9 s); more are thinned evenly,
#: the first (drawn in full) and the last kept.
MAX_CONFIGURATIONS = 200


def _configurations(robot: Robot, beta: ArrayLike | None, what: str = "beta") -> np.ndarray:
    """Steering configurations to draw, ``(n_configs, n_steer)``; the described one when `beta` is None. `what`:
    the keyword the caller gave (``heading`` is converted to `beta` before)."""
    n = len(robot.steer_names)
    if beta is None:
        return robot.beta.reshape(1, n)
    b = as_vectors(beta, n, "beta")
    if n == 0:
        return np.zeros((1, 0))
    if b.size == 0:
        raise ShapeError(f"{what}: no configuration to draw, got shape {b.shape}")
    b = b.reshape(-1, n)
    return b[spread_indices(len(b), MAX_CONFIGURATIONS)]


def _wheel_betas(robot: Robot, config: np.ndarray) -> list[float]:
    it = iter(config.tolist())
    return [next(it) if w.kind.steers else w.beta for w in robot.wheels]


def _size(robot: Robot, elements: list[list[ElementGeometry]]) -> float:
    """A length scale of the drawing [m]: the extent of the wheel layout, at least a few wheel radii."""
    pts = np.array([p for els in elements for e in els for p in (e.joint, e.centre)])
    extent = float(np.max(np.ptp(pts, axis=0)))
    r_max = max(w.r for w in robot.wheels)
    return max(extent, 4 * r_max)


def footprint(robot: Robot, *, origin: bool = False) -> np.ndarray:
    """Outline of the robot's body in its frame [m] for an animation: the wheels' mount points (and the origin,
    the tracked point, with `origin`) in order of angle about their centroid, so that its polygon does not cross
    itself (in description order a four-wheel robot drew a bow-tie). ``(k, 2)``."""
    pts = np.array([w.position for w in robot.wheels] + ([(0.0, 0.0)] if origin else []))
    centre = pts.mean(axis=0)
    return pts[np.argsort(np.arctan2(pts[:, 1] - centre[1], pts[:, 0] - centre[0]))]


def _rounded_hull(points: np.ndarray, pad: float) -> np.ndarray:
    """Convex hull of discs of radius `pad` around `points`, as a closed polygon ``(n, 2)``."""
    t = np.linspace(0, 2 * np.pi, 48, endpoint=False)
    disc = pad * np.stack([np.cos(t), np.sin(t)], axis=-1)
    cloud = (points[:, None, :] + disc[None]).reshape(-1, 2)
    return cloud[ConvexHull(cloud).vertices]


def _rect(centre: np.ndarray, along: np.ndarray, across: np.ndarray, half_len: float, half_w: float) -> np.ndarray:
    return np.array([centre + sa * half_len * along + sc * half_w * across
                     for sa, sc in ((1, 1), (-1, 1), (-1, -1), (1, -1))])


def _draw_element(ax: Axes, wheel: Wheel, e: ElementGeometry, width: float, alpha: float) -> list[np.ndarray]:
    """Draw one wheel element; return the points it covers (for the limits)."""
    axle = np.array([math.cos(e.axle), math.sin(e.axle)])
    roll = np.array([-axle[1], axle[0]])
    face = DRIVEN if e.spin_joint in wheel.actuated else PASSIVE
    edge, lw = (SENSOR, 2.4) if e.spin_joint in wheel.sensed else (INK, 1.2)
    # axle: thin dash-dot line through the wheel centre
    reach = width / 2 + 0.9 * e.r
    ends = np.array([e.centre - reach * axle, e.centre + reach * axle])
    ax.plot(ends[:, 0], ends[:, 1], linestyle="-.", linewidth=0.8, color="#555555", alpha=alpha, zorder=3)
    if wheel.type == "ball":
        ax.add_patch(Polygon(_circle(e.centre, e.r), closed=True, facecolor=face, edgecolor=edge,
                             linewidth=lw, alpha=alpha, zorder=4))
        corners = _circle(e.centre, e.r)
    else:
        corners = _rect(e.centre, roll, axle, e.r, width / 2)
        ax.add_patch(Polygon(corners, closed=True, facecolor=face, edgecolor=edge, linewidth=lw,
                             alpha=alpha, zorder=4, joinstyle="round"))
    if e.roller is not None:
        _draw_rollers(ax, e, axle, roll, width, alpha)
    return [corners, ends]


def _circle(centre: np.ndarray, radius: float) -> np.ndarray:
    t = np.linspace(0, 2 * np.pi, 40, endpoint=False)
    return centre + radius * np.stack([np.cos(t), np.sin(t)], axis=-1)


def _draw_rollers(ax: Axes, e: ElementGeometry, axle: np.ndarray, roll: np.ndarray, width: float, alpha: float) -> None:
    """Short strokes along the contact rollers' axes (at gamma from the axle), spread along the wheel."""
    rel = e.roller - e.axle
    direction = math.cos(rel) * axle + math.sin(rel) * roll
    c, s = abs(math.cos(rel)), abs(math.sin(rel))
    along = 0.3 if c > 0.2 else 0.12  # slanted (Mecanum) rollers cross the tyre; omni rollers are short dashes
    half = min(0.45 * width / c if c > 1e-9 else np.inf, along * e.r / s if s > 1e-9 else np.inf)
    span = e.r - half * s - 0.08 * e.r
    for t in np.linspace(-span, span, 4):
        mid = e.centre + t * roll
        seg = np.array([mid - half * direction, mid + half * direction])
        ax.plot(seg[:, 0], seg[:, 1], color=INK, linewidth=1.3, alpha=alpha, solid_capstyle="round", zorder=5)


def _draw_joint(ax: Axes, wheel: Wheel, els: list[ElementGeometry], alpha: float) -> list[np.ndarray]:
    """Steering arm(s) and the steering joint of a wheel that steers."""
    joint = els[0].joint
    pts = [joint[None]]
    if wheel.type in ARMED_TYPES:
        mid = np.mean([e.centre for e in els], axis=0)
        arm = np.array([joint, mid])
        ax.plot(arm[:, 0], arm[:, 1], color=INK, linewidth=2.2, alpha=alpha, solid_capstyle="round", zorder=5)
        pts.append(arm)
    if len(els) == 2:  # the bar joining the two sub-wheels of a double wheel or double castor
        bar = np.array([els[0].centre, els[1].centre])
        ax.plot(bar[:, 0], bar[:, 1], color=INK, linewidth=2.2, alpha=alpha, solid_capstyle="round", zorder=5)
    steer_driven = "steer" in wheel.actuated
    ax.plot(*joint, marker="s" if steer_driven else "o", markersize=8 if steer_driven else 7,
            markerfacecolor=DRIVEN if steer_driven else "white", markeredgecolor=INK, markeredgewidth=1.2,
            alpha=alpha, zorder=10)
    if "steer" in wheel.sensed:
        ax.plot(*joint, marker="o", markersize=13, markerfacecolor="none", markeredgecolor=SENSOR,
                markeredgewidth=1.6, alpha=alpha, zorder=10)
    return pts


def _draw_frame(ax: Axes, scale: float) -> list[np.ndarray]:
    """Robot frame at the origin: x red, y green, labelled."""
    length = 0.16 * scale
    head = 0.22 * length
    for (dx, dy), color, label in (((1, 0), "#d62728", "x"), ((0, 1), "#2ca02c", "y")):
        ax.add_patch(FancyArrow(0, 0, dx * length, dy * length, width=0.012 * length * 4, head_width=head,
                                head_length=head, length_includes_head=True, color=color, zorder=8))
        ax.text(dx * (length + 0.5 * head) + (dy * 0.35 * head), dy * (length + 0.5 * head) - dx * 0.35 * head,
                label, color=color, fontsize=11, fontweight="bold", ha="center", va="center", zorder=9)
    ax.plot(0, 0, marker="o", markersize=4, color=INK, zorder=9)
    return [np.array([[0, 0], [length + head, 0], [0, length + head]])]


def draw_robot(robot: Robot, ax: Axes | None = None, *, beta: ArrayLike | None = None,
               labels: bool = True, heading: ArrayLike | None = None) -> Axes:
    """Draw `robot` seen from above (x right, y up) and return the Axes.

    ``beta``: steering configuration ``(..., n_steer)`` [rad] (``Robot.steer_names`` order); default the
    described one. With several configurations (leading batch axes) the first is drawn in full and the others'
    steering wheels faintly over it, e.g. to show a steering sweep (at most :data:`MAX_CONFIGURATIONS`, evenly).
    Orange wheels and square joints are actuated, blue dots and rings are sensed joints; see the legend.
    ``labels=False`` leaves out wheel names, title and legend. Without `ax`, a new figure 800 px wide is sized
    to the robot's shape. ``heading``: the steering as headings instead of `beta` (0 = rolling straight ahead).
    """
    configs = _configurations(robot, robot.steering(beta, heading), "heading" if heading is not None else "beta")
    own = ax is None
    if ax is None:
        ax = Figure(figsize=(8, 8), dpi=100).add_subplot()
    per_config = [[element_geometry(w, b) for w, b in zip(robot.wheels, _wheel_betas(robot, c), strict=True)]
                  for c in configs]
    first = per_config[0]
    scale = _size(robot, first)
    r_mean = float(np.mean([w.r for w in robot.wheels]))
    width = float(np.clip(0.5 * r_mean, 0.03 * scale, 0.07 * scale))
    covered: list[np.ndarray] = []

    mounts = np.array([p for els in first for e in els for p in (e.joint, e.centre)])
    body = _rounded_hull(mounts, pad=0.6 * max(w.r for w in robot.wheels) + 0.04 * scale)
    ax.add_patch(Polygon(body, closed=True, facecolor=BODY, edgecolor="#6b7f94", linewidth=1.5, alpha=0.55,
                         zorder=1))
    covered.append(body)

    for k, elements in reversed(list(enumerate(per_config))):  # the first configuration is drawn last, on top
        alpha = 1.0 if k == 0 else 0.3
        for wheel, els in zip(robot.wheels, elements, strict=True):
            if k > 0 and not wheel.kind.steers:
                continue
            for e in els:
                covered += _draw_element(ax, wheel, e, width, alpha)
            if wheel.kind.steers:
                covered += _draw_joint(ax, wheel, els, alpha)
    covered += _draw_frame(ax, scale)
    if labels:
        centroid = mounts.mean(axis=0)
        for wheel, els in zip(robot.wheels, first, strict=True):
            covered.append(_label(ax, wheel, els, centroid, width, scale))
        ax.set_title(robot.name, fontsize=14, fontweight="bold")
    lo, hi = _set_limits(ax, np.concatenate(covered), scale)
    legend_rows = _legend(ax, robot, outside=own) if labels else 0
    if own:
        _layout(ax, (hi[1] - lo[1]) / (hi[0] - lo[0]), legend_rows)
    return ax


def _layout(ax: Axes, aspect: float, legend_rows: int) -> None:
    """Size our own figure to the drawing: 8 in (800 px) wide, axes of the data's aspect, room for the text."""
    left, right, top = 0.8, 0.25, 0.5  # inches: tick labels and y label, margin, title
    bottom = 0.6 + 0.22 * legend_rows + (0.1 if legend_rows else 0.0)  # x label, then the legend
    width = 8.0 - left - right
    height = width * aspect
    if height > 9.0:  # a tall robot: keep the figure at most ~10.5 in high, centre the axes
        height = 9.0
    drawn_w = height / aspect
    fig_h = bottom + height + top
    fig = ax.figure
    fig.set_size_inches(8.0, fig_h)
    x0 = left + (width - drawn_w) / 2
    ax.set_position((x0 / 8.0, bottom / fig_h, drawn_w / 8.0, height / fig_h))


def _label(ax: Axes, wheel: Wheel, els: list[ElementGeometry], centroid: np.ndarray, width: float,
           scale: float) -> np.ndarray:
    """Wheel name, placed just outside the wheel on the side away from the robot's centroid."""
    centre = np.mean([e.centre for e in els], axis=0)
    out = centre - centroid
    norm = float(np.hypot(*out))
    out = out / norm if norm > 1e-6 * scale else np.array([0.0, -1.0])
    reach = 0.0
    for e in els:  # support function of the wheel outline in the direction `out`
        axle = np.array([math.cos(e.axle), math.sin(e.axle)])
        roll = np.array([-axle[1], axle[0]])
        offset = float(np.dot(e.centre - centre, out))
        outline = e.r * abs(float(roll @ out)) + width / 2 * abs(float(axle @ out))
        axle_end = (width / 2 + 0.9 * e.r) * abs(float(axle @ out)) if abs(float(axle @ out)) > 0.6 else 0.0
        reach = max(reach, offset + max(outline, axle_end))
    where = centre + (reach + 0.025 * scale) * out
    ha = "left" if out[0] > 0.3 else "right" if out[0] < -0.3 else "center"
    va = "bottom" if out[1] > 0.3 else "top" if out[1] < -0.3 else "center"
    ax.text(*where, wheel.name, fontsize=10, ha=ha, va=va, color=INK, zorder=9,
            bbox={"boxstyle": "round,pad=0.15", "facecolor": "white", "edgecolor": "none", "alpha": 0.75})
    # room for the text itself, roughly (10 pt characters on an 800 px wide drawing of the robot's size)
    text_w, text_h = 0.016 * scale * len(wheel.name), 0.035 * scale
    x0 = {"left": 0.0, "right": -text_w, "center": -text_w / 2}[ha]
    y0 = {"bottom": 0.0, "top": -text_h, "center": -text_h / 2}[va]
    return where + np.array([[x0, y0], [x0 + text_w, y0 + text_h]])


def _legend(ax: Axes, robot: Robot, *, outside: bool) -> int:
    """Legend of the marks this robot uses, below the figure (own figure) or in the axes; returns its rows."""
    wheels = robot.wheels
    spins = {"spin", "spin1", "spin2"}
    handles = []
    if any(set(w.actuated) & spins for w in wheels):
        handles.append(Patch(facecolor=DRIVEN, edgecolor=INK, label="driven wheel (spin actuated)"))
    if any(set(w.kind.joints) & spins - set(w.actuated) for w in wheels):
        handles.append(Patch(facecolor=PASSIVE, edgecolor=INK, label="free wheel (spin passive)"))
    if any(set(w.sensed) & spins for w in wheels):
        handles.append(Patch(facecolor="white", edgecolor=SENSOR, linewidth=2.4, label="spin sensed (encoder)"))
    if any("steer" in w.actuated for w in wheels):
        handles.append(Line2D([], [], marker="s", linestyle="none", markerfacecolor=DRIVEN,
                              markeredgecolor=INK, markersize=8, label="steering joint, actuated"))
    if any(w.kind.steers and "steer" not in w.actuated for w in wheels):
        handles.append(Line2D([], [], marker="o", linestyle="none", markerfacecolor="white",
                              markeredgecolor=INK, markersize=7, label="steering joint, free"))
    if any("steer" in w.sensed for w in wheels):
        handles.append(Line2D([], [], marker="o", linestyle="none", markerfacecolor="none",
                              markeredgecolor=SENSOR, markeredgewidth=1.6, markersize=12,
                              label="steering angle sensed"))
    handles.append(Line2D([], [], linestyle="-.", color="#555555", linewidth=0.8, label="axle"))
    if any(w.type in ROLLED_TYPES for w in wheels):
        handles.append(Line2D([], [], color=INK, linewidth=1.3, label="axes of the contact rollers"))
    if outside:
        ax.figure.legend(handles=handles, loc="lower center", bbox_to_anchor=(0.5, 0.0), ncol=3, fontsize=9,
                         frameon=False)
        return -(-len(handles) // 3)
    ax.legend(handles=handles, loc="best", fontsize=8, framealpha=0.8)
    return 0


def _set_limits(ax: Axes, points: np.ndarray, scale: float) -> tuple[np.ndarray, np.ndarray]:
    lo, hi = points.min(axis=0) - 0.06 * scale, points.max(axis=0) + 0.06 * scale
    ax.set_xlim(lo[0], hi[0])
    ax.set_ylim(lo[1], hi[1])
    ax.set_aspect("equal", adjustable="box")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.grid(True, linewidth=0.4, alpha=0.4)
    ax.set_axisbelow(True)
    return lo, hi


def save_robot_figure(robot: Robot, path: str | os.PathLike[str], *, beta: ArrayLike | None = None) -> None:
    """Draw `robot` (see :func:`draw_robot`) to a PNG, SVG or PDF file chosen by the extension of `path`."""
    check_figure_path(path)
    path = Path(path)
    ax = draw_robot(robot, beta=beta)
    try:
        ax.figure.savefig(path, dpi=100)
    except OSError as err:
        raise PlotError(f"{path}: cannot write the drawing ({err.strerror or err})") from None
