"""What a robot's held ``linkage`` couplings leave of the motions its wheels allow (``analyze``).

The thesis classifies a robot by its wheels' geometry (Table 5.1): a robot whose steering must be coordinated
reaches every ICR its fixed wheels allow, each steered wheel aimed at it on its own. A held linkage sets its wheels'
angles from one (:mod:`wmrkit.kinematics.linkage_law`): an ``ackermann`` law keeps every ICR of the fixed axle, a
``parallel`` chain keeps the linked axles parallel, so a synchro drive only translates and a car whose front wheels
are linked in parallel beside a fixed rear axle only drives straight (their axles meet the fixed axle nowhere else).

An ICR is *reachable* when the linkages can set the steering that aims every axle at it
(:func:`wmrkit.analysis.icr.steer_to_icr`), judged as ``ik`` judges its angles for a twist
(:func:`wmrkit.kinematics.linkage_check.linkage_holds`) with a unit twist about it. :func:`linked_reach` samples the
ICRs the wheels allow (:func:`wmrkit.analysis.coordinated.admissible_icrs`, plus the described one) and gives the
mobility and steerability the linkages leave; :func:`unreachable` judges the singular configurations of
:mod:`.coordinated`, whose sets are kept (the thesis's), the report saying which of them the robot cannot reach.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from ..couplings import linkage_law
from ..kinematics.linkage_check import _plan, _speeds, linkage_holds
from ..kinematics.wheel_ik import SLIP_TOL
from ..robot import Robot
from ._fast import CHUNK
from .classification import classify
from .coordinated import admissible_icrs
from .icr import ICRSet, icr, icr_homogeneous, twist_of_icr
from .singularity import SingularSet

#: Isolated reachable ICRs listed by :class:`LinkedReach` (and ``analyze --json``).
MAX_LISTED = 8
#: Finest grid :func:`linked_reach` judges [points per turn]: a set's dimension needs no finer one (at 1440, the
#: finest ``--resolution``, a plane of ICRs took 5 s).
MAX_REACH_RESOLUTION = 360


def _holds(robot: Robot, h: np.ndarray, beta: np.ndarray) -> np.ndarray:
    """``(n, n_couplings)`` bool: each coupling holds at steering `beta` ``(n, n_steer)`` for a unit twist about the
    ICR `h` ``(n, 3)``, scaled so that the fastest steering axis moves at 1 m/s (a judge free of the robot's size)."""
    twist = twist_of_icr(h)
    speed = _speeds(_plan(robot), twist).max(axis=-1, keepdims=True)
    return linkage_holds(robot, twist / np.where(speed > 0, speed, 1.0), beta, SLIP_TOL)


def reachable(robot: Robot, icr_h: np.ndarray) -> np.ndarray:
    """``(n, 3) -> (n,)`` bool: the held linkages can set the steering that aims every axle at each ICR `icr_h`
    (module docstring); True everywhere without a held linkage."""
    from .icr import steer_to_icr

    h = np.asarray(icr_h, dtype=float).reshape(-1, 3)
    out = np.ones(len(h), dtype=bool)
    if not len(_plan(robot).lead):
        return out
    for s in range(0, len(h), CHUNK):  # a fine grid of a many-wheeled robot at once took gigabytes
        part = h[s:s + CHUNK]
        out[s:s + CHUNK] = _holds(robot, part, steer_to_icr(robot, part)).all(axis=-1)
    return out


def held_linkages(robot: Robot) -> tuple[str, ...]:
    """The linkages the kinematics hold (a law to hold), each as ``"<channel> (law <law>)"``."""
    plan = _plan(robot)
    return tuple(f"{robot.couplings[k].channel_name} (law {linkage_law(robot.couplings[k], robot.wheels)})"
                 for k in sorted(set(plan.coupling.tolist())))


@dataclass(frozen=True)
class LinkedReach:
    """The ICRs a robot's held linkages let it reach among those its wheels allow (:func:`linked_reach`).

    ``mobility``: 1 when it reaches one, else 0 (it cannot move without slipping at any steering the linkages give);
    ``steerability``: the dimension of the set of ICRs it reaches (0: isolated ICRs, listed in ``icrs``; at most the
    thesis's d); ``every``: it reaches every ICR sampled, the thesis's classification stands.
    """

    linkages: tuple[str, ...]  # the held linkages, "<channel> (law <law>)"
    mobility: int
    steerability: int
    every: bool
    sampled: int  # ICRs sampled (the admissible grid and the described ICR)
    found: int  # of them reachable
    icrs: tuple[tuple[float, float, float], ...]  # the isolated ICRs reached (homogeneous), at most MAX_LISTED
    words: str  # the set reached, for people

    def describe(self) -> str:
        """One line: m and d with the linkages held, and which ICRs they leave."""
        return f"with its steering linkages held: m = {self.mobility}, d = {self.steerability}: {self.words}"

    def to_dict(self) -> dict[str, Any]:
        """JSON of ``analyze``'s ``linkages``."""
        return {"held": list(self.linkages), "mobility": self.mobility, "steerability": self.steerability,
                "every_icr": self.every, "sampled": self.sampled, "reachable": self.found,
                "icrs": [list(h) for h in self.icrs], "icr_texts": [f"ICR {_icr_words(h)}" for h in self.icrs],
                "text": self.describe()}


def linked_reach(robot: Robot, resolution: int = 90) -> LinkedReach | None:
    """Which of the ICRs `robot`'s wheels allow its held linkages reach (module docstring): judged on the grid of
    :func:`.coordinated.admissible_icrs` of `resolution` points per turn (at most :data:`MAX_REACH_RESOLUTION`), on
    the line through each linkage's first two steering axes (where wheels held parallel meet at a finite ICR: their
    common axle) and at the described ICR; None without a held linkage or for a robot the thesis calls degenerate.
    An ICR reached off those (a linkage with odd rest angles) is not found."""
    held = held_linkages(robot)
    cls = classify(robot)
    if not held or cls.degenerate or cls.fixed_rank > 1:
        return None
    resolution = min(resolution, MAX_REACH_RESOLUTION)
    grid, dims = admissible_icrs(robot, resolution)
    ok = reachable(robot, grid)
    lines = _pair_lines(robot, resolution) if dims == 2 else np.zeros((0, resolution, 3))
    on_line = reachable(robot, lines.reshape(-1, 3)).reshape(len(lines), resolution)
    described = icr(robot).homogeneous()
    extra = described is not None and bool(reachable(robot, described[None])[0])
    if dims == 1:
        near = ok & (np.roll(ok, 1) | np.roll(ok, -1))  # an arc of the axle, not an isolated ICR
        opened = False
    else:
        rows = ok.reshape(-1, resolution)
        along = rows & (np.roll(rows, 1, axis=1) | np.roll(rows, -1, axis=1))
        across = np.zeros_like(rows)
        across[1:-1] = rows[1:-1] & rows[:-2] & rows[2:]
        near, opened = along.reshape(-1), bool((along & across).any())
    line_near = on_line & (np.roll(on_line, 1, axis=1) | np.roll(on_line, -1, axis=1))
    every = bool(ok.all()) and (described is None or extra)
    isolated = [h for h in grid[ok & ~near]] + [h for h in lines[on_line & ~line_near]]
    if extra and not near.any() and not line_near.any():
        isolated.insert(0, described)
    isolated = list(dict.fromkeys(_rounded(h) for h in isolated))
    d = min(cls.steerability, 2 if opened else 1 if near.any() or line_near.any() else 0)
    m = int(bool(ok.any() or on_line.any() or extra))
    found = int(ok.sum()) + int(on_line.sum()) + int(extra)
    if not m:
        words = "no ICR its wheels allow: it cannot move without slipping at any steering its linkages give"
    elif every:
        words = "every ICR its wheels allow (the type above stands)"
    elif not near.any() and not line_near.any():
        listed = "; ".join(_icr_words(h) for h in isolated[:MAX_LISTED])
        words = (f"only {'one ICR' if len(isolated) == 1 else f'{len(isolated)} ICRs'}, {listed} (at any other "
                 "steering its linkages give it cannot move without slipping)")
    elif dims == 1:
        words = f"{int(ok.sum())} of the {ok.size} ICRs sampled on the fixed axle"
    else:
        words = _plane_words(robot, ok.reshape(-1, resolution), line_near)
    return LinkedReach(held, m, d, every, len(grid) + lines.shape[0] * resolution + int(described is not None),
                       found, tuple(isolated[:MAX_LISTED]), words)


def _pair_lines(robot: Robot, resolution: int) -> np.ndarray:
    """``(n_linkages, resolution, 3)``: homogeneous points of the line through each held linkage's first two
    steering axes, ``p0 + size tan(t) u`` (t from -pi/2: its point at infinity first)."""
    from .singularity import robot_size

    plan, size = _plan(robot), float(robot_size(robot))
    t = np.linspace(-np.pi / 2, np.pi / 2, resolution, endpoint=False)
    out = []
    for g in range(len(plan.lead)):
        follower = int(plan.table[plan.start[g], 0])
        p, q = np.array([plan.x[plan.lead[g]], plan.y[plan.lead[g]]]), np.array([plan.x[follower], plan.y[follower]])
        u = (q - p) / max(float(np.hypot(*(q - p))), 1e-300)
        c, s = np.cos(t)[:, None], np.sin(t)[:, None]
        out.append(np.concatenate([c * p + s * size * u, c], axis=-1))
    return np.array(out, dtype=float).reshape(-1, resolution, 3)


def _plane_words(robot: Robot, rows: np.ndarray, line_near: np.ndarray) -> str:
    """The ICRs reached by a robot without fixed wheels, in words: those at infinity (the grid's last row), finite
    ones on the grid, and those on the lines through a linkage's wheels (:func:`_pair_lines`)."""
    plan = _plan(robot)
    ring, finite = rows[-1], int(rows[:-1].sum())
    parts = ["every ICR at infinity (translation in any direction)" if ring.all() else
             f"{int(ring.sum())} of the {ring.size} ICRs sampled at infinity"]
    if finite:
        parts.append(f"{finite} of the {rows[:-1].size} finite ICRs sampled")
    for g in np.flatnonzero(line_near.any(axis=1)):
        a, b = robot.steer_names[plan.lead[g]], robot.steer_names[int(plan.table[plan.start[g], 0])]
        parts.append(f"ICRs on the line through {a} and {b} ({int(line_near[g].sum())} of {line_near.shape[1]} "
                     "sampled)")
    if not finite and not line_near.any():
        return f"{parts[0]}; no finite ICR found: it only translates"
    return ", ".join(parts[:-1]) + (" and " if len(parts) > 1 else "") + parts[-1]


def _rounded(h: tuple[float, ...]) -> tuple[float, float, float]:
    """A homogeneous ICR scaled to a largest entry of 1, its sign fixed, rounded (one ICR listed once)."""
    a = np.array(h, dtype=float)
    a = a / a[np.flatnonzero(np.abs(a) > 1e-12 * np.abs(a).max())[0]]  # h and -h: one ICR
    a = a / np.abs(a).max()
    return tuple(float(v) + 0.0 for v in np.round(a, 12))


def _icr_words(h: tuple[float, float, float]) -> str:
    """An ICR ``(x, y, w)`` in ``icr``'s words, without its leading "ICR ": ``at (0.000, 1.000) m``."""
    x, y, w = h
    if abs(w) < 1e-12:
        n = float(np.hypot(x, y))
        return ICRSet("infinity", direction=(y / n, -x / n)).describe().removeprefix("ICR ")
    return ICRSet("point", point=(x / w, y / w)).describe().removeprefix("ICR ")


def unreachable(robot: Robot, s: SingularSet) -> tuple[np.ndarray, tuple[str, ...]]:
    """``(n,)`` bool over ``s.configurations``: True where a held linkage cannot set that steering (judged at a unit
    twist about its ICR, as ``ik``; a configuration with no single ICR is not judged), and the linkages that break,
    each as ``"<channel> (law <law>)"``. Only coordinated sets over every steering angle are judged."""
    out, broken = _unreachable(robot, s)
    return out, tuple(_law_named(robot, k, robot.couplings[k].channel_name) for k in broken)


def _law_named(robot: Robot, k: int, name: str) -> str:
    return f"{name} (law {linkage_law(robot.couplings[k], robot.wheels)})"


def _unreachable(robot: Robot, s: SingularSet) -> tuple[np.ndarray, list[int]]:
    """:func:`unreachable` with the broken linkages as their indices in ``robot.couplings``."""
    n = len(s.configurations)
    none = np.zeros(n, dtype=bool)
    if not n or not s.coordinated or not len(_plan(robot).lead) or s.variables != robot.steer_names:
        return none, []
    out, broken = none.copy(), set()
    for i, beta in enumerate(np.asarray(s.configurations, dtype=float)):
        h = icr_homogeneous(robot, beta)
        if h is None:
            continue
        holds = _holds(robot, h[None], beta[None])[0]
        out[i] = not holds.all()
        broken.update(int(k) for k in np.flatnonzero(~holds))
    return out, sorted(broken)


def unreachable_note(robot: Robot, s: SingularSet, *, words: bool = False) -> str | None:
    """One line for the report under a singular set: how many of its configurations a held linkage cannot set, or
    None when it can set them all. `words`: each linkage named in the description's terms (text; the JSON keeps its
    channel name, :meth:`wmrkit.couplings.Coupling.words`)."""
    bad, broken = _unreachable(robot, s)
    names = [_law_named(robot, k, robot.couplings[k].words() if words else robot.couplings[k].channel_name)
             for k in broken]
    if not bad.any():
        return None
    n, k = len(bad), int(bad.sum())
    which = "this singular configuration" if n == 1 else (
        f"{'every one' if k == n else k} of these {n} singular configurations")
    return (f"not reachable: {', '.join(names)} cannot set the steering of {which} (the thesis's coordinated "
            "steering turns each wheel on its own)")
