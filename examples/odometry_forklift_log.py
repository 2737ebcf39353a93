"""The forklift of thesis ch. 7 from raw encoder counts: a CSV log in, a TUM trajectory and a plot out.

Its drive wheels have incremental encoders of 8290 pulses per revolution (here on 16-bit counters that wrap) and
its steered wheel an absolute encoder of 1.4118 deg (thesis §7.5.1) reading the wheel's heading, 0 straight ahead,
like every steering angle in a log (docs/conventions.md). A synthetic drive (an S-curve with stops to
steer) is written as a counts log whose header gives the units (``right_drive.spin [counts:u16]``), then read back
the way ``wmrkit odometry forklift LOG --out path.tum`` does. The steering quantisation makes the sensors slightly
inconsistent: the slip indicator (least-squares residual, thesis (4.11)) shows it, and with equal weights the
least squares lets the coarse steering angle bend the path. Trusting the steered wheel's equations less
(``--weight steer=0.02``, the weighting idea of the thesis's WLS, §7.4.4) brings the drive wheels' accuracy
back while the residual still reports the disagreement. Run: ``python examples/odometry_forklift_log.py [DIR]``.
"""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path

import numpy as np

from wmrkit import catalog
from wmrkit.odometry.encoders import encoders_for
from wmrkit.odometry.files import odometry_file
from wmrkit.odometry.logs import LogFormat, write_csv
from wmrkit.odometry.model import odometry_model
from wmrkit.odometry.synthetic import TwistProfile, simulate
from wmrkit.odometry.trajectories import read_tum

out_dir = Path(sys.argv[1]) if len(sys.argv) > 1 else Path(tempfile.mkdtemp(prefix="wmrkit-forklift-"))
out_dir.mkdir(parents=True, exist_ok=True)
robot = catalog.load("forklift")
joints = odometry_model(robot).joints
encoders = dict(encoders_for("forklift", joints, bits=16))

# twists of the drive-axle midpoint (1 m behind the fork tips, the origin): arcs, stops to steer, straight
path = TwistProfile.from_segments([(6.0, 1.5, 0.0, 0.15), (1.0, 0, 0, 0), (4.0, 1.5, 0.0, 0.0), (1.0, 0, 0, 0),
                                   (6.0, 1.5, 0.0, -0.2)]).about((-1.0, 0.0))
run = simulate(robot, path, 100.0, encoders=encoders)
log_path = out_dir / "forklift_counts.csv"
# the header says what the columns hold: counts of 16-bit counters, so `wmrkit odometry forklift LOG` needs no options
write_csv(log_path, ("time [s]", *(f"{j} [counts:u16]" if j.endswith(".spin") else f"{j} [counts]" for j in joints)),
          np.column_stack([run.log.time, *(run.counts[j] for j in joints)]), fmt="%.10g")

fmt = LogFormat(spin="counts", steer="counts", encoders=tuple(encoders.items()), time_column="time [s]",
                columns=tuple((j, f"{j} [counts:u16]" if j.endswith(".spin") else f"{j} [counts]") for j in joints))
for weights, name in (({}, "forklift"), ({"steer": 0.02}, "forklift_weighted")):
    summary = odometry_file(robot, log_path, fmt=fmt, weights=weights, out=out_dir / f"{name}.tum",
                            plot=out_dir / f"{name}.png")
    time, poses = read_tum(out_dir / f"{name}.tum")
    err = np.hypot(*(poses[-1, :2] - run.truth[-1, :2]))
    print(f"weights {weights or 'all 1'}: {summary.samples} samples, {summary.path_length:.2f} m driven; end-point "
          f"error {err:.3f} m ({100 * err / summary.path_length:.2f} %); slip indicator max "
          f"{summary.max_slip * 1e3:.2f} mm per interval")
print(f"wrote {log_path.name} and the .tum/.png outputs in {out_dir}")
