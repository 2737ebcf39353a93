"""``wmrkit park``: JSON shape, headings, infeasible answers, plot and animation files, errors."""

from __future__ import annotations

import json
import math
from dataclasses import replace

import numpy as np
import pytest

from wmrkit.cli.main import main
from wmrkit.errors import WmrkitError
from wmrkit.parking import plan_parking


def run(capsys, *argv):
    code = main(["park", *argv])
    out = capsys.readouterr()
    return code, out.out, out.err


def test_json_output_of_table_9_2(capsys):
    code, out, _ = run(capsys, "thesis-9.2", "--json")
    assert code == 0
    data = json.loads(out)
    assert data["maneuvers"] == 4 and data["feasible"] is True
    assert {"path", "poses", "wall_time", "warnings"} <= data.keys()
    assert data["wall_time"] > 0 and data["warnings"]  # dx2 < c1/2 is reported
    assert data["length_ratio"] == pytest.approx(0.706, abs=5e-4)  # (9.37), the digest's 70.6 %, as a fraction
    steering = [seg["steering"] for seg in data["path"]]
    # headings: the equivalent front wheel, 0 = straight, |steering| <= phi_max = 46 deg, atan(h1 kappa)
    assert max(abs(s) for s in steering) <= math.radians(46) + 1e-12
    for seg in data["path"]:
        assert seg["steering"] == pytest.approx(math.atan(0.60 * seg["curvature"]), abs=1e-12)
    assert data["poses"][-1] == pytest.approx(data["path"][-1]["end"], abs=1e-9)
    assert [a["direction"] for a in data["arcs"]] == ["backward", "forward", "backward", "forward"]


def test_text_output_and_exact_check(capsys):
    code, out, _ = run(capsys, "thesis-9.1", "--check")
    assert code == 0
    assert "feasible: 2 manoeuvres" in out and "collision-free, ends inside the slot" in out


def test_one_manoeuvre_is_singular(capsys, tmp_path):
    """A narrow slot entered in one reverse manoeuvre printed '1 manoeuvres, ... 1 direction changes'."""
    f = tmp_path / "one.yaml"
    f.write_text("vehicle: {a1: 150 cm, b1: 50 cm, c1: 140 cm, h1: 105 cm, d1: 50 cm, phi_max: 46 deg}\n"
                 "space: {H: 400 cm, J: 150 cm, MS: 20 cm, dx2: 70 cm, final_gap: 30 cm}\n")
    code, out, _ = run(capsys, str(f))
    assert code == 0 and "feasible: 1 manoeuvre, " in out and ", 1 direction change, " in out


def test_infeasible_slot_says_why_and_the_shortest_slot(capsys, tmp_path):
    f = tmp_path / "short.yaml"
    f.write_text("vehicle: {a1: 150 cm, b1: 50 cm, c1: 140 cm, h1: 105 cm, d1: 50 cm, phi_max: 46 deg}\n"
                 "space: {H: 230 cm, J: 200 cm, MS: 20 cm, dx2: 90 cm, final_gap: 7 cm}\n")
    code, out, _ = run(capsys, str(f), "--json")
    data = json.loads(out)
    # the answer is printed, exit 1: 'park ... && next' went on (exit 0) as if the car had parked
    assert code == 1 and data["feasible"] is False and "too short" in data["reason"]
    assert 2.4 < data["shortest_H"] < 3.35
    assert data["approach"]["dx1"] is None and data["final_gap"] is None  # not defined: documented nulls, not NaN
    code, out, _ = run(capsys, str(f))
    assert "infeasible: the slot is too short" in out and "shortest slot that works" in out


def test_plot_and_animation_files(capsys, tmp_path):
    png, gif, html = tmp_path / "p.png", tmp_path / "a.gif", tmp_path / "a.html"
    code, _, _ = run(capsys, "thesis-9.1", "--plot", str(png), "--animate", str(gif), "--frames", "4")
    assert code == 0
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    from PIL import Image

    with Image.open(gif) as im:
        assert im.n_frames == 4
    code, _, _ = run(capsys, "thesis-9.2", "--animate", str(html), "--frames", "3")
    assert code == 0 and "<script" in html.read_text()


def test_an_html_animation_keeps_every_frame(capsys, tmp_path):
    """Past matplotlib's embedding limit (rcParams, 20 MB: about 500 frames of a plan) to_jshtml dropped the rest of
    the frames with a log message, and park said it wrote them all; a small limit shows it on a short run."""
    import matplotlib

    html = tmp_path / "a.html"
    with matplotlib.rc_context({"animation.embed_limit": 0.05}):
        code, _, _ = run(capsys, "thesis-9.2", "--animate", str(html), "--frames", "6")
    assert code == 0
    assert html.read_text().count("data:image/png;base64") == 6


@pytest.mark.parametrize(("argv", "message"), [
    (["nope.yaml"], "nope.yaml: cannot read the file"),
    (["thesis-9.9"], "no parking problem 'thesis-9.9'"),
    (["thesis-9.1", "--plot", "x.jpg"], "x.jpg: cannot draw to '.jpg' (plot files are .png, .svg, .pdf)"),
])
def test_errors_are_one_line_exit_2(capsys, tmp_path, monkeypatch, argv, message):
    monkeypatch.chdir(tmp_path)
    code, _, err = run(capsys, *argv)
    assert code == 2 and message in err and err.count("\n") == 1


def test_errors_as_json(capsys, tmp_path):
    f = tmp_path / "bad.yaml"
    f.write_text("vehicle:\n  a1: 1 deg\n")
    code, _, err = run(capsys, str(f), "--json")
    data = json.loads(err)
    assert code == 2 and data["line"] == 2 and "expected a length" in data["error"]


def test_animation_executed_through_the_tracker(capsys, tmp_path):
    """--controller runs the plan through wmrkit.control's closed loop (the thesis's law) before animating it."""
    out = tmp_path / "park.html"
    code, _, err = run(capsys, "thesis-9.1", "--animate", str(out), "--controller", "p", "--frames", "4")
    assert code == 0 and err == f"wmrkit: animation written to {out}\n" and out.stat().st_size > 1000
    code, _, err = run(capsys, "thesis-9.1", "--animate", str(out), "--controller", "stanley")
    assert code == 2 and "invalid choice" in err


@pytest.mark.parametrize(("argv", "message"), [
    (["--controller", "p"], "--controller p drives the plan for --animate or --check (it would be ignored)"),
    (["--controller", "pi", "--plot", "x.png"], "--controller pi drives the plan for --animate or --check"),
    (["--frames", "10"], "--frames applies to --animate (it would be ignored)"),
])
def test_options_of_the_executed_plan_need_animate_or_check(capsys, argv, message):
    """'park thesis-9.1 --controller p' printed the plan, exit 0, and drove nothing."""
    code, out, err = run(capsys, "thesis-9.1", *argv)
    assert code == 2 and out == "" and message in err


def test_check_reads_the_executed_path_too(capsys):
    """--check with --controller also checks the path the closed loop drove: example 1's plan only touches the
    front car (zero lateral clearance), and a tracker a fraction of a millimetre off clips it; example 2 stays
    clear. Said in the text and in JSON (``executed_check``); a collision is an answer, exit 1 (it was 0, so a
    script went on as if the car had parked)."""
    code, out, _ = run(capsys, "thesis-9.1", "--check", "--controller", "p", "--json")
    data = json.loads(out)
    assert code == 1 and data["check"]["collision_free"] is True
    executed = data["executed_check"]
    assert executed["mode"] == "p" and executed["collision_free"] is False and executed["first_hit"] == "front"
    assert executed["colliding_poses"] > 0 and executed["inside_slot"] is True
    code, out, _ = run(capsys, "thesis-9.2", "--check", "--controller", "pi")
    assert code == 0 and "executed path, closed loop with the PI law" in out
    assert out.count("collision-free") == 2
    code, out, _ = run(capsys, "thesis-9.1", "--check")  # no execution asked: the plan alone
    assert "executed" not in out


def test_a_plan_too_long_for_the_closed_loop_is_refused_in_parking_terms(capsys, tmp_path):
    """A pass 1000 m out (the largest length a problem takes) makes a 2.6 km plan, 86 min to drive: the closed loop
    refused it with track's advice (--duration, --speed, --size, --period), none of which park has."""
    f = tmp_path / "far.yaml"
    f.write_text("vehicle: {a1: 1.5, b1: 0.5, c1: 1.4, h1: 1.05, d1: 0.5, phi_max: 46 deg}\n"
                 "space: {H: 3.35, J: 2.0, MS: 0.2, dx2: 1000, final_gap: 0.07}\n")
    code, _, err = run(capsys, str(f), "--controller", "p", "--animate", str(tmp_path / "far.gif"))
    assert code == 2 and err.count("\n") == 1
    assert "controller 'p': the plan takes 5163 s to drive" in err and "open loop" in err
    assert not any(option in err for option in ("--duration", "--speed", "--size", "--period"))
    assert not (tmp_path / "far.gif").exists()


@pytest.mark.parametrize("argv", [["--plot", "x.txt"], ["--animate", "x.mp4"], ["--json", "--animate", "x.png"]])
def test_output_files_it_cannot_write_are_refused_before_the_answer(capsys, tmp_path, monkeypatch, argv):
    """The whole answer (text, or JSON on stdout) was printed, then the error, exit 2."""
    monkeypatch.chdir(tmp_path)
    code, out, err = run(capsys, "thesis-9.1", *argv)
    assert code == 2 and out == "" and err.count("\n") == 1 and argv[-1] in err
    assert list(tmp_path.iterdir()) == []


def test_an_exact_check_too_big_is_refused_before_it_allocates(capsys, tmp_path, monkeypatch):
    """A 600 m car in a 1 km slot (lengths within the 1 km bound) plans a 9.8 km path; '--check' sampled it every
    2 mm of corner motion, 4.5e6 car polygons at once: over 3.5 GB, a GEOS 'std::bad_alloc' traceback under a memory
    limit. The check now samples in car sizes (0.6 m for this car: 28,030 poses, collision-free); 2 mm is refused
    before anything is allocated, and so is a check past the bound from the command line: one line naming the
    count and the bound, exit 2."""
    from wmrkit.parking import verify
    from wmrkit.parking.problem import load_problem

    f = tmp_path / "big.yaml"
    f.write_text("vehicle: {a1: 500, b1: 100, c1: 400, h1: 500, d1: 1, phi_max: 45 deg}\n"
                 "space: {H: 1000, J: 1000, MS: 0, dx2: 1000, final_gap: 0.01}\n")
    code, out, _ = run(capsys, str(f))
    assert code == 0 and "feasible: 13 manoeuvres" in out  # the plan itself is cheap
    problem = load_problem(f)
    plan = plan_parking(problem.vehicle, problem.space)
    with pytest.raises(WmrkitError, match="at most 2000000"):
        verify.check_plan(problem.vehicle, problem.space, plan.segments, corner_step=0.002)
    code, out, _ = run(capsys, str(f), "--check")
    assert code == 0 and "exact check (28030 poses): collision-free, ends inside the slot" in out
    monkeypatch.setattr(verify, "MAX_CHECK_POSES", 20_000)
    code, out, err = run(capsys, str(f), "--check", "--json")
    assert code == 2 and out == "" and err.count("\n") == 1
    assert "poses" in json.loads(err)["error"] and "at most 20000" in err


def test_a_plan_too_long_to_time_is_still_the_answer_with_a_warning(capsys, tmp_path, monkeypatch):
    """A 900 m car in a 1 km slot plans 92 manoeuvres over 14 km; timing it for Table 8.1's line took 28,630 s at
    0.5 m/s, past the 25,000 s execution bound. `wmrkit park` printed only 'wmrkit: error: the plan takes 2.863e+04
    s to drive ...' and exited 2 (bad input), as if there were no plan. Now the plan, and the verdict not judged.
    (Driven at 0.25 car lengths/s it takes 509.5 s, 10,268 samples: the bound is lowered to 5,000 here.)"""
    from wmrkit.parking import execute

    monkeypatch.setattr(execute, "MAX_SAMPLES", 5000)
    f = tmp_path / "long-plan.yaml"
    f.write_text("vehicle: {a1: 700, b1: 200, c1: 300, h1: 600, d1: 1, phi_max: 45 deg}\n"
                 "space: {H: 1000, J: 301, MS: 0, dx2: 1000, final_gap: 0.01}\n")
    code, out, err = run(capsys, str(f))
    assert code == 0 and "feasible: 92 manoeuvres" in out and "Table 8.1 (" not in out
    assert err.startswith("wmrkit: warning: Table 8.1 not judged: the plan takes 509.5 s to drive")
    assert err.count("\n") == 1
    code, out, _ = run(capsys, str(f), "--json")
    data = json.loads(out)
    assert code == 0 and data["feasible"] and data["maneuvers"] == 92 and data["feasibility"] is None
    assert data["warnings"][-1].startswith("Table 8.1 not judged: the plan takes")


@pytest.mark.parametrize("json_flag", [[], ["--json"]])
def test_an_impossible_slot_with_animate_is_the_answer_exit_1(capsys, tmp_path, json_flag):
    """An impossible slot with --animate exited 2 (bad input) with 'the plan is not feasible (...): nothing to
    execute', without the answer (the reason, the shortest slot) that it prints, exit 1, without --animate."""
    f = tmp_path / "short.yaml"
    f.write_text("vehicle: {a1: 150 cm, b1: 50 cm, c1: 140 cm, h1: 105 cm, d1: 50 cm, phi_max: 46 deg}\n"
                 "space: {H: 230 cm, J: 200 cm, MS: 20 cm, dx2: 90 cm, final_gap: 7 cm}\n")
    gif = tmp_path / "a.gif"
    code, out, err = run(capsys, str(f), "--animate", str(gif), "--check", "--controller", "p", *json_flag)
    assert code == 1 and not gif.exists() and "no animation" in err
    if json_flag:
        assert json.loads(out)["feasible"] is False
    else:
        assert "infeasible: the slot is too short" in out and "shortest slot that works" in out


def test_park_shows_table_8_1_s_verdict_on_the_timed_plan(capsys, monkeypatch):
    """The plan, timed as it is driven (a trapezoid a segment, the steering turned at rest), judged by Table 8.1 at
    the steering axle's midpoint (the point the closed loop tracks), through track's code: text line, JSON
    'feasibility', a warning when not feasible. Its arcs meet at rest, so the car follows them; before the signals'
    fix the plans' last sample was a false 'tangent-angle jump' (thesis-9.1 at 29.35 s)."""
    from wmrkit.control.feasibility import Violation
    from wmrkit.parking import execute

    for name in ("thesis-9.1", "thesis-9.2"):
        assert main(["park", name]) == 0
        out, err = capsys.readouterr()
        assert "Table 8.1 (column 'type 4, off axle' for the steering axle's midpoint, kinematic framework): " \
               "feasible: yes" in out.splitlines() and "cannot follow" not in err  # (9.2's dx2 warning said)
        assert main(["park", name, "--json"]) == 0
        data = json.loads(capsys.readouterr().out)
        assert data["feasibility"]["feasible"] and data["feasibility"]["column"] == "type 4, off axle"
    judged = execute.plan_feasibility

    def corner(plan, robot=None):  # a plan Table 8.1 refuses: the warning and the line say so, the answer stands
        verdict = judged(plan, robot)
        jump = Violation(3.0, "chi", "tangent-angle jump (chi not C0)", 1.0, "stop and re-orient the orientable wheel")
        return type(verdict)(verdict.requirement, (jump,))

    monkeypatch.setattr(execute, "plan_feasibility", corner)
    assert main(["park", "thesis-9.1"]) == 0
    out, err = capsys.readouterr()
    assert "feasible: NO (1 violation(s))" in out and err.startswith(
        "wmrkit: warning: the robot cannot follow this reference with zero error (Table 8.1, column 'type 4, off axle' "
        "for the tracked point, kinematic framework): tangent-angle jump (chi not C0) at t = 3 s: stop and re-orient")
    assert main(["park", "thesis-9.1", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert not data["feasibility"]["feasible"] and data["warnings"][0].startswith("the robot cannot follow")


@pytest.mark.parametrize("scale", [1e-3, 1e-5, 1.0])
def test_the_text_answer_prints_lengths_at_the_cars_scale(capsys, tmp_path, scale):
    """Example 1 scaled: every length the text prints (read back with its unit) is within 1/1000 of the car's size
    of the JSON's full-precision value. The 2 mm copy printed 'final gap to the curb 0.0 cm', 'lateral 0.2 cm',
    'radius 0.001 m', a 2.7 % error of the car's size."""
    import re

    metres = {"nm": 1e-9, "um": 1e-6, "mm": 1e-3, "cm": 1e-2, "m": 1.0}
    f = tmp_path / "scaled.yaml"
    lengths = {"a1": 1.5, "b1": 0.5, "c1": 1.4, "h1": 1.05, "d1": 0.5}
    space = {"H": 3.35, "J": 2.0, "MS": 0.2, "dx2": 0.7, "final_gap": 0.07}
    f.write_text(json.dumps({"vehicle": {**{k: v * scale for k, v in lengths.items()}, "phi_max": "46 deg"},
                             "space": {k: v * scale for k, v in space.items()}}))
    code, text, _ = run(capsys, str(f), "--check")
    code_json, out, _ = run(capsys, str(f), "--check", "--json")
    data = json.loads(out)
    assert code == code_json == 0

    def printed(pattern: str) -> list[float]:
        return [float(v) * metres[u] for v, u in re.findall(pattern + r"\s*(-?[\d.]+) (nm|um|mm|cm|m)\b", text)]

    pairs = [(printed("final gap to the curb"), [data["final_gap"]]),
             (printed("path"), [data["path_length"]]),
             (printed("radius"), [a["radius"] for a in data["arcs"]]),
             (printed("lateral"), [a["X"] for a in data["arcs"]]),
             (printed("gap"), [a["gap_after"] for a in data["arcs"]]),
             (printed("min clearance"), [data["check"]["min_clearance"]]),
             (printed("dx1 ="), [data["approach"]["dx1"]])]
    for shown, true in pairs:
        assert len(shown) == len(true) and len(true) > 0
        np.testing.assert_allclose(shown, true, rtol=0, atol=1e-3 * 2.0 * scale)


@pytest.mark.parametrize("scale", [1e-3, 1.0])
def test_table_8_1_and_the_closed_loop_run_agree_at_any_scale(capsys, tmp_path, monkeypatch, scale):
    """`park FILE --check --controller p`: Table 8.1's line on the plan and the closed-loop run's own verdict
    (control.track's TrackingRun.feasibility, captured) are the same, and no warning calls the plan's stops jumps.
    Before the speeds were in car lengths (9197d37), the 2 mm copy of example 1 at 0.5 m/s moved 12 car lengths a
    sample: 'feasible: NO (3 violation(s))' and the warning 'position jump (p_ref not C0) at t = 0.04924, 1.51,
    4.21 s'; the stops and cusps of a parking plan are at rest, which Table 8.1's type-4 column allows."""
    import importlib

    tracking = importlib.import_module("wmrkit.control.track")  # the module (wmrkit.control.track is the function)
    runs = []
    real = tracking.track

    def spy(*args, **kwargs):
        runs.append(real(*args, **kwargs))
        return runs[-1]

    monkeypatch.setattr(tracking, "track", spy)
    f = tmp_path / "scaled.yaml"
    lengths = {"a1": 1.5, "b1": 0.5, "c1": 1.4, "h1": 1.05, "d1": 0.5}
    space = {"H": 3.35, "J": 2.0, "MS": 0.2, "dx2": 0.7, "final_gap": 0.07}
    f.write_text(json.dumps({"vehicle": {**{k: v * scale for k, v in lengths.items()}, "phi_max": "46 deg"},
                             "space": {k: v * scale for k, v in space.items()}}))
    _, text, err = run(capsys, str(f), "--check", "--controller", "p")
    _, out, err_json = run(capsys, str(f), "--check", "--controller", "p", "--json")
    data = json.loads(out)
    assert err == err_json == "" and data["warnings"] == []
    assert "kinematic framework): feasible: yes" in text and data["feasibility"]["feasible"]
    assert len(runs) == 2 and all(r.feasibility.feasible for r in runs)
    assert runs[0].feasibility.requirement.column == data["feasibility"]["column"] == "type 4, off axle"


@pytest.mark.parametrize("scale", [1e-3, 1e2])  # (1e3: a 1.5 km car is beyond the 1 km parking limit)
def test_json_poses_are_as_many_at_any_scale(capsys, tmp_path, scale):
    """The JSON's poses of example 1 scaled by k are those of 1:1 scaled by k (one every 1/40 car size): a fixed 5 cm
    step gave the 2 mm car 6 poses (its segment ends) against 190."""
    lengths = {"a1": 1.5, "b1": 0.5, "c1": 1.4, "h1": 1.05, "d1": 0.5}
    space = {"H": 3.35, "J": 2.0, "MS": 0.2, "dx2": 0.7, "final_gap": 0.07}
    poses = []
    for k in (1.0, scale):
        f = tmp_path / f"k{k:g}.yaml"
        f.write_text(json.dumps({"vehicle": {**{n: v * k for n, v in lengths.items()}, "phi_max": "46 deg"},
                                 "space": {n: v * k for n, v in space.items()}}))
        _, out, _ = run(capsys, str(f), "--json")
        poses.append(np.array(json.loads(out)["poses"]))
    assert len(poses[0]) > 100 and poses[1].shape == poses[0].shape
    np.testing.assert_allclose(poses[1][:, :2] / scale, poses[0][:, :2], rtol=0, atol=1e-9)
    np.testing.assert_allclose(poses[1][:, 2], poses[0][:, 2], rtol=0, atol=1e-9)


def test_the_plan_s_warnings_are_said_on_stderr_as_every_command_s(capsys):
    """park printed its plan's warnings in its text answer on stdout ('warning: dx2 = ...'), unlike every other
    command ('wmrkit: warning: ...' on stderr). Under --json stdout stays the JSON answer, the warning in it once."""
    dx2 = "dx2 = 0.17 m puts the car over the parked cars (c1/2 = 1.75 m)"  # Table 9.2: 17 cm, c1 = 3.5 m
    code, out, err = run(capsys, "thesis-9.2")
    assert code == 0 and "warning" not in out and out.startswith("problem thesis-9.2: ")
    assert [line for line in err.splitlines() if dx2 in line] == [f"wmrkit: warning: {dx2}; the detection pass is "
                                                                  "driven at c1/2 + MS = 1.87 m"]
    code, out, err = run(capsys, "thesis-9.2", "--json")
    assert code == 0 and [w for w in json.loads(out)["warnings"] if w.startswith(dx2)] and dx2 in err
    assert len(json.loads(out)["warnings"]) == 1


def test_the_plan_figure_s_legend_names_every_element_drawn(tmp_path):
    """The legend named the executed path alone (and a plan drawn without one had no legend): the planned path's
    two colours, the cars at the stops, the parked car, the scene were left to guess."""
    from matplotlib.colors import to_hex

    from wmrkit.parking.execute import execute_plan
    from wmrkit.parking.plot import BACKWARD, FORWARD, plot_plan
    from wmrkit.parking.problem import load_problem

    problem = load_problem("thesis-9.1")
    plan = plan_parking(problem.vehicle, problem.space)
    ax = plot_plan(plan, execute_plan(plan), name="thesis-9.1").axes[0]
    legend = {t.get_text(): h for t, h in zip(ax.get_legend().get_texts(), ax.get_legend().legend_handles,
                                              strict=True)}
    assert list(legend) == ["planned path of the rear axle's midpoint, forward",
                            "planned path of the rear axle's midpoint, backward", "executed path (open-loop)",
                            "car at each stop", "car parked (goal)", "parked cars", "curb", "slot",
                            "safety margins (MS)"]
    drawn = {to_hex(line.get_color()) for line in ax.lines}  # the legend's colours are those drawn
    assert {FORWARD, BACKWARD} <= drawn and to_hex(legend["planned path of the rear axle's midpoint, forward"]
                                                   .get_color()) == FORWARD
    assert ax.get_title().startswith("thesis-9.1: H = 3.35 m")
    short = load_problem("thesis-9.1")
    impossible = plan_parking(short.vehicle, replace(short.space, H=2.0))  # nothing drawn but the scene
    texts = [t.get_text() for t in plot_plan(impossible).axes[0].get_legend().get_texts()]
    assert not impossible.feasible and texts == ["parked cars", "curb", "slot", "safety margins (MS)"]
