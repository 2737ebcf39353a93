"""Where batch work runs: serially in this process, on an embedded Dask ``LocalCluster``, or on a Dask scheduler.

One API for the three (:class:`Engine`): ``map`` (results in input order) and ``as_completed`` (``(index,
result)`` pairs as they finish, what a progress bar and incremental output need). Tasks are module-level
functions of picklable arguments, so a task computes the same floats wherever it runs: results are identical
across the three engines (tested bit for bit). Dask (the ``batch`` extra, ``dask[distributed]``) is imported
only when a cluster is asked for; without it :func:`engine` with no scheduler falls back to serial work and
says so once on stderr, and a scheduler address raises :class:`BatchError` naming the extra.

Failures: a task that raises is returned as a :class:`TaskFailure` (its error message) instead of a result
(``errors="return"``) or re-raised (``errors="raise"``). A worker that dies mid-task (killed, ``os._exit``) is
the scheduler's business: the task is re-run on another worker (``retries`` and Dask's
``distributed.scheduler.allowed-failures``); the batch completes.
"""

from __future__ import annotations

import contextlib
import itertools
import os
import sys
from collections.abc import Callable, Iterable, Iterator, Sequence
from dataclasses import dataclass
from numbers import Integral
from typing import Any, Literal

from ..errors import WmrkitError

#: The optional dependency group that provides Dask and pyarrow.
EXTRA = "batch"


#: Dask settings of the embedded ``LocalCluster`` (read when it starts; a remote cluster keeps its own). Dask's
#: nanny starts workers with ``MALLOC_TRIM_THRESHOLD_=65536``, which turns every array above 128 kB into a fresh
#: ``mmap`` and costs a log's parsing about 20 % more CPU (page faults) than in the serial engine: workers get
#: glibc's default instead (also when an earlier cluster left the variable in ``os.environ``). The statistical
#: profiler (a stack sample every 10 ms) and the 20 ms event-loop tick and 100 ms memory monitor cost an idle
#: two-worker cluster 6 % of a core; they only feed the dashboard, and the memory limit is still enforced (every
#: second).
LOCAL_CLUSTER_CONFIG = {
    "distributed.nanny.pre-spawn-environ.MALLOC_TRIM_THRESHOLD_": None,
    "distributed.worker.profile.enabled": False,
    "distributed.admin.tick.interval": "500ms",
    "distributed.admin.system-monitor.interval": "2s",
    "distributed.worker.memory.monitor-interval": "1s",
}


class BatchError(WmrkitError, ValueError):
    """A batch that cannot run as asked (missing extra, bad scheduler address, bad options)."""


def need_extra(module: str) -> Any:
    """Import `module` (a dependency of the ``batch`` extra) or raise :class:`BatchError` naming the extra."""
    import importlib

    try:
        return importlib.import_module(module)
    except ImportError:
        raise BatchError(f"the '{EXTRA}' extra is needed for {module.split('.')[0]}: "
                         f"pip install 'wmrkit[{EXTRA}]'") from None


@dataclass(frozen=True, slots=True)
class TaskFailure:
    """A task that raised: its position in the input, the exception's type name (``WmrkitError`` for every error of
    wmrkit's, whose messages stand alone) and one-line message."""

    index: int
    kind: str
    message: str

    def __str__(self) -> str:
        return f"{self.kind}: {self.message}" if self.kind != "WmrkitError" else self.message


def _call(fn: Callable[[Any], Any], index: int, item: Any) -> tuple[int, bool, Any]:
    """Run ``fn(item)``; ``(index, ok, result or (kind, message))``: a task never raises, so one bad item cannot
    stop the batch, and the error travels back as plain strings (any exception pickles that way)."""
    try:
        return index, True, fn(item)
    except Exception as err:  # wmrkit's own errors are one-line messages: no class name in front (HeaderError: ...)
        kind = "WmrkitError" if isinstance(err, WmrkitError) else type(err).__name__
        return index, False, (kind, " ".join(str(err).split()) or repr(err))


class Engine:
    """Runs functions over items: ``mode`` ``"serial"``, ``"local"`` (embedded cluster) or ``"remote"``.

    Use :func:`engine` to make one; close it (or use it as a context manager) to stop an embedded cluster.
    """

    def __init__(self, mode: Literal["serial", "local", "remote"], client: Any = None, cluster: Any = None,
                 retries: int = 2, owns_client: bool = True) -> None:
        self.mode, self.client, self._cluster, self.retries = mode, client, cluster, retries
        self._owns = owns_client

    @property
    def workers(self) -> int:
        """Number of worker processes (1 for serial)."""
        return 1 if self.client is None else max(len(self.client.scheduler_info().get("workers", {})), 1)

    def as_completed(self, fn: Callable[[Any], Any], items: Sequence[Any], *, progress: bool = False,
                     desc: str = "batch", errors: Literal["return", "raise"] = "return",
                     chunk: int = 1) -> Iterator[tuple[int, Any]]:
        """``(index, result)`` of ``fn(items[index])`` in completion order (a :class:`TaskFailure` for a task
        that raised, with ``errors="return"``). Up to `chunk` items go to one task (less scheduler traffic for
        small items; :func:`chunk_spans`). A tqdm bar over all items shows when `progress`."""
        from tqdm import tqdm

        items = list(items)
        with tqdm(total=len(items), desc=desc, unit="task", disable=not progress, leave=False) as bar:
            for index, ok, value in self._run(fn, items, max(int(chunk), 1)):
                bar.update(1)
                if not ok:
                    failure = TaskFailure(index, *value)
                    if errors == "raise":
                        raise BatchError(f"task {index} failed: {failure}")
                    value = failure
                yield index, value

    def map(self, fn: Callable[[Any], Any], items: Iterable[Any], *, progress: bool = False, desc: str = "batch",
            errors: Literal["return", "raise"] = "raise", chunk: int = 1) -> list[Any]:
        """``[fn(item) for item in items]``, computed by the engine, in input order."""
        items = list(items)
        out: list[Any] = [None] * len(items)
        for index, value in self.as_completed(fn, items, progress=progress, desc=desc, errors=errors, chunk=chunk):
            out[index] = value
        return out

    def _run(self, fn, items: list, chunk: int) -> Iterator[tuple[int, bool, Any]]:
        if self.client is None:
            with _compiled_kernels():
                for i, item in enumerate(items):
                    yield _call(fn, i, item)
            return
        distributed = need_extra("distributed")
        spans = chunk_spans(len(items), chunk, self.workers)
        futures = self.client.map(_call_many, [fn] * len(spans), [a for a, _ in spans],
                                  [items[a:b] for a, b in spans], pure=False, retries=self.retries)
        span_of = {f.key: span for f, span in zip(futures, spans, strict=True)}
        try:
            for future in distributed.as_completed(futures):
                try:
                    results = future.result()
                except Exception as err:
                    a, b = span_of[future.key]
                    results = [(k, False, (type(err).__name__, str(err))) for k in range(a, b)]
                yield from results
                future.release()
        finally:
            for future in futures:
                future.cancel()

    def share(self, obj: Any) -> Any:
        """`obj` placed once on every worker (a future to use in Dask graphs), or `obj` itself when serial: large
        constants then travel once instead of with every task."""
        if self.client is None:
            return obj
        return self.client.scatter(obj, broadcast=True, hash=False)

    def compute(self, parts: Sequence[Any], *, window: int | None = None, progress: bool = False,
                desc: str = "chunks") -> Iterator[tuple[int, Any]]:
        """``(index, value)`` of Dask collections (e.g. the blocks of a Dask array, ``to_delayed()``) as they
        finish; at most `window` in flight (default: four per worker), so memory stays bounded. Serially, each
        is computed by Dask's synchronous scheduler in this process."""
        from tqdm import tqdm

        parts = parts if isinstance(parts, Sequence) else list(parts)  # a lazy sequence stays lazy
        with tqdm(total=len(parts), desc=desc, unit="chunk", disable=not progress, leave=False) as bar:
            if self.client is None:
                with _compiled_kernels():
                    for i, part in enumerate(parts):
                        yield i, part.compute(scheduler="synchronous")
                        bar.update(1)
                return
            distributed = need_extra("distributed")
            window = window or 4 * self.workers
            index_of: dict[str, int] = {}
            pending = iter(enumerate(parts))

            def submit(n: int) -> list:
                out = []
                for i, part in itertools.islice(pending, n):
                    future = self.client.compute(part, retries=self.retries)
                    index_of[future.key] = i
                    out.append(future)
                return out

            queue = distributed.as_completed(submit(window))
            for future in queue:
                yield index_of.pop(future.key), future.result()
                future.release()
                bar.update(1)
                for new in submit(1):
                    queue.add(new)

    def close(self) -> None:
        """Disconnect; stop the embedded cluster if this engine started one."""
        if self.client is not None and self._owns:
            self.client.close()
        if self._cluster is not None:
            self._cluster.close()
        self.client = self._cluster = None

    def __enter__(self) -> Engine:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def __repr__(self) -> str:
        return f"Engine(mode={self.mode!r}, workers={self.workers})"


def chunk_spans(n: int, chunk: int, workers: int) -> list[tuple[int, int]]:
    """``(start, stop)`` of the tasks over `n` items: `chunk` items each (fewer round trips through the
    scheduler), shrinking to ``chunk // 8`` as the work runs out (a quarter of the remaining items per worker at
    most, "guided" self-scheduling), so that at the end no worker waits long for another's last big task."""
    spans, start, least = [], 0, max(1, chunk // 8)
    while start < n:
        size = max(least, min(chunk, -(-(n - start) // (4 * max(workers, 1)))))
        spans.append((start, min(start + size, n)))
        start += size
    return spans


def _call_many(fn: Callable[[Any], Any], start: int, items: list) -> list[tuple[int, bool, Any]]:
    from .. import _jit

    _jit.INTERPRET_BUDGET = 0  # a worker lives for the batch: compile the kernels at once (see _compiled_kernels)
    return [_call(fn, start + k, item) for k, item in enumerate(items)]


@contextlib.contextmanager
def _unset_env(name: str) -> Iterator[None]:
    """`name` out of ``os.environ`` while the workers are spawned: a nanny writes its pre-spawn variables into
    this process's environment, so an earlier default Dask cluster would otherwise hand them on to ours."""
    saved = os.environ.pop(name, None)
    try:
        yield
    finally:
        if saved is not None:
            os.environ[name] = saved


@contextlib.contextmanager
def _compiled_kernels() -> Iterator[None]:
    """Batch work compiles wmrkit's numba kernels at once instead of first interpreting a budget of elements
    (:mod:`wmrkit._jit`, meant for one short command): the same machine code runs in every engine, so results
    are identical, and no worker spends its first logs in the Python source of a kernel."""
    from .. import _jit

    saved, _jit.INTERPRET_BUDGET = _jit.INTERPRET_BUDGET, 0
    try:
        yield
    finally:
        _jit.INTERPRET_BUDGET = saved


#: Most worker processes of an embedded cluster per CPU: each is a Python process of about 100 MB, and more of
#: them than CPUs only share the same cores.
WORKERS_PER_CPU = 4


def engine(scheduler: str | Any | None = None, workers: int | None = None, *, retries: int = 2,
           quiet: bool = False) -> Engine:
    """An :class:`Engine`: `scheduler` an address (``tcp://host:8786``) or a ``distributed.Client``; else, with
    ``workers`` 0 a serial engine, otherwise an embedded ``LocalCluster`` of `workers` processes (default: the
    CPU count, at most :data:`WORKERS_PER_CPU` per CPU), one thread each. Without Dask installed and no scheduler:
    serial, with one line on stderr."""
    cpus = os.cpu_count() or 1
    if scheduler is not None and workers is not None:  # the scheduler's cluster has its own workers: ignored
        raise BatchError("--workers sets the size of the embedded cluster; a --scheduler's cluster has its own workers")
    if workers is not None and (isinstance(workers, bool) or not isinstance(workers, Integral)  # True: a cluster of
                                or not 0 <= workers <= WORKERS_PER_CPU * cpus):           # 'True' workers failed
        raise BatchError(f"--workers must be in [0, {WORKERS_PER_CPU * cpus}] ({WORKERS_PER_CPU} per CPU of this "
                         f"machine; a larger fleet needs a cluster: --scheduler), got {workers}")
    if scheduler is None and workers == 0:
        return Engine("serial", retries=retries)
    if scheduler is None:
        try:
            distributed = need_extra("distributed")
        except BatchError as err:
            if not quiet:
                print(f"wmrkit: {err}; running serially", file=sys.stderr)
            return Engine("serial", retries=retries)
        n = workers or cpus
        # ":0": the scheduler's HTTP server (and the dashboard, when bokeh is installed) on a free port, so that
        # several batches on one machine do not compete for port 8787
        with need_extra("dask").config.set(LOCAL_CLUSTER_CONFIG), _unset_env("MALLOC_TRIM_THRESHOLD_"):
            cluster = distributed.LocalCluster(n_workers=n, threads_per_worker=1, processes=True,
                                               dashboard_address=":0", silence_logs=40)
        return Engine("local", distributed.Client(cluster), cluster, retries=retries)
    distributed = need_extra("distributed")
    if isinstance(scheduler, distributed.Client):
        return Engine("remote", scheduler, retries=retries, owns_client=False)
    try:
        client = distributed.Client(str(scheduler), timeout="10s")
    except (OSError, TimeoutError, ValueError) as err:
        raise BatchError(f"--scheduler {scheduler}: cannot connect ({' '.join(str(err).split())})") from None
    return Engine("remote", client, retries=retries)
