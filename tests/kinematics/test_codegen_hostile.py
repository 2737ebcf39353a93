"""Generated code under hostile names and directories (wmrkit.kinematics.codegen): names never break or inject code,
and no file is written over a folder, a user's file or another robot's code."""

from __future__ import annotations

import importlib.util
import math
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

from wmrkit import Robot, Wheel, catalog
from wmrkit.cli.main import main
from wmrkit.kinematics.codegen import CodegenError, write_code

GCC = shutil.which("gcc")


def load_module(path: Path):
    spec = importlib.util.spec_from_file_location(path.stem, path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _robot(name: str, steered: str, castor: str = "caster") -> Robot:
    """A steered wheel, a fixed one and a castor, built in Python (description files allow only plain wheel names)."""
    return Robot(name, (
        Wheel(steered, "steerable", 0.2, math.pi / 2, 0.0, 0.05, sensed=("spin",)),
        Wheel("right", "fixed", 0.2, -math.pi / 2, math.pi / 2, 0.05, sensed=("spin",)),
        Wheel(castor, "castor", 0.3, math.pi, 0.0, 0.03, d=0.04)))


def _gcc_errors(source: Path, *flags: str) -> str:
    out = subprocess.run([GCC, "-std=c99", "-Wall", "-Wextra", "-pedantic", "-Werror", *flags, "-c", "-o", "/dev/null",
                          str(source)], capture_output=True, text=True)
    return out.stderr


def test_a_wheel_name_with_a_line_break_cannot_inject_code(tmp_path):
    """A name went into a Python comment as it was: a line break ended the comment and the rest ran as code (here it
    would raise SystemExit on import), or broke the module (IndentationError, NUL: SyntaxError)."""
    robot = _robot("bot", "a\n    raise SystemExit('injected')\n    #", castor="c\r\x00\u2028x")
    mod = load_module(write_code(robot, "python", tmp_path)[0])
    assert mod.STEER_NAMES == ("a\n    raise SystemExit('injected')\n    #", "c\r\x00\u2028x")
    np.testing.assert_allclose(mod.inverse([1.0, 0.0, 0.0], [0.0, 0.0])[:2], [20.0, 20.0], atol=1e-12)
    text = (tmp_path / "bot_kinematics.py").read_text()
    assert "\n    raise SystemExit" not in text and "\x00" not in text


def test_names_that_are_no_utf8_or_end_a_c_line_still_give_code(tmp_path):
    """A lone surrogate in the robot's name raised UnicodeEncodeError while writing the C; a steered wheel named
    'w??/' ended a header line with a C99 trigraph (a line splice: gcc -Wall -Werror refused the header)."""
    robot = _robot("bot\ud800", "w??/", castor="c\nx */ int y;")
    header, source = write_code(robot, "c", tmp_path)
    assert "w?\\?/" in header.read_text() and "\ud800" not in header.read_text()
    if GCC is not None:
        assert _gcc_errors(source) == ""


def test_files_are_checked_before_any_is_written(tmp_path):
    """The source's name was a folder: the header was written, then IsADirectoryError."""
    (tmp_path / "forklift_kinematics.c").mkdir()
    with pytest.raises(CodegenError, match=r"forklift_kinematics\.c: is a folder"):
        write_code(catalog.load("forklift"), "c", tmp_path)
    assert not (tmp_path / "forklift_kinematics.h").exists()


@pytest.mark.parametrize("lang", ["c", "python"])
def test_a_name_too_long_for_a_file_name_is_refused_before_writing(tmp_path, lang):
    """A 300-character robot name (Python allows it; descriptions stop at 64) failed with OSError 'File name too
    long'; the refusal now says why, and nothing is written."""
    with pytest.raises(CodegenError, match=r"would have 3\d\d bytes, file systems allow 255; give the robot a shorter"):
        write_code(_robot("r" * 300, "front"), lang, tmp_path / "out")
    assert not (tmp_path / "out").exists()


def test_a_users_file_or_another_robots_code_is_never_overwritten(tmp_path):
    """Existing files were overwritten silently: a user's own file, or the code of another robot whose name gives
    the same identifier ('diff drive' and 'diff-drive'). Regenerating the same robot's code still overwrites it."""
    mine = tmp_path / "forklift_kinematics.py"
    mine.write_text("# my hand-tuned model\n")
    with pytest.raises(CodegenError, match=r"forklift_kinematics\.py: exists and is not wmrkit's code for robot "
                                           "'forklift'"):
        write_code(catalog.load("forklift"), "python", tmp_path)
    assert mine.read_text() == "# my hand-tuned model\n"
    forklift = catalog.load("forklift")
    write_code(Robot("diff drive", forklift.wheels), "c", tmp_path)
    header = (tmp_path / "diff_drive_kinematics.h").read_text()
    assert write_code(Robot("diff drive", forklift.wheels), "c", tmp_path)  # the same robot: regenerated
    with pytest.raises(CodegenError, match=r"diff_drive_kinematics\.h: exists and is not wmrkit's code for robot "
                                           "'diff-drive'"):
        write_code(Robot("diff-drive", forklift.wheels), "c", tmp_path)
    assert (tmp_path / "diff_drive_kinematics.h").read_text() == header


def test_names_that_differ_only_by_case_are_refused(tmp_path):
    """'Bot' and 'bot' give the same header guard and macros (BOT_KINEMATICS_H, BOT_N_RATES): both headers in one
    program kept the first robot's sizes; on a file system that ignores case they are the same files."""
    forklift = catalog.load("forklift")
    write_code(Robot("Bot", forklift.wheels), "c", tmp_path)
    with pytest.raises(CodegenError, match=r"Bot_kinematics\.h: differs from bot_kinematics\.h only by case"):
        write_code(Robot("bot", forklift.wheels), "c", tmp_path)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["Bot_kinematics.c", "Bot_kinematics.h"]


def test_cli_refuses_to_overwrite_with_one_line(tmp_path, capsys):
    (tmp_path / "forklift_kinematics.h").write_text("/* mine */\n")
    assert main(["kinematics", "forklift", "--codegen", "c", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "forklift_kinematics.h: exists and is not wmrkit's code" in err
    assert (tmp_path / "forklift_kinematics.h").read_text() == "/* mine */\n"


@pytest.mark.skipif(GCC is None, reason="gcc not installed")
def test_c_compiles_under_the_warnings_embedded_projects_use(tmp_path):
    """-Wdouble-promotion refused `status == 0 ? x[i] : NAN` (NAN is a float) in every generated forward model."""
    _, source = write_code(catalog.load("swerve-4"), "c", tmp_path)
    assert _gcc_errors(source, "-Wshadow", "-Wconversion", "-Wdouble-promotion", "-Wfloat-equal", "-Wcast-qual",
                       "-Wstrict-prototypes", "-Wmissing-prototypes", "-Wundef") == ""


def test_a_micro_robot_is_not_refused(tmp_path):
    """The sensed-rates check ran on the raw matrix: a 1 um robot with a 1 nm castor (within docs/limits.md) was
    refused, 'the sensed rates (left.spin, right.spin) do not determine ...'. Now on the nondimensional robot."""
    robot = Robot.from_dict({"name": "micro", "wheels": [
        {"name": "left", "type": "fixed", "position": [0, 0.4e-6], "heading": 0, "r": 1e-7, "sensed": ["spin"]},
        {"name": "right", "type": "fixed", "position": [0, -0.4e-6], "heading": 0, "r": 1e-7, "sensed": ["spin"]},
        {"name": "caster", "type": "castor", "position": [-1e-6, 0], "d": 1e-7, "r": 1e-9}]})
    assert [p.name for p in write_code(robot, "python", tmp_path)] == ["micro_kinematics.py"]
