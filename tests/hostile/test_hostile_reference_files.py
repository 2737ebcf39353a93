"""Reference files of ``track`` and ``feasibility`` and parking problems, hostile: one line naming the place, exit 2.

Each case is a file a user or a broken exporter could write; the error must point at the sample that is wrong (by
its count from 1, as the other messages of the reader do) or the field that is missing."""

from __future__ import annotations

import pytest

from wmrkit.cli.main import main
from wmrkit.control.references import load_reference

H = "t,x,y,theta\n"


@pytest.mark.parametrize(("rows", "bad", "value"), [
    ("0,0,0,0\n1,1,0,0\n0.5,2,0,0\n2,3,0,0\n", 3, "0.5"),  # the third sample goes back
    ("0,0,0,0\n1,1,0,0\n1,1,0,0\n2,2,0,0\n", 3, "1.0"),  # the third repeats the second
    ("0,0,0,0\n0,0.1,0,0\n1,1,0,0\n", 2, "0.0"),
])
def test_a_reference_whose_times_do_not_increase_names_the_sample_that_does_not(tmp_path, rows, bad, value):
    """Before: 'times must increase (sample 2: 0.5 after 1.0)' for the third sample (0.5), the one before it named."""
    path = tmp_path / "ref.csv"
    path.write_text(H + rows)
    with pytest.raises(Exception) as err:
        load_reference(path)
    samples = [float(r.split(",")[0]) for r in rows.splitlines()]
    assert samples[bad - 1] <= samples[bad - 2]  # the sample named is the one that does not increase
    assert f"(sample {bad}: {value} after " in str(err.value)


@pytest.mark.parametrize(("text", "words"), [
    ("", "no poses in the file"),
    (H, "at least 3 samples"),
    (H + "0,0,0,0\n", "at least 3 samples"),
    (H + "0,0,0,0\n1,nan,0,0\n2,1,0,0\n", "sample 2: x nan is not a finite number"),
    (H + "0,0,0,0\n1,inf,0,0\n2,1,0,0\n", "sample 2: x inf is not a finite number"),
    (H + "0,0,0,0\n1,1e300,0,0\n2,2e300,0,0\n", "sample 2: position (1e+300, 0) m is beyond 1e+09 m"),
    (H + "0,0,0\n1,1,0\n", ":2: expected 4 fields, got 3"),
    (H + "0,0,0,0,1\n", ":2: expected 4 fields, got 5"),
    ("t,x,y,\u03b8\n0,0,0,0\n", ":1: expected the columns t,x,y,theta"),
    (H + "0,0,0,0\n0.001,100,0,0\n0.002,200,0,0\n", "samples 1-2 move at 1e+05 m/s"),
    ("0 0 0 0 0 0 0 0\n1 1 0 0 0 0 0 0\n2 2 0 0 0 0 0 0\n", "pose 1: the quaternion is (almost) zero"),
    ("0 0 0 0\n1 1 0 0\n", "a TUM file has 8 columns, got 4"),
])
@pytest.mark.parametrize("command", ["feasibility", "track"])
def test_a_hostile_reference_is_one_line_and_exit_2(tmp_path, capsys, text, words, command):
    path = tmp_path / "ref.csv"
    path.write_text(text, encoding="utf-8")
    assert main([command, "diff-drive", "--reference", str(path)]) == 2
    out = capsys.readouterr()
    assert out.out == "" and out.err.count("\n") == 1 and words in out.err, out.err


def test_a_reference_with_a_byte_order_mark_and_crlf_is_the_plain_one(tmp_path, capsys):
    rows = "".join(f"{0.1 * k:.1f},{0.05 * k:.2f},0,0\n" for k in range(30))
    plain, windows = tmp_path / "plain.csv", tmp_path / "windows.csv"
    plain.write_text(H + rows, encoding="utf-8")
    windows.write_bytes(("\ufeff" + H + rows).replace("\n", "\r\n").encode("utf-8"))
    a, b = load_reference(plain), load_reference(windows)
    assert (a.t == b.t).all() and (a.pose == b.pose).all()


def test_a_parking_field_left_empty_says_so(tmp_path, capsys):
    """Before: 'space.H: expected a length, got NoneType' (Python's name of YAML's null)."""
    path = tmp_path / "p.yaml"
    path.write_text("vehicle: {a1: 1.5, b1: 0.5, c1: 1.4, h1: 1.05, d1: 0.5, phi_max: 46 deg}\n"
                    "space:\n  H:\n  J: 2\n  MS: 0.2\n  dx2: 0.7\n  final_gap: 0.07\n")
    assert main(["park", str(path)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and f"{path}:3: space.H: expected a length, got no value (null)" in err, err
