"""Batch benchmarks (issue 15): fleet odometry on two Dask workers against the serial engine, the engine's
per-log overhead, and a sweep of 10^7 four-wheel geometries in bounded memory.

Targets: 1000 logs of 10^4 samples at >= 1.7x the serial throughput with two workers; the engine's overhead per
log < 5 ms; the 10^7-design sweep completes with a progress bar, the client's peak memory printed. The logs are
one synthetic CSV hard-linked 1000 times (each is read and integrated separately; the page cache holds the
bytes, as it would for a fleet's recent logs). The cluster start-up is timed separately and not counted.
"""

from __future__ import annotations

import os
import resource
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from wmrkit import catalog
from wmrkit.batch.engine import engine
from wmrkit.batch.fleet import batch_odometry
from wmrkit.batch.sweep import sweep
from wmrkit.batch.sweep_kernel import parse_vary
from wmrkit.odometry.logs import write_csv
from wmrkit.odometry.synthetic import TwistProfile, simulate

from ._harness import Result

SWEEP_AXES = ("wheels[0].gamma,wheels[3].gamma=30deg:60deg:50", "wheels[1].gamma,wheels[2].gamma=-60deg:-30deg:50",
              "wheels.front_left.l,wheels.front_right.l=0.3:0.45:40",
              "wheels.rear_left.l,wheels.rear_right.l=0.3:0.45:100")


def _noop(x):
    return x


def _logs(folder: Path, n: int, samples: int) -> list[str]:
    robot = catalog.load("diff-drive")
    rate = 100.0
    profile = TwistProfile.from_segments([((samples - 1) / rate / 2, 0.5, 0.0, 0.3),
                                          ((samples - 1) / rate / 2, 0.4, 0.0, -0.2)])
    run = simulate(robot, profile, rate, spin_noise_per_rad=1e-6, oversample=1)
    first = folder / "log0000.csv"
    write_csv(first, ("time", *run.log.joints), np.column_stack([run.log.time, run.log.positions]))
    paths = [first]
    for i in range(1, n):
        p = folder / f"log{i:04d}.csv"
        os.link(first, p)
        paths.append(p)
    return [os.fspath(p) for p in paths]


def run(quick: bool) -> list[Result]:
    n_logs, samples = (100, 10_000) if quick else (1000, 10_000)
    robot = catalog.load("diff-drive")
    results = []
    with tempfile.TemporaryDirectory() as tmp:
        logs = _logs(Path(tmp), n_logs, samples)
        serial = engine(workers=0)
        t0 = time.perf_counter()
        cluster = engine(workers=2)
        print(f"local cluster of 2 workers started in {time.perf_counter() - t0:.2f} s", flush=True)
        try:
            for r in (serial, cluster):  # warm up: numba kernels compiled (or loaded from cache) in every process
                batch_odometry(robot, logs[:8], runner=r)
            t0 = time.perf_counter()
            res = batch_odometry(robot, logs, runner=serial)
            t_serial = time.perf_counter() - t0
            t0 = time.perf_counter()
            batch_odometry(robot, logs, runner=cluster, progress=sys.stderr.isatty())
            t_cluster = time.perf_counter() - t0
            assert res.failed == 0
            compute = sum(r["seconds"] for r in res.rows) / n_logs
            results.append(Result(f"batch odometry, {n_logs} logs x {samples} samples, 2 workers", n_logs * samples,
                                  t_cluster, "serial engine", t_serial, ">= 1.7x serial"))
            t0 = time.perf_counter()
            cluster.map(_noop, range(n_logs), chunk=max(1, min(16, n_logs // 16)))  # as batch_odometry sends
            per_task = (time.perf_counter() - t0) / n_logs
            print(f"per-log work {compute * 1e3:.2f} ms; engine overhead per log: {per_task * 1e3:.2f} ms round trip "
                  f"of an empty item on 2 workers, {(2 * t_cluster / n_logs - compute) * 1e3:.2f} ms per log in the "
                  f"batch (2 x wall / logs - work) [target < 5 ms]", flush=True)
            results.append(Result("engine: empty tasks, 2 workers", n_logs, per_task * n_logs, "target 5 ms/log",
                                  0.005 * n_logs, "< 5 ms per log"))
            results.append(_sweep(cluster, quick))
        finally:
            cluster.close()
    return results


def _sweep(runner, quick: bool) -> Result:
    robot = catalog.load("mecanum-4")
    axes = [parse_vary(a, robot) for a in SWEEP_AXES]
    if quick:
        axes[3] = parse_vary("wheels.rear_left.l,wheels.rear_right.l=0.3:0.45:10", robot)
    t0 = time.perf_counter()
    res = sweep(robot, axes, "kappa_mean", runner=runner, length=0.4, chunk=1 << 14, progress=True)
    wall = time.perf_counter() - t0
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    best = res.best[0]
    print(f"sweep: {res.total:,} mecanum-4 designs (kappa_mean, D = 0.4 m) in {wall:.1f} s on {runner.workers} "
          f"workers, {res.chunks} chunks; client peak RSS {peak:.0f} MB; best kappa {best['kappa_mean']:.6g} at "
          + ", ".join(f"{a.label} = {best[a.label]:.4g}" for a in axes), flush=True)
    return Result(f"sweep, {res.total:,} geometries of mecanum-4", res.total, wall, "none", None, "completes")
