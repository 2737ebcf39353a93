"""``wmrkit vision locate|calibrate`` and ``wmrkit follow-line``: end to end, with errors as one line and exit 2."""

from __future__ import annotations

import json
import math
from pathlib import Path

import cv2
import numpy as np
import pytest

from wmrkit.cli.main import main
from wmrkit.vision.camera import Camera, extrinsics, ground_from_image
from wmrkit.vision.render import Scene, render

FIGURES = Path(__file__).parents[2] / "docs" / "figures" / "vision"
THESIS_CAMERA = Camera(325.7, math.radians(45), 0.134, 320, 240)


def run(argv, capsys):
    code = main(argv)
    out, err = capsys.readouterr()
    return code, out, err


def test_calibrate_then_locate_from_images(tmp_path, capsys):
    cal_img = render(THESIS_CAMERA, [0, 0, 0], Scene(ns=(), extra=(-0.035, 0.035), width=0.008), noise=2)
    cv2.imwrite(str(tmp_path / "cal.png"), cal_img)
    psi, t = extrinsics([0, 0, 0], THESIS_CAMERA)
    g = ground_from_image(np.array([[0.0, 60.0], [0.0, -60.0]]), psi, THESIS_CAMERA.tilt, t, 325.7)
    cam_file = tmp_path / "cam.yaml"
    code, out, _ = run(["vision", "calibrate", str(tmp_path / "cal.png"), "--rows", "60", "--half-separation",
                        "3.5 cm", "--row-distance", f"{g[1, 1] - g[0, 1]:.6f}", "--out", str(cam_file), "--json"],
                       capsys)
    assert code == 0
    data = json.loads(out)
    assert data["height"] == pytest.approx(0.134, abs=5e-4)
    assert data["tilt"] == pytest.approx(math.radians(45), abs=math.radians(0.2))
    cam = Camera.from_file(cam_file)
    assert (cam.width, cam.rows) == (320, 240)
    pose = (0.0, -0.0583, math.radians(35.434))
    cv2.imwrite(str(tmp_path / "three.png"), render(THESIS_CAMERA, pose, Scene((-1, 0, 1), 0.035, 0.006)))
    code, out, _ = run(["vision", "locate", str(tmp_path / "three.png"), "--camera", str(cam_file), "--spacing",
                        "3.5cm", "--json"], capsys)
    assert code == 0
    fix = json.loads(out)
    assert set(fix) == {"psi", "h", "lines", "warnings"} and [ln["n"] for ln in fix["lines"]] == [-1, 0, 1]
    assert fix["psi"] == pytest.approx(-pose[2], abs=math.radians(0.5))
    assert fix["h"] == pytest.approx(pose[1], abs=0.002)


def test_locate_points_file_is_the_chufa_example(tmp_path, capsys):
    (tmp_path / "cam.yaml").write_text(f"focal_px: 545\ntilt: {math.radians(76)}\nheight: 1.42\n")
    lines = [{"n": -1, "points": [[-10, -93], [-90, 93]]}, {"n": 0, "points": [[4, -93], [-2, 93]]},
             {"n": 1, "points": [[18, -93], [83, 93]]}]
    (tmp_path / "p.json").write_text(json.dumps({"lines": lines}))
    code, out, _ = run(["vision", "locate", "--points", str(tmp_path / "p.json"), "--camera",
                        str(tmp_path / "cam.yaml"), "--spacing", "60cm", "--json"], capsys)
    assert code == 0
    psis = [math.degrees(ln["psi"]) for ln in json.loads(out)["lines"]]
    np.testing.assert_allclose(psis, [-0.86, -0.55, -0.3], atol=0.01)
    code, out, _ = run(["vision", "locate", "--points", str(tmp_path / "p.json"), "--camera",
                        str(tmp_path / "cam.yaml"), "--spacing", "60cm"], capsys)
    assert code == 0 and out.startswith("psi = ")


def test_calibrate_from_measurements(capsys):
    code, out, _ = run(["vision", "calibrate", "--x1", "71.2357", "--x2", "49.0727", "--rows", "60",
                        "--half-separation", "0.035", "--row-distance", "0.10221"], capsys)
    assert code == 0 and "tilt = " in out and "height = 0.134" in out
    # rows +-60 px and x1 = 71 px lie outside a 100 x 100 px image: refused (it wrote a camera file)
    code, out, err = run(["vision", "calibrate", "--x1", "71.2357", "--x2", "49.0727", "--rows", "60",
                          "--half-separation", "0.035", "--row-distance", "0.10221", "--size", "100", "100"], capsys)
    assert code == 2 and "--rows 60 px: measured from the centre of a 100 x 100 px image" in err
    assert "it must be below 50 px" in err  # it named --size, not the measurement beyond the image


def test_calibrate_refuses_rows_below_a_pixel(capsys):
    """--rows 0.001 with x1 = 80, x2 = 40 px printed a camera 1.75 um high at 89.999 deg, exit 0."""
    argv = ["vision", "calibrate", "--x1", "80", "--x2", "40", "--half-separation", "3.5cm", "--row-distance",
            "10cm", "--rows"]
    code, out, err = run([*argv, "0.001"], capsys)
    assert code == 2 and out == "" and err.count("\n") == 1
    assert "rows A must be at least 1 px from the image's centre (rows +-A are rows of the image), got 0.001 px" in err
    assert run([*argv, "1"], capsys)[0] == 0


def test_calibrate_prints_the_height_at_its_own_precision(capsys):
    """The height is linear in the ground lengths (9.24): x_w and y_w scaled by 1e-4 scale it by 1e-4, the tilt
    and focal length unchanged. It printed 'height = 0.00001 m' (one digit) for the 13.4 um camera."""
    heights = []
    for scale in (1.0, 1e-4):
        code, out, _ = run(["vision", "calibrate", "--x1", "71.2357", "--x2", "49.0727", "--rows", "60",
                            "--half-separation", str(0.035 * scale), "--row-distance", str(0.10221 * scale)], capsys)
        assert code == 0
        heights.append(float(out.split("height = ")[1].split(" m")[0]))
    assert heights[1] == pytest.approx(1e-4 * heights[0], rel=1e-4)


@pytest.mark.parametrize(("x1", "x2", "size", "message"), [
    ("71.2357", "49.0727", ["0", "0"], "calibrate: --size: the image is 0 x 0 px, expected 8 to 4096 px a side"),
    ("71.2357", "49.0727", ["100000", "480"], "calibrate: --size: the image is 100000 x 480 px, expected 8 to 4096"),
    ("0", "49.0727", [], "--x1: x1 must be > 0, got 0"),  # 'nan': refused as no number (test_option_units.py)
    ("71.2357", "-1", [], "--x2: x2 must be > 0, got -1"),
])
def test_calibrate_names_a_bad_size_or_measurement(x1, x2, size, message, tmp_path, capsys):
    """'--size 0 0' said 'A must be below 0 px and x1, x2 below 0 px', '--size 100000 480' was refused after the
    calibration as 'camera: width: out of range', and '--x1 nan' said x1 must be below 320 px."""
    argv = ["vision", "calibrate", "--x1", x1, "--x2", x2, "--rows", "60", "--half-separation", "0.035",
            "--row-distance", "0.10221", "--out", str(tmp_path / "camera.yaml"), "--json"]
    code, out, err = run(argv + (["--size", *size] if size else []), capsys)
    assert code == 2 and out == "" and json.loads(err)["error"].startswith(message)
    assert not (tmp_path / "camera.yaml").exists()


def test_follow_line_json_and_animation(tmp_path, capsys):
    Camera(150.0, math.radians(60), 0.3, 160, 120).to_file(tmp_path / "cam.yaml")
    gif = tmp_path / "run.gif"
    code, out, _ = run(["follow-line", "line-follower", "--camera", str(tmp_path / "cam.yaml"), "--duration", "3",
                        "--noise", "0.02", "3deg", "--animate", str(gif), "--json"], capsys)
    assert code == 0
    data = json.loads(out)
    assert data["robot"] == "line-follower" and len(data["trace"]) == 7
    assert data["trace"][-1]["h"] < 0.3
    assert gif.read_bytes()[:6] in (b"GIF89a", b"GIF87a")


@pytest.mark.parametrize("argv, message", [
    (["vision", "locate", "missing.png", "--camera", "CAM"], "no such image file"),
    (["vision", "locate", "--points", "PTS", "--camera", "nocam.yaml"], "nocam.yaml: cannot read the file"),
    (["vision", "calibrate", "--rows", "60", "--half-separation", "1", "--row-distance", "1"], "either IMAGE"),
    (["vision", "calibrate", "--x1", "40", "--x2", "50", "--rows", "60", "--half-separation", "0.03",
      "--row-distance", "0.1"], "must exceed x2"),
    (["vision", "calibrate", "--x1", "60", "--x2", "50", "--rows", "60", "--half-separation", "3 deg",
      "--row-distance", "0.1"], "--half-separation"),
    (["follow-line", "line-follower", "--camera", "CAM", "--gain", "3"], "unstable"),
])
def test_user_errors_exit_2_with_one_line(tmp_path, capsys, argv, message):
    Camera(150.0, math.radians(60), 0.3, 160, 120).to_file(tmp_path / "cam.yaml")
    (tmp_path / "p.json").write_text('{"lines": [{"n": 0, "points": [[0, -10], [1, 10]]}]}')
    argv = [str(tmp_path / "cam.yaml") if a == "CAM" else str(tmp_path / "p.json") if a == "PTS" else a
            for a in argv]
    code, _, err = run(argv, capsys)
    assert code == 2
    assert err.startswith("wmrkit: error: ") and message in err and len(err.strip().splitlines()) == 1


def test_follow_line_refuses_a_line_wider_than_the_view(tmp_path, capsys):
    # --line-width 10 was accepted and the run (the robot spinning, 37 of 40 images without a line) exited 0
    Camera(150.0, math.radians(60), 0.3, 320, 240).to_file(tmp_path / "cam.yaml")
    code, out, err = run(["follow-line", "line-follower", "--camera", str(tmp_path / "cam.yaml"),
                          "--line-width", "10", "--z-p", "1e-6"], capsys)
    assert code == 2 and out == ""
    assert "--line-width" in err and "0.7538 m" in err and len(err.strip().splitlines()) == 1


def _lose_the_line_after(images: int, monkeypatch) -> None:
    """follow-line's positioning finds no line in any image after the first `images`."""
    from wmrkit.errors import WmrkitError
    from wmrkit.vision import follow as follow_module

    real, calls = follow_module.locate_image, []

    def flaky(*args, **kwargs):
        calls.append(1)
        if len(calls) > images:
            raise WmrkitError("image: found 0 line(s), expected 1")
        return real(*args, **kwargs)

    monkeypatch.setattr(follow_module, "locate_image", flaky)


def test_follow_line_with_lost_images_is_a_failed_run(tmp_path, capsys, monkeypatch):
    # a run in which images lost the line printed a summary and exited 0 (the robot drove on stale positions)
    _lose_the_line_after(3, monkeypatch)
    Camera(150.0, math.radians(60), 0.3, 160, 120).to_file(tmp_path / "cam.yaml")
    code, out, err = run(["follow-line", "line-follower", "--camera", str(tmp_path / "cam.yaml"), "--duration", "3",
                          "--json"], capsys)
    assert code == 2 and out == ""
    error = json.loads(err)["error"]
    assert "the line was lost in 4 of 6 images (first at t = 1 s" in error


def test_a_failed_follow_line_run_writes_no_animation(tmp_path, capsys, monkeypatch):
    """The GIF was written before the run's failure check: a run that lost the line left a GIF and a 'written'
    line beside its error (exit 2). A failed run is no result: one error line, no file."""
    _lose_the_line_after(3, monkeypatch)
    Camera(150.0, math.radians(60), 0.3, 160, 120).to_file(tmp_path / "cam.yaml")
    gif = tmp_path / "run.gif"
    code, out, err = run(["follow-line", "line-follower", "--camera", str(tmp_path / "cam.yaml"), "--duration", "3",
                          "--animate", str(gif)], capsys)
    assert code == 2 and out == "" and not gif.exists()
    assert err.startswith("wmrkit: error: follow-line: the line was lost in 4 of 6 images") and err.count("\n") == 1


def test_follow_line_that_does_not_settle_says_so(tmp_path, capsys):
    # --gain 1e-6 printed '95 % settling 20.0 s' (the end of the run) for an error that had not moved
    Camera(150.0, math.radians(60), 0.3, 160, 120).to_file(tmp_path / "cam.yaml")
    code, out, _ = run(["follow-line", "line-follower", "--camera", str(tmp_path / "cam.yaml"), "--duration", "3",
                        "--gain", "1e-6"], capsys)
    assert code == 0 and "95 % settling not reached within the run" in out
    code, out, _ = run(["follow-line", "line-follower", "--camera", str(tmp_path / "cam.yaml"), "--duration", "3",
                        "--gain", "1e-6", "--json"], capsys)
    assert json.loads(out)["settling_time_95"] is None


@pytest.mark.parametrize("spacing, lines, seen", [
    ("1e3", [], "are 0.035 m apart"),  # printed lines 999.9 m and -1000 m away, their mean -0.0583 m, exit 0
    ("2cm", [], "are 0.035 m apart"),
    ("3.5cm", ["--lines", "2"], "are 0.0175 m apart"),  # neighbouring lines read as a road's two (n = -1, +1)
])
def test_locate_refuses_a_spacing_the_image_contradicts(spacing, lines, seen, capsys):
    image = str(FIGURES / "three-lines.png")
    code, out, err = run(["vision", "locate", image, "--camera", str(FIGURES / "thesis-camera.yaml"),
                          "--spacing", spacing, *lines], capsys)
    assert code == 2 and out == ""
    assert err.startswith("wmrkit: error: --spacing: the lines n = -1 and +1 ") and seen in err
    assert "--spacing says" in err and len(err.strip().splitlines()) == 1


def test_locate_refuses_a_camera_height_the_image_contradicts(tmp_path, capsys):
    # a camera file 10 times too high made every h 10 times too large (-0.583 m for -0.0583 m), exit 0
    Camera(325.7, math.radians(45), 1.34, 320, 240).to_file(tmp_path / "cam.yaml")
    code, _, err = run(["vision", "locate", str(FIGURES / "three-lines.png"), "--camera",
                        str(tmp_path / "cam.yaml"), "--spacing", "3.5cm", "--json"], capsys)
    assert code == 2 and "are 0.35 m apart" in json.loads(err)["error"]


def test_locate_refuses_a_spacing_it_would_ignore(capsys):
    code, _, err = run(["vision", "locate", str(FIGURES / "three-lines.png"), "--camera",
                        str(FIGURES / "thesis-camera.yaml"), "--spacing", "3.5cm", "--lines", "1"], capsys)
    assert code == 2 and "--spacing applies to 2 or 3 lines" in err


def test_follow_line_refuses_an_animation_it_cannot_write_before_the_run(tmp_path, capsys, monkeypatch):
    """--animate run.png was refused only after the whole simulated run (40 images rendered and located)."""
    from wmrkit.vision import follow as follow_module

    def no_run(*args, **kwargs):
        raise AssertionError("the run started")

    monkeypatch.setattr(follow_module, "follow_line", no_run)
    Camera(150.0, math.radians(60), 0.3, 160, 120).to_file(tmp_path / "cam.yaml")
    code, out, err = run(["follow-line", "line-follower", "--camera", str(tmp_path / "cam.yaml"), "--animate",
                          str(tmp_path / "run.png")], capsys)
    assert code == 2 and out == "" and "run.png: the animation is written as .gif" in err


def test_calibrate_refuses_to_write_the_camera_file_over_its_image(tmp_path, capsys):
    # --out equal to IMAGE replaced the calibration image by the camera file's YAML, exit 0
    image = tmp_path / "cal.png"
    image.write_bytes((FIGURES / "calibration.png").read_bytes())
    before = image.read_bytes()
    code, out, err = run(["vision", "calibrate", str(image), "--rows", "60", "--half-separation", "3.5cm",
                          "--row-distance", "10.22cm", "--out", str(tmp_path / "." / "cal.png")], capsys)
    assert code == 2 and out == "" and "is also IMAGE" in err and len(err.strip().splitlines()) == 1
    assert image.read_bytes() == before


def test_locate_refuses_a_negative_spacing_instead_of_ignoring_it(capsys):
    # --spacing -3.5cm located from one line (n = 0), as without --spacing, exit 0
    code, out, err = run(["vision", "locate", str(FIGURES / "three-lines.png"), "--camera",
                          str(FIGURES / "thesis-camera.yaml"), "--spacing", "-3.5cm"], capsys)
    assert code == 2 and out == "" and "spacing: expected a length in [0, 1000] m" in err


@pytest.mark.parametrize(("option", "value", "said"), [
    ("--spacing", "1e308", "--spacing: expected a length in [0, 1000] m (0: one line), got 1e+308"),
    ("--z-p", "-1e300", "--z-p: expected a length in [-1000, 1000] m, got -1e+300"),
])
def test_locate_names_the_option_of_a_placement_out_of_range(monkeypatch, capsys, option, value, said):
    """'--spacing 1e308' said 'spacing: ...' and '--z-p 1e300' 'z_p: ...' (the API's names), after the image's lines
    were extracted; now the option, before the image is read."""
    import wmrkit.vision.follow

    def extracted(*args, **kwargs):
        raise AssertionError("the image was read")

    monkeypatch.setattr(wmrkit.vision.follow, "locate_image", extracted)
    code, out, err = run(["vision", "locate", str(FIGURES / "three-lines.png"), "--camera",
                          str(FIGURES / "thesis-camera.yaml"), option, value], capsys)
    assert code == 2 and out == "" and err == f"wmrkit: error: {said}\n"


@pytest.mark.parametrize("lines", ["2", "3"])
def test_locate_lines_without_spacing_names_the_options(lines, capsys):
    # the error named 'points: lines[0]', which an IMAGE does not have
    code, out, err = run(["vision", "locate", str(FIGURES / "three-lines.png"), "--camera",
                          str(FIGURES / "thesis-camera.yaml"), "--lines", lines], capsys)
    assert code == 2 and out == "" and f"locate: --lines {lines} needs --spacing D > 0" in err


def _png_header_only(path, width, rows):
    """A PNG whose header says `width` x `rows` px (its data is a few bytes: a decompression bomb's header)."""
    import struct
    import zlib

    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)

    path.write_bytes(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", width, rows, 8, 0, 0, 0, 0))
                     + chunk(b"IDAT", zlib.compress(b"\0" * 100)) + chunk(b"IEND", b""))


@pytest.mark.parametrize("command", [["locate", "--camera", str(FIGURES / "thesis-camera.yaml")],
                                     ["calibrate", "--rows", "60", "--half-separation", "3.5cm",
                                      "--row-distance", "10cm"]])
def test_images_larger_than_wmrkit_handles_are_refused_in_one_line(tmp_path, capsys, command):
    # a 40000 x 40000 px header made OpenCV raise past its decoding limit: a cv2.error traceback
    _png_header_only(tmp_path / "huge.png", 40000, 40000)
    # a 5000 x 5000 px image was read (and calibrated: 25 M pixels, the camera file then refused its width)
    cv2.imwrite(str(tmp_path / "big.png"), np.zeros((5000, 20), np.uint8))
    for name in ("huge.png", "big.png"):
        code, out, err = run(["vision", command[0], str(tmp_path / name), *command[1:]], capsys)
        assert code == 2 and out == "" and len(err.strip().splitlines()) == 1
        assert f"{name}: larger than the 4096 px a side wmrkit handles" in err


@pytest.mark.skipif(not Path("/proc/self/status").exists(), reason="reads the peak memory from /proc")
def test_a_large_image_is_refused_from_its_header_before_decoding(tmp_path):
    """The CLI process sets OpenCV's decoding limits to 4096 px a side before importing it: a 12000 x 12000 px
    PNG of 140 kB (144 MB decoded; a 30000 px one took 1.8 GB and 5 s) is refused without being decoded."""
    import struct
    import subprocess
    import sys
    import zlib

    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)

    side, packer = 12000, zlib.compressobj(1)
    row = bytes(side + 1)
    data = b"".join(packer.compress(row) for _ in range(side)) + packer.flush()
    (tmp_path / "big.png").write_bytes(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", side, side, 8, 0,
                                                                                        0, 0, 0))
                                       + chunk(b"IDAT", data) + chunk(b"IEND", b""))
    script = ("import sys\nfrom wmrkit.cli.vision import read_image\nfrom wmrkit.errors import WmrkitError\n"
              "try:\n    read_image(sys.argv[1])\nexcept WmrkitError as err:\n    print(err)\n"  # this process's peak:
              "print(open('/proc/self/status').read().split('VmHWM:')[1].split()[0])")  # ru_maxrss has the parent's
    env = {k: v for k, v in __import__("os").environ.items() if not k.startswith("OPENCV_IO_MAX_IMAGE")}
    done = subprocess.run([sys.executable, "-c", script, str(tmp_path / "big.png")], capture_output=True, text=True,
                          env=env, timeout=60)
    assert "big.png: larger than the 4096 px a side" in done.stdout
    peak_kb = done.stdout.splitlines()[-1]
    assert int(peak_kb) < 200_000  # about 100 MB: Python, NumPy and OpenCV; decoding would add 144 MB


def test_a_broken_image_file_gives_one_line(tmp_path, capfd):
    # a PNG signature without its header printed OpenCV's own '[ERROR:0@...] ... readHeader' line before wmrkit's
    (tmp_path / "broken.png").write_bytes(b"\x89PNG\r\n\x1a\n")
    code = main(["vision", "locate", str(tmp_path / "broken.png"), "--camera", str(FIGURES / "thesis-camera.yaml")])
    out, err = capfd.readouterr()
    assert code == 2 and out == "" and err.strip().splitlines() == [
        f"wmrkit: error: {tmp_path / 'broken.png'}: not an image OpenCV can read"]


@pytest.mark.parametrize(("text", "field", "line", "message"), [
    ("focal_px: 300\ntilt: 0.8\nheight: -1\n", "height", 3, "out of range, got -1.0 (expected a length in (0, "),
    ("focal_px: 300\ntilt: 0.8\nheigth: 0.2\n", "heigth", 3, "unknown field (camera fields: focal_px, height, "),
    ("focal_px: 300\ntilt: 0.8\n", "height", None, "missing field (a camera file needs focal_px, tilt and height)"),
    ("focal_px: 300 px\ntilt: 0.8\nheight: 0.2\n", "focal_px", 1, "unknown unit 'px' in '300 px'"),
    ("focal_px: 300\ntilt: 0.8\nheight: 0.2\nwidth: 64.5\n", "width", 4, "expected a whole number of pixels"),
    ("focal_px: 300\ntilt: 0.8\nheight: 0.2\nk1: -0.9\n", "k1", 4, "-0.9 folds the distortion model over"),
    ("focal_px: 300\ntilt: 0.8\nheight: 0.2\ntilt: 0.9\n", "tilt", 4, "field 'tilt' given twice"),
])
def test_a_camera_file_error_names_its_field_and_line(tmp_path, capsys, text, field, line, message):
    """Under --json every camera file error had field null (and line null but for duplicate keys): the field was
    in the message only."""
    cam = tmp_path / "cam.yaml"
    cam.write_text(text)
    code, _, err = run(["vision", "locate", "--points", str(tmp_path / "p.json"), "--camera", str(cam), "--json"],
                       capsys)
    data = json.loads(err)
    assert code == 2 and data["error"].startswith(message), data
    assert (data["file"], data["field"], data["line"], data["wheel"]) == (str(cam), field, line, None)
    code, _, err = run(["vision", "locate", "--points", str(tmp_path / "p.json"), "--camera", str(cam)], capsys)
    place = f"{cam}:{line}" if line else str(cam)
    assert code == 2 and err.startswith(f"wmrkit: error: {place}: {field}: {message}") and err.count("\n") == 1


def test_errors_about_an_image_or_a_points_file_name_it(tmp_path, capsys):
    """'image: found 0 line(s), expected 1' and 'points: lines[0]: ...' named neither the IMAGE nor the file."""
    cv2.imwrite(str(tmp_path / "black.png"), np.zeros((240, 320), np.uint8))
    code, _, err = run(["vision", "locate", str(tmp_path / "black.png"), "--camera",
                        str(FIGURES / "thesis-camera.yaml"), "--json"], capsys)
    assert code == 2 and json.loads(err) == {"error": "found 0 line(s), expected 1",
                                             "file": str(tmp_path / "black.png"), "wheel": None, "field": "IMAGE",
                                             "line": None}
    (tmp_path / "p.json").write_text('{"lines": [{"n": 0, "points": [[300, -200], [-300, -199]]}]}')
    code, _, err = run(["vision", "locate", "--points", str(tmp_path / "p.json"), "--camera",
                        str(FIGURES / "chufa-camera.yaml")], capsys)
    assert code == 2 and err.startswith(f"wmrkit: error: {tmp_path / 'p.json'}: lines[0]: a point ")


@pytest.mark.parametrize(("stripes", "rows", "message"), [
    ((), "60", "the image does not show two stripes"),
    ((), "200", "--rows: rows A must be in (0, 120) px, got 200"),
    ((-0.035, 0.0, 0.035), "60", "the image shows more than two stripes"),
])
def test_calibrate_names_the_image_whose_content_it_refuses(stripes, rows, message, tmp_path, capsys):
    """'calibration: the image does not show two stripes' named no file (file null under --json), where `locate`
    names the IMAGE of every error about its content."""
    image = tmp_path / "stripes.png"
    cv2.imwrite(str(image), render(THESIS_CAMERA, [0, 0, 0], Scene(ns=(), extra=stripes, width=0.008)))
    argv = ["vision", "calibrate", str(image), "--rows", rows, "--half-separation", "3.5cm", "--row-distance", "10cm"]
    code, out, err = run(argv, capsys)
    assert code == 2 and out == "" and err.startswith(f"wmrkit: error: {image}: {message}") and err.count("\n") == 1
    code, _, err = run([*argv, "--json"], capsys)
    error = json.loads(err)
    assert code == 2 and error["file"] == str(image) and error["error"].startswith(message.removeprefix("--rows: "))
    assert error["field"] == ("--rows" if message.startswith("--rows") else "IMAGE")  # what was wrong: null


def test_calibrate_an_image_of_one_row_gives_one_line(tmp_path, capsys):
    """OpenCV's resize raised on it: a traceback."""
    row = np.full((1, 1000), 70, np.uint8)
    row[0, 100:110] = row[0, 800:810] = 220
    cv2.imwrite(str(tmp_path / "row.png"), row)
    code, _, err = run(["vision", "calibrate", str(tmp_path / "row.png"), "--rows", "0.4", "--half-separation", "1",
                        "--row-distance", "1"], capsys)
    assert code == 2 and err == f"wmrkit: error: {tmp_path / 'row.png'}: 1000 x 1 px, smaller than 8 px a side\n"


def test_an_image_that_is_a_folder_is_called_one(tmp_path, capsys):
    """'no such image file' was said of a folder that exists."""
    code, _, err = run(["vision", "locate", str(tmp_path), "--camera", str(FIGURES / "thesis-camera.yaml")], capsys)
    assert code == 2 and err == f"wmrkit: error: {tmp_path}: a folder; an image is a file\n"


def test_follow_line_started_on_the_line_has_no_settling_time(tmp_path, capsys):
    """Started on the line (h = 0) the 5 % band of the start's distance is empty, so rounding noise of 1e-16 m
    made the summary say '95 % settling not reached within the run' and 'final h = -0.00 cm'."""
    Camera(150.0, math.radians(60), 0.3, 160, 120).to_file(tmp_path / "cam.yaml")
    argv = ["follow-line", "line-follower", "--camera", str(tmp_path / "cam.yaml"), "--duration", "3"]
    code, out, _ = run([*argv, "--start", "0", "0"], capsys)
    assert code == 0 and "95 % settling undefined (the run starts on the line)" in out
    assert "final h = 0.00 cm, psi = 0.00 deg" in out and "-0.00" not in out
    code, out, _ = run([*argv, "--start", "0", "0", "--json"], capsys)
    assert json.loads(out)["settling_time_95"] is None
    code, out, _ = run([*argv, "--start", "0.1", "0"], capsys)  # off the line: a settling time or 'not reached'
    assert code == 0 and "undefined" not in out


def test_locate_prints_no_negative_zero(tmp_path, capsys):
    """A line straight ahead through P printed 'line n = +0: psi = -0.000 deg' (round-off of -1e-17 rad)."""
    camera = Camera(150.0, math.radians(60), 0.3, 320, 240)
    camera.to_file(tmp_path / "camera.yaml")
    cv2.imwrite(str(tmp_path / "ahead.png"), render(camera, (0.0, 0.0, 0.0), Scene(ns=(-1, 0, 1), spacing=0.2)))
    assert main(["vision", "locate", str(tmp_path / "ahead.png"), "--camera", str(tmp_path / "camera.yaml"),
                 "--spacing", "0.2"]) == 0
    out = capsys.readouterr().out
    assert "psi = 0.000000 rad (0.000 deg), h = 0.00000 m" in out and "n = +0: psi = 0.000 deg" in out
    assert "-0.000 " not in out


def test_the_line_following_animation_names_the_robot_and_the_path(tmp_path, monkeypatch):
    """The GIF named the robot nowhere and its plan view's legend said 'P' alone."""
    from wmrkit import catalog
    from wmrkit.vision import animation
    from wmrkit.vision.follow import follow_line

    figures = []
    monkeypatch.setattr(animation, "save_gif", lambda fig, *args, **kwargs: figures.append(fig))
    camera = Camera(150.0, math.radians(60), 0.3, 160, 120)
    robot = catalog.load("line-follower")
    run = follow_line(robot, camera, duration=1.0, keep_images=True)
    animation.save_animation(run, robot, camera, tmp_path / "run.gif")
    plan = figures[0].axes[1]
    assert plan.get_title() == "line-follower: plan view"
    assert [t.get_text() for t in plan.get_legend().get_texts()] == ["line", "path of P (tracked point)"]
