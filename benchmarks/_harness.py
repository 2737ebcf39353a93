"""Helpers shared by the benchmark modules: best-of-N wall time, one printed line per comparison, the forklift log."""

from __future__ import annotations

import importlib
import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from wmrkit import catalog
from wmrkit.odometry.logs import JointLog
from wmrkit.odometry.model import odometry_model


@dataclass(frozen=True)
class Result:
    """One comparison: wmrkit's time against a peer's on the same work (`n` items)."""

    name: str
    n: int
    ours_s: float
    peer: str
    peer_s: float | None  # None when the peer is absent
    target: str = ""

    def line(self) -> str:
        rate = self.n / self.ours_s
        text = f"{self.name:<46} {self.n:>10,d} items  {_time(self.ours_s)}  {rate / 1e6:8.2f} M/s"
        if self.peer_s is None:
            text += f"  | peer {self.peer}: ABSENT"
        else:
            text += f"  | {self.peer}: {_time(self.peer_s)}  ratio {self.peer_s / self.ours_s:8.1f}x"
        return text + (f"  [target: {self.target}]" if self.target else "")


def _time(seconds: float) -> str:
    """Milliseconds, microseconds below one millisecond (single calls), nanoseconds below one microsecond."""
    if seconds >= 1e-3:
        return f"{seconds * 1e3:9.2f} ms"
    return f"{seconds * 1e6:9.2f} us" if seconds >= 1e-6 else f"{seconds * 1e9:9.2f} ns"


def best_time(fn: Callable[[], object], *, repeat: int = 3) -> float:
    """Best wall time of `repeat` calls of `fn` [s]."""
    best = float("inf")
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t0)
    return best


def peer(module: str):
    """Import a peer library, or None when it is absent (the runner then says so)."""
    try:
        return importlib.import_module(module)
    except ImportError:
        return None


def forklift_log(n: int) -> JointLog:
    """A forklift log at 1 kHz: drive spins with noise, and a steering angle that wanders within +-30 encoder steps of
    straight ahead (a random walk reflected at the ends, never jumping), quantised to the 1.4118 deg encoder."""
    rng = np.random.default_rng(2)
    walk = np.cumsum(rng.normal(0, 0.05, n))
    steps = np.round(np.abs((walk - 30) % 120 - 60) - 30)  # reflected into [-30, 30]
    pos = np.column_stack([np.cumsum(rng.normal(0.01, 0.001, size=(n, 2)), axis=0), np.radians(90 + 1.4118 * steps)])
    return JointLog(np.arange(n) * 1e-3, odometry_model(catalog.load("forklift")).joints, pos)
