"""Fixtures of the batch tests: small synthetic logs written at test time (wmrkit.odometry.synthetic)."""

from __future__ import annotations

import numpy as np
import pytest

#: Parameters of the differential drive fitted in the calibration tests, and the "true" robot's offsets.
from batch_params import PARAMS, TRUE_P, write_log

from wmrkit import catalog
from wmrkit.odometry.calibration import apply_parameters
from wmrkit.odometry.synthetic import TwistProfile, simulate, square_path
from wmrkit.odometry.trajectories import Trajectory, write_trajectory


@pytest.fixture(scope="session")
def diff():
    return catalog.load("diff-drive")


@pytest.fixture(scope="session")
def fleet_dir(tmp_path_factory, diff):
    """Five closed square runs of a differential drive (noisy, 10 Hz) and one log with a repeated timestamp."""
    d = tmp_path_factory.mktemp("fleet")
    for i in range(5):
        run = simulate(diff, square_path(1.0 + 0.2 * i), 10.0, spin_noise_per_rad=1e-5, seed=i)
        write_log(d / f"run{i}.csv", run)
    (d / "broken.csv").write_text("time,left.spin,right.spin\n0,0,0\n0.1,0.1,0.1\n0.1,0.2,0.2\n")
    return d


@pytest.fixture(scope="session")
def calibration_data(tmp_path_factory, diff):
    """Eight runs of a robot whose radii and track differ from the catalog's: logs, reference TUM files."""
    true = apply_parameters(diff, PARAMS, TRUE_P)
    d = tmp_path_factory.mktemp("cal")
    (d / "ref").mkdir()
    rng = np.random.default_rng(7)
    for i in range(8):
        segs = [(2.0, 0.3 + 0.1 * rng.random(), 0.0, rng.uniform(-0.6, 0.6)) for _ in range(3)]
        run = simulate(true, TwistProfile.from_segments(segs), 10.0, spin_noise_per_rad=1e-5, seed=i)
        write_log(d / f"c{i}.csv", run)
        write_trajectory(d / "ref" / f"c{i}.tum", Trajectory(run.log.time, run.truth, np.zeros(len(run.log)), None),
                         "tum")
    return d
