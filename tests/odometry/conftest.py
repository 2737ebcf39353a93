"""Fixtures of the odometry tests: synthetic runs and the log files written from them."""

from __future__ import annotations

import numpy as np
import pytest

from wmrkit import catalog
from wmrkit.odometry.logs import write_csv
from wmrkit.odometry.synthetic import SyntheticRun, TwistProfile, simulate


def csv_of(path, run: SyntheticRun, names=None, robot=None) -> str:
    """Write the log of `run` as a CSV (time + joint angles, steering as headings of `robot`'s wheels) and return
    the path as a string."""
    names = names or ("time", *run.log.joints)
    write_csv(path, names, np.column_stack([run.log.time, run.log.heading_positions(robot)]))
    return str(path)


@pytest.fixture(scope="session")
def diff_run() -> SyntheticRun:
    """A differential drive on an S-shaped path (arc left, straight, arc right), 20 Hz."""
    profile = TwistProfile.from_segments([(3.0, 0.4, 0.0, 0.5), (2.0, 0.5, 0.0, 0.0), (3.0, 0.4, 0.0, -0.6)])
    return simulate(catalog.load("diff-drive"), profile, 20.0)


@pytest.fixture
def diff_csv(tmp_path, diff_run) -> str:
    """The differential-drive run as a default-format CSV log."""
    return csv_of(tmp_path / "diff.csv", diff_run)


@pytest.fixture
def write_log():
    """The helper :func:`csv_of` (fixtures, not imports: ``conftest`` names clash between test folders)."""
    return csv_of
