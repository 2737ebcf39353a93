"""The same API on a real Dask cluster: two worker processes, one thread each, started once for this module.

Results are compared bit for bit with the serial engine; the scheduler's address is also used as a "remote"
scheduler (a new client connecting over TCP, what a user with a cluster does); a worker killed mid-batch
does not stop the batch.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pytest
from batch_params import die_once

from wmrkit import catalog
from wmrkit.batch.calibrate import fleet_calibrate, load_runs
from wmrkit.batch.engine import engine
from wmrkit.batch.fleet import LogJob, batch_odometry, expand_logs, process_log
from wmrkit.batch.montecarlo import monte_carlo, path_log
from wmrkit.batch.sweep import sweep
from wmrkit.batch.sweep_kernel import parse_vary

distributed = pytest.importorskip("distributed")
pytest.importorskip("pyarrow")


@pytest.fixture(scope="module")
def cluster():
    # the workers import the tasks of batch_params by name: this folder goes on their path
    path = os.pathsep.join(p for p in (str(Path(__file__).parent), os.environ.get("PYTHONPATH", "")) if p)
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None,
                                  silence_logs=50, env={"PYTHONPATH": path}) as c, distributed.Client(c) as client:
        yield c, client


@pytest.fixture(scope="module")
def engines(cluster):
    c, client = cluster
    local = engine(client)
    remote = engine(c.scheduler_address)
    yield {"local": local, "remote": remote}
    remote.close()


def _strip(rows):
    return [{k: v for k, v in r.items() if k != "wall_time"} for r in rows]


def test_batch_odometry_bit_identical_with_a_failing_log_and_resume(engines, fleet_dir, diff, tmp_path):
    serial = batch_odometry(diff, [fleet_dir], closed=True)
    assert serial.failed == 1
    for name, runner in engines.items():
        assert runner.workers == 2
        out = tmp_path / f"{name}.parquet"
        res = batch_odometry(diff, [fleet_dir], runner=runner, closed=True, out=out)
        assert _strip(res.rows) == _strip(serial.rows), name  # == on floats: bit for bit
        again = batch_odometry(diff, [fleet_dir], runner=runner, closed=True, out=out)
        assert again.skipped == 5 and _strip(again.rows) == _strip(serial.rows)


def test_sweep_montecarlo_calibration_identical(engines, diff, calibration_data):
    robot = catalog.load("mecanum-4")
    axes = [parse_vary("wheels[0].gamma,wheels[3].gamma=30deg:60deg:9", robot),
            parse_vary("wheels.front_left.l,wheels.front_right.l=0.3:0.45:7", robot)]
    s0 = sweep(robot, axes, chunk=10)
    square = path_log(diff, "square", 5.0)
    m0 = monte_carlo(diff, square, 40, block=8)
    runs = load_runs(diff, expand_logs([calibration_data / "*.csv"]), reference_dir=calibration_data / "ref")
    params = ["left.r", "right.r", ("left.l", "right.l")]
    c0 = fleet_calibrate(diff, runs, params)
    for name, runner in engines.items():
        s = sweep(robot, axes, chunk=10, runner=runner)
        assert s.best == s0.best and np.array_equal(s.grid, s0.grid), name
        m = monte_carlo(diff, square, 40, block=8, runner=runner)
        np.testing.assert_array_equal(m.poses, m0.poses)
        c = fleet_calibrate(diff, runs, params, runner=runner)
        assert c.values == c0.values and c.interval == c0.interval
        assert c.residual_ratios == c0.residual_ratios and c.warnings == c0.warnings
        assert load_runs(diff, [str(calibration_data / "c0.csv")], reference_dir=calibration_data / "ref",
                         runner=runner)[0].reference.tolist() == runs[0].reference.tolist()


def test_tasks_of_several_logs_with_a_shared_model(engines, fleet_dir, diff):
    from wmrkit.odometry.model import odometry_model

    model = odometry_model(diff)  # as batch_odometry sends it: one model, pickled once per task
    jobs = [LogJob(p, diff, closed=True, model=model) for p in expand_logs([fleet_dir])] * 4
    serial = [process_log(LogJob(j.path, diff, closed=True)) for j in jobs]  # the model built per log
    out = engines["local"].map(process_log, jobs, chunk=5)
    assert _strip(out) == _strip(serial) and sum(r["error"] is not None for r in out) == 4


def test_a_worker_killed_mid_batch(engines, fleet_dir, diff, tmp_path):
    jobs = [LogJob(p, diff) for p in expand_logs([fleet_dir])]
    marker = str(tmp_path / "killed")
    runner = engines["local"]
    out = runner.map(die_once, [(j, marker) for j in jobs], chunk=2)  # the dead worker's task of 2 logs is redone
    assert os.path.exists(marker)  # a worker did die
    assert _strip(out) == _strip([process_log(j) for j in jobs])
    runner.client.wait_for_workers(2, timeout=60)  # the nanny restarted it


def test_embedded_cluster():
    with engine(workers=1) as e:
        assert e.mode == "local" and e.workers == 1
        assert e.map(abs, [-1, -2]) == [1, 2]
        # glibc's malloc defaults (not the nanny's 64 kB trim threshold, which the module's default cluster has
        # meanwhile left in this process's os.environ) and no profiler
        settings = e.client.run(lambda: (os.environ.get("MALLOC_TRIM_THRESHOLD_"),  # a lambda travels by value
                                         __import__("dask").config.get("distributed.worker.profile.enabled")))
        assert list(settings.values()) == [(None, False)]


def test_cli_on_the_remote_scheduler(cluster, fleet_dir, capsys):
    import json

    from wmrkit.cli.main import main

    c, _ = cluster
    argv = ["batch", "odometry", "diff-drive", str(fleet_dir), "--closed", "--json"]
    assert main([*argv, "--scheduler", c.scheduler_address]) == 1  # the broken log fails: exit 1
    remote = json.loads(capsys.readouterr().out)
    assert main([*argv, "--workers", "0"]) == 1
    serial = json.loads(capsys.readouterr().out)
    assert _strip(remote["rows"]) == _strip(serial["rows"]) and remote["failed"] == 1


def test_closed_path_fleet_judged_identically(engines, diff):
    """Six closed squares, one of another robot: the closed-path scores (a refit on the engine) are those of the
    serial engine, bit for bit, and name the same run."""
    from batch_params import closed_fleet

    params, runs = closed_fleet(diff, 1, [0.06, 0.03])
    c0 = fleet_calibrate(diff, runs, params)
    assert c0.inconsistent is True
    for name, runner in engines.items():
        c = fleet_calibrate(diff, runs, params, runner=runner)
        assert c.closed_scores == c0.closed_scores and c.warnings == c0.warnings, name


def test_a_failed_refit_leaves_the_calibration_not_judged(engines, diff, monkeypatch):
    """The closed-path judge's one refit raises (on the cluster and serially): the whole calibration failed as 'task 0
    failed' with the fit lost. Now the fit is returned, the same, and the runs are not judged: one reason naming the
    run left out and the error."""
    from batch_params import closed_fleet, refit_fails

    from wmrkit.batch import calibrate

    params, runs = closed_fleet(diff, 1, [0.06, 0.03])
    c0 = fleet_calibrate(diff, runs, params)
    monkeypatch.setattr(calibrate, "_refit_without", refit_fails)
    for name, runner in {"serial": None, **engines}.items():
        c = fleet_calibrate(diff, runs, params, runner=runner)
        assert c.estimate == c0.estimate and c.interval == c0.interval, name
        assert c.inconsistent is None and c.residual_ratios == c.closed_scores == (None,) * 6, name
        assert c.not_judged.startswith("run 1 (<synthetic>): the fit of the other runs without it failed "
                                       "(RuntimeError: injected refit failure)"), c.not_judged
        assert c.to_dict()["not_judged"] == c.not_judged and not [w for w in c.warnings if "disagrees" in w]


def test_a_failed_curvature_leaves_the_calibration_not_judged(engines, diff, monkeypatch):
    """The closed-path judge's curvature (the fleet Jacobian one step from the fit) raises on a worker: the whole
    calibration failed as 'task 0 failed' (exit 2), the fit lost, where a failed refit kept it. Now the same as a
    failed refit: the fit returned, the runs not judged, the reason naming the runs of the failed task and the error."""
    from batch_params import closed_fleet, curvature_fails

    from wmrkit.batch import calibrate

    params, runs = closed_fleet(diff, 1, [0.06, 0.03])
    c0 = fleet_calibrate(diff, runs, params)
    assert c0.inconsistent is True  # judged without the failure (the odd run named)
    monkeypatch.setattr(calibrate, "_curvature_of", curvature_fails)
    for name, runner in {"serial": None, **engines}.items():
        c = fleet_calibrate(diff, runs, params, runner=runner)
        assert c.estimate == c0.estimate and c.interval == c0.interval, name
        assert c.inconsistent is None and c.residual_ratios == c.closed_scores == (None,) * 6, name
        runs_named = "every run" if name == "serial" else ", ".join(f"run {k} (<synthetic>)" for k in (1, 3, 5))
        assert c.not_judged.startswith(f"{runs_named}: the Jacobian 0.001 from the fleet fit"), (name, c.not_judged)
        assert "(RuntimeError: injected curvature failure)" in c.not_judged, c.not_judged
        assert c.to_dict()["not_judged"] == c.not_judged and not [w for w in c.warnings if "disagrees" in w]


def test_slip_aware_batch_odometry_is_bit_identical_on_the_cluster(engines, tmp_path):
    """FK2 and WLS (``method="fk2"``, ``"wls"``): each worker builds the log's estimator from the batch's spec; the
    rows are the serial engine's, bit for bit."""
    from wmrkit.odometry.logs import write_csv
    from wmrkit.slip.synthetic import wheel_speed_run
    from wmrkit.slip.weights import SlipWeights

    robot = catalog.load("skid-steer-4")
    for i, wheels in enumerate(([8, 12, 8, 12], [12, 8, 12, 8], [6, 14, 6, 14])):
        run = wheel_speed_run(robot, [(2.0, wheels), (1.0, [10, 10, 10, 10])], 20.0, model="mqe")
        write_csv(tmp_path / f"s{i}.csv", ("time", *run.log.joints), np.column_stack([run.log.time, run.log.positions]))
    for options in ({"method": "fk2", "scheme": "rk2"}, {"method": "wls", "slip_weights": SlipWeights.uniform(0.3)}):
        serial = batch_odometry(robot, [tmp_path], **options)
        assert serial.failed == 0 and len(serial.rows) == 3
        for name, runner in engines.items():
            assert _strip(batch_odometry(robot, [tmp_path], runner=runner, **options).rows) == _strip(serial.rows), name
