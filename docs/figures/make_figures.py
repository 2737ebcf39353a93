"""Regenerate every figure of the docs: ``python docs/figures/make_figures.py`` (from the repository root or anywhere).

Writes ``docs/figures/wheel-parameters.png`` and ``.svg`` (the thesis's wheel parameters, eq. 3.8 and Fig. 3.4)
and ``docs/figures/catalog/NAME.png`` for every catalog robot (``wmrkit.plotting.save_robot_figure``).
Only matplotlib's object API is used, so no display is needed.
"""

from __future__ import annotations

import math
from pathlib import Path

import matplotlib
import numpy as np
from matplotlib.figure import Figure
from matplotlib.patches import Arc, FancyArrowPatch, Polygon

from wmrkit import catalog
from wmrkit.plotting import save_robot_figure

HERE = Path(__file__).resolve().parent
RED, GREEN, BLUE, GREY, INK = "#d62728", "#2ca02c", "#1f77b4", "#777777", "#222222"


def unit(angle: float) -> np.ndarray:
    """The unit vector at `angle` [rad] from the x axis."""
    return np.array([math.cos(angle), math.sin(angle)])


def arrow(ax, start, vec, color, label=None, *, lw=2.0, offset=(0.0, 0.0), fontsize=12, style="-|>"):
    """An arrow from `start` along `vec`, with an optional label past its tip."""
    start, vec = np.asarray(start, float), np.asarray(vec, float)
    ax.add_patch(FancyArrowPatch(start, start + vec, arrowstyle=style, mutation_scale=16, color=color, lw=lw,
                                 zorder=6, shrinkA=0, shrinkB=0))
    if label:
        tip = start + vec * (1 + 0.16 / np.hypot(*vec)) + np.asarray(offset)
        ax.text(*tip, label, color=color, fontsize=fontsize, ha="center", va="center", zorder=7)


def angle_mark(ax, centre, radius, start, stop, label, color=INK, *, label_radius=None):
    """An arc from angle `start` to `stop` [rad] about `centre`, labelled at its middle."""
    a0, a1 = sorted((math.degrees(start), math.degrees(stop)))
    ax.add_patch(Arc(centre, 2 * radius, 2 * radius, theta1=a0, theta2=a1, color=color, lw=1.3, zorder=5))
    tip = np.asarray(centre) + unit(stop) * radius
    direction = unit(stop + (math.pi / 2 if stop > start else -math.pi / 2))
    ax.add_patch(FancyArrowPatch(tip - 0.02 * direction, tip, arrowstyle="-|>", mutation_scale=10, color=color,
                                 lw=1.0, zorder=5, shrinkA=0, shrinkB=0))
    where = np.asarray(centre) + unit((start + stop) / 2) * (label_radius or radius + 0.07)
    ax.text(*where, label, fontsize=13, color=color, ha="center", va="center", zorder=7)


def dashed(ax, start, vec, color=GREY):
    """A thin dashed reference line."""
    pts = np.array([start, np.asarray(start) + np.asarray(vec)])
    ax.plot(pts[:, 0], pts[:, 1], linestyle=(0, (4, 3)), color=color, lw=1.0, zorder=2)


def wheel_parameters_figure() -> Figure:
    """The generic wheel of thesis Fig. 3.4 / eq. (3.8) seen from above, with every parameter and the spin sign."""
    l, alpha, beta, d = 1.5, math.radians(20), math.radians(45), 0.55
    delta, gamma, r = math.radians(25), math.radians(55), 0.22
    fig = Figure(figsize=(10, 7.4), dpi=100)
    ax = fig.add_axes((0.0, 0.17, 0.68, 0.76))
    ax.set_aspect("equal")
    ax.axis("off")
    origin = np.zeros(2)
    joint = l * unit(alpha)
    s_x, s_y = unit(beta), unit(beta + math.pi / 2)
    centre = joint + d * s_y
    axle_angle = beta + delta
    l_x, l_y = unit(axle_angle), unit(axle_angle + math.pi / 2)
    e_angle = axle_angle + gamma

    # robot frame R and the polar coordinates (l, alpha) of the steering joint
    arrow(ax, origin, 0.45 * unit(0), RED, r"$X_R$")
    arrow(ax, origin, 0.45 * unit(math.pi / 2), GREEN, r"$Y_R$")
    ax.plot(*origin, "o", color=INK, ms=5, zorder=7)
    ax.text(-0.05, -0.05, "$R$", fontsize=14, ha="right", va="top")
    dashed(ax, origin, joint, INK)
    ax.text(*(0.6 * joint + 0.07 * unit(alpha - math.pi / 2)), "$l$", fontsize=15, ha="center", va="center")
    angle_mark(ax, origin, 0.42, 0.0, alpha, r"$\alpha$", label_radius=0.52)

    # steering frame S at beta from X_R; castor arm of length d along S_y
    dashed(ax, joint, 0.42 * unit(0))
    arrow(ax, joint, 0.4 * s_x, INK, r"$S_x$", lw=1.4)
    angle_mark(ax, joint, 0.24, 0.0, beta, r"$\beta$", label_radius=0.33)
    ax.plot(*np.array([joint, centre]).T, color=INK, lw=3.5, solid_capstyle="round", zorder=4)
    ax.plot(*joint, "o", ms=11, mfc="white", mec=INK, mew=1.6, zorder=7)
    ax.text(*(0.5 * (joint + centre) + 0.07 * s_x), "$d$ (along $S_y$)", fontsize=13, ha="left", va="bottom")
    ax.annotate("steering joint $S$\n(steering axis $Z_S$)", joint, joint + np.array([0.05, -0.38]),
                fontsize=10.5, ha="left", arrowprops={"arrowstyle": "-", "color": GREY, "lw": 0.8})

    # wheel L: axle L_x at delta from S_x; rolling direction L_y; length 2r; contact rollers at gamma
    corners = np.array([centre + a * r * l_y + b * 0.06 * l_x for a, b in ((1, 1), (-1, 1), (-1, -1), (1, -1))])
    ax.add_patch(Polygon(corners, closed=True, facecolor="#f7f7f7", edgecolor=INK, lw=1.5, zorder=3))
    for t in np.linspace(-0.72 * r, 0.72 * r, 5):
        mid = centre + t * l_y
        seg = np.array([mid - 0.05 * unit(e_angle), mid + 0.05 * unit(e_angle)])
        ax.plot(*seg.T, color="#9467bd", lw=1.6, zorder=4)
    ax.plot(*np.array([centre - 0.1 * l_x, centre + 0.65 * l_x]).T, linestyle="-.", color=GREY, lw=1, zorder=2)
    dashed(ax, centre, 0.55 * s_x)
    arrow(ax, centre, 0.58 * l_x, BLUE, r"$L_x$ (axle)", lw=1.8, offset=(0.05, 0.02))
    arrow(ax, centre, 0.42 * l_y, BLUE, r"$L_y$", lw=1.4, offset=(-0.02, -0.04))
    angle_mark(ax, centre, 0.48, beta, axle_angle, r"$\delta$", BLUE, label_radius=0.56)
    arrow(ax, centre, 0.42 * unit(e_angle), "#9467bd", r"$E_x$", lw=1.6)
    angle_mark(ax, centre, 0.27, axle_angle, e_angle, r"$\gamma$", "#9467bd", label_radius=0.34)
    side = centre - 0.17 * l_x
    ax.add_patch(FancyArrowPatch(side - r * l_y, side + r * l_y, arrowstyle="<->", mutation_scale=10, lw=1,
                                 color=INK, zorder=5, shrinkA=0, shrinkB=0))
    ax.text(*(side - 0.07 * l_x), "$2r$", fontsize=12, ha="center", va="center")
    ax.set_xlim(-0.3, 2.0)
    ax.set_ylim(-0.2, 1.65)
    fig.suptitle("Wheel parameters (thesis eq. 3.8, Fig. 3.4), seen from above", fontsize=15, fontweight="bold")
    _spin_inset(fig.add_axes((0.68, 0.2, 0.3, 0.68)))
    fig.text(0.03, 0.02, (
        "$(l, \\alpha)$: steering joint (or mount point) in polar coordinates of $R$.\n"
        "$\\beta$: absolute angle of $S_x$ from $X_R$; for fixed, steerable and Swedish wheels it is the axle.\n"
        "$d$: castor offset along $S_y$ to the wheel centre.   $\\delta$: from $S_x$ to the axle $L_x$ "
        "(axle at $\\beta + \\delta$).\n"
        "$\\gamma$: from the axle to the axis $E_x$ of the roller touching the ground (omni 90°, Mecanum ±45°).   "
        "$r$, $r_r$: wheel and roller radii.\n"
        "Double wheel / double castor: two sub-wheels at $\\pm b$ along the common axle (double wheel: $d = 0$)."),
        fontsize=10.5, va="bottom", linespacing=1.55)
    return fig


def _spin_inset(ax) -> None:
    """The spin sign: right-hand rule about L_x; with no slip the robot moves along -L_y."""
    ax.set_aspect("equal")
    ax.axis("off")
    r = 0.35
    ax.add_patch(Polygon([(-0.08, -r), (0.08, -r), (0.08, r), (-0.08, r)], closed=True, facecolor="#f7f7f7",
                         edgecolor=INK, lw=1.5))
    ax.plot([-0.3, 0.75], [0, 0], linestyle="-.", color=GREY, lw=1)
    arrow(ax, (0, 0), (0.55, 0), BLUE, r"$L_x$", lw=1.8, offset=(0.04, 0.0))
    arrow(ax, (0, 0), (0, 0.55), BLUE, r"$L_y$", lw=1.4, offset=(0.0, 0.02))
    ax.text(0.3, 0.05, r"$\dot\varphi > 0$", fontsize=13, ha="left", va="bottom")
    arrow(ax, (-0.2, -0.1), (0, 0.35), "#8c564b", None, lw=1.6)
    ax.text(-0.25, 0.1, "contact point,\nrelative\nto the axle", color="#8c564b", fontsize=9.5, ha="right",
            va="center")
    arrow(ax, (0.2, -0.12), (0, -0.45), GREEN, None, lw=2.4)
    ax.text(0.25, -0.38, "robot", color=GREEN, fontsize=11, ha="left", va="center")
    ax.set_xlim(-0.85, 0.85)
    ax.set_ylim(-1.25, 0.75)
    ax.set_title("spin sign", fontsize=12, fontweight="bold")
    ax.text(0.02, 0.02, "right-hand rule about the axle $L_x$: the\ncontact point is pushed along $+L_y$, so\n"
            "without slip the robot moves along $-L_y$.\nAxle along $+y$ ($\\beta$ = 90°): "
            "$\\dot\\varphi > 0$ drives $+x$.", transform=ax.transAxes, fontsize=10, va="bottom", ha="left")


def heading_figure() -> Figure:
    """Heading (users' steering angle) against the thesis's β: a centred steerable wheel and a castor, from above."""
    fig = Figure(figsize=(10, 4.6))
    cases = (("centred steerable wheel", 0.0, 0.0), ("castor (offset d, δ = 0)", 0.5, 0.0))
    for k, (title, d, delta) in enumerate(cases):
        ax = fig.add_subplot(1, 2, k + 1)
        heading = math.radians(35)
        beta = heading - delta + math.pi / 2
        joint = np.zeros(2)
        centre = joint + d * unit(beta + math.pi / 2)  # the wheel centre is d along S_y (thesis 3.8)
        dashed(ax, centre - unit(0) * 0.2, unit(0) * 1.6)
        ax.text(centre[0] + 1.4, centre[1] - 0.08, "x (forward)", color=GREY, fontsize=10, ha="right")
        axle = unit(beta + delta)
        body = np.array([centre + 0.35 * unit(heading) + 0.09 * axle, centre + 0.35 * unit(heading) - 0.09 * axle,
                         centre - 0.35 * unit(heading) - 0.09 * axle, centre - 0.35 * unit(heading) + 0.09 * axle])
        ax.add_patch(Polygon(body, closed=True, facecolor="#dddddd", edgecolor=INK, lw=1.5, zorder=3))
        if d:
            ax.plot(*np.array([joint, centre]).T, color=INK, lw=2.5, zorder=4)
            ax.plot(*joint, "o", color=INK, ms=6, zorder=6)
            ax.text(*(joint + np.array([0.06, 0.08])), "steering joint", fontsize=10)
        arrow(ax, centre, 0.55 * axle, BLUE, "axle: β + δ", offset=(0.0, 0.12))
        arrow(ax, centre, 0.9 * unit(heading), RED, "heading", offset=(0.15, 0.05))
        angle_mark(ax, centre, 0.6, 0.0, heading, "heading", RED, label_radius=0.75)
        angle_mark(ax, centre, 0.3, 0.0, beta + delta, "β", BLUE, label_radius=0.2)
        ax.set_title(title)
        ax.set_aspect("equal")
        ax.set_xlim(-0.9, 1.5)
        ax.set_ylim(-1.0, 1.1)
        ax.axis("off")
    fig.suptitle("heading = β + δ − 90°: the direction the wheel rolls when it spins forward (0 = straight ahead)")
    fig.tight_layout()
    return fig


def main() -> None:
    """Write every figure."""
    with matplotlib.rc_context({"svg.hashsalt": "wmrkit", "svg.fonttype": "none"}):
        fig = wheel_parameters_figure()
        fig.savefig(HERE / "wheel-parameters.png", dpi=100)
        fig.savefig(HERE / "wheel-parameters.svg", metadata={"Date": None})
        heading_figure().savefig(HERE / "heading.png", dpi=100)
    out = HERE / "catalog"
    out.mkdir(exist_ok=True)
    for name in catalog.names():
        save_robot_figure(catalog.load(name), out / f"{name}.png")
    print(f"wrote {HERE / 'wheel-parameters.png'}, .svg and {len(catalog.names())} drawings in {out}")


if __name__ == "__main__":
    main()
