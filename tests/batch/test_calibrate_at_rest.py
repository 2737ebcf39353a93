"""batch calibrate: a reference that moves while the wheels are still is said beyond the reference's noise only."""

from __future__ import annotations

import json
from dataclasses import replace

import numpy as np
import pytest
from batch_params import PARAMS, TRUE_P

from wmrkit.batch.calibrate import fleet_calibrate

STILL = "the reference moves while the wheels are still"


def paused_fleet(diff, seed: int, push=(0.0, 0.0, 0.0), sigma: float = 1e-3):
    """6 runs that stand still 1 s, then drive three random arcs; references of three poses (the start, 0.5 s into
    the pause, the end) with `sigma` [m, rad] of noise on each coordinate, run 2's middle one moved by `push`."""
    from wmrkit.odometry.calibration import CalibrationRun, apply_parameters
    from wmrkit.odometry.synthetic import TwistProfile, simulate

    rng = np.random.default_rng(seed)
    out = []
    for i in range(6):
        segs = [(1.0, 0.0, 0.0, 0.0)] + [(2.0, 0.3 + 0.1 * rng.random(), 0.0, rng.uniform(-0.6, 0.6)) for _ in range(3)]
        run = simulate(apply_parameters(diff, PARAMS, TRUE_P), TwistProfile.from_segments(segs), 10.0,
                       spin_noise_per_rad=1e-5, seed=int(rng.integers(1 << 30)))
        at = np.array([0, 5, len(run.log) - 1])
        ref = run.truth[at] + rng.normal(size=(3, 3)) * sigma
        ref[1] += push if i == 2 else 0.0
        out.append(CalibrationRun(replace(run.log, source=f"r{i}.csv"), ref, at=at))
    return out


def test_a_noisy_reference_of_a_still_robot_is_not_said_pushed_a_moved_one_is(diff):
    """Motion-capture noise (1 mm, 1 mrad) on every reference pose of 6 runs that pause, run 2 pushed 2 cm while
    its wheels are still. Before, every run was said pushed (any move of a still reference at all: the noise's
    1-2 mm); now run 2 alone, its move beyond 5 sqrt(2) times the reference's noise (7.07 mm); with a noise of 1 cm
    given (tolerance 7 cm) nothing is said."""
    runs = paused_fleet(diff, 99, push=(0.02, 0.0, 0.0))
    said = fleet_calibrate(diff, runs, PARAMS).not_judged
    still = said[said.index(STILL) - 200:said.index(STILL)].rpartition("; ")[2]
    assert still.startswith("r2.csv (samples 0-5: 0.0") and still.count(".csv") == 1, said
    assert "beyond its noise (0.00707 m, 0.00707 rad)" in said
    assert STILL not in (fleet_calibrate(diff, runs, PARAMS, reference_noise=(0.01, 0.01)).not_judged or "")


@pytest.mark.parametrize("noise", [(-1e-3, 0.0), (1e-3, float("nan")), (1e-3,), "1mm", (True, 0.0), (1e308, 0.0),
                                   (0.0, 4.0)])
def test_a_bad_reference_noise_is_refused_by_name(diff, noise):
    from wmrkit.errors import WmrkitError

    with pytest.raises(WmrkitError, match=r"^reference_noise: expected the reference's noise"):
        fleet_calibrate(diff, paused_fleet(diff, 1)[:2], PARAMS, reference_noise=noise)


@pytest.mark.parametrize(("given", "said"), [
    ("1mm", "expected XY,HEADING"), ("1mm,nan", "cannot read 'nan' as an angle"),
    ("-1mm,0", "expected the reference's noise (x and y [m], heading [rad]): two numbers in [0, 1000] m and [0, pi] "
               "rad, got (-0.001, 0.0)"),
    ("1e308,0", "expected the reference's noise")])
def test_cli_refuses_a_bad_reference_noise_before_any_work(tmp_path, capsys, given, said):
    from wmrkit.cli.main import main

    args = ["batch", "calibrate", "diff-drive", str(tmp_path / "none.csv"), "--reference", str(tmp_path),
            "--reference-noise", given, "--workers", "0"]
    assert main(args) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"wmrkit: error: --reference-noise: {said}") and err.count("\n") == 1, err
    assert main([*args, "--json"]) == 2
    assert "--reference-noise" in json.loads(capsys.readouterr().err)["error"]
