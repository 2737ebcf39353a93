"""Numbers in text files are read by one strict grammar, by every reader (docs/limits.md, "Numbers in text files").

Python's float reads '1_0' as 10, Arabic-Indic '١' as 1 and full-width '４' as 4: a reference's row '1_0,1,0,0' was
read as t = 10 and a torque file's '١' as 1 N m (exit 0). Each reader, through the CLI: exit 2, one line naming the
file, the line, the column and the text.
"""

from __future__ import annotations

import json

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from wmrkit._numbers import number_problem, read_number
from wmrkit.cli.main import main
from wmrkit.odometry.trajectories import read_trajectory_csv, read_tum

#: (field, the words of its refusal); the words are written out here, not taken from the code.
FIELDS = [
    ("1_0", "cannot read '1_0' as a number"),
    ("\u0661", "cannot read '\u0661' as a number"),
    ("\uff14", "cannot read '\uff14' as a number"),
    ("\u22122", "cannot read '\u22122' as a number"),
    ("0x10", "cannot read '0x10' as a number"),
    ("", "cannot read '' as a number"),
    ("nan", "value nan is not a finite number"),
    ("-Infinity", "value -Infinity is not a finite number"),
    ("1e400", "'1e400' is beyond the largest float (1.8e+308): not a finite number"),
]


def _refused(capsys, argv: list[str], where: str, words: str) -> None:
    assert main(argv) == 2
    out = capsys.readouterr()
    assert out.out == "" and out.err == f"wmrkit: error: {where}: {words}\n", out.err


@pytest.mark.parametrize(("field", "words"), FIELDS)
def test_a_csv_reference_field(tmp_path, capsys, field, words):
    path = tmp_path / "ref.csv"
    path.write_text(f"t,x,y,theta\n0,0,0,0\n1,0.5,0,0\n2,1,0,0\n{field},1.5,0,0\n", encoding="utf-8")
    _refused(capsys, ["feasibility", "diff-drive", "--reference", str(path)], f"{path}:5: column 't'", words)


@pytest.mark.parametrize(("field", "words"), FIELDS)
def test_a_tum_reference_field(tmp_path, capsys, field, words):
    """Before: "cannot read the reference (...: could not convert string '1_0' to float64 at row 2, column 2.)",
    numpy's row counted from 0 without the comment line; 1e400: 'pose 3: times and positions must be finite'."""
    path = tmp_path / "ref.tum"
    rows = ["# t x y z qx qy qz qw", "0 0 0 0 0 0 0 1", "1 0.5 0 0 0 0 0 1", f"2 {field} 0 0 0 0 0 1"]
    if not field:  # an empty field of a blank-separated table is a missing one
        words = "expected 8 fields, got 7"
    path.write_text("\n".join(rows) + "\n", encoding="utf-8")
    where = f"{path}:4" + ("" if not field else ": column 'tx'")
    _refused(capsys, ["track", "diff-drive", "--reference", str(path)], where, words)


@pytest.mark.parametrize(("field", "words"), FIELDS)
def test_a_torque_file_field(tmp_path, capsys, field, words):
    path = tmp_path / "tau.csv"
    path.write_text(f"time,left_drive.spin,right_drive.spin\n0,10,10\n0.5,{field},10\n1,10,10\n", encoding="utf-8")
    _refused(capsys, ["simulate", "forklift", "--torques", str(path)], f"{path}:3: column 'left_drive.spin'", words)


@pytest.mark.parametrize(("field", "words"), FIELDS)
def test_a_joint_log_field(tmp_path, capsys, field, words):
    """The joint log's reader refused separators already; '1e400' was 'left.spin: value inf is not a finite number'."""
    path = tmp_path / "log.csv"
    path.write_text(f"time,left.spin,right.spin\n0,0,0\n0.1,0.1,0.1\n0.2,{field},0.2\n", encoding="utf-8")
    _refused(capsys, ["odometry", "diff-drive", str(path)], f"{path}:4: column 'left.spin'", f"{words} (field 2)")


@pytest.mark.parametrize(("field", "words"), FIELDS)
def test_a_trajectory_csv_field(tmp_path, field, words):
    path = tmp_path / "traj.csv"
    path.write_text(f"time,x,y,theta,slip\n0,0,0,0,0\n1,1,0,{field},0\n", encoding="utf-8")
    with pytest.raises(ValueError) as err:
        read_trajectory_csv(path)
    assert str(err.value) == f"{path}:3: column 'theta': {words}"


def test_a_trajectory_csv_row_with_a_trailing_comma_names_its_line(tmp_path):
    """Before: "cannot read the trajectory (could not convert string '' to float64 at row 0, column 6.)"."""
    path = tmp_path / "traj.csv"
    path.write_text("time,x,y,theta,slip\n0,0,0,0,0,\n1,1,0,0,0,\n", encoding="utf-8")
    with pytest.raises(ValueError) as err:
        read_trajectory_csv(path)
    assert str(err.value) == f"{path}:2: expected 5 fields, got 6"


def test_json_names_the_file_line_and_column(tmp_path, capsys):
    path = tmp_path / "ref.csv"
    path.write_text("t,x,y,theta\n0,0,0,0\n1,0.5,0,0\n2,1_0,0,0\n", encoding="utf-8")
    assert main(["track", "diff-drive", "--reference", str(path), "--json"]) == 2
    data = json.loads(capsys.readouterr().err)
    assert (data["file"], data["line"], data["field"]) == (str(path), 4, "x"), data


def test_a_tum_file_with_a_byte_order_mark_and_crlf_is_the_plain_one(tmp_path):
    """Before: refused, "could not convert string '\\ufeff0' to float64" (the CSV readers skip the mark)."""
    rows = "".join(f"{0.1 * k:.1f} {0.05 * k:.2f} 0 0 0 0 0 1\n" for k in range(5))
    plain, windows = tmp_path / "plain.tum", tmp_path / "windows.tum"
    plain.write_text(rows, encoding="utf-8")
    windows.write_bytes(("\ufeff" + rows).replace("\n", "\r\n").encode("utf-8"))
    (ta, pa), (tb, pb) = read_tum(plain), read_tum(windows)
    assert (ta == tb).all() and (pa == pb).all() and ta[1] == 0.1 and pa[2, 0] == 0.1


def test_a_trajectory_csv_with_a_byte_order_mark_is_the_plain_one(tmp_path):
    """Before: "expected the columns time,x,y,theta,slip ..., got \\ufefftime,x,...": the mark read as the header's."""
    text = "time,x,y,theta,slip\n0,0,0,0,0\n1,1,0,0.5,0\n"
    plain, marked = tmp_path / "plain.csv", tmp_path / "marked.csv"
    plain.write_text(text, encoding="utf-8")
    marked.write_bytes(("\ufeff" + text).replace("\n", "\r\n").encode("utf-8"))
    a, b = read_trajectory_csv(plain), read_trajectory_csv(marked)
    assert (a.time == b.time).all() and (a.poses == b.poses).all() and a.poses[1, 2] == 0.5


def _loadtxt_finite(text: str) -> float | None:
    """numpy's reader (which refuses separators and other digits, but reads nan and inf), finite values only."""
    try:
        value = np.loadtxt([text + ",0"], delimiter=",", comments=None, dtype=float, ndmin=2)[0, 0]
    except ValueError:
        return None
    return float(value) if np.isfinite(value) else None


@settings(max_examples=1000, deadline=None)
@given(st.text(alphabet="0123456789.eE+-_ \t\u0661\uff14naifxINF", max_size=8))
def test_the_grammar_is_numpys_finite_numbers(text):
    """Accepted exactly when numpy's reader gives a finite number, and then as the same number (another reader)."""
    expected = _loadtxt_finite(text)
    assert (number_problem(text) is None) == (expected is not None), text
    if expected is not None:
        assert read_number(text) == expected
