"""Pictures for the analysis report: the robot with its axles and ICR, sample motions, condition-number maps,
singular configurations drawn as the thesis draws them (Figs. 6.2-6.10: the lines G meeting at one point).

matplotlib's object API only (no pyplot, no GUI backend); every function returns a :class:`Figure`.
"""

from __future__ import annotations

import math

import numpy as np
from matplotlib.figure import Figure

from ..kinematics.linalg import characteristic_length
from ..plotting.robot import draw_robot
from ..robot import Robot
from ..wheels import heading_from_beta
from .classification import Classification
from .icr import (
    coordinate_decimals,
    format_coordinate,
    icr,
    line_rank,
    meeting_point,
    steer_to_icr,
    twist_of_icr,
)
from .isotropy import condition_map, natural_length, twist_condition_number
from .lines import common_point, constraint_lines
from .singularity import SingularSet, robot_size

ICR_COLOR = "#d62728"
LINE_COLORS = ("#9467bd", "#2ca02c", "#8c564b", "#e377c2", "#17becf", "#bcbd22", "#7f7f7f", "#1f77b4")


def _draw_line(ax, lam, **style) -> None:
    """Draw the line ``(lambda_x, lambda_y, d)`` (6.18) across the current view without changing it."""
    lx, ly, d = lam
    n = math.hypot(lx, ly)
    if n < 1e-12:
        return
    lx, ly, d = lx / n, ly / n, d / n
    foot = np.array([d * ly, -d * lx])
    xlim, ylim = ax.get_xlim(), ax.get_ylim()
    big = 10 * (abs(xlim[1] - xlim[0]) + abs(ylim[1] - ylim[0]) + np.hypot(*foot))
    p, q = foot - big * np.array([lx, ly]), foot + big * np.array([lx, ly])
    ax.plot([p[0], q[0]], [p[1], q[1]], **style)
    ax.set_xlim(xlim)
    ax.set_ylim(ylim)


def _include(ax, point, margin: float) -> None:
    """Grow the view (keeping the aspect) to show `point`."""
    xlim, ylim = ax.get_xlim(), ax.get_ylim()
    ax.set_xlim(min(xlim[0], point[0] - margin), max(xlim[1], point[0] + margin))
    ax.set_ylim(min(ylim[0], point[1] - margin), max(ylim[1], point[1] + margin))


def _mark_icr(ax, h: np.ndarray, size: float, label: str = "ICR") -> str:
    """Mark the point `h` (homogeneous) when it is near; else return a note for the title (never text over the
    drawing, where it would cover wheel labels)."""
    x, y, w = h
    if abs(w) > 1e-9 * max(abs(x), abs(y)) and math.hypot(x / w, y / w) < 6 * size:
        p = (x / w, y / w)
        _include(ax, p, 0.25 * size)
        ax.plot(*p, marker="*", markersize=18, color=ICR_COLOR, markeredgecolor="white", zorder=12, label=label)
        return ""
    return f"{label} far away ({'at infinity' if abs(w) < 1e-9 else f'{np.hypot(x / w, y / w):.1f} m'})"


def _heading_ticks(ax, which: str = "x") -> None:
    """Heading axes in degrees with a tick every 90 deg (never crowded)."""
    ticks = [-180, -90, 0, 90, 180]
    (ax.set_xticks if which == "x" else ax.set_yticks)(ticks)
    (ax.set_xlim if which == "x" else ax.set_ylim)(-180, 180)


def _velocity_arrows(ax, robot: Robot, twist: np.ndarray, size: float) -> None:
    """Velocity of every wheel's mount point for a unit twist, scaled to the robot."""
    pts = np.array([w.position for w in robot.wheels])
    v = np.stack([twist[0] - twist[2] * pts[:, 1], twist[1] + twist[2] * pts[:, 0]], axis=-1)
    scale = 0.35 * size / max(np.linalg.norm(v, axis=-1).max(), 1e-12)
    ax.quiver(pts[:, 0], pts[:, 1], v[:, 0] * scale, v[:, 1] * scale, angles="xy", scale_units="xy", scale=1,
              color="#ff7f0e", width=0.006, zorder=11)


def robot_figure(robot: Robot, cls: Classification) -> Figure:
    """The robot at its described configuration with its axles (the constraint lines K_r*) and ICR set (5.9)."""
    fig = Figure(figsize=(9.5, 6.5), dpi=100)
    ax = fig.add_axes((0.08, 0.09, 0.6, 0.82))
    draw_robot(robot, ax)
    legend = ax.get_legend()
    if legend is not None:  # move the drawing's legend beside the axes
        handles = legend.legend_handles
        legend.remove()
        ax.legend(handles=handles, loc="upper left", bbox_to_anchor=(1.02, 1.0), fontsize=8, frameon=False)
    size = robot_size(robot)
    geared = any(c.kind == "gear" for c in robot.couplings)  # the gears' lines too, as analyze's ICR holds them
    for lam in constraint_lines(robot, coupled=geared).lines():
        _draw_line(ax, lam, color="#555555", linestyle="--", linewidth=0.9, zorder=3)
    s = icr(robot, geared=True)
    if s.kind in ("point", "infinity"):
        _mark_icr(ax, s.homogeneous(), size)
    elif s.kind == "line":
        _draw_line(ax, s.line, color=ICR_COLOR, linewidth=2.5, alpha=0.6, zorder=4)
    ax.set_title(f"{robot.name}: {s.describe()}", fontsize=10)
    return fig


def sample_icrs(robot: Robot, cls: Classification) -> list[np.ndarray]:
    """A few admissible homogeneous ICRs: on every axle that does not steer and every line a gear adds (the gears
    held, as analyze's ICR holds them), the steered wheels aimed at them; a sample whose aimed steering turns a
    gear's line off it (a gear on a steered wheel) is left out."""
    if cls.mobility == 0:
        return []
    size = robot_size(robot)
    cl = constraint_lines(robot, coupled=any(c.kind == "gear" for c in robot.couplings))
    fixed = cl.lines()[~np.array(cl.steered, dtype=bool)]
    rank = line_rank(robot, fixed)
    if rank == 3:
        return []
    if rank == 2:
        s = meeting_point(robot, fixed)
        samples = [np.array([*s.point, 1.0]) if s.kind == "point" else np.array([-s.direction[1], s.direction[0], 0.0])]
    elif rank == 1:
        lx, ly, d = fixed[np.argmax(np.linalg.norm(fixed[:, :2], axis=-1))]
        lx, ly, d = np.array([lx, ly, d]) / np.hypot(lx, ly)
        foot, u = np.array([d * ly, -d * lx]), np.array([lx, ly])
        samples = [np.array([*p, 1.0]) for p in (foot, foot + 1.6 * size * u, foot - 3.0 * size * u)]
        samples.append(np.array([lx, ly, 0.0]))
    else:
        samples = [np.array([0.0, 0.0, 1.0]), np.array([1.2 * size, 1.5 * size, 1.0]),
                   np.array([-2.5 * size, 0.8 * size, 1.0]), np.array([1.0, 0.0, 0.0])]
    return [h for h in samples if _holds(robot, cl, h)]


def _holds(robot: Robot, cl, h: np.ndarray) -> bool:
    """Whether the homogeneous ICR `h` [m] lies on every line of `cl` with the steered wheels aimed at it."""
    beta = steer_to_icr(robot, h) if robot.steer_names else robot.beta
    unit = characteristic_length(robot)
    v = np.array([h[1] / unit, -h[0] / unit, h[2]])  # h as a line-space vector (common_point's map), in robot sizes
    lines = cl.lines(beta) * np.array([1.0, 1.0, 1.0 / unit])
    return bool(np.all(np.abs(lines @ (v / np.linalg.norm(v))) < 1e-9))


def motions_figure(robot: Robot, cls: Classification) -> Figure | None:
    """Sample motions: the robot steered for each sample ICR, velocity arrows at the wheels, lines to the ICR."""
    samples = sample_icrs(robot, cls)
    if not samples:
        return None
    size = robot_size(robot)
    decimals = coordinate_decimals(robot) - 1  # cm from 10 cm up, as analyze's ICR text to 10 % of the size
    n = len(samples)
    cols = 2 if n > 1 else 1
    fig = Figure(figsize=(5 * cols, 4.6 * math.ceil(n / cols)), dpi=90, layout="constrained")
    for k, h in enumerate(samples):
        ax = fig.add_subplot(math.ceil(n / cols), cols, k + 1)
        beta = steer_to_icr(robot, h) if robot.steer_names else robot.beta
        draw_robot(robot, ax, beta=beta, labels=False)
        twist = twist_of_icr(h)
        _velocity_arrows(ax, robot, twist, size)
        far = _mark_icr(ax, h, size)
        if abs(h[2]) > 1e-12:
            c = h[:2] / h[2]
            for w in robot.wheels:
                ax.plot([w.position[0], c[0]], [w.position[1], c[1]], color=ICR_COLOR, linewidth=0.6, alpha=0.5)
        c = [format_coordinate(v / h[2], decimals) for v in h[:2]] if abs(h[2]) >= 1e-12 else None
        what = f"turn about ({c[0]}, {c[1]}) m" if c else "translation"
        headings = robot.heading_of_beta(beta)
        steer = ", ".join(f"{n} {round(math.degrees(b)):d}°" for n, b in zip(robot.steer_names, headings, strict=True)
                          if n in set(constraint_lines(robot).wheels))
        what += f"; {far}" if far and abs(h[2]) > 1e-12 else ""
        ax.set_title(what + (f"\nheadings: {steer}" if steer else ""), fontsize=9)
    return fig


def length_figure(robot: Robot, joints: tuple[str, ...]) -> Figure | None:
    """kappa (5.28) against the characteristic length D at the described configuration; natural D marked."""
    d0, k0 = natural_length(robot, joints=joints)
    lengths = d0 * np.logspace(-1.5, 1.5, 121)
    kappa = np.array([float(twist_condition_number(robot, joints=joints, length=d)) for d in lengths])
    if not np.isfinite(kappa).any() or np.nanmax(kappa) - np.nanmin(kappa) < 1e-9:
        return None
    fig = Figure(figsize=(6, 3.6), dpi=100, layout="constrained")
    ax = fig.add_subplot()
    ax.loglog(lengths, kappa, color="#1f77b4")
    ax.plot([d0], [k0], "o", color=ICR_COLOR)
    ax.annotate(f"natural D = {d0:.3g} m, κ = {k0:.3g}", (d0, k0), textcoords="offset points", xytext=(8, 8))
    ax.set_xlabel("characteristic length D [m]")
    ax.set_ylabel("condition number κ")
    ax.set_title(f"κ of ({', '.join(joints)}) ← (v, D·ω)", fontsize=10)
    ax.grid(True, which="both", alpha=0.3)
    return fig


def condition_figure(robot: Robot, joints: tuple[str, ...], length: float, variables: tuple[str, ...],
                     resolution: int) -> Figure | None:
    """Condition-number map over one or two steering angles (others as described); white where undefined."""
    if not variables:
        return None
    idx = [robot.steer_names.index(v) for v in variables[:2]]
    axis = np.linspace(-np.pi, np.pi, resolution + 1)  # headings
    fig = Figure(figsize=(6.4, 4.4), dpi=100, layout="constrained")
    ax = fig.add_subplot()
    if len(idx) == 1:
        heading = np.broadcast_to(robot.heading, (len(axis), len(robot.beta))).copy()
        heading[:, idx[0]] = axis
        kappa = condition_map(robot, robot.beta_of_heading(heading), joints=joints, length=length)
        ax.semilogy(np.degrees(axis), np.where(np.isfinite(kappa), kappa, np.nan), color="#1f77b4")
        ax.axvline(math.degrees(robot.heading[idx[0]]), color="#999999", linestyle=":", label="described")
        _heading_ticks(ax)
        ax.set_xlabel(f"heading of {variables[0]} [deg]")
        ax.set_ylabel("condition number κ")
        ax.legend(loc="upper right", fontsize=8)
    else:
        b1, b2 = np.meshgrid(axis, axis, indexing="ij")
        heading = np.broadcast_to(robot.heading, (*b1.shape, len(robot.beta))).copy()
        heading[..., idx[0]], heading[..., idx[1]] = b1, b2
        kappa = condition_map(robot, robot.beta_of_heading(heading), joints=joints, length=length)
        shown = np.log10(np.clip(np.where(np.isfinite(kappa), kappa, np.nan), 1.0, 1e4))
        mesh = ax.pcolormesh(np.degrees(b1), np.degrees(b2), shown, cmap="viridis_r", shading="auto",
                             vmin=0.0, vmax=max(1.0, float(np.nanmax(shown)) if np.isfinite(shown).any() else 1.0))
        fig.colorbar(mesh, ax=ax, label="log10 κ")
        ax.plot(*np.degrees(robot.heading[idx]), "o", color="white", markeredgecolor="black", label="described")
        _heading_ticks(ax, "x")
        _heading_ticks(ax, "y")
        ax.set_xlabel(f"heading of {variables[0]} [deg]")
        ax.set_ylabel(f"heading of {variables[1]} [deg]")
        ax.legend(loc="upper right", fontsize=8)
    ax.set_title(f"κ of ({', '.join(joints)}) at D = {length:.3g} m", fontsize=10)
    return fig


def singular_figure(robot: Robot, s: SingularSet, title: str) -> Figure | None:
    """A singular configuration drawn with its lines G (6.17) meeting at one point; plus the set's map."""
    if s.never or len(s.assigned) == 0:
        return None
    beta = robot.beta.copy()
    idx = [robot.steer_names.index(v) for v in s.variables]
    if not s.always:  # the singular configuration nearest the described one
        gap = np.abs(np.angle(np.exp(1j * (s.configurations - beta[idx])))).sum(axis=1)
        beta[idx] = s.configurations[int(np.argmin(gap))]
    two = len(s.variables) == 2 and len(s.configurations) > 1
    fig = Figure(figsize=(11 if two else 6.5, 5.6), dpi=90, layout="constrained")
    ax = fig.add_subplot(1, 2 if two else 1, 1)
    draw_robot(robot, ax, beta=beta, labels=False)
    size = robot_size(robot)
    cl = constraint_lines(robot, s.assigned, coupled=s.coupled)
    lines = cl.lines(beta)
    for k, (lam, label) in enumerate(zip(lines, cl.labels, strict=True)):
        _draw_line(ax, lam, color=LINE_COLORS[k % len(LINE_COLORS)], linewidth=1.4, label=label, zorder=4)
    if len(lines) >= 2:
        far = _mark_icr(ax, common_point(lines), size, label="common point")
    else:
        far = ""
    ax.legend(loc="lower left", fontsize=7, framealpha=0.85)
    shown = robot.heading_of_beta(beta)[[robot.steer_names.index(v) for v in s.variables]] if s.variables else []
    where = "heading " + ", ".join(f"{v} {math.degrees(b):.1f}°" for v, b in zip(s.variables, shown, strict=True))
    ax.set_title(f"{title}: {'always singular' if s.always else 'singular at ' + where}"
                 + (f"\n{far}" if far else ""), fontsize=9)
    if two:
        ax2 = fig.add_subplot(1, 2, 2)
        delta = np.array([robot.wheel(v).delta for v in s.variables])
        c = np.degrees(heading_from_beta(s.configurations, delta))
        ax2.plot(c[:, 0], c[:, 1], ".", markersize=3, color=ICR_COLOR)
        _heading_ticks(ax2, "x")
        _heading_ticks(ax2, "y")
        ax2.set_xlabel(f"heading of {s.variables[0]} [deg]")
        ax2.set_ylabel(f"heading of {s.variables[1]} [deg]")
        ax2.plot(*np.degrees(robot.heading[idx]), "o", color="white", markeredgecolor="black", label="described")
        ax2.legend(loc="upper right", fontsize=8)
        ax2.set_title("singular configurations", fontsize=9)
        ax2.grid(True, alpha=0.3)
    return fig
