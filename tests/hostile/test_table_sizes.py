"""Files read whole (trajectories, references, torque files, a Monte Carlo LOG) are refused above
``limits.MAX_TABLE_SIZE`` bytes, naming the file, before they are read: bounded memory (the joint logs of odometry
stream and have no such limit)."""

from __future__ import annotations

import contextlib
import io

import pytest

from wmrkit import catalog, limits
from wmrkit.cli.main import main
from wmrkit.control.references import load_reference
from wmrkit.dynamics.model import DynamicModel
from wmrkit.dynamics.programs import read_torques
from wmrkit.errors import WmrkitError
from wmrkit.odometry.trajectories import read_trajectory_csv, read_tum

TUM = "0 0 0 0 0 0 0 1\n1 1 0 0 0 0 0 1\n2 2 0 0 0 0 0 1\n"


@pytest.fixture
def files(tmp_path):
    paths = {"tum": tmp_path / "ref.tum", "csv": tmp_path / "ref.csv", "traj": tmp_path / "traj.csv",
             "torques": tmp_path / "tau.csv", "log": tmp_path / "log.csv"}
    paths["tum"].write_text(TUM)
    paths["csv"].write_text("t,x,y,theta\n0,0,0,0\n1,1,0,0\n2,2,0,0\n")
    paths["traj"].write_text("time,x,y,theta,slip\n0,0,0,0,0\n1,1,0,0,0\n")
    paths["torques"].write_text("time,left_drive.spin,right_drive.spin\n0,10,10\n1,10,10\n")
    paths["log"].write_text("time,front_left.spin,front_right.spin,rear_left.spin,rear_right.spin\n"
                            + "".join(f"{k},{k},{k},{k},{k}\n" for k in range(3)))
    return paths


def _readers():
    forklift = DynamicModel.of(catalog.load("forklift"))
    return {"tum": read_tum, "csv": load_reference, "traj": read_trajectory_csv,
            "torques": lambda p: read_torques(forklift, p)}


def test_files_at_the_limit_are_read_and_larger_ones_refused(files, monkeypatch):
    readers = _readers()
    for key, path in files.items():
        if key == "log":
            continue
        monkeypatch.setattr(limits, "MAX_TABLE_SIZE", path.stat().st_size)
        readers[key](path)  # exactly at the limit: read
        monkeypatch.setattr(limits, "MAX_TABLE_SIZE", path.stat().st_size - 1)
        with pytest.raises(WmrkitError, match=rf"{path.name}: {path.stat().st_size} bytes: .* at most"):
            readers[key](path)
    assert load_reference(files["tum"]).t.shape == (3,)  # the TUM branch of load_reference is bounded too
    monkeypatch.setattr(limits, "MAX_TABLE_SIZE", 10)
    with pytest.raises(WmrkitError, match=r"ref\.tum: .* bytes"):
        load_reference(files["tum"])


@pytest.mark.parametrize("argv", [["simulate", "forklift", "--torques", "{torques}"],
                                  ["track", "diff-drive", "--reference", "{tum}"],
                                  ["calibrate", "skid-steer-4", "{log}", "--reference", "{tum}"],
                                  ["batch", "montecarlo", "skid-steer-4", "{log}", "-n", "2", "--workers", "0"]])
def test_the_commands_refuse_them_in_one_line(files, monkeypatch, argv):
    monkeypatch.setattr(limits, "MAX_TABLE_SIZE", 10)
    err = io.StringIO()
    with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
        code = main([a.format(**{k: str(v) for k, v in files.items()}) for a in argv])
    assert code == 2
    lines = err.getvalue().strip().splitlines()
    assert len(lines) == 1 and "bytes: a" in lines[0] and "at most 10 bytes" in lines[0]
