"""Singular sets of robots whose steering must be coordinated (Ackermann, swerve): over admissible configurations.

With more steered wheels than the type needs, almost every steering configuration leaves the robot unable to
move (§5.3, consequence 3 of 5.12); only configurations with every axle through one ICR matter. They are
parameterised by the ICR itself, a point of the projective plane allowed by the fixed wheels: the fixed axle
(a projective line, one parameter) or the whole plane (two). Each ICR gives the steering by
:func:`~wmrkit.analysis.icr.steer_to_icr`, and the singularity test (6.17) is applied there.
"""

from __future__ import annotations

import functools

import numpy as np
from scipy.optimize import minimize

from ..robot import Robot
from . import _fast
from .classification import classify
from .icr import icr, steer_to_icr
from .lines import constraint_lines, line_parameters
from .singularity import SingularSet, is_singular, robot_size

#: Evaluations of the singularity distance shared by the 2-D searches for isolated singular ICRs of one singular
#: set (up to 6 starts, about 200 evaluations each; the starts left when it is spent are not searched).
MAX_EVALUATIONS = 1200


def admissible_icrs(robot: Robot, resolution: int) -> tuple[np.ndarray, int]:
    """Homogeneous ICRs ``(n, 3)`` allowed by the fixed wheels on a grid, and the number of parameters (1 or 2)."""
    cls, size = classify(robot), robot_size(robot)
    t = np.linspace(-np.pi / 2, np.pi / 2, resolution, endpoint=False)
    if cls.fixed_rank == 1:
        return _on_axle(robot, t), 1
    theta, phi = np.meshgrid(np.linspace(0.0, np.pi / 2, resolution // 4 + 1),
                             np.linspace(-np.pi, np.pi, resolution, endpoint=False), indexing="ij")
    h = np.stack([size * np.sin(theta) * np.cos(phi), size * np.sin(theta) * np.sin(phi), np.cos(theta)], -1)
    return h.reshape(-1, 3), 2


def _on_axle(robot: Robot, t: np.ndarray) -> np.ndarray:
    """Points of the fixed axle, ``foot + size tan(t) u``, as homogeneous ICRs (t = +-pi/2: at infinity)."""
    cl = constraint_lines(robot)
    steer = set(robot.steer_names)
    lam = next(g for g, w in zip(cl.lines(), cl.wheels, strict=True) if w not in steer)
    lx, ly, d = lam / np.hypot(*lam[:2])
    size = robot_size(robot)
    c, s = np.cos(t), np.sin(t)
    return np.stack([c * d * ly + s * size * lx, -c * d * lx + s * size * ly, c], axis=-1)


def coordinated_singular_set(robot: Robot, assigned: tuple[str, ...], *, resolution: int = 90,
                             coupled: bool = False) -> SingularSet:
    """Singular configurations among the coordinated ones (all axles through one ICR) of `robot`.

    One parameter (a fixed axle): minima of the singularity distance along the axle, refined to machine
    precision. Two (no fixed wheel): refined minima along each grid row of ICR directions, points on the
    singular curves. ``configurations`` are steering configurations over all of ``robot.steer_names``.
    `coupled`: through the robot's rate couplings (:func:`wmrkit.analysis.lines.constraint_lines`).
    """
    cl = constraint_lines(robot, assigned, coupled=coupled)
    names = robot.steer_names
    empty = np.zeros((0, len(names)))
    if cl.internal or len(cl.labels) < 3:
        return SingularSet(cl.assigned, names, True, empty, True, ("fewer assigned velocities than the mobility",),
                           coordinated=True, coupled=cl.coupled)
    params, length = line_parameters(robot), float(robot_size(robot))

    def distance_at(beta: np.ndarray) -> np.ndarray:
        """singularity_distance's kernel without its per-call checks (the 2-D searches ask for one ICR at a time)."""
        rows = _fast.element_rows_cm(params, beta)
        return _fast.distance_cm(_fast.combine_lines(cl, rows), length)

    distance = functools.partial(_at_icrs, robot, distance_at, float)
    singular = functools.partial(_at_icrs, robot, functools.partial(is_singular, robot, assigned=cl.assigned,
                                                                    coupled=cl.coupled), bool)
    grid, dims = admissible_icrs(robot, resolution)
    dist = distance(grid)
    if not (dist > 1e-3).any() and singular(grid).all():  # a distance far from 1e-8: regular there
        return SingularSet(cl.assigned, names, True, empty, dims == 1, ("singular at every coordinated steering",),
                           coordinated=True, coupled=cl.coupled)
    rows = dist.reshape(-1, resolution) if dims == 2 else dist[None]
    size, step = robot_size(robot), (np.pi if dims == 1 else 2 * np.pi) / resolution
    thetas = np.linspace(0.0, np.pi / 2, resolution // 4 + 1)
    start = -np.pi / 2 if dims == 1 else -np.pi

    def icr_of(r: np.ndarray, x: np.ndarray) -> np.ndarray:  # grid rows r, parameters x along them -> (n, 3)
        if dims == 1:
            return _on_axle(robot, x)
        th = thetas[r]
        return np.stack([size * np.sin(th) * np.cos(x), size * np.sin(th) * np.sin(x), np.cos(th)], axis=-1)

    is_min = (rows <= np.roll(rows, 1, axis=1)) & (rows <= np.roll(rows, -1, axis=1)) & (rows < 0.2)
    r_idx, i_idx = np.nonzero(is_min)
    x0 = start + i_idx * step
    x = _golden_batch(lambda x: distance(icr_of(r_idx, x)), x0 - 2 * step, x0 + 2 * step)
    minima = icr_of(r_idx, x)
    found = list(steer_to_icr(robot, minima[singular(minima)]).reshape(-1, len(names)))
    if dims == 2 and not found and len(minima):  # an isolated singular ICR (e.g. at a wheel): minimise in 2-D
        d = distance(minima)
        seen: list[np.ndarray] = []
        budget = MAX_EVALUATIONS
        for k in np.argsort(d)[:6]:
            if budget <= 0:
                break

            def g(p):
                h = np.array([size * np.sin(p[0]) * np.cos(p[1]), size * np.sin(p[0]) * np.sin(p[1]), np.cos(p[0])])
                return float(distance(h)[0])

            res = minimize(g, [thetas[r_idx[k]], x[k]], method="Nelder-Mead",
                           options={"xatol": 1e-12, "fatol": 1e-15, "maxiter": 600, "maxfev": budget})
            budget -= res.nfev
            t, ph = res.x
            h = np.array([size * np.sin(t) * np.cos(ph), size * np.sin(t) * np.sin(ph), np.cos(t)])
            if singular(h)[0] and not any(np.linalg.norm(np.cross(h, e)) < 1e-7 for e in seen):
                seen.append(h)
                found.append(steer_to_icr(robot, h))
    out = np.array(found).reshape(-1, len(names))
    if len(out) > 1:
        keep = [0]
        for i in range(1, len(out)):
            if all(np.abs(np.angle(np.exp(1j * (out[i] - out[j])))).max() > 1e-7 for j in keep):
                keep.append(i)
        out = out[keep]
    where = tuple(icr(robot, b).describe() for b in out[:8])
    return SingularSet(cl.assigned, names, False, out, dims == 1, where, coordinated=True, coupled=cl.coupled)


def _at_icrs(robot: Robot, measure, dtype: type, h: np.ndarray) -> np.ndarray:
    """`measure` of the steering aimed at the ICRs `h` ``(..., 3)`` -> ``(n,)``, :data:`_fast.CHUNK` ICRs at a time
    (the steering of a whole grid of many wheels at once took gigabytes)."""
    h = h.reshape(-1, 3)
    out = np.empty(len(h), dtype)
    for s in range(0, len(h), _fast.CHUNK):
        out[s:s + _fast.CHUNK] = measure(steer_to_icr(robot, h[s:s + _fast.CHUNK]))
    return out


def _golden_batch(f, a: np.ndarray, b: np.ndarray, iterations: int = 70) -> np.ndarray:
    """Golden-section minimisation of ``f`` (arrays in, arrays out) on many brackets ``[a, b]`` at once."""
    ratio = (np.sqrt(5) - 1) / 2
    a, b = np.array(a, dtype=float), np.array(b, dtype=float)
    if a.size == 0:
        return a
    c, d = b - ratio * (b - a), a + ratio * (b - a)
    fc, fd = f(c), f(d)
    for _ in range(iterations):
        left = fc <= fd
        b = np.where(left, d, b)
        a = np.where(left, a, c)
        c_new, d_new = b - ratio * (b - a), a + ratio * (b - a)
        new = f(np.where(left, c_new, d_new))
        c, d = np.where(left, c_new, d), np.where(left, c, d_new)
        fc, fd = np.where(left, new, fd), np.where(left, fc, new)
    return (a + b) / 2
