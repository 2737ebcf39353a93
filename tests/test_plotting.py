"""Robot drawings: every catalog robot draws to files; the wheels drawn are where the model puts them."""

from __future__ import annotations

import importlib.util
from pathlib import Path

import numpy as np
import pytest
from matplotlib.axes import Axes
from matplotlib.colors import to_hex
from matplotlib.figure import Figure

from wmrkit import Robot, ShapeError, WmrkitError, catalog
from wmrkit.cli.main import main
from wmrkit.plotting import PlotError, draw_robot, save_robot_figure
from wmrkit.plotting.robot import DRIVEN, PASSIVE

HEADERS = {".png": b"\x89PNG\r\n\x1a\n", ".pdf": b"%PDF-"}

SPECIALS = Robot.from_dict({"name": "specials", "wheels": [
    {"name": "dbl", "type": "double", "position": [0.4, 0.3], "beta": "70 deg", "b": 0.08, "r": 0.06,
     "actuated": ["spin1"], "sensed": ["spin1", "spin2", "steer"]},
    {"name": "dcas", "type": "double_castor", "position": [0.4, -0.3], "beta": "100 deg", "d": 0.1, "b": 0.07,
     "r": 0.05},
    {"name": "cas", "type": "castor", "position": [-0.5, 0], "beta": "30 deg", "d": 0.08, "delta": "20 deg",
     "r": 0.05, "actuated": ["steer", "spin"]},
    {"name": "ball", "type": "ball", "position": [-0.3, 0.3], "beta": "90 deg", "r": 0.06, "actuated": ["spin"]},
    {"name": "orth", "type": "orthogonal", "position": [-0.3, -0.3], "beta": "90 deg", "r": 0.06},
    {"name": "mec", "type": "swedish", "position": [0.0, -0.5], "beta": "60 deg", "gamma": "45 deg", "r": 0.07,
     "r_r": 0.01},
]})


def _wheel_patches(ax: Axes) -> list:
    return [p for p in ax.patches if to_hex(p.get_facecolor()) in (DRIVEN, PASSIVE)]


@pytest.mark.parametrize("name", catalog.names())
def test_every_catalog_robot_draws_to_png_and_svg(name, tmp_path):
    robot = catalog.load(name)
    for suffix in (".png", ".svg"):
        path = tmp_path / f"{name}{suffix}"
        save_robot_figure(robot, path)
        data = path.read_bytes()
        assert len(data) > 5000
        if suffix == ".png":
            assert data.startswith(HEADERS[".png"])
        else:
            assert b"<svg" in data[:2000] and data.rstrip().endswith(b"</svg>")


def test_pdf_and_unknown_extensions(tmp_path):
    robot = catalog.load("omni-3")
    save_robot_figure(robot, tmp_path / "r.pdf")
    assert (tmp_path / "r.pdf").read_bytes().startswith(HEADERS[".pdf"])
    with pytest.raises(PlotError, match=r"r\.txt: cannot draw to '\.txt'"):
        save_robot_figure(robot, tmp_path / "r.txt")
    assert issubclass(PlotError, WmrkitError)


def test_cli_show_plot(tmp_path, capsys):
    out = tmp_path / "x.png"
    assert main(["show", "thesis-omni-castor", "--plot", str(out)]) == 0
    assert out.read_bytes().startswith(HEADERS[".png"])
    assert main(["show", "diff-drive", "--plot", str(tmp_path / "x.gif")]) == 2
    assert f"--plot {tmp_path / 'x.gif'}: cannot draw to '.gif'" in capsys.readouterr().err  # the option named


@pytest.mark.parametrize("robot", [SPECIALS, catalog.load("thesis-steer-castor"), catalog.load("mecanum-4")],
                         ids=lambda r: r.name)
def test_wheels_are_drawn_at_the_model_contact_points_with_the_model_axles(robot):
    """Independent of the drawing code: a rotation about a drawn wheel centre, with the wheel's joints still,
    leaves that contact point's slip zero (rows of (3.10)); the short side of a plain wheel lies along its axle,
    the row-0 direction (cos, sin)(beta + delta) of (3.12). One patch per contact element, coloured driven
    exactly when the element's spin is actuated."""
    ax = draw_robot(robot)
    patches = _wheel_patches(ax)
    a = robot.constraint_matrix()
    elements = [(w, spin) for w in robot.wheels
                for spin in (("spin1", "spin2") if w.type in ("double", "double_castor") else ("spin",))]
    assert len(patches) == len(elements)
    for i, (patch, (wheel, spin)) in enumerate(zip(patches, elements, strict=True)):
        corners = patch.get_xy()[:-1]  # a closed polygon repeats its first point
        x, y = corners.mean(axis=0)
        np.testing.assert_allclose(a[2 * i: 2 * i + 2, :3] @ [y, -x, 1.0], 0, atol=1e-12)
        assert (to_hex(patch.get_facecolor()) == DRIVEN) == (spin in wheel.actuated), (wheel.name, spin)
        if wheel.type in ("fixed", "steerable", "castor", "double", "double_castor"):
            short = corners[0] - corners[3]  # _rect: corners 0 and 3 differ across the wheel width
            row0 = a[2 * i, :2]
            assert abs(short[0] * row0[1] - short[1] * row0[0]) < 1e-12


def test_batched_and_other_configurations():
    robot = catalog.load("thesis-tricycle")
    sweep = np.radians(np.linspace(-60, 60, 7))[:, None]
    ax = draw_robot(robot, beta=sweep)
    # 2 fixed wheels once, the steered wheel once per configuration
    assert len(_wheel_patches(ax)) == 2 + 7
    two_d = draw_robot(robot, beta=np.zeros((2, 3, 1)), labels=False)
    assert len(_wheel_patches(two_d)) == 2 + 6 and two_d.get_title() == "" and two_d.get_legend() is None
    other = draw_robot(robot, beta=[0.3])
    centre = _wheel_patches(other)[-1].get_xy()[:4].mean(axis=0)
    np.testing.assert_allclose(centre, robot.wheel("o3").position, atol=1e-12)
    with pytest.raises(ShapeError, match=r"beta: expected shape \(\.\.\., 1\)"):
        draw_robot(robot, beta=[0.1, 0.2])


def test_draws_into_a_given_axes():
    fig = Figure()
    axes = fig.subplots(1, 2)
    got = draw_robot(catalog.load("ackermann"), axes[1])
    assert got is axes[1] and got.figure is fig
    assert got.get_title() == "ackermann" and got.get_legend() is not None
    assert got.get_aspect() == 1.0
    assert tuple(fig.get_size_inches()) == tuple(Figure().get_size_inches())  # a user's figure is not resized


def test_the_docs_figure_script_draws_the_wheel_parameters(tmp_path):
    """docs/figures/make_figures.py stays runnable: its wheel-parameter figure draws (to a temporary file)."""
    script = Path(__file__).resolve().parents[1] / "docs" / "figures" / "make_figures.py"
    spec = importlib.util.spec_from_file_location("make_figures", script)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    fig = module.wheel_parameters_figure()
    fig.savefig(tmp_path / "w.svg")
    assert b"<svg" in (tmp_path / "w.svg").read_bytes()[:2000]


@pytest.mark.skipif(importlib.util.find_spec("PIL") is None, reason="the GIF writer needs Pillow")
def test_the_line_following_animation_has_bounded_frames_and_an_increasing_plan_axis(tmp_path, monkeypatch):
    """Every camera image was a frame (about 0.25 s and 1.5 MB each until written: 400 took 106 s and 640 MB, and
    follow-line allows 10^4). The plan view ran from the start's x to the end's: a run along -x (started at 180
    deg) had an inverted x axis with the robot out of view."""
    from PIL import Image

    import wmrkit.vision.animation as animation
    from wmrkit.vision.camera import Camera
    from wmrkit.vision.follow import follow_line

    root = Path(__file__).resolve().parents[1]
    camera = Camera.from_file(root / "docs" / "figures" / "vision" / "follower-camera.yaml")
    robot = catalog.load("line-follower")
    run = follow_line(robot, camera, duration=5.0, start=(0.0, 0.05, np.pi), keep_images=True)
    monkeypatch.setattr(animation, "MAX_FRAMES", 4)
    animation.save_animation(run, robot, camera, tmp_path / "run.gif")
    assert len(run.images) == 11 and Image.open(tmp_path / "run.gif").n_frames == 4
    backward = np.array([[0.0, 0.05, np.pi], [-1.0, 0.02, np.pi], [-2.0, 0.0, np.pi]])
    (x0, x1), (y0, y1) = animation._plan_limits(backward)
    assert x0 < -2.0 and x1 > 0.0 and y0 < 0.0 < 0.05 < y1


def test_a_long_trajectory_is_thinned_before_it_is_drawn(tmp_path, monkeypatch):
    """save_trajectory_plot drew every pose: 10^7 poses took 21 s and 1.1 GB more memory (now 3 s). The path keeps
    its first and last pose (the start and end marks)."""
    from matplotlib.axes import Axes as MplAxes

    from wmrkit.odometry.plot import MAX_PLOT_POINTS, save_trajectory_plot

    drawn = []
    plot = MplAxes.plot

    def spy(self, *args, **kwargs):
        drawn.append(np.asarray(args[:2], dtype=float))
        return plot(self, *args, **kwargs)

    monkeypatch.setattr(MplAxes, "plot", spy)
    t = np.linspace(0.0, 20 * np.pi, 250_001)
    poses = np.stack([np.cos(t) * (1 + t), np.sin(t) * (1 + t), t], axis=-1)
    save_trajectory_plot(tmp_path / "long.png", {"spiral": poses})
    line = drawn[0]
    assert line.shape[1] <= MAX_PLOT_POINTS + 1
    np.testing.assert_array_equal(line[:, 0], poses[0, :2])
    np.testing.assert_array_equal(line[:, -1], poses[-1, :2])
    assert (tmp_path / "long.png").read_bytes().startswith(HEADERS[".png"])


def test_a_detection_figure_checks_its_file_type(tmp_path):
    """save_detection_figure raised matplotlib's ValueError for 'x.txt' and wrote 'x.png' when given 'x'."""
    from wmrkit.vision.animation import save_detection_figure
    from wmrkit.vision.camera import Camera

    figures = Path(__file__).resolve().parents[1] / "docs" / "figures"
    camera = Camera.from_file(figures / "vision" / "follower-camera.yaml")
    image = np.zeros((camera.rows, camera.width), dtype=np.uint8)
    for name in ("x.txt", "x"):
        with pytest.raises(PlotError, match="cannot draw to"):
            save_detection_figure(camera, image, tmp_path / name)
    assert not (tmp_path / "x.png").exists()
    save_detection_figure(camera, image, tmp_path / "ok.png")
    assert (tmp_path / "ok.png").read_bytes().startswith(HEADERS[".png"])


def test_many_configurations_are_thinned_and_an_empty_heading_batch_is_named():
    """Each configuration drawn costs about 10 ms (1000 took 9 s; a batch of 10^5 about 15 min): at most
    MAX_CONFIGURATIONS are drawn, first and last included. An empty batch given as heading= was reported as 'beta:'."""
    from wmrkit.plotting.robot import MAX_CONFIGURATIONS

    robot = catalog.load("swerve-4")
    headings = np.linspace(-1.0, 1.0, 1000)[:, None].repeat(4, axis=1)
    ax = draw_robot(robot, heading=headings)
    assert len(_wheel_patches(ax)) == 4 * MAX_CONFIGURATIONS
    with pytest.raises(ShapeError, match=r"^heading: no configuration to draw"):
        draw_robot(robot, heading=np.zeros((0, 4)))


def test_an_animation_body_does_not_cross_itself():
    """track --animate filled the wheels' mount points in description order: front_left, rear_right, front_right,
    rear_left drew a bow-tie. The footprint (shared with follow-line's animation) orders them around the body."""
    shapely = pytest.importorskip("shapely.geometry")
    from wmrkit.plotting.robot import footprint

    corners = {"front_left": (0.5, 0.3), "rear_right": (-0.5, -0.3), "front_right": (0.5, -0.3),
               "rear_left": (-0.5, 0.3)}
    robot = Robot.from_dict({"name": "x", "wheels": [
        {"name": n, "type": "swedish", "position": list(p), "heading": 0, "r": 0.05, "r_r": 0.01, "gamma": "45 deg"}
        for n, p in corners.items()]})
    described = shapely.Polygon([w.position for w in robot.wheels])
    assert not described.is_valid  # the bow-tie
    body = shapely.Polygon(footprint(robot))
    assert body.is_valid and body.area == pytest.approx(0.6, abs=1e-12)
    with_origin = footprint(robot, origin=True)
    assert len(with_origin) == 5 and shapely.Polygon(with_origin).is_valid


@pytest.mark.parametrize("poses", [[[0.0, 0.0, 0.0], [float("nan"), 1.0, 0.0], [2.0, 2.0, 0.0]],
                                   [[0.0, 0.0, 0.0], [float("inf"), 1.0, 0.0]], np.zeros((0, 3)), np.zeros(3),
                                   np.zeros((4, 2)), [[0, 0, 0], [1, "a", 0]]])
def test_a_trajectory_plot_refuses_a_path_it_cannot_draw_naming_it(tmp_path, poses):
    """save_trajectory_plot drew a path with a NaN or an infinite pose as a broken line (or none) and wrote the
    file; an empty path raised an IndexError, a flat (3,) one 'too many indices', a text value numpy's ValueError."""
    from wmrkit.errors import WmrkitError
    from wmrkit.odometry.plot import save_trajectory_plot

    with pytest.raises(WmrkitError, match=r"^odometry \(diff-drive\): "):
        save_trajectory_plot(tmp_path / "p.png", {"ok": np.zeros((2, 3)), "odometry (diff-drive)": poses})
    assert list(tmp_path.iterdir()) == []


def _gif_frames(path) -> list[np.ndarray]:
    from PIL import Image, ImageSequence

    return [np.asarray(f.convert("RGB")) for f in ImageSequence.Iterator(Image.open(path))]


@pytest.mark.parametrize("argv", [["park", "thesis-9.2", "--frames", "12"],
                                  ["track", "forklift", "--reference", "arc-line"]])
def test_blitted_animation_frames_are_the_full_redraws_pixel_for_pixel(tmp_path, monkeypatch, argv):
    """park and track --animate render the static figure once and draw only the moving artists over it (save_gif's
    blit: 200 parking frames took 20 s, now about 2): every frame is the one a full redraw renders."""
    import wmrkit.parking.plot
    import wmrkit.plotting.files as files

    assert main([*argv, "--animate", str(tmp_path / "blit.gif")]) == 0
    full = files.save_gif

    def redrawn(*args, blit=False, **kwargs):
        return full(*args, blit=False, **kwargs)

    monkeypatch.setattr(files, "save_gif", redrawn)
    monkeypatch.setattr(wmrkit.parking.plot, "save_gif", redrawn)
    assert main([*argv, "--animate", str(tmp_path / "full.gif")]) == 0
    blit, drawn = _gif_frames(tmp_path / "blit.gif"), _gif_frames(tmp_path / "full.gif")
    assert len(blit) == len(drawn) > 10
    assert all(np.array_equal(a, b) for a, b in zip(blit, drawn, strict=True))
    assert any(not np.array_equal(blit[0], b) for b in blit[1:])  # it moves
