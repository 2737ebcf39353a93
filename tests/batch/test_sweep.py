"""Design sweeps: the vectorised kernel against wmrkit's per-robot functions, the driver, Parquet, errors."""

from __future__ import annotations

import math
import re
import sys

import numpy as np
import pytest

from wmrkit import catalog
from wmrkit.analysis.isotropy import default_joints, natural_length, twist_condition_number
from wmrkit.analysis.singularity import singularity_distance
from wmrkit.batch.engine import BatchError
from wmrkit.batch.sweep import plot_sweep, sweep
from wmrkit.batch.sweep_kernel import build_spec, evaluate, parse_vary, variant

CASES = [
    ("mecanum-4", ["wheels.front_left.l,wheels.rear_right.l=0.3:0.5:3", "wheels[0].gamma=30deg:60deg:3",
                   "wheels[1].r=50mm:100mm:2"]),
    ("omni-3", ["wheels[0].alpha=0deg:60deg:3", "wheels[1].l=0.1:0.3:3"]),
    ("thesis-steer-castor", ["wheels.c2.l=0.3:0.6:3", "wheels.o1.r=0.05:0.2:2"]),
    ("diff-drive", ["wheels.left.l=0.1:0.3:3"]),
]


def _reference(robot, axes, spec, flat):
    sub = np.unravel_index(flat, spec.shape)
    return variant(robot, {t: axes[k].values[sub[k]] for k in range(len(axes)) for t in axes[k].targets})


@pytest.mark.parametrize(("name", "vary"), CASES)
def test_kernel_equals_the_per_robot_functions(name, vary):
    robot = catalog.load(name)
    axes = [parse_vary(v, robot) for v in vary]
    for metric in ("kappa_mean", "kappa_max", "inv_kappa_mean", "singular_margin"):
        spec = build_spec(robot, axes, metric, configs=8)
        total = int(np.prod(spec.shape))
        out = evaluate(np.arange(total), spec)
        for flat in range(total):
            r = _reference(robot, axes, spec, flat)
            beta = spec.configs if r.steer_names else None
            if metric == "singular_margin":
                ref = np.min(singularity_distance(r, beta, default_joints(r)))
            else:
                k = np.atleast_1d(twist_condition_number(r, beta, length=out[flat, 1]))
                k = k[~np.isnan(k)]
                ref = {"kappa_max": np.max(k), "kappa_mean": np.mean(k), "inv_kappa_mean": np.mean(1 / k)}[metric]
            assert out[flat, 0] == pytest.approx(ref, rel=1e-9), (name, metric, flat)
            if metric == "kappa_mean" and not r.steer_names:  # the natural length of a design that does not steer
                d, kappa = natural_length(r)
                assert out[flat, 1] == pytest.approx(d, rel=1e-6) and out[flat, 0] == pytest.approx(kappa, rel=1e-9)


def test_sweep_driver_best_designs_parquet_and_chunks(tmp_path):
    pq = pytest.importorskip("pyarrow.parquet")
    robot = catalog.load("omni-3")
    axes = [parse_vary("wheels[0].alpha,wheels[0].beta=30deg:90deg:7", robot),
            parse_vary("wheels[1].l=0.1:0.3:5", robot), parse_vary("wheels[2].l=150mm:250mm:3", robot)]
    res = sweep(robot, axes, "kappa_mean", chunk=16, out=tmp_path / "s.parquet", top=4)
    brute = evaluate(np.arange(105), build_spec(robot, axes, "kappa_mean"))[:, 0]
    # the best four, by value: designs 53 and 55 tie (mirror images) up to round-off, which depends on the chunk's
    # path and the CPU's LAPACK kernels, so the order among ties is not checked
    np.testing.assert_allclose([b["kappa_mean"] for b in res.best], np.sort(brute)[:4], rtol=1e-12)
    np.testing.assert_allclose([brute[b["index"]] for b in res.best], np.sort(brute)[:4], rtol=1e-12)
    assert len({b["index"] for b in res.best}) == 4
    assert res.best[0]["kappa_mean"] == pytest.approx(1.0, abs=1e-9)  # the symmetric kiwi drive is isotropic
    assert res.best[0]["wheels[0].alpha,wheels[0].beta"] == pytest.approx(math.radians(60))
    assert res.best[0]["wheels[1].l"] == pytest.approx(0.2)
    table = pq.read_table(tmp_path / "s.parquet").to_pydict()
    assert sorted(table["index"]) == list(range(105))
    # the chunk size changes only round-off (small chunks take LAPACK, large ones closed-form eigenvalues)
    np.testing.assert_allclose(np.array(table["metric"])[np.argsort(table["index"])], brute, rtol=1e-12)
    np.testing.assert_allclose(res.grid, brute.reshape(7, 5, 3).min(axis=2), rtol=1e-12)
    other = sweep(robot, axes, "kappa_mean", chunk=1000, top=4)
    np.testing.assert_allclose([b["kappa_mean"] for b in other.best], [b["kappa_mean"] for b in res.best],
                               rtol=1e-12)
    margin = sweep(robot, axes, "singular_margin", top=2)
    assert margin.best[0]["singular_margin"] == pytest.approx(np.max(evaluate(
        np.arange(105), build_spec(robot, axes, "singular_margin"))[:, 0]))
    plot_sweep(res, tmp_path / "s.png")
    plot_sweep(sweep(robot, axes[:1], top=1), tmp_path / "s1.png")
    assert (tmp_path / "s.png").stat().st_size > 1000


def test_without_dask_the_same_kernel_runs(monkeypatch):
    robot = catalog.load("omni-3")
    axes = [parse_vary("wheels[0].alpha=0deg:60deg:5", robot)]
    with_dask = sweep(robot, axes, chunk=2)

    def need(module):
        raise BatchError("the 'batch' extra is needed")

    monkeypatch.setattr(sys.modules["wmrkit.batch.sweep"], "need_extra", need)  # the module, not the function
    assert sweep(robot, axes, chunk=2).best == with_dask.best


def test_parse_vary_units_and_errors():
    robot = catalog.load("mecanum-4")
    ax = parse_vary("wheels.front_left.alpha,wheels[3].alpha=30deg:60deg:4", robot)
    assert ax.targets == ((0, "alpha"), (3, "alpha"))
    np.testing.assert_allclose(ax.values, np.radians([30, 40, 50, 60]))
    np.testing.assert_allclose(parse_vary("wheels[0].r=50mm:0.1:2", robot).values, [0.05, 0.1])
    for bad, msg in [("wheels.nope.l=0:1:2", "no wheel 'nope'"), ("wheels[9].l=0:1:2", "out of range"),
                     ("wheels[0].colour=0:1:2", "not a geometry field"), ("wheels[0].l=0:1", "START:STOP:N"),
                     ("wheels[0].l,wheels[1].alpha=0:1:2", "share a unit"), ("wheels[0].l=0:1:0", "N must be"),
                     ("wheels[0].l=0:1kg:3", "wheels"), ("robot.l=0:1:2", "is not wheels"),
                     ("wheels[0].l=0:1:\u00b2", "N must be")]:  # a superscript two: int()'s ValueError (traceback)
        with pytest.raises(BatchError, match=msg):
            parse_vary(bad, robot)
    with pytest.raises(BatchError, match="--vary"):  # a value the description refuses
        build_spec(robot, [parse_vary("wheels[0].r=-0.1:0.1:3", robot)], "kappa_mean")
    with pytest.raises(BatchError, match="unknown metric"):
        sweep(robot, [ax], "beauty")
    assert math.isfinite(sweep(robot, [ax], length=0.4, top=1).best[0]["kappa_mean"])



@pytest.mark.parametrize("name", ["swerve-4", "ackermann", "forklift"])
def test_kappa_metrics_are_refused_for_robots_of_mobility_1(name):
    """Types 4 and 5 have kappa 1 wherever they can move (§5.5.4-5.5.5): a swerve drive's random configurations are
    never coordinated, so 'sweep swerve-4 --vary ...' printed 'kappa_mean nan' for every design, exit 0. The
    singularity margin still sweeps, finite, where no coupling ties the actuated joints (the car's and the
    forklift's differentials join wheels, which the per-wheel kernel cannot: refused, as analyze searches them)."""
    robot = catalog.load(name)
    axes = [parse_vary("wheels[0].l=0.3:0.5:2" if name != "forklift" else "wheels[0].l=0.8:1.2:2", robot)]
    for metric in ("kappa_mean", "kappa_max", "inv_kappa_mean"):
        with pytest.raises(BatchError, match=r"has mobility 1.*--metric singular_margin"):
            build_spec(robot, axes, metric)
    if name == "swerve-4":
        spec = build_spec(robot, axes, "singular_margin", configs=8)
        assert np.all(np.isfinite(evaluate(np.arange(2), spec)))
    else:  # driven through a differential: the per-wheel kernel would give the margin of separate joints
        with pytest.raises(BatchError, match=r"are one differential.*not of this robot's actuated model"):
            build_spec(robot, axes, "singular_margin", configs=8)


def test_refusals_come_before_the_per_wheel_tables(monkeypatch):
    """A robot the metric cannot rate was refused after one rebuild per swept value (a 3000-point axis of a swerve
    drive: 35 s, hours at the 10^6 points allowed)."""
    import wmrkit.batch.sweep_kernel as kernel

    def no_rebuild(*args, **kwargs):
        raise AssertionError("a robot was rebuilt before the refusal")

    monkeypatch.setattr(kernel, "variant", no_rebuild)
    for name, metric, msg in [("swerve-4", "kappa_mean", "has mobility 1"),
                              ("forklift", "singular_margin", "are one differential")]:
        robot = catalog.load(name)
        with pytest.raises(BatchError, match=msg):
            build_spec(robot, [parse_vary("wheels[0].l=0.8:1.2:1000", robot)], metric)


def test_a_chunk_holds_a_bounded_number_of_configurations(monkeypatch):
    """A chunk evaluates designs x configurations at once (about 0.5 kB each): 4096 designs of --configs 10000
    needed 22 GB. Fewer designs go into a chunk when there are many configurations; the values do not change."""
    driver = sys.modules["wmrkit.batch.sweep"]  # the module (wmrkit.batch.sweep is also the function's name)
    robot = catalog.load("thesis-steer-castor")
    axes = [parse_vary("wheels.o1.l=0:0.4:10", robot)]
    want = sweep(robot, axes, "inv_kappa_mean", configs=16, length=0.4, chunk=4, top=10)
    monkeypatch.setattr(driver, "MAX_CHUNK_COLUMNS", 64)  # 4 designs of 16 configurations
    res = sweep(robot, axes, "inv_kappa_mean", configs=16, length=0.4, top=10)
    assert res.chunks == 3 and res.best == want.best


def test_the_plot_names_units_and_survives_a_sweep_without_a_finite_value(tmp_path):
    """Every design singular: a log colour scale of no data raised ValueError after the whole sweep. The axes were
    labelled without units (radians and metres, whatever units --vary was given in)."""
    import matplotlib

    robot = catalog.load("thesis-steer-castor")
    axes = [parse_vary("wheels.c2.alpha=0:0:1", robot), parse_vary("wheels.o1.l=0.5:0.5:1", robot)]
    singular = sweep(robot, axes, configs=8)
    assert singular.best[0]["kappa_mean"] == math.inf
    with matplotlib.rc_context({"svg.fonttype": "none"}):  # text stays text in the SVG
        plot_sweep(singular, tmp_path / "none.svg")
        plot_sweep(sweep(robot, [parse_vary("wheels.c2.alpha=90deg:180deg:3", robot)], configs=8, top=1),
                   tmp_path / "one.svg")
    text = (tmp_path / "none.svg").read_text()
    assert "no finite kappa_mean" in text and "wheels.c2.alpha [deg]" in text and "wheels.o1.l [m]" in text
    assert "wheels.c2.alpha [deg]" in (tmp_path / "one.svg").read_text()  # people read degrees, as typed
    assert [a["unit"] for a in singular.to_dict()["axes"]] == ["rad", "m"]


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="needs Linux's /proc (no one can write into it)")
def test_an_output_that_cannot_be_written_is_named():
    """pyarrow's error carries no file name: 'sweep --out' into an unwritable folder ended in a traceback."""
    robot = catalog.load("omni-3")
    with pytest.raises(BatchError, match=r"/proc/s\.parquet: cannot write the table"):
        sweep(robot, [parse_vary("wheels[0].l=0.1:0.2:2", robot)], out="/proc/s.parquet")


def test_configuration_counts_and_seeds_must_be_whole_numbers():
    """configs=2.5 and configs=True swept silently (numpy took them as a size), seed=-1 and seed=2.5 reached
    numpy's ValueError and TypeError."""
    robot = catalog.load("omni-3")
    axes = [parse_vary("wheels[0].l=0.1:0.2:2", robot)]
    for configs in (2.5, True):
        with pytest.raises(BatchError, match=r"--configs must be in \[1, 10000\] \(a whole number\)"):
            sweep(robot, axes, configs=configs)
    for seed in (-1, 2.5):
        with pytest.raises(BatchError, match="seed must be an integer >= 0"):
            sweep(robot, axes, seed=seed)


def test_a_length_with_the_singular_margin_is_refused():
    """--length is D of the condition number; the margin scales by each design's size, so a --length given with it
    was ignored without a word (rule 8)."""
    robot = catalog.load("omni-3")
    with pytest.raises(BatchError, match="--length sets D of the kappa metrics"):
        sweep(robot, [parse_vary("wheels[0].l=0.1:0.2:2", robot)], "singular_margin", length=0.3)


def test_the_number_of_best_designs_is_bounded():
    """--top 10^9 kept every design in memory (about 2 kB each) and printed them all: the memory grew with the
    number of designs, which the sweep promises it does not."""
    robot = catalog.load("omni-3")
    with pytest.raises(BatchError, match=r"^top: 1000000000 is more than 10000 best designs"):
        sweep(robot, [parse_vary("wheels[0].l=0.1:0.2:2", robot)], top=10**9)


def test_the_table_says_which_metric_it_holds_and_the_units(tmp_path):
    """The Parquet table had a column 'metric' but did not say which (kappa_mean is better low, inv_kappa_mean
    high) nor the robot, nor that an angle axis is in rad though --vary was given in deg."""
    pq = pytest.importorskip("pyarrow.parquet")
    robot = catalog.load("omni-3")
    axes = [parse_vary("wheels[0].alpha=30deg:90deg:2", robot), parse_vary("wheels[1].l=0.1:0.2:2", robot)]
    sweep(robot, axes, "inv_kappa_mean", out=tmp_path / "s.parquet")
    schema = pq.read_schema(tmp_path / "s.parquet")
    assert {k.decode(): v.decode() for k, v in schema.metadata.items()} == {
        "robot": "omni-3", "metric": "inv_kappa_mean", "better": "higher"}
    units = {f.name: f.metadata[b"unit"].decode() for f in schema if f.metadata}
    assert units == {"wheels[0].alpha": "rad", "wheels[1].l": "m", "metric": "1", "length": "m"}


def test_heading_is_swept_as_users_write_it():
    """--vary wheels.X.heading (0 = straight ahead) moves the same designs as the thesis's beta 90 deg higher, and
    cannot be swept with that wheel's beta."""
    robot = catalog.load("thesis-omni-swedish")
    by_heading = sweep(robot, [parse_vary("wheels[0].heading=-60deg:30deg:4", robot)], "inv_kappa_mean", top=4)
    by_beta = sweep(robot, [parse_vary("wheels[0].beta=30deg:120deg:4", robot)], "inv_kappa_mean", top=4)
    assert [b["inv_kappa_mean"] for b in by_heading.best] == pytest.approx(
        [b["inv_kappa_mean"] for b in by_beta.best], rel=1e-12)
    assert parse_vary("wheels[0].heading=-60deg:30deg:4", robot).unit == "rad"
    with pytest.raises(BatchError, match="move the same field"):
        build_spec(robot, [parse_vary("wheels[0].heading=0:1:2", robot), parse_vary("wheels[0].beta=0:1:2", robot)],
                   "inv_kappa_mean")


def test_position_is_swept_as_users_write_it(capsys):
    """--vary wheels.X.x / .y move the wheel's position [x, y] (the users' form; only the thesis's polar l, alpha
    could be swept): each design equals the robot described by hand with that position."""
    from wmrkit.analysis.isotropy import natural_length
    from wmrkit.description import robot_from_dict

    robot = catalog.load("omni-3")
    axes = [parse_vary("wheels[0].x=100mm:300mm:3", robot), parse_vary("wheels[0].y=-0.1:0.1:2", robot)]
    assert [a.unit for a in axes] == ["m", "m"]
    result = sweep(robot, axes, top=6, configs=8)
    assert len(result.best) == 6
    for b in result.best:
        data = robot.to_dict()
        data["wheels"][0]["position"] = [b["wheels[0].x"], b["wheels[0].y"]]
        _, kappa = natural_length(robot_from_dict(data))
        assert b["kappa_mean"] == pytest.approx(kappa, rel=1e-9)
    for other in ("l", "alpha"):
        with pytest.raises(BatchError, match="move the same field"):
            build_spec(robot, [axes[0], parse_vary(f"wheels[0].{other}=0.1:0.2:2", robot)], "kappa_mean")


def test_the_table_prints_angles_in_degrees(capsys):
    """'--vary ...heading=-30deg:30deg:5' printed 'heading = -0.523599 rad': the table people read shows degrees
    (JSON and Parquet keep radians, SI)."""
    import json

    from wmrkit.cli.main import main

    argv = ["sweep", "omni-3", "--vary", "wheels[0].heading=-30deg:30deg:3", "--workers", "0", "--quiet"]
    assert main(argv) == 0
    out = capsys.readouterr().out
    assert "wheels[0].heading = -30 deg" in out and "wheels[0].heading = 30 deg" in out and "rad" not in out
    assert main([*argv, "--json"]) == 0
    axis = json.loads(capsys.readouterr().out)["axes"][0]
    assert axis["unit"] == "rad" and axis["start"] == pytest.approx(-math.pi / 6)


def test_an_output_file_of_another_kind_is_refused_not_replaced(tmp_path):
    """'sweep ... --out run.csv' replaced a joint log (any file not a sweep's table) with the table, exit 0; a
    batch odometry table too. A sweep's own table is replaced, as before."""
    pa = pytest.importorskip("pyarrow")
    pq = pytest.importorskip("pyarrow.parquet")
    robot = catalog.load("omni-3")
    axes = [parse_vary("wheels[0].l=0.1:0.2:2", robot)]
    log = tmp_path / "run.csv"
    log.write_text("time,a.spin\n0,0\n")
    with pytest.raises(BatchError, match=r"run\.csv: not a readable Parquet table"):
        sweep(robot, axes, out=log)
    assert log.read_text() == "time,a.spin\n0,0\n"
    other = tmp_path / "fleet.parquet"
    pq.write_table(pa.table({"log": ["a.csv"], "x": [1.0]}), other)
    with pytest.raises(BatchError, match=r"fleet\.parquet: not a table of this command \(no column 'index'"):
        sweep(robot, axes, out=other)
    assert pq.read_table(other).column_names == ["log", "x"]
    own = tmp_path / "s.parquet"
    sweep(robot, axes, out=own)
    sweep(robot, [parse_vary("wheels[1].l=0.1:0.3:3", robot)], out=own)  # a sweep's table: replaced
    assert pq.read_table(own).num_rows == 3 and list(tmp_path.glob(".*.tmp")) == []


def test_a_sweep_that_fails_leaves_no_temporary_file(tmp_path, monkeypatch):
    """A chunk that raised left '.s.parquet.PID.tmp' behind, the half-written table, at every failed run."""
    module = sys.modules["wmrkit.batch.sweep"]  # the module, not the function
    robot = catalog.load("omni-3")

    def broken(flat, spec):
        raise RuntimeError("a worker's failure")

    monkeypatch.setattr(module, "evaluate", broken)
    with pytest.raises(RuntimeError, match="worker's failure"):
        sweep(robot, [parse_vary("wheels[0].l=0.1:0.2:2", robot)], out=tmp_path / "s.parquet")
    assert list(tmp_path.iterdir()) == []


def test_a_misspelt_wheel_or_field_gets_a_suggestion():
    robot = catalog.load("omni-3")
    for bad, msg in [("wheels.bak.l=0:1:2", "no wheel 'bak' (did you mean 'back'?)"),
                     ("wheels[0].alph=0:1:2", "'alph' is not a geometry field (did you mean 'alpha'?)"),
                     ("wheels[0].radius=0:1:2", "did you mean 'r'?")]:
        with pytest.raises(BatchError, match=re.escape(msg)):
            parse_vary(bad, robot)


def test_an_axis_of_a_wheel_the_robot_lacks_is_refused():
    """An Axis made by hand for wheel 9 of a 3-wheel robot was swept as if it moved nothing (every design equal)."""
    from wmrkit.batch.sweep_kernel import Axis

    with pytest.raises(BatchError, match=r"wheels\[9\]\.r: the robot has 3 wheels"):
        sweep(catalog.load("omni-3"), [Axis("wheels[9].r", ((9, "r"),), np.array([0.05, 0.1]))])


def test_the_variants_of_one_wheel_are_bounded_before_they_are_built(monkeypatch):
    """Three 1000-point axes of one wheel (1e9 designs, allowed) made a table of 1e9 robots rebuilt one by one
    (about 10 ms each: months, and the memory of the table) with no refusal: a wheel's table is the product of its
    own axes, not their sum. At most MAX_POINTS variants a wheel, refused before any rebuild."""
    import wmrkit.batch.sweep_kernel as kernel

    robot = catalog.load("omni-3")

    def no_rebuild(*args, **kwargs):
        raise AssertionError("a robot was rebuilt before the refusal")

    monkeypatch.setattr(kernel, "variant", no_rebuild)
    axes = [parse_vary(v, robot) for v in ("wheels[0].l=0.1:0.2:1000", "wheels[0].alpha=0:1:1000",
                                           "wheels[0].r=0.01:0.1:1000")]
    with pytest.raises(BatchError, match=r"wheel 'front_left': its --vary axes make 1000 x 1000 x 1000 variants"):
        build_spec(robot, axes, "kappa_mean")
    monkeypatch.setattr(kernel, "variant", variant)
    monkeypatch.setattr(kernel, "MAX_POINTS", 4)  # at the bound, 2 x 2 variants of one wheel are built; 2 x 3 not
    axes = [parse_vary(v, robot) for v in ("wheels[0].l=0.1:0.2:2", "wheels[0].r=0.01:0.1:2", "wheels[1].r=0.01:0.1:3")]
    assert build_spec(robot, axes, "kappa_mean").tables[0]["l"].shape == (4,)
    with pytest.raises(BatchError, match=r"wheel 'front_left': its --vary axes make 2 x 3 variants"):
        build_spec(robot, [axes[0], parse_vary("wheels[0].r=0.01:0.1:3", robot)], "kappa_mean")


def test_one_point_between_two_ends_is_refused():
    """'wheels[1].l=0.1:0.3:1' swept 0.1 m alone, the 0.3 m dropped without a word."""
    robot = catalog.load("omni-3")
    with pytest.raises(BatchError, match=r"N = 1 is the one value START; STOP differs"):
        parse_vary("wheels[1].l=0.1:0.3:1", robot)
    np.testing.assert_array_equal(parse_vary("wheels[1].l=100mm:0.1:1", robot).values, [0.1])
