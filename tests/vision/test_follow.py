"""Closed-loop line following by vision (§9.2.2-9.2.3): the thesis's three examples and the forklift variant."""

from __future__ import annotations

import json
import math
import re

import numpy as np
import pytest

from wmrkit import catalog
from wmrkit.errors import WmrkitError
from wmrkit.kinematics.models import kinematic_model
from wmrkit.vision.camera import Camera
from wmrkit.vision.follow import follow_line, line_following_twist, thesis_initial_commands

ROBOT = catalog.load("line-follower")
#: A small camera on the line follower: 0.3 m high, 60 deg from the vertical, 320 x 240 px (sees 0.3 m aside).
CAMERA = Camera(150.0, math.radians(60), 0.3, 320, 240)


@pytest.fixture(scope="module")
def runs():
    return {
        "a0.3": follow_line(ROBOT, CAMERA, gain=0.3, duration=20),
        "a0.8": follow_line(ROBOT, CAMERA, gain=0.8, duration=20),
        "noise": follow_line(ROBOT, CAMERA, gain=0.3, duration=20, noise=(0.02, math.radians(3)), seed=3),
        "exact": follow_line(ROBOT, CAMERA, gain=0.3, duration=20, from_image=False),
    }


def test_thesis_initial_commands_example_1():
    """Digest §2.6: h = 0.3, theta = 0 -> R v = (0.09 right, 0.1 ahead), omega = -0.2308 rad/s, wheel rates
    1.2154 and 2.7846 rad/s (the thesis prints -1.2154, -2.7846: its spin sign is opposite to wmrkit's)."""
    c = thesis_initial_commands(ROBOT, h=0.3, gain=0.3, speed=0.1)
    assert (c["vx"], c["vy"]) == pytest.approx((0.1, -0.09))
    assert c["omega"] == pytest.approx(-0.09 / 0.39)
    assert c["right.spin"] == pytest.approx(1.2154, abs=1e-4)
    assert c["left.spin"] == pytest.approx(2.7846, abs=1e-4)


def test_errata_9_26_lateral_command_sign():
    """(9.25) gives ^G x_R = -h in the thesis's frame (X to the right); (9.26) prints ^G v_x = -a h, which would
    push P away from the line. Corrected: +a h there, i.e. -a h along wmrkit's y (left)."""
    a, h, dt = 0.3, 0.3, 0.1
    v = line_following_twist(ROBOT, 0.0, h, a, 0.1)  # robot aligned with the line: robot frame = line frame
    thesis_gx = -v[1]  # thesis X_G = -y_L
    assert thesis_gx == pytest.approx(+a * h)
    assert abs(h + v[1] * dt) < abs(h)  # the corrected command reduces the error ...
    assert abs(h + (a * h) * dt) > abs(h)  # ... the printed one, read in wmrkit's frame, increases it


def test_example_1_gain_0_3_is_monotone(runs):
    h = runs["a0.3"].lateral
    assert np.all(np.diff(h) <= 1e-4)  # no oscillation
    assert h.min() > -1e-3
    assert abs(h[-1]) < 0.005
    assert not runs["a0.3"].lost.any()
    # the wheel commands settle at v / r = 0.1 / 0.05 = 2 rad/s (the thesis's -2 rad/s with its spin sign)
    np.testing.assert_allclose(runs["a0.3"].rates[-1], [2.0, 2.0], atol=0.05)


def test_example_3_gain_0_8_oscillates_slightly(runs):
    slow, fast = runs["a0.3"], runs["a0.8"]
    h = fast.lateral
    assert h.min() < -0.01  # crosses the line: no longer an exponential approach
    assert -h.min() < 0.25 * h[0]  # a small oscillation
    assert abs(h[-1]) < 0.005
    assert np.abs(fast.rates).max() > np.abs(slow.rates).max()  # larger wheel commands


def test_example_2_noise_jitters_the_wheels_but_tracks(runs):
    noisy, clean = runs["noise"], runs["a0.3"]
    late = noisy.time > 10.0
    assert np.abs(noisy.lateral[late]).max() < 0.03
    jitter = np.abs(np.diff(noisy.rates[-20:], axis=0)).max()
    assert jitter > 5 * np.abs(np.diff(clean.rates[-20:], axis=0)).max()
    seen = np.concatenate([noisy.lateral[:1], noisy.lateral[:-2]])  # the image of the previous period
    assert np.all(np.abs(noisy.measured[:, 1] - seen) <= 0.02 + 0.002)  # the noise bound, plus vision error


def test_camera_in_the_loop_matches_exact_positioning(runs):
    """Rendering, extraction and (9.10)-(9.11) at every period give the same run as measuring the pose exactly."""
    np.testing.assert_allclose(runs["a0.3"].pose, runs["exact"].pose, atol=2e-3)


def test_the_measurement_is_one_period_old(runs):
    r = runs["exact"]
    np.testing.assert_allclose(r.measured[1:, 1], r.lateral[:-2], atol=1e-12)
    np.testing.assert_allclose(r.measured[1:, 0], -r.pose[:-2, 2], atol=1e-12)


def test_wheel_commands_obey_the_differential_kinematics(runs):
    r = runs["a0.3"]
    model = kinematic_model(ROBOT, ["vx", "omega"])
    rates = model.solve(r.twist[:, [0, 2]])
    names = list(model.solved)
    for wheel in ("left.spin", "right.spin"):
        np.testing.assert_allclose(r.rates[:, r.rate_names.index(wheel)], rates[:, names.index(wheel)], atol=1e-9)
    np.testing.assert_allclose(r.twist[:, 1], 0.39 * r.twist[:, 2], atol=1e-12)  # v_y = e omega


def test_forklift_variant():
    """The forklift of ch. 7-8 (rear-steered tricycle, P at the fork tips) following a line with a camera 1.42 m
    high (the chufa camera's height and tilt), 1 m off the line at 0.5 m/s."""
    forklift = catalog.load("forklift")
    cam = Camera(272.5, math.radians(60), 1.42, 320, 240)
    run = follow_line(forklift, cam, gain=0.3, speed=0.5, start=(0.0, 1.0, 0.0), duration=20)
    assert not run.lost.any()
    assert abs(run.lateral[-1]) < 0.01
    assert np.all(np.abs(run.steer) <= math.radians(90))  # within the forklift's steering range
    assert run.steer[0, 0] > 0  # the rear wheel steers left to turn the truck right, towards the line
    assert run.steer_names == ("steer",)


def test_a_lost_image_keeps_the_previous_positioning(monkeypatch):
    from wmrkit.vision import follow as follow_module

    real, calls = follow_module.locate_image, []

    def flaky(*args, **kwargs):
        calls.append(1)
        if len(calls) % 3 == 0:
            raise WmrkitError("image: found 0 line(s), expected 1")
        return real(*args, **kwargs)

    monkeypatch.setattr(follow_module, "locate_image", flaky)
    run = follow_line(ROBOT, CAMERA, gain=0.3, duration=5)
    assert run.lost.sum() == len(calls) // 3
    k = int(np.flatnonzero(run.lost)[0])
    np.testing.assert_array_equal(run.measured[k + 1], run.measured[k])  # held, not invented
    assert abs(run.lateral[-1]) < abs(run.lateral[0])


def test_the_run_ends_within_its_duration():
    """Periods were rounded: 20.3 s ran 20.5 s, and 0.1 s at T = 0.5 s ran no period, its start printed as a result."""
    assert follow_line(ROBOT, CAMERA, duration=20.3, from_image=False).time[-1] == 20.0
    assert follow_line(ROBOT, CAMERA, duration=0.5 * 3, period=0.5, from_image=False).time[-1] == 1.5
    with pytest.raises(WmrkitError, match=re.escape("follow-line: duration (--duration) 0.1 s is shorter than one "
                                                    "period (--period, 0.5 s)")):
        follow_line(ROBOT, CAMERA, duration=0.1)


def test_refused_setups():
    with pytest.raises(WmrkitError, match="unstable"):
        follow_line(ROBOT, CAMERA, gain=2.0)
    with pytest.raises(WmrkitError, match=re.escape("follow-line: gain 0.3 1/s times the start's distance to the "
                                                    "line and the noise bound on h (0.3 + 1e+09 m) commands up to "
                                                    "3e+08 m/s across the line, faster than 1000 m/s")):
        follow_line(ROBOT, CAMERA, noise=(1e9, 0.0))  # it failed in twist_robot, naming neither
    with pytest.raises(WmrkitError, match="does not see the line"):
        follow_line(ROBOT, CAMERA, start=(0.0, 5.0, 0.0))


def test_a_run_renders_a_bounded_number_of_pixels(monkeypatch):
    """A 4096 x 4096 camera took 10 s and 1.9 GB an image: 10^4 periods of it ran for a day."""
    from wmrkit.vision import follow as follow_module

    def no_render(*args, **kwargs):
        raise AssertionError("rendered before the run was refused")

    monkeypatch.setattr(follow_module, "render", no_render)
    big = Camera(1920.0, math.radians(60), 0.3, 4096, 4096)
    with pytest.raises(WmrkitError, match=re.escape("follow-line: 60 periods of 4096 x 4096 px images are more "
                                                     "than the 7.68e+08 pixels a run renders")):
        follow_line(ROBOT, big, duration=30)
    run = follow_line(ROBOT, big, duration=30, from_image=False)  # no image rendered: not counted
    assert len(run.time) == 61


@pytest.mark.parametrize(("args", "message"), [
    ((math.nan, 0.1, 0.3, 0.1), "psi: expected a finite number, got nan"),
    ((0.0, math.inf, 0.3, 0.1), "h: expected a finite number, got inf"),
    ((0.0, 0.1, 0.0, 0.1), "gain: expected a finite number > 0, got 0.0"),
    ((0.0, 0.1, math.nan, 0.1), "gain: expected a finite number > 0, got nan"),
    ((0.0, 0.1, 0.3, math.inf), "speed: expected a finite number > 0, got inf"),
    ((0.0, 0.1, 0.3, 0.0), "speed: expected a finite number > 0, got 0.0"),
    ((0.0, 0.1, 0.3, 2e3), "speed: 2000 m/s is faster than 1000 m/s"),
    ((0.0, "0.1", 0.3, 0.1), "h: expected a finite number, got '0.1'"),
    # 'follow-line --noise 1e9 0' answered "twist_robot: expected finite speeds ... within 1e+06", naming no option
    ((0.0, 1e4, 0.3, 0.1), "gain * h: 0.3 1/s x 10000 m commands 3000 m/s across the line, faster than 1000 m/s"),
])
def test_line_following_twist_refuses_its_inputs_by_name(args, message):
    """NaN psi or h and speed = inf gave a twist of NaN; gain = 0 a law without correction."""
    with pytest.raises(WmrkitError, match=f"^line_following_twist: {re.escape(message)}$"):
        line_following_twist(ROBOT, *args)


def test_an_omnidirectional_robot_follows_without_turning():
    run = follow_line(catalog.load("omni-3"), CAMERA, gain=0.3, duration=6)
    assert np.all(np.diff(run.lateral) < 0) and np.allclose(run.pose[:, 2], 0.0, atol=1e-9)


def test_a_camera_too_noisy_to_see_the_line_is_an_error_with_its_reason(capsys):
    """'--image-noise 1e300' ran 40 periods steering to lines found in noise (final h 40 cm, exit 0)."""
    from pathlib import Path

    from wmrkit.cli.main import main

    camera = str(Path(__file__).resolve().parents[2] / "docs" / "figures" / "vision" / "follower-camera.yaml")
    assert main(["follow-line", "line-follower", "--camera", camera, "--image-noise", "40"]) == 2
    err = capsys.readouterr().err
    assert "follow-line: the camera does not see the line at the start pose (--start): image: too noisy" in err
    assert main(["follow-line", "line-follower", "--camera", camera, "--image-noise", "1e300"]) == 2
    assert "image noise must be in [0, 255] grey levels" in capsys.readouterr().err


@pytest.mark.parametrize("option, named", [
    (["--image-noise", "300"], "image_noise (--image-noise): image noise must be in [0, 255] grey levels"),
    (["--image-noise", "-1"], "image_noise (--image-noise): image noise must be in [0, 255] grey levels"),
    (["--blur", "60"], "blur (--blur): expected a blur in [0, 50] px (a Gaussian sigma), got 60"),
    (["--clutter", "1000"], "clutter (--clutter): clutter must be an integer in [0, 100] blobs, got 1000"),
])
def test_a_bad_synthetic_camera_option_is_named_as_the_option(option, named, capsys):
    """They were refused by the synthetic camera in the first image, naming no option ('render: image noise must
    be in [0, 255] grey levels and blur in [0, 50] px, got nan, 0' for --image-noise nan), under --json too."""
    from pathlib import Path

    from wmrkit.cli.main import main

    camera = str(Path(__file__).resolve().parents[2] / "docs" / "figures" / "vision" / "follower-camera.yaml")
    assert main(["follow-line", "line-follower", "--camera", camera, "--json", *option]) == 2
    out = capsys.readouterr()
    assert json.loads(out.err)["error"].startswith(f"follow-line: {named}") and out.out == ""


def test_a_robot_started_facing_back_follows_the_line_the_other_way_and_psi_stays_wrapped():
    """Started at theta = 3 rad the robot follows the line towards -x (the camera cannot tell the line's
    direction); the summary printed psi = -180.77 deg, outside (-180, 180]: now 179.23 deg."""
    run = follow_line(ROBOT, CAMERA, start=(0.0, 0.3, 3.0))
    assert run.failure() is None and abs(run.lateral[-1]) < 0.005 and run.pose[-1, 0] < -1.0
    out = run.to_dict()
    assert out["final_psi"] == pytest.approx(math.remainder(-run.pose[-1, 2], 2 * math.pi), abs=1e-12)
    assert -math.pi < out["final_psi"] <= math.pi
    assert all(-math.pi < s["psi"] <= math.pi for s in out["trace"])


@pytest.mark.parametrize("name", ["diff-drive", "thesis-tricycle", "ackermann"])
def test_a_robot_whose_origin_is_on_its_fixed_axle_is_refused_with_what_to_do(name):
    # it failed at the first command with control's 'choose a point ahead of the axle', which follow-line has no
    # option for: P is the robot's origin (9.25)
    with pytest.raises(WmrkitError, match=rf"^follow-line: robot '{name}': its origin, the point P .* lies on its "
                                          r"fixed axle.*describe the robot with its origin ahead of the axle"):
        follow_line(catalog.load(name), CAMERA, duration=1)


@pytest.mark.parametrize("z_p", [1e4, -2e3, math.nan, math.inf])
def test_a_z_p_out_of_range_is_named_not_read_as_a_line_not_seen(z_p):
    # 1e4 said "the camera does not see the line at the start pose: z_p: expected a length in [-1000, 1000] m"
    with pytest.raises(WmrkitError, match=r"^follow-line: z_p \(--z-p\): expected a length in \[-1000, 1000\] m"):
        follow_line(ROBOT, CAMERA, z_p=z_p, duration=1)


@pytest.mark.parametrize("kwargs, named", [
    ({"gain": math.nan}, "gain (--gain): expected a finite number > 0 [1/s], got nan"),
    ({"period": 0.0}, "period (--period): expected a finite number > 0 [s], got 0"),
    ({"duration": math.inf}, "duration (--duration): expected a finite number > 0 [s], got inf"),
    ({"speed": -0.1}, "speed (--speed): expected a finite number > 0 [m/s], got -0.1"),
    ({"gain": "0.3"}, "gain (--gain): expected a finite number > 0 [1/s], got '0.3'"),  # a bare TypeError
    ({"speed": True}, "speed (--speed): expected a finite number > 0 [m/s], got True"),  # taken as 1 m/s
])
def test_a_bad_loop_setting_is_named(kwargs, named):
    # "follow-line: gain, period, duration and speed must be finite numbers > 0" named none of the four
    with pytest.raises(WmrkitError, match=rf"^follow-line: {re.escape(named)}$"):
        follow_line(ROBOT, CAMERA, **kwargs)


@pytest.mark.parametrize("kwargs, message", [
    ({"noise": (0.1,)}, "noise: expected shape (..., 2), got (1,)"),  # IndexError: tuple index out of range
    ({"start": (0.0, 0.3, math.nan)},
     "follow-line: start (--start): expected a finite pose (x, y, theta), got (0, 0.3, nan)"),
])
def test_follow_line_names_a_bad_noise_or_start(kwargs, message):
    # a NaN start was refused by render, as 'render: pose and z_p must be finite'
    with pytest.raises(WmrkitError, match=f"^{re.escape(message)}$"):
        follow_line(ROBOT, CAMERA, duration=1, **kwargs)


def test_the_json_of_a_steered_robot_gives_its_steering_headings():
    """The forklift's wheel commands are its drive rates and its steering: --json gave only 'wheel_rates'
    (steer.spin among them), not the steering heading the rear wheel was turned to. Each heading is checked
    against the direction of the steered wheel's velocity under the twist the run produced (v + omega x r)."""
    robot = catalog.load("forklift")
    camera = Camera(272.5, math.radians(60), 1.42, 320, 240)
    run = follow_line(robot, camera, speed=0.5, start=(0.0, 1.0, 0.0), duration=5)
    steering = run.to_dict()["steering"]
    assert list(steering) == ["steer"]
    x, y = robot.wheel("steer").position
    for heading, (vx, vy, omega) in zip(steering["steer"], run.twist, strict=True):
        assert heading == pytest.approx(math.atan2(vy + omega * x, vx - omega * y), abs=1e-9)
    assert math.degrees(steering["steer"][0]) == pytest.approx(39.0, abs=0.1)  # (0.5, -0.3 + 0.3 * 2.35) m/s
    assert follow_line(ROBOT, CAMERA, duration=1).to_dict()["steering"] == {}


@pytest.mark.parametrize("noise", [(0.02, 3.0), (0.02, math.pi / 2), (0.02, math.pi)])
def test_a_heading_noise_beyond_what_an_image_can_give_is_refused(noise):
    """'--noise 0.02 3' (3 rad, meant as the thesis's 3 deg) ran with noise of +-172 deg on a heading that (9.10)
    gives within +-90 deg, and printed 'final h = 27.51 cm, psi = 40.60 deg, ... settling not reached', exit 0."""
    with pytest.raises(WmrkitError, match=r"^follow-line: noise \(--noise H PSI\): noise bounds must be .* psi in "
                                          r"\[0, 90\) deg .* write e\.g\. '3deg'\), got 0\.02 m"):
        follow_line(ROBOT, CAMERA, noise=noise, duration=1)
    assert follow_line(ROBOT, CAMERA, noise=(0.02, math.radians(89)), duration=1).failure() is None


def test_the_kept_images_are_the_views_from_the_poses_beside_them():
    """images[k] was the view from pose[k - 1] (the start's image twice, then each one period late), so the
    animation drew each camera view beside the next period's plan view and h: frame 1 showed the view from
    h = 30 cm beside 'h = +25.2 cm', frame 2 the view from 25.2 cm beside 'h = +19.9 cm'."""
    from wmrkit.vision.render import Scene, render

    run = follow_line(ROBOT, CAMERA, duration=2, keep_images=True)
    assert len(run.images) == len(run.pose) == 5
    for image, pose in zip(run.images, run.pose, strict=True):
        assert np.array_equal(image, render(CAMERA, pose, Scene(ns=(0,), width=0.02)))
    plain = follow_line(ROBOT, CAMERA, duration=2)
    assert np.array_equal(plain.pose, run.pose) and np.array_equal(plain.measured, run.measured)
