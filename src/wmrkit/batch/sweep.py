"""Design sweeps on the engine: the product of ``--vary`` axes as a chunked Dask array, best designs, Parquet, plot.

The flat design index ``0 .. prod(N_i) - 1`` is cut into chunks, each a Dask array; ``map_blocks`` applies
:func:`~.sweep_kernel.evaluate` (metric and characteristic length of every design of the chunk, vectorised) and
the chunks are computed on the engine with a bounded number in flight. Each finished chunk is streamed to the
Parquet file (one row group per chunk, rows in completion order with their ``index``), folded into the best
``top`` designs and into a reduced grid over the first two axes (the best value over the other axes) for the
plot; nothing of the size of the whole product is kept. Without Dask the same kernel runs chunk by chunk.
"""

from __future__ import annotations

import math
import os
import time
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .._shapes import readonly
from ..robot import Robot, check_robot
from .engine import BatchError, Engine, engine, need_extra
from .parquet import check_table
from .sweep_kernel import METRICS, Axis, build_spec, evaluate

#: Most designs x steering configurations evaluated in one chunk (4096 x 128, the documented example; the chunk is
#: made smaller for more configurations): a chunk's memory is about 0.5 kB per pair.
MAX_CHUNK_COLUMNS = 2**19
#: Most best designs kept and reported (``top``): they are kept in memory and sorted at every chunk, so a larger
#: `top` made the memory grow with the number of designs (about 2 kB each); every design goes to ``out``.
MAX_TOP = 10**4
#: Columns every sweep table has besides its axes': an existing --out without them is not replaced.
TABLE_KEYS = (("index", "int64"), ("metric", "float64"), ("length", "float64"))
#: Whether a metric is better when smaller.
LOWER_IS_BETTER = {"kappa_mean": True, "kappa_max": True, "inv_kappa_mean": False, "singular_margin": False}
#: What a design's metric that is not a number means (the JSON's ``status``, the text's words; null in JSON for both):
#: ``infinite``, singular at a configuration sampled (inf in Parquet); ``undefined``, it cannot move at any
#: configuration sampled (NaN in Parquet). A finite metric's status is ``finite``.
STATUS = {"infinite": "singular at a configuration sampled", "undefined": "it cannot move at any configuration sampled"}


def metric_status(value: float) -> str:
    """``finite``, ``infinite`` (+inf: singular) or ``undefined`` (NaN: cannot move) (:data:`STATUS`)."""
    return "finite" if math.isfinite(value) else "infinite" if value == math.inf else "undefined"


@dataclass(frozen=True, eq=False)  # eq=False: array fields
class SweepResult:
    """A sweep: the ``axes``, the ``metric``, ``total`` designs; ``best`` the ``top`` designs (mappings with
    ``index``, one value per axis label (SI), the metric, ``length`` (D [m] for kappa metrics, the robot size
    for the margin)); ``grid`` the best metric over the other axes, shape ``(N_0,)`` or ``(N_0, N_1)``."""

    robot: str
    axes: tuple[Axis, ...]
    metric: str
    total: int
    chunks: int
    best: tuple[dict, ...]
    grid: np.ndarray
    wall_time: float

    def to_dict(self) -> dict:
        """JSON-ready mapping."""
        return {"robot": self.robot, "metric": self.metric, "designs": self.total, "chunks": self.chunks,
                "wall_time": self.wall_time,
                "axes": [{"field": a.label, "start": float(a.values[0]), "stop": float(a.values[-1]),
                          "n": len(a.values), "unit": a.unit} for a in self.axes],
                "best": [{k: (None if isinstance(v, float) and not math.isfinite(v) else v) for k, v in b.items()}
                         | {"status": metric_status(b[self.metric])} for b in self.best]}


def check_counts(chunk: int, top: int, names: tuple[str, str] = ("chunk", "top")) -> None:
    """Refuse (:class:`BatchError` naming the argument by `names`: the CLI's options) a `chunk` or `top` that is
    not an integer >= 1, or a `top` above :data:`MAX_TOP`."""
    for name, value in zip(names, (chunk, top), strict=True):
        if isinstance(value, bool) or not isinstance(value, int | np.integer) or value < 1:
            raise BatchError(f"{name}: expected an integer >= 1, got {value!r}")
    if top > MAX_TOP:
        raise BatchError(f"{names[1]}: {top} is more than {MAX_TOP} best designs (every design is in the table "
                         "written by --out)")


def sweep(robot: Robot, axes: Sequence[Axis], metric: str = "kappa_mean", *, runner: Engine | None = None,
          chunk: int = 4096, out: str | os.PathLike[str] | None = None, top: int = 10, length: float | None = None,
          configs: int = 64, seed: int = 0, progress: bool = False) -> SweepResult:
    """Evaluate `metric` over the product of `axes` (module docstring); `length` fixes D [m] (default: the
    natural length of each design); `configs` steering configurations per design for steered robots."""
    check_robot(robot, BatchError)
    if metric not in METRICS:
        raise BatchError(f"unknown metric '{metric}' (metrics: {', '.join(METRICS)})")
    check_counts(chunk, top)
    t0 = time.perf_counter()
    axes = tuple(axes)
    spec = build_spec(robot, list(axes), metric, length=length, configs=configs, seed=seed, progress=progress)
    total = math.prod(spec.shape)
    # a chunk evaluates designs x configurations at once (about 0.5 kB each): 4096 designs of 10^4 configurations
    # took 22 GB; fewer designs per chunk keep it within MAX_CHUNK_COLUMNS
    chunk = min(chunk, max(1, MAX_CHUNK_COLUMNS // len(spec.configs)))
    lower = LOWER_IS_BETTER[metric]
    grid = np.full(spec.shape[:2], np.inf if lower else -np.inf)
    best = np.zeros((0, 3))  # rows (index, metric, length)
    writer = _Writer(out, axes, robot.name, metric) if out is not None else None
    own = runner is None
    runner = engine(workers=0) if runner is None else runner
    try:
        blocks, parts = _blocks(total, chunk, runner.share(spec))
        stream = (runner.compute(parts, progress=progress, desc="designs") if parts is not None
                  else ((i, evaluate(np.arange(s, min(s + chunk, total)), spec)) for i, s in enumerate(blocks)))
        for i, values in stream:
            index = np.arange(blocks[i], min(blocks[i] + chunk, total))
            if writer is not None:
                writer.write(index, spec.shape, values)
            sub = np.unravel_index(index, spec.shape)[:2]
            key = np.where(np.isnan(values[:, 0]), np.inf if lower else -np.inf, values[:, 0])
            (np.minimum if lower else np.maximum).at(grid, sub, key)
            best = _keep_best(np.vstack([best, np.column_stack([index, values])]), top, lower)
        if writer is not None:
            writer.close()
    finally:
        if own:
            runner.close()
        if writer is not None:  # a failed sweep left its half-written '.NAME.PID.tmp' behind
            writer.abort()
    rows = []
    for idx, value, d in best:
        sub = np.unravel_index(int(idx), spec.shape)
        row = {"index": int(idx)} | {a.label: float(a.values[s]) for a, s in zip(axes, sub, strict=True)}
        rows.append(row | {metric: float(value), "length": float(d)})
    return SweepResult(robot.name, axes, metric, total, len(blocks), tuple(rows), readonly(grid),
                       time.perf_counter() - t0)


def _blocks(total: int, chunk: int, spec) -> tuple[range, Sequence | None]:
    """Chunk starts (a range: 10^9 designs in chunks of one made a list of 10^9 numbers before any work) and, with
    Dask, the chunks of the flat design index as a lazy sequence of delayed values."""
    starts = range(0, total, chunk)
    try:
        da = need_extra("dask.array")
    except BatchError:
        return starts, None
    return starts, _LazyBlocks(da, total, chunk, spec)


class _LazyBlocks(Sequence):
    """Chunk ``i`` of ``arange(total)``, a one-chunk Dask array, with :func:`evaluate` mapped over it
    (``map_blocks``), as a delayed value made on access: the graph in memory is one chunk's, whatever the size of
    the product (the whole ``arange(total, chunks=chunk)`` graph would be materialised per access)."""

    def __init__(self, da, total: int, chunk: int, spec) -> None:
        self.da, self.total, self.chunk, self.spec = da, total, chunk, spec

    def __len__(self) -> int:
        return -(-self.total // self.chunk)

    def __getitem__(self, i):  # type: ignore[override]
        if not 0 <= i < len(self):
            raise IndexError(i)
        start, stop = i * self.chunk, min((i + 1) * self.chunk, self.total)
        flat = self.da.arange(start, stop, chunks=stop - start, dtype=np.int64)
        block = flat.map_blocks(evaluate, self.spec, dtype=float, new_axis=1, chunks=((stop - start,), (2,)))
        return block.to_delayed().ravel()[0]


def _keep_best(rows: np.ndarray, top: int, lower: bool) -> np.ndarray:
    """The `top` rows ``(index, metric, length)``: best metric first, NaN last, ties by index (deterministic)."""
    key = np.where(np.isnan(rows[:, 1]), np.inf, rows[:, 1] if lower else -rows[:, 1])
    return rows[np.lexsort((rows[:, 0], key))[:top]]


class _Writer:
    """Streams chunks of the sweep to Parquet (a temporary file renamed into place at the end). The schema's
    metadata names the ``robot`` and the ``metric`` (the column is ``metric``), each field's its ``unit``."""

    def __init__(self, path: str | os.PathLike[str], axes: Sequence[Axis], robot: str, metric: str) -> None:
        pa, pq = need_extra("pyarrow"), need_extra("pyarrow.parquet")
        self.path, self.axes, self._pa = Path(path), axes, pa
        if not self.path.parent.exists():
            raise BatchError(f"{self.path}: the folder {self.path.parent} does not exist")
        if self.path.is_dir():
            raise BatchError(f"{self.path}: a folder, not a file")
        if self.path.exists():  # a log or another command's table was replaced without a word; a sweep's is replaced
            check_table(self.path, TABLE_KEYS, [name for name, _ in TABLE_KEYS])
        names = [a.label for a in axes]
        if len(set(names)) != len(names):
            raise BatchError("two --vary axes have the same fields")
        self.schema = pa.schema([pa.field("index", pa.int64()),
                                 *(pa.field(a.label, pa.float64(), metadata={"unit": a.unit}) for a in axes),
                                 pa.field("metric", pa.float64(), metadata={"unit": "1"}),  # every metric is a ratio
                                 pa.field("length", pa.float64(), metadata={"unit": "m"})],
                                metadata={"robot": robot, "metric": metric,
                                          "better": "lower" if LOWER_IS_BETTER[metric] else "higher"})
        self.tmp = self.path.with_name(f".{self.path.name}.{os.getpid()}.tmp")
        try:
            self._w = pq.ParquetWriter(self.tmp, self.schema)
        except OSError as err:  # pyarrow's error carries no file name: the command ended in a traceback
            raise BatchError(f"{self.path}: cannot write the table ({' '.join(str(err.strerror or err).split())})") \
                from None

    def write(self, index: np.ndarray, shape: tuple[int, ...], values: np.ndarray) -> None:
        sub = np.unravel_index(index, shape)
        cols = [index, *(a.values[s] for a, s in zip(self.axes, sub, strict=True)), values[:, 0], values[:, 1]]
        self._w.write_table(self._pa.Table.from_arrays([self._pa.array(c) for c in cols], schema=self.schema))

    def close(self) -> None:
        self._w.close()
        os.replace(self.tmp, self.path)

    def abort(self) -> None:
        """Remove the temporary file of a sweep that did not finish (nothing once :meth:`close` renamed it)."""
        self._w.close()
        self.tmp.unlink(missing_ok=True)


def plot_sweep(result: SweepResult, path: str | os.PathLike[str]) -> None:
    """The metric over the first axis (a line) or the first two (a map; the best over any other axes)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    g = np.where(np.isfinite(result.grid), result.grid, np.nan)
    a0 = result.axes[0]
    fig, ax = plt.subplots(figsize=(6, 4.5))
    best = result.best[0] if result.best else None
    if best is not None and not math.isfinite(best[result.metric]):
        best = None  # nothing to mark
    label = lambda a: f"{a.label} [{a.shown_unit}]"  # noqa: E731 - angles in degrees, as typed into --vary
    with np.errstate(all="ignore"):  # kappa >= 1 spanning decades: a log scale (not over a few per cent of one)
        log = result.metric in ("kappa_mean", "kappa_max") and np.nanmin(g, initial=np.inf) > 0 \
            and np.nanmax(g, initial=0.0) > 10 * np.nanmin(g, initial=np.inf)
    if np.isnan(g).all():  # every design singular or immobile: a log colour scale of no data raised ValueError
        ax.text(0.5, 0.5, f"no finite {result.metric}: every design is singular\nat a configuration sampled, or "
                "cannot move", ha="center", va="center", transform=ax.transAxes)
        ax.set_xlabel(label(a0) if len(result.axes) == 1 else label(result.axes[1]))
        ax.set_ylabel(result.metric if len(result.axes) == 1 else label(a0))
    elif len(result.axes) == 1:
        ax.plot(a0.shown(a0.values), g, "-o", ms=3)
        if log:
            ax.set_yscale("log")
        ax.set_xlabel(label(a0))
        ax.set_ylabel(result.metric)
        if best is not None:
            ax.plot(a0.shown(best[a0.label]), best[result.metric], "r*", ms=14, label="best")
    else:
        a1 = result.axes[1]
        from matplotlib.colors import LogNorm

        mesh = ax.pcolormesh(a1.shown(a1.values), a0.shown(a0.values), g, shading="nearest",
                             cmap="viridis_r" if log else "viridis",
                             norm=LogNorm() if log else None)
        fig.colorbar(mesh, ax=ax, label=result.metric + (" (best over other axes)" if len(result.axes) > 2 else ""))
        ax.set_xlabel(label(a1))
        ax.set_ylabel(label(a0))
        if best is not None:
            ax.plot(a1.shown(best[a1.label]), a0.shown(best[a0.label]), "r*", ms=14, label="best")
    if best is not None:
        ax.legend(loc="best", fontsize=8)
    ax.set_title(f"{result.robot}: {result.metric} over {result.total:,} designs")
    fig.tight_layout()
    try:
        fig.savefig(path)
    finally:  # a failed write leaves no open figure behind
        plt.close(fig)
