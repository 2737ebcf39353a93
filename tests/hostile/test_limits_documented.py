"""docs/limits.md and the constants the code enforces: each documented value, as the page words it, next to the
constant it names; a constant changed without the page (or the page without the code) fails here."""

from __future__ import annotations

import importlib
import math
from pathlib import Path

import pytest

DOC = (Path(__file__).parents[2] / "docs" / "limits.md").read_text(encoding="utf-8")

#: (module, constant, the page's words, the value those words state)
DOCUMENTED = [
    ("wmrkit.limits", "MAX_FILE_SIZE", "256 KiB (`MAX_FILE_SIZE`", 256 * 1024),
    ("wmrkit.limits", "MAX_WHEELS", "| wheels | 64 (`MAX_WHEELS`) |", 64),
    ("wmrkit.limits", "MAX_NAME", "64 characters (`MAX_NAME`)", 64),
    ("wmrkit.limits", "MAX_NOTES", "4096 characters (`MAX_NOTES`)", 4096),
    ("wmrkit.limits", "MIN_SIZE", "`MIN_SIZE = 1e-6`", 1e-6),
    ("wmrkit.limits", "MAX_SIZE", "`MAX_SIZE = 1e3` m", 1e3),
    ("wmrkit.limits", "MIN_RATIO", "`MIN_RATIO = 1e-4`", 1e-4),
    ("wmrkit.limits", "ANGLE_MARGIN", "at least 1 deg from 0 and 180 deg | `ANGLE_MARGIN`", math.radians(1)),
    ("wmrkit.limits", "MIN_COUPLING_RATIO", "magnitude 1e-6 ... 1e6", 1e-6),
    ("wmrkit.limits", "MAX_COUPLING_RATIO", "magnitude 1e-6 ... 1e6", 1e6),
    ("wmrkit.limits", "MAX_TABLE_SIZE", "at most 64 MiB (`MAX_TABLE_SIZE`)", 64 << 20),
    ("wmrkit.limits", "MAX_CHUNK", "1 to 2^22 samples (`limits.MAX_CHUNK`)", 1 << 22),
    ("wmrkit.limits", "MAX_COORDINATE", "within 1e9 m (`MAX_COORDINATE`)", 1e9),
    ("wmrkit.limits", "MAX_SPEED", "up to 1e3 m/s (`MAX_SPEED`)", 1e3),
    ("wmrkit.limits", "MAX_TORQUE", "within 1e10 N m (`limits.MAX_TORQUE`)", 1e10),
    ("wmrkit.dynamics.linkages", "SETPOINT_TOL", "within 1e-5 rad (`linkages.SETPOINT_TOL`", 1e-5),
    ("wmrkit.dynamics.linkages", "MAX_SETPOINT_KNOTS", "at most 1e6 inserted knots (`linkages.MAX_SETPOINT_KNOTS`",
     1e6),
    ("wmrkit.kinematics.codegen", "MAX_FILENAME", "255 bytes (`codegen.MAX_FILENAME`)", 255),
    ("wmrkit.kinematics.codegen", "MAX_STACK_WORK", "512 doubles, 4 KiB (`codegen.MAX_STACK_WORK`)", 512),
    ("wmrkit.kinematics.search", "MAX_SETS", "after 1000 sets (`MAX_SETS`", 1000),
    ("wmrkit.kinematics.search", "MAX_MINIMAL_SETS", "minimal actuator/sensor sets: 24, `MAX_MINIMAL_SETS`", 24),
    ("wmrkit.kinematics.search", "MAX_CANDIDATES", "after 2,000,000 candidates (`MAX_CANDIDATES`)", 2_000_000),
    ("wmrkit.kinematics.extended", "MAX_STARTS", "at most 4096 grid points per problem", 4096),
    ("wmrkit.kinematics.symbolic", "MAX_LSQ_ANGLES", "more than 4 steering angles is refused", 4),
    ("wmrkit.analysis.coordinated", "MAX_EVALUATIONS", "sharing 1200 evaluations (`coordinated.MAX_EVALUATIONS`",
     1200),
    ("wmrkit.analysis.report", "TABLE_RESOLUTION", "at most 90 points a turn (`report.TABLE_RESOLUTION`)", 90),
    ("wmrkit.analysis.report", "MIN_DPI", "20 to 600 dots per inch (`report.MIN_DPI`, `MAX_DPI`)", 20),
    ("wmrkit.analysis.report", "MAX_DPI", "20 to 600 dots per inch (`report.MIN_DPI`, `MAX_DPI`)", 600),
    ("wmrkit.units", "MAX_TURNS", "at most 1e6 turns (`units.MAX_TURNS`", 1e6),
    ("wmrkit.odometry._text", "MAX_LINE", "a row longer than 262,144 characters (`odometry._text.MAX_LINE`", 262_144),
    ("wmrkit.odometry.model", "MAX_WEIGHT_RATIO", "at most 1e6, a wheel without a weight counting 1 "
     "(`odometry.model.MAX_WEIGHT_RATIO`", 1e6),
    ("wmrkit.odometry.files", "FIRST_SAMPLES", "the first 20,000 samples of a CSV log (`odometry.files.FIRST_SAMPLES`",
     20_000),
    ("wmrkit.dynamics.simulate", "MAX_STEPS", "at most 5e7 steps (`dynamics.simulate.MAX_STEPS`", 5e7),
    ("wmrkit.dynamics.simulate", "MAX_RECORD_VALUES", "(`dynamics.simulate.MAX_RECORD_VALUES`, 2^27 numbers",
     1 << 27),
    ("wmrkit.dynamics.runs", "MAX_EVALUATIONS", "at most 1e7 evaluations of the model (`dynamics.runs.MAX_EVALUATIONS`",
     1e7),
    ("wmrkit.dynamics.tyres", "MAX_LOAD", "`--load` in [0, 1e7] N (`tyres.MAX_LOAD`)", 1e7),
    ("wmrkit.dynamics.tyres", "MAX_PARAM", "at most 1e12 (`MAX_PARAM`)", 1e12),
    ("wmrkit.dynamics.tyres", "PACEJKA_FITTED_SPEED", "Pacejka above 18 m/s (`PACEJKA_FITTED_SPEED`", 18.0),
    ("wmrkit.slip.weights", "MAX_RATIO", "differ by at most 1e12 (`slip.weights.MAX_RATIO`)", 1e12),
    ("wmrkit.slip.kalman", "MAX_SPREAD", "a spread of at most 1e6 (`slip.kalman.MAX_SPREAD`)", 1e6),
    ("wmrkit.slip.calibration", "MAX_SCALE", "within a factor 2 of the log's no-slip odometry", 2.0),
    ("wmrkit.control.loop", "MAX_SAMPLED_EVALUATIONS", "at most 100,000 evaluations "
     "(`control.loop.MAX_SAMPLED_EVALUATIONS`", 100_000),
    ("wmrkit.control.loop", "MAX_CONTINUOUS_SECONDS", "at most 2 min of computing "
     "(`control.loop.MAX_CONTINUOUS_SECONDS`",
     120.0),
    ("wmrkit.control.track", "MAX_CONTINUOUS_SAMPLES", "(`MAX_CONTINUOUS_SAMPLES`, 40,000 output samples of 0.05 s",
     40_000),
    ("wmrkit.control.track", "MAX_SLIP_PERIODS", "at most 50,000 control periods (`control.track.MAX_SLIP_PERIODS`",
     50_000),
    ("wmrkit.control.trackers", "MIN_LOOKAHEAD_TIME", "2 s at the reference's top speed "
     "(`trackers.MIN_LOOKAHEAD_TIME`", 2.0),
    ("wmrkit.control.trackers", "ARRIVAL_FRACTION", "farther than 0.1 of the follower's length", 0.1),
    ("wmrkit.control.trackers", "AIM_FRACTION", "aim radius 1e-3 of its lookahead (`trackers.AIM_FRACTION`)", 1e-3),
    ("wmrkit.control.trackers", "EPS_FRACTION", "eps 2e-3 of the top speed (`trackers.EPS_FRACTION`)", 2e-3),
    ("wmrkit.parking.execute", "MAX_SAMPLES", "at most 500,000 samples (`parking.execute.MAX_SAMPLES`", 500_000),
    ("wmrkit.parking.execute", "CHUNK", "10,000 samples at a time (`execute.CHUNK`)", 10_000),
    ("wmrkit.parking.verify", "MAX_CHECK_POSES", "at most 2e6 poses (`verify.MAX_CHECK_POSES`", 2e6),
    ("wmrkit.parking.verify", "CHUNK", "50,000 at a time (`verify.CHUNK`", 50_000),
    ("wmrkit.parking.planner", "MAX_MANEUVERS", "at most 100 manoeuvres (`planner.MAX_MANEUVERS`", 100),
    ("wmrkit.parking.problem", "MAX_LENGTH", "Lengths up to 1 km are accepted (`problem.MAX_LENGTH`)", 1e3),
    ("wmrkit.parking.plot", "MAX_FRAMES", "2 to 800 frames (`parking.plot.MAX_FRAMES`", 800),
    ("wmrkit.parking.plot", "MAX_TRAIL", "at most 12,000 dots, `parking.plot.MAX_TRAIL`", 12_000),
    ("wmrkit.batch.sweep", "MAX_TOP", "`--top` up to 1e4 (`batch.sweep.MAX_TOP`", 1e4),
    ("wmrkit.batch.calibrate", "MAX_BOOTSTRAP", "2 to 10,000 replicates "
     "(`--bootstrap`, `batch.calibrate.MAX_BOOTSTRAP`)",
     10_000),
    ("wmrkit.batch.calibrate", "MAX_LEVEL", "in (0.5, 0.9999] (`batch.calibrate.MIN_LEVEL`, `MAX_LEVEL`)", 0.9999),
    ("wmrkit.batch.calibrate", "MIN_LEVEL", "in (0.5, 0.9999] (`batch.calibrate.MIN_LEVEL`, `MAX_LEVEL`)", 0.5),
    ("wmrkit.batch.consistency", "MAX_RATIO", "exceeds 20 times what noise leaves there", 20.0),
    ("wmrkit.batch.consistency", "MIN_RUNS", "judged with 3 runs or more (`MIN_RUNS`)", 3),
    ("wmrkit.batch.consistency", "MIN_DOF", "6 or more residuals beyond their own parameters (`MIN_DOF`", 6),
    ("wmrkit.batch.consistency", "ROUNDOFF", "floored at 1e-9 of its wheel travel (`ROUNDOFF`", 1e-9),
    ("wmrkit.batch.consistency", "PAIR_CANDIDATES", "among the 6 runs of largest score", 6),
    ("wmrkit.batch.consistency", "PAIR_REFITS", "the best of the 3 pairs of largest quadratic-model score", 3),
    ("wmrkit.batch.consistency", "MAX_PAIR_SCORE", "over 30, `MAX_PAIR_SCORE`", 30.0),
    ("wmrkit.batch.consistency", "MIN_CLOSED_RUNS", "judged with 5 runs or more (`MIN_CLOSED_RUNS`)", 5),
    ("wmrkit.batch.consistency", "MAX_CLOSED_SCORE", "over 20 (`MAX_CLOSED_SCORE`) names it", 20.0),
    ("wmrkit.batch.homogeneity", "MAX_HOMOGENEITY", "over 60 (`homogeneity.MAX_HOMOGENEITY`)", 60.0),
    ("wmrkit.batch.homogeneity", "MIN_DOF", "27 degrees of freedom or more (`homogeneity.MIN_DOF`", 27),
    ("wmrkit.batch.likelihood", "LEVEL", "over its 0.1 % point for agreeing fleets of as many runs (`likelihood.LEVEL`",
     1e-3),
    ("wmrkit.batch.likelihood", "MIN_OWN_DOF", "3 degrees of freedom of their own, `likelihood.MIN_OWN_DOF`", 3),
    ("wmrkit.batch.montecarlo", "MAX_LOG_VALUES", "at most 2^23 numbers, samples x (joints + 3) "
     "(`batch.montecarlo.MAX_LOG_VALUES`)", 1 << 23),
    ("wmrkit.batch.montecarlo", "MAX_WORK", "at most 2e9 numbers integrated per worker (`MAX_WORK`", 2e9),
    ("wmrkit.batch.montecarlo", "RUN_COST", "1000 (`RUN_COST`", 1000),
    ("wmrkit.batch.montecarlo", "STEERED_RUN_COST", "5000 for a steered robot (`STEERED_RUN_COST`", 5000),
    ("wmrkit.batch.montecarlo", "CONFIGURATION_RUN_COST", "100,000 where the perturbed joints are also the "
     "configuration (`CONFIGURATION_RUN_COST`", 100_000),
    ("wmrkit.batch.montecarlo", "CONFIGURATION_COST", "plus 2000 a sample (`CONFIGURATION_COST`)", 2000),
    ("wmrkit.odometry.synthetic", "MAX_FINE_VALUES", "at most 2^27 numbers (1 GiB) in their fine arrays "
     "(`odometry.synthetic.MAX_FINE_VALUES`", 1 << 27),
    ("wmrkit.batch.engine", "WORKERS_PER_CPU", "0 (serial) to 4 per CPU (`batch.engine.WORKERS_PER_CPU`)", 4),
    ("wmrkit.studio.app", "MAX_BODY", "a body of at most 1 MB (`studio.app.MAX_BODY`", 1_000_000),
    ("wmrkit.studio.api", "MAX_RESOLUTION", "at most 181 points per axis (`studio.api.MAX_RESOLUTION`)", 181),
    ("wmrkit.studio.api", "MAX_ISOTROPIC_STEERING", "up to 4 steering wheels (`MAX_ISOTROPIC_STEERING`", 4),
    ("wmrkit.studio.files", "MAX_ENTRIES", "among at most 20,000 folder entries", 20_000),
    ("wmrkit.vision.camera", "MAX_PIXELS", "at most 4096 px a side (`vision.camera.MAX_PIXELS`)", 4096),
    ("wmrkit.vision.camera", "MIN_FOCAL_PX", "at least 1 px (`vision.camera.MIN_FOCAL_PX`", 1.0),
    ("wmrkit.vision.camera", "MAX_FOCAL_PX", "at most 1e7 px (`vision.camera.MAX_FOCAL_PX`", 1e7),
    ("wmrkit.vision.calibration", "MIN_CONVERGENCE_PX", "at least 1 px (`vision.calibration.MIN_CONVERGENCE_PX`)",
     1.0),
    ("wmrkit.vision.positioning", "SPACING_TOLERANCE", "within 25 % of the spacing", 0.25),
    ("wmrkit.vision.follow", "MAX_RUN_PIXELS", "at most 7.68e8 pixels rendered over the run", 7.68e8),
]


@pytest.mark.parametrize(("module", "name", "words", "value"), DOCUMENTED, ids=[f"{m}.{n}" for m, n, *_ in DOCUMENTED])
def test_the_documented_limit_is_the_one_enforced(module, name, words, value):
    assert words in DOC, f"docs/limits.md no longer says {words!r}"
    assert getattr(importlib.import_module(module), name) == pytest.approx(value, rel=1e-12)


def test_the_modules_that_copy_a_limit_agree_with_wmrkit_limits():
    """A constant re-exported or copied under the same name elsewhere is the same number (one rule, one value)."""
    import wmrkit.limits as limits

    for module in ("wmrkit.description", "wmrkit.couplings", "wmrkit.control.references", "wmrkit.control.track",
                   "wmrkit.control.loop", "wmrkit.cli.dynamics", "wmrkit.control.points"):
        mod = importlib.import_module(module)
        for name in ("MAX_FILE_SIZE", "MAX_WHEELS", "MAX_NAME", "MAX_NOTES", "MIN_SIZE", "MAX_SIZE", "MIN_RATIO",
                     "ANGLE_MARGIN", "MIN_COUPLING_RATIO", "MAX_COUPLING_RATIO", "MAX_COORDINATE", "MAX_SPEED"):
            if hasattr(mod, name):
                assert getattr(mod, name) == getattr(limits, name), f"{module}.{name}"
