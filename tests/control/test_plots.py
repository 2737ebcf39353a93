"""What the figures of ``track --plot`` and ``feasibility --plot`` say, read from their matplotlib objects."""

from __future__ import annotations

import numpy as np
import pytest

from wmrkit import catalog
from wmrkit.cli.main import main
from wmrkit.control import builtin_reference, track
from wmrkit.control import plots as plots_module


@pytest.fixture
def drawn(monkeypatch):
    """The figures the plotting functions draw, kept (the file written all the same)."""
    figures, save = [], plots_module._save

    def keep(fig, path):
        figures.append(fig)
        fig.canvas.draw()  # the legend and texts laid out as in the file
        save(fig, path)

    monkeypatch.setattr(plots_module, "_save", keep)
    return figures


def _texts(ax) -> list[str]:
    legend = ax.get_legend()
    return [t.get_text() for t in (legend.get_texts() if legend else [])] + [ax.get_title()]


def test_errors_below_the_log_axis_floor_are_said_to_be_drawn_at_it(drawn, tmp_path):
    """The error panel's log axis drew errors below 1e-12 m (the diff drive's exact 0 on the first leg of the
    corner) at 1e-12 and said nothing: a user read 1e-12 m as the error."""
    run = track(catalog.load("diff-drive"), builtin_reference("corner"))
    assert run.error[run.t < 5].max() < 1e-12 < run.error.max()  # some errors below the floor, some above
    plots_module.plot_run(run, tmp_path / "run.png")
    ax = drawn[0].axes[1]
    assert ax.get_yscale() == "log" and "errors below 1e-12 m drawn at 1e-12 m" in _texts(ax)
    assert drawn[0].axes[0].get_title() == "diff-drive, controller p"  # it was 'diff-drive: p'


def test_errors_that_are_all_round_off_get_a_linear_axis_that_says_so(drawn, tmp_path):
    """A run whose errors are all round-off drew two flat lines at the log axis' floor, 1e-12 m."""
    run = track(catalog.load("diff-drive"), builtin_reference("line", duration=2.0))
    assert max(run.error.max(), run.cross_track.max()) < 1e-12  # on the line from the start: no error to speak of
    plots_module.plot_run(run, tmp_path / "run.png")
    ax = drawn[0].axes[1]
    assert ax.get_yscale() == "linear" and "every error below 1e-12 m (round-off)" in _texts(ax)
    drawn_values = np.concatenate([line.get_ydata() for line in ax.get_lines()])
    assert drawn_values.max() < 1e-12  # as computed, none raised to the floor


def test_errors_all_above_the_floor_get_no_note(drawn, tmp_path):
    run = track(catalog.load("diff-drive"), builtin_reference("line", duration=2.0), initial_pose=[0.0, 0.2, 0.0])
    assert min(run.error.min(), run.cross_track.min()) > 1e-12
    plots_module.plot_run(run, tmp_path / "run.png")
    assert not [t for t in _texts(drawn[0].axes[1]) if "drawn at" in t or "round-off" in t]


def test_a_robot_without_steered_wheels_says_so_in_the_heading_panel(drawn, tmp_path):
    plots_module.plot_run(track(catalog.load("omni-3"), builtin_reference("line", duration=1.0)), tmp_path / "r.png")
    assert [t.get_text() for t in drawn[0].axes[2].texts] == ["no steered wheels"]


def test_the_feasibility_figure_names_the_robot(drawn, tmp_path, capsys):
    """Every other command's figure names the robot; feasibility's title was the Table 8.1 column alone."""
    assert main(["feasibility", "forklift", "--reference", "corner", "--plot", str(tmp_path / "f.png")]) == 1
    column = capsys.readouterr().out.split("'")[1]  # 'robot forklift: Table 8.1 column 'type 4, off axle', ...'
    title = drawn[0].axes[0].get_title()
    assert title == f"forklift: Table 8.1 '{column}', kinematic: NOT feasible"


def test_the_feasibility_figure_marks_a_turn_tighter_than_the_stops(drawn, tmp_path, capsys):
    """The car's 1 m circle: no jump, a stretch tighter than its stops (drawn over the lap it spans); before, the
    figure said 'feasible' with nothing marked."""
    assert main(["feasibility", "ackermann", "--reference", "circle", "--size", "1", "--plot",
                 str(tmp_path / "f.png")]) == 1
    capsys.readouterr()
    ax = drawn[0].axes[0]
    assert "tighter than the steering stops" in _texts(ax) and ax.get_title().endswith("NOT feasible")
    (stretch,) = [line for line in ax.get_lines() if line.get_label() == "tighter than the steering stops"]
    assert np.hypot(stretch.get_xdata(), stretch.get_ydata() - 1.0) == pytest.approx(1.0, abs=1e-9)  # on it
    assert len(stretch.get_xdata()) > 0.9 * len(builtin_reference("circle", size=1.0).t)
