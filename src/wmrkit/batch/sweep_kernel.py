"""Design sweeps, the kernel: an isotropy or singularity metric over the cartesian product of description fields.

``--vary wheels.front_left.l=0.2:0.4:21`` (or ``wheels[0].alpha=30deg:60deg:7``, ``wheels.left.heading=...``;
several targets joined by commas move together) gives an axis; the product of the axes is flattened and cut into
chunks, a Dask array ``map_blocks`` over the flat indices; each chunk is evaluated vectorised. Metrics (thesis ch. 5-6):

- ``kappa_mean`` / ``kappa_max``: the condition number (5.28) of the actuated joint rates over the admissible
  twists (:func:`wmrkit.analysis.isotropy.twist_condition_number`), mean / max over steering configurations
  (K random ones for steered robots, seeded; where the robot cannot move it is left out), at the natural length
  of each design (the D minimising the mean, searched per design) or a fixed `length`. The mean over the
  configuration space is the global-isotropy criterion of thesis §5.4 and future work 2 (lower is better);
- ``inv_kappa_mean``: the mean of ``1 / kappa`` (in [0, 1], higher is better), Kim et al.'s global isotropy
  (digest §3.3): bounded, so not dominated by the configurations near a singularity where kappa explodes;
- ``singular_margin``: the smallest distance to singularity (6.17) over the configurations,
  :func:`wmrkit.analysis.singularity.singularity_distance` of the actuated model (higher is better).

How a chunk is vectorised: a wheel's contribution depends only on its own fields, so for every wheel and every
combination of *its* varied values the robot is rebuilt through the description (``robot_from_dict``) and its
wheel's slip-row parameters and joint-rate / constraint-line blocks are taken from wmrkit's own compiled models
(:func:`~wmrkit.analysis.isotropy.twist_model`, :func:`~wmrkit.analysis.lines.constraint_lines`); a chunk
gathers them per design and runs the batched kernels of :mod:`wmrkit.analysis._fast`. Memory is bounded by the
chunk size; rows stream to Parquet.
"""

from __future__ import annotations

import copy
import itertools
import math
import re
from dataclasses import dataclass
from types import SimpleNamespace
from typing import Any

import numpy as np

from ..limits import check_length, check_seed
from ..robot import Robot
from ..wheels import GEOMETRY_FIELDS
from .engine import BatchError

METRICS = ("kappa_mean", "kappa_max", "inv_kappa_mean", "singular_margin")
_TARGET = re.compile(r"^wheels(?:\.([A-Za-z_][A-Za-z0-9_-]*)|\[(\d+)\])\.([a-z_]+)$")


#: Most points of one --vary axis (and variants of one wheel, the product of its axes: each a robot rebuilt),
#: designs of a sweep, designs over the first two axes (the map of the result, kept in memory), and steering
#: configurations per design.
MAX_POINTS, MAX_DESIGNS, MAX_MAP, MAX_CONFIGS = 10**6, 10**9, 10**7, 10**4


#: The fields a --vary may move: the description's geometry fields, ``heading`` (the users' steering angle,
#: 0 = straight ahead) in place of the thesis's ``beta``, and ``x``, ``y`` (the wheel's ``position`` [m]) in place
#: of the thesis's polar ``l``, ``alpha``.
VARY_FIELDS = {**GEOMETRY_FIELDS, "heading": "angle", "x": "length", "y": "length"}


@dataclass(frozen=True, eq=False)  # eq=False: array field
class Axis:
    """One swept quantity: ``targets`` ``((wheel index, field), ...)`` moved together through ``values`` (SI)."""

    label: str
    targets: tuple[tuple[int, str], ...]
    values: np.ndarray

    @property
    def unit(self) -> str:
        """Unit of the values: ``"rad"`` for the angle fields, ``"m"`` for the lengths."""
        return "rad" if VARY_FIELDS[self.targets[0][1]] == "angle" else "m"

    @property
    def shown_unit(self) -> str:
        """Unit in which the values are shown to people (the table printed, the plot): ``"deg"`` or ``"m"``."""
        return "deg" if self.unit == "rad" else "m"

    def shown(self, values: Any) -> Any:
        """`values` (SI) in :attr:`shown_unit`: angles in degrees, as typed into ``--vary``."""
        return np.degrees(values) if self.unit == "rad" else values


def parse_vary(text: str, robot: Robot) -> Axis:
    """An :class:`Axis` from ``FIELD[,FIELD...]=START:STOP:N`` (values with units, e.g. ``30deg``, ``250mm``)."""
    from ..documents import hint
    from ..units import UnitError, parse_quantity

    lhs, sep, rng = text.partition("=")
    parts = rng.split(":")
    if not sep or len(parts) != 3:
        raise BatchError(f"--vary {text}: expected FIELD=START:STOP:N")
    names = [w.name for w in robot.wheels]
    targets, kinds = [], set()
    for item in lhs.split(","):
        m = _TARGET.match(item.strip())
        if m is None:
            raise BatchError(f"--vary {text}: '{item}' is not wheels.NAME.FIELD or wheels[I].FIELD")
        name, index, fld = m.groups()
        if name is not None and name not in names:
            raise BatchError(f"--vary {text}: robot '{robot.name}' has no wheel '{name}'{hint(name, names)} "
                             f"(wheels: {', '.join(names)})")
        i = names.index(name) if name is not None else int(index)
        if i >= len(names):
            raise BatchError(f"--vary {text}: wheel index {i} out of range (the robot has {len(names)} wheels)")
        if fld not in VARY_FIELDS:
            raise BatchError(f"--vary {text}: '{fld}' is not a geometry field{hint(fld, VARY_FIELDS)} "
                             f"({', '.join(VARY_FIELDS)})")
        targets.append((i, fld))
        kinds.add(VARY_FIELDS[fld])
    if len(kinds) != 1:
        raise BatchError(f"--vary {text}: fields moved together must share a unit (lengths or angles)")
    try:
        kind = kinds.pop()
        start, stop = (parse_quantity(p.strip(), kind) for p in parts[:2])
    except UnitError as err:
        raise BatchError(f"--vary {text}: {err}") from None
    n = int(parts[2]) if parts[2].strip().isdecimal() else 0  # isdigit() took "²", which int() refuses
    if not 1 <= n <= MAX_POINTS:
        raise BatchError(f"--vary {text}: N must be a whole number of points in [1, {MAX_POINTS}], got "
                         f"{parts[2].strip()!r}")
    if n == 1 and stop != start:  # linspace's one value is START: STOP was dropped without a word
        raise BatchError(f"--vary {text}: N = 1 is the one value START; STOP differs and would be ignored (write "
                         "START:START:1, or N >= 2)")
    if kind == "angle" and max(abs(start), abs(stop)) > 2 * math.pi * (1 + 1e-12):
        raise BatchError(f"--vary {text}: an angle beyond one turn repeats a geometry of the sweep; sweep within "
                         "-360 deg to 360 deg")
    return Axis(lhs.strip(), tuple(targets), np.linspace(start, stop, n))


def variant(robot: Robot, assignments: dict[tuple[int, str], float], *, where: str = "--vary") -> Robot:
    """`robot` with wheel fields set through its description (validated by ``robot_from_dict``)."""
    from ..description import robot_from_dict, robot_to_dict
    from ..errors import WmrkitError

    data = copy.deepcopy(robot_to_dict(robot, thesis=True))  # --vary sets the thesis's fields, or heading for beta
    for (i, fld), value in assignments.items():
        wheel = data["wheels"][i]
        if fld in ("x", "y"):
            if "position" not in wheel:
                l, alpha = wheel.pop("l"), wheel.pop("alpha")
                wheel["position"] = [l * math.cos(alpha), l * math.sin(alpha)]
            wheel["position"][fld == "y"] = float(value)
            continue
        if fld == "heading":
            wheel.pop("beta", None)
        wheel[fld] = float(value)
    try:
        return robot_from_dict(data, source=where)
    except WmrkitError as err:
        raise BatchError(str(err)) from None  # the description's message names `where` already


@dataclass(frozen=True, eq=False)
class SweepSpec:
    """Everything a chunk needs (picklable, small): per wheel the axes it depends on and, per combination of
    their values, its slip-row parameters and its blocks of the joint-rate and constraint-line maps."""

    shape: tuple[int, ...]
    metric: str
    mobility: int
    length: float | None
    configs: np.ndarray  # (K, n_steer) steering configurations (thesis beta)
    steer_wheels: np.ndarray
    element_wheel: np.ndarray
    wheel_axes: tuple[tuple[int, ...], ...]
    tables: tuple[dict[str, np.ndarray], ...]
    size: float  # nominal robot size (search range of the natural length)


def build_spec(robot: Robot, axes: list[Axis], metric: str, *, length: float | None = None, configs: int = 64,
               seed: int = 0, progress: bool = False) -> SweepSpec:
    """Compile the per-wheel tables of a sweep (module docstring); a tqdm bar counts the robots rebuilt when
    `progress` (about 8 ms each: a 10^6-point axis is a few hours)."""
    from tqdm import tqdm

    from ..analysis.classification import classify
    from ..analysis.isotropy import default_joints
    from ..analysis.lines import constraint_lines, line_parameters
    from ..analysis.singularity import robot_size

    if metric not in METRICS:
        raise BatchError(f"unknown metric '{metric}' (metrics: {', '.join(METRICS)})")
    if not axes:
        raise BatchError("a sweep needs at least one --vary")
    if length is not None:
        check_length(length, BatchError, "--length")
        if metric == "singular_margin":  # its length is the robot's size: a --length was ignored without a word
            raise BatchError("--length sets D of the kappa metrics; singular_margin scales by each design's size")
    if isinstance(configs, bool) or not isinstance(configs, int | np.integer) or not 1 <= configs <= MAX_CONFIGS:
        raise BatchError(f"--configs must be in [1, {MAX_CONFIGS}] (a whole number), got {configs!r}")
    check_seed(seed, BatchError)  # -1 and 2.5 reached numpy's ValueError and TypeError
    targets = [t for a in axes for t in a.targets]
    for a in axes:  # an Axis made by hand (parse_vary checks its own): a wheel beyond the robot's moved nothing
        if any(not 0 <= i < len(robot.wheels) for i, _ in a.targets):
            raise BatchError(f"--vary {a.label}: the robot has {len(robot.wheels)} wheels")
    if len(set(targets)) != len(targets) or any((i, "beta") in targets for i, f in targets if f == "heading") \
            or any((i, f) in targets for i, g in targets if g in ("x", "y") for f in ("l", "alpha")):
        raise BatchError("two --vary axes move the same field (one would overwrite the other; heading is beta - 90 "
                         "deg, and x, y place the wheel that l, alpha place)")
    shape = [len(a.values) for a in axes]
    if math.prod(shape[:2]) > MAX_MAP or math.prod(shape) > MAX_DESIGNS:
        raise BatchError(f"{' x '.join(map(str, shape))} designs: at most {MAX_DESIGNS:.0e} designs, and "
                         f"{MAX_MAP:.0e} over the first two --vary axes (the map kept in memory)")
    joints = default_joints(robot)
    # the refusals that depend on the robot alone come before the tables (one rebuild per value: a 3000-point
    # axis of a swerve drive took 35 s to be refused)
    mobility = classify(robot).mobility
    if metric != "singular_margin" and mobility < 2:
        raise BatchError(f"robot '{robot.name}' has mobility {mobility}: its condition number is 1 at every "
                         "configuration it can move in and undefined elsewhere (isotropy does not apply to types 4 "
                         "and 5, §5.5.4-5.5.5), so a --metric of kappa compares nothing; sweep --metric "
                         "singular_margin")
    tied = [c for c in robot.couplings if c.rates and sum(j in joints for j in c.joints) > 1]
    if metric == "singular_margin" and tied:
        raise BatchError(f"robot '{robot.name}': its actuated joints {', '.join(tied[0].joints)} are one "
                         f"{tied[0].kind}; the sweep's kernel takes each wheel on its own, and a line through the "
                         f"coupling joins wheels: its singular_margin would be that of separate joints, not of this "
                         f"robot's actuated model (use 'wmrkit analyze' on the designs)")
    cl = constraint_lines(robot, joints)
    if metric == "singular_margin" and (cl.internal or len(cl.labels) < 3):
        raise BatchError(f"robot '{robot.name}': its actuated model is singular everywhere (fewer than 3 lines)")
    p0 = line_parameters(robot)
    n_steer = len(robot.steer_names)
    rng = np.random.default_rng(seed)
    beta = rng.uniform(-np.pi, np.pi, (configs, n_steer)) if n_steer else np.zeros((1, 0))
    wheel_axes = [tuple(k for k, ax in enumerate(axes) if any(i == w for i, _ in ax.targets))
                  for w in range(len(robot.wheels))]
    for w, mine in enumerate(wheel_axes):  # a wheel's table is the product of its own axes: one rebuild each
        if math.prod(shape[k] for k in mine) > MAX_POINTS:
            raise BatchError(f"wheel '{robot.wheels[w].name}': its --vary axes make "
                             f"{' x '.join(str(shape[k]) for k in mine)} variants, each a robot rebuilt (about 10 "
                             f"ms): at most {MAX_POINTS:.0e} a wheel; sweep fewer fields of one wheel, or fewer points")
    with tqdm(total=sum(math.prod(shape[k] for k in mine) for mine in wheel_axes), desc="robots", unit="robot",
              disable=not progress, leave=False) as bar:
        tables = [_wheel_table(robot, axes, w, mine, joints, p0, bar) for w, mine in enumerate(wheel_axes)]
    return SweepSpec(tuple(len(a.values) for a in axes), metric, mobility, length, beta,
                     p0.steer_wheels, p0.element_wheel, tuple(wheel_axes), tuple(tables), robot_size(robot))


def _wheel_table(robot: Robot, axes: list[Axis], w: int, mine: tuple[int, ...], joints, p0, bar) -> dict:
    """Wheel `w`'s table: per combination of the values of its axes `mine`, its slip-row parameters and blocks."""
    from ..analysis.isotropy import twist_model
    from ..analysis.lines import constraint_lines, line_parameters

    el, rows = p0.element_wheel == w, np.repeat(p0.element_wheel, 2) == w
    cols: dict[str, list] = {k: [] for k in ("theta", "lc", "ls", "lsn", "dc", "ds", "beta", "l", "rates", "lines",
                                             "sing")}
    for combo in itertools.product(*(range(len(axes[k].values)) for k in mine)):
        assign = {t: axes[k].values[c] for k, c in zip(mine, combo, strict=True)
                  for t in axes[k].targets if t[0] == w}
        r = variant(robot, assign) if assign else robot
        p = line_parameters(r)
        for key, arr in (("theta", p.theta_offset), ("lc", p.l_c_alpha), ("ls", p.l_s_alpha),
                         ("lsn", p.l_s_alpha_neg), ("dc", p.d_c), ("ds", p.d_s)):
            cols[key].append(arr[el])
        cols["beta"].append(p.beta_described[w])
        cols["l"].append(r.wheels[w].l)
        cols["rates"].append(twist_model(r, joints).coefficients[:, rows])
        cols["lines"].append(_wheel_lines(constraint_lines(r), r, w, rows))
        cols["sing"].append(_wheel_lines(constraint_lines(r, joints), r, w, rows))
        bar.update(1)
    shapes = {k: {np.shape(v) for v in vs} for k, vs in cols.items()}
    if any(len(s) > 1 for s in shapes.values()):
        raise BatchError(f"the swept values change the structure of wheel '{robot.wheels[w].name}' (e.g. a castor "
                         "offset through 0): sweep a range on one side")
    return {k: np.asarray(v, dtype=float) for k, v in cols.items()}


def _wheel_lines(cl, robot: Robot, w: int, rows: np.ndarray) -> np.ndarray:
    """The rows of the constraint-line map that belong to wheel `w`, restricted to its slip rows."""
    mine = [i for i, name in enumerate(cl.wheels) if name == robot.wheels[w].name]
    return cl.coefficients[mine][:, rows]


def evaluate(flat: np.ndarray, spec: SweepSpec) -> np.ndarray:
    """Metric and characteristic length of the designs with flat indices `flat`: ``(n,) -> (n, 2)``."""
    from ..analysis import _fast

    flat = np.asarray(flat, dtype=np.int64).ravel()
    n, k = len(flat), len(spec.configs)
    if n == 0:
        return np.zeros((0, 2))
    index = np.unravel_index(flat, spec.shape)
    combos = [np.ravel_multi_index([index[a] for a in axes], [spec.shape[a] for a in axes]) if axes
              else np.zeros(n, dtype=np.int64) for axes in spec.wheel_axes]
    rep = lambda a: np.repeat(a, k, axis=-1)  # noqa: E731 - designs x configurations, configurations fastest
    el_combo = [combos[w] for w in spec.element_wheel]
    el_pos = [int(np.sum(spec.element_wheel[:e] == w)) for e, w in enumerate(spec.element_wheel)]
    get = lambda key: np.stack([rep(spec.tables[w][key][el_combo[e], el_pos[e]])  # noqa: E731
                                for e, w in enumerate(spec.element_wheel)])
    p = SimpleNamespace(element_wheel=spec.element_wheel, steer_wheels=spec.steer_wheels,
                        beta_described=[rep(spec.tables[w]["beta"][combos[w]]) for w in range(len(combos))],
                        theta_offset=get("theta"), l_c_alpha=get("lc"), l_s_alpha=get("ls"),
                        l_s_alpha_neg=get("lsn"), d_c=get("dc"), d_s=get("ds"))
    rows = _fast.element_rows_cm(p, np.tile(spec.configs, (n, 1)))  # (2E, 3, n k)
    row_wheel = np.repeat(spec.element_wheel, 2)

    def assemble(key: str) -> np.ndarray:
        """Per wheel, its block ``(n, L_w, R_w)`` of the map applied to its slip rows; rates add, lines stack."""
        parts = [np.einsum("nlr,rcnk->lcnk", spec.tables[w][key][combos[w]],
                           rows[row_wheel == w].reshape(-1, 3, n, k)).reshape(-1, 3, n * k) for w in range(len(combos))]
        return sum(parts) if key == "rates" else np.concatenate(parts)

    if spec.metric == "singular_margin":
        size = np.sqrt(np.mean([spec.tables[w]["l"][combos[w]] ** 2 for w in range(len(combos))], axis=0))
        size = np.maximum(size, 1e-3)
        lines = assemble("sing")
        lines[:, 2] /= rep(size)
        d = _fast.distance_cm(lines, 1.0).reshape(n, k)
        return np.column_stack([np.min(d, axis=1), size])
    rates, lines = assemble("rates"), _fast.normalize_cm(assemble("lines"))

    def kappa(length: np.ndarray) -> np.ndarray:  # (n,) -> (n, k)
        if spec.mobility == 3:
            scaled = rates.copy()
            scaled[:, 2] /= rep(length)
            return _fast.kappa_cm(3, scaled, lines, 1.0).reshape(n, k)
        return _fast.kappa_cm(spec.mobility, rates, lines, rep(length)).reshape(n, k)  # type: ignore[arg-type]

    sign = -1.0 if spec.metric == "inv_kappa_mean" else 1.0  # minimise -mean(1/kappa): maximise it
    reduce = {"kappa_max": np.nanmax, "kappa_mean": np.nanmean,
              "inv_kappa_mean": lambda k, axis: -np.nanmean(1.0 / k, axis=axis)}[spec.metric]
    score = lambda length: _quiet(reduce, kappa(length))  # noqa: E731
    length = np.full(n, spec.length) if spec.length is not None else _natural(score, n, spec.size)
    return np.column_stack([sign * score(length), length])


def _quiet(reduce, values: np.ndarray) -> np.ndarray:
    """`reduce` over configurations ignoring NaN (cannot move); NaN where no configuration can move."""
    with np.errstate(invalid="ignore"), _no_warnings():
        return reduce(np.where(np.isnan(values), np.nan, values), axis=1)


def _natural(score, n: int, size: float, *, points: int = 21, iterations: int = 40) -> np.ndarray:
    """Per design, the length D minimising `score` over ``[1e-2, 1e2] * size`` (log grid, then golden section),
    vectorised over the designs; where the score does not depend on D (m = 1), the nominal size."""
    grid = np.log(size) + np.linspace(np.log(1e-2), np.log(1e2), points)
    values = np.stack([score(np.full(n, np.exp(g))) for g in grid], axis=1)  # (n, points)
    finite = np.where(np.isfinite(values), values, np.inf)
    i = np.argmin(finite, axis=1)
    a, b = grid[np.maximum(i - 1, 0)], grid[np.minimum(i + 1, points - 1)]
    ratio = (np.sqrt(5) - 1) / 2
    c, d = b - ratio * (b - a), a + ratio * (b - a)
    fc, fd = score(np.exp(c)), score(np.exp(d))
    for _ in range(iterations):
        left = ~(fd < fc)  # minimum in [a, d]
        b, a = np.where(left, d, b), np.where(left, a, c)
        c_new, d_new = b - ratio * (b - a), a + ratio * (b - a)
        c, d = np.where(left, c_new, d), np.where(left, c, d_new)
        probe = np.exp(np.where(left, c, d))
        f_new = score(probe)
        fc, fd = np.where(left, f_new, fd), np.where(left, fc, f_new)
    x = (a + b) / 2
    with np.errstate(invalid="ignore"), _no_warnings():  # a design singular everywhere: all inf, no warning
        flat = ~np.isfinite(finite).any(axis=1) | (np.nanmax(np.where(np.isfinite(values), values, np.nan), axis=1)
                                                   - np.min(finite, axis=1) < 1e-9 * np.abs(np.min(finite, axis=1)))
    best = np.where(score(np.exp(x)) <= finite[np.arange(n), i], x, grid[i])
    return np.where(flat, size, np.exp(best))


class _no_warnings:
    def __enter__(self) -> None:
        import warnings

        self._ctx = warnings.catch_warnings()
        self._ctx.__enter__()
        warnings.simplefilter("ignore", RuntimeWarning)

    def __exit__(self, *exc: Any) -> None:
        self._ctx.__exit__(*exc)
