"""The analysis report and ``wmrkit analyze``: a report for every catalog robot; the JSON keys of the issue."""

from __future__ import annotations

import json
import re

import pytest

from wmrkit import Robot, catalog
from wmrkit.analysis import report
from wmrkit.analysis.classification import classify
from wmrkit.analysis.isotropy import natural_length
from wmrkit.analysis.report import write_report
from wmrkit.analysis.summary import analyze, describe_singular
from wmrkit.cli.main import main


@pytest.mark.parametrize("name", catalog.names())
def test_report_for_every_catalog_robot(name, tmp_path):
    robot = catalog.load(name)
    result = analyze(robot, resolution=12)
    page = write_report(result, tmp_path / name, resolution=12, dpi=30)
    text = page.read_text(encoding="utf-8")
    images = re.findall(r"<img src='([^']+)'", text)
    assert "robot.png" in images
    for img in images:  # every picture the page shows is there and is a PNG
        assert (page.parent / img).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    c = classify(robot)
    if c.degenerate:
        assert "Degenerate robot" in text
    else:
        assert f"Type {c.type} of the thesis" in text and f"m = {c.mobility}, d = {c.steerability}" in text
    assert "Singular configurations" in text and "Isotropy" in text
    for c in robot.couplings:  # the actuated model's channels, as analyze searches it
        if c.rates and all(j in robot.actuated for j in c.joints):
            assert f"<td>({c.channel_name}): " in text


def test_json_output_has_the_keys_of_the_issue(capsys):
    assert main(["analyze", "forklift", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert (out["mobility"], out["steerability"], out["type"], out["degenerate"]) == (1, 1, 4, False)
    assert set(out["actuation"]) >= {"consistent", "sufficient"} and set(out["sensing"]) >= {"sufficient"}
    assert out["actuation"]["consistent"] is True  # two driven wheels, one motor: the catalog declares the differential
    assert out["actuation"]["sufficient"] is True and out["sensing"]["sufficient"] is True
    assert out["condition_number"] is None and out["isotropy_note"].startswith("does not apply (m = 1")
    assert out["characteristic_length"] is None  # m = 1: isotropy does not apply, no length to choose


def test_couplings_decide_the_actuation_verdict(capsys):
    """Issue 8: the forklift drives both wheels through one differential; without that coupling its two driven
    wheels and one degree of mobility are over-actuated (ch. 4), and the words say what that means."""
    import dataclasses

    from wmrkit.kinematics import actuation_analysis

    robot = catalog.load("forklift")
    assert robot.couplings and bool(actuation_analysis(robot).consistent)
    free = dataclasses.replace(robot, couplings=())
    assert not bool(actuation_analysis(free).consistent) and bool(actuation_analysis(free).sufficient)
    assert main(["analyze", "mecanum-4"]) == 0
    line = next(x for x in capsys.readouterr().out.splitlines() if "actuation:" in x)
    assert "over-actuated" in line and "coordinated" in line and "inconsistent" not in line


def test_analyze_names_a_differential_as_one_actuator_as_kinematics_does(capsys):
    """analyze listed the differential's two joints as actuators beside a verdict counting them as one, while its
    own singular line and `kinematics` named the channel."""
    assert main(["analyze", "forklift"]) == 0
    lines = capsys.readouterr().out.splitlines()
    channel = "differential of right_drive and left_drive"  # the JSON's differential(right_drive.spin, ...)
    actuation = next(x for x in lines if x.strip().startswith("actuation:"))
    assert actuation.endswith(f"({channel}, steer.steer)")
    assert any(x.strip().startswith(f"singular (actuated: {channel})") for x in lines)


def test_json_condition_number_at_the_natural_or_given_length(capsys):
    assert main(["analyze", "thesis-omni-swedish", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    d, k = natural_length(catalog.load("thesis-omni-swedish"))
    assert out["characteristic_length"] == pytest.approx(d) and out["condition_number"] == pytest.approx(k)
    assert out["type"] == 1 and out["mobility"] == 3 and out["steerability"] == 0
    assert main(["analyze", "thesis-omni-swedish", "--json", "--length", "500 mm"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["characteristic_length"] == pytest.approx(0.5)
    assert out["condition_number"] == pytest.approx(2**0.5)  # L = 0.5 m: kappa(D = L) = sqrt(2) (digest §9)


def test_degenerate_robot_json(capsys):
    assert main(["analyze", "skid-steer-4", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["degenerate"] is True and out["type"] is None and out["mobility"] == 1


def test_text_summary_and_report_flag(capsys, tmp_path):
    assert main(["analyze", "thesis-tricycle", "--report", str(tmp_path / "r"), "--resolution", "12"]) == 0
    out = capsys.readouterr()
    text = out.out
    assert "type 4" in text and "m = 1" in text and "singular" in text
    assert out.err == f"wmrkit: report written to {tmp_path / 'r' / 'index.html'}\n"
    assert (tmp_path / "r" / "index.html").exists()


def test_steer_option_changes_the_configuration(capsys):
    assert main(["analyze", "thesis-tricycle", "--steer", "o3=0 deg", "--json"]) == 0  # heading 0: beta = 90 deg
    out = json.loads(capsys.readouterr().out)
    assert "(0.000, 0.000)" in out["icr"]  # axle through the origin: pure rotation about O_R (Fig. 6.8a)


@pytest.mark.parametrize(("argv", "message"), [
    (["analyze", "no-such-robot"], "no robot 'no-such-robot'"),
    (["analyze", "forklift", "--length", "3 deg"], "--length"),
    (["analyze", "forklift", "--length", "-1"], "--length: -1 m is outside the lengths"),
    (["analyze", "forklift", "--resolution", "3"], "--resolution"),
    (["analyze", "forklift", "--steer", "right_drive=1"], "does not steer"),
])
def test_user_errors_exit_2_with_one_line(argv, message, capsys):
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert message in err and err.count("\n") == 1


ONE_WHEEL = "name: one\nwheels:\n" \
            "  - {name: left, type: fixed, position: [0, 0.2], heading: 0, r: 0.05, actuated: spin}\n"


def test_no_natural_length_where_every_length_leaves_the_twist_undetermined(tmp_path, capsys):
    """One driven wheel, m = 2: kappa is infinite at every D, yet analyze printed "at the natural length D = 0.2 m"
    (the robot size natural_length falls back to) and the JSON and report gave that D as natural."""
    path = tmp_path / "one.yaml"
    path.write_text(ONE_WHEEL, encoding="utf-8")
    assert main(["analyze", str(path)]) == 0
    line = next(x for x in capsys.readouterr().out.splitlines() if "condition number" in x)
    assert line == "  condition number infinite (these joints do not determine the twist), joints left.spin"
    assert main(["analyze", str(path), "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["condition_number"] is None and out["characteristic_length"] is None
    assert main(["analyze", str(path), "--length", "300 mm"]) == 0  # a given length is still reported
    assert "infinite (these joints do not determine the twist) at the given length D = 0.3 m" in capsys.readouterr().out
    text = write_report(analyze(Robot.from_file(path), resolution=12), tmp_path / "r", resolution=12,
                        dpi=30).read_text(encoding="utf-8")
    assert "characteristic length D" not in text and "infinite (these joints do not determine the twist)" in text


def test_the_table_of_every_assigned_set_repeats_the_summary_for_the_analysed_sets(tmp_path):
    """thesis-two-steer-castor's page said "(o1.spin): on curves over (o1, o2), 180 sampled points" in the summary
    and "o1.spin | on curves over (o1, o2), 44 sampled points" in the table below: the table searched again at a
    quarter of the resolution. The analysed sets are now shown as analysed."""
    result = analyze(catalog.load("thesis-two-steer-castor"), resolution=48)
    s = result.singular["actuated"]
    assert s.assigned == ("o1.spin",) and not s.exact and not s.coupled
    text = write_report(result, tmp_path, resolution=48, dpi=30).read_text(encoding="utf-8")
    assert f"<tr><td>o1.spin</td><td>{describe_singular(s, result.robot, limit=4)}</td></tr>" in text


def test_the_table_of_every_assigned_set_has_a_bounded_grid(monkeypatch):
    """The table searched each of its up to 36 sets at a quarter of --resolution: at 1440, a 360-point grid per
    set, 150 s for a robot of 64 steered wheels (the singular sets above it are searched at --resolution)."""
    asked = []

    def recorder(real):
        return lambda robot, q_a, **k: asked.append(k["resolution"]) or real(robot, q_a, **{**k, "resolution": 12})

    monkeypatch.setattr(report, "coordinated_singular_set", recorder(report.coordinated_singular_set))
    monkeypatch.setattr(report, "singular_set", recorder(report.singular_set))
    for name in ("swerve-4", "thesis-steer-castor"):
        report._assignable_table(analyze(catalog.load(name), resolution=12), 1440)
    assert asked and max(asked) == 90  # report.TABLE_RESOLUTION



@pytest.mark.parametrize(("name", "figure"), [("forklift", "singular"), ("ackermann", "singular"),
                                              ("thesis-steer-castor", "length")])
def test_report_figures_keep_every_axis_label_inside(name, figure):
    """The forklift's and the car's singular pictures lost the left of their 'y [m]' label, the kappa(D) curve of
    thesis-steer-castor half of 'condition number κ': the labels reached past the figure's left edge, which the
    PNG cuts off. Every axis label and title now lies inside the figure."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    from wmrkit.analysis.figures import length_figure, singular_figure

    robot = catalog.load(name)
    result = analyze(robot, resolution=12)
    fig = (singular_figure(robot, result.singular["actuated"], "actuated") if figure == "singular"
           else length_figure(robot, result.joints))
    canvas = FigureCanvasAgg(fig)
    canvas.draw()
    for ax in fig.axes:
        for text in (ax.xaxis.label, ax.yaxis.label, ax.title):
            box = text.get_window_extent(canvas.get_renderer())
            assert fig.bbox.x0 <= box.x0 and box.x1 <= fig.bbox.x1, text.get_text()
            assert fig.bbox.y0 <= box.y0 and box.y1 <= fig.bbox.y1, text.get_text()


@pytest.mark.parametrize("name", ["ackermann", "thesis-tricycle", "swerve-4"])
def test_no_natural_length_where_isotropy_does_not_apply(name, capsys):
    """m = 1: kappa is 1 at every length, yet `analyze --json` gave the robot size (natural_length's fallback,
    2.06 m for the car) as `characteristic_length` with `natural_length: true`, while the text and the report say
    isotropy does not apply. No length is reported now unless one is given."""
    assert main(["analyze", name, "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["mobility"] == 1 and out["condition_number"] is None  # as the text: isotropy does not apply
    assert out["characteristic_length"] is None
    assert main(["analyze", name, "--json", "--length", "300 mm"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["characteristic_length"] == pytest.approx(0.3) and out["natural_length"] is False


@pytest.mark.parametrize("resolution", [0, 7, 1441, 10**6, -5, 2.5, "90"])
def test_the_python_doors_bound_the_resolution_as_analyze_resolution_does(resolution, tmp_path):
    """analyze(resolution=0) said the actuated model of thesis-steer-castor is 'always' singular (an empty search
    reads as all-singular), 10**6 ran without end, -5 and 2.5 raised numpy's ValueError / TypeError; the CLI refused
    them all. analyze and write_report now apply --resolution's rule, 8 to 1440 points a turn."""
    from wmrkit.errors import WmrkitError

    robot = catalog.load("thesis-steer-castor")
    with pytest.raises(WmrkitError, match="resolution"):
        analyze(robot, resolution=resolution)
    with pytest.raises(WmrkitError, match="resolution"):
        write_report(analyze(robot), tmp_path, resolution=resolution)
    assert not (tmp_path / "index.html").exists()


@pytest.mark.parametrize("dpi", [0, -5, float("nan"), float("inf"), 5, 601, 10**5, "100", True])
def test_write_report_refuses_a_resolution_of_images_it_cannot_draw(dpi, tmp_path):
    """write_report(dpi=) was passed to matplotlib unchecked: -5 and NaN raised its ValueError after robot.png was
    written, 0 drew at the default silently, 3000 drew a 28500 x 19500 px robot picture (2 GB, killed); a
    number from MIN_DPI to MAX_DPI or None is taken, anything else refused before the report folder is made."""
    from wmrkit.errors import WmrkitError

    with pytest.raises(WmrkitError, match="dpi"):
        write_report(analyze(catalog.load("diff-drive"), resolution=12), tmp_path / "r", resolution=12, dpi=dpi)
    assert not (tmp_path / "r").exists()


def test_singular_set_refuses_an_empty_search():
    """singular_set(resolution=0, max_samples=0) searched nothing and called the model always singular."""
    from wmrkit.analysis.singularity import singular_set
    from wmrkit.errors import WmrkitError

    robot = catalog.load("thesis-steer-castor")
    for bad in ({"resolution": 0, "max_samples": 0}, {"max_samples": 0}, {"resolution": 2.5}, {"resolution": -1}):
        with pytest.raises(WmrkitError):
            singular_set(robot, ("o1.spin", "c2.spin"), **bad)
