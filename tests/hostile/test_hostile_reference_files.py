"""Reference files of ``track`` and ``feasibility`` and parking problems, hostile: one line naming the place, exit 2.

Each case is a file a user or a broken exporter could write; the error must point at the sample that is wrong (by
its count from 1, as the other messages of the reader do) or the field that is missing."""

from __future__ import annotations

import numpy as np
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
    (H + "0,0,0,0\n1,nan,0,0\n2,1,0,0\n", "ref.csv:3: column 'x': value nan is not a finite number"),
    (H + "0,0,0,0\n1,inf,0,0\n2,1,0,0\n", "ref.csv:3: column 'x': value inf is not a finite number"),
    (H + "0,0,0,0\n1,1e300,0,0\n2,2e300,0,0\n", "sample 2: position (1e+300, 0) m is beyond 1e+09 m"),
    (H + "0,0,0\n1,1,0\n", ":2: expected 4 fields, got 3"),
    (H + "0,0,0,0,1\n", ":2: expected 4 fields, got 5"),
    ("t,x,y,\u03b8\n0,0,0,0\n", ":1: expected the columns t,x,y,theta"),
    (H + "0,0,0,0\n0.001,100,0,0\n0.002,200,0,0\n", "samples 1-2 move at 1e+05 m/s"),
    ("0 0 0 0 0 0 0 0\n1 1 0 0 0 0 0 0\n2 2 0 0 0 0 0 0\n", "ref.csv:1: the quaternion is (almost) zero"),
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


@pytest.mark.parametrize("extra", ["", ",note"])
def test_a_large_plain_reference_reads_as_its_numbers(tmp_path, extra):
    """A plain CSV is read by numpy (a 41 MB file of 1e6 samples: 709 MB and 6 s through Python lists before, 409 MB
    and 2.5 s after, for `feasibility`); the values are those of Python's float, row by row, with or without a
    byte-order mark, CRLF line ends and an extra column."""
    rng = np.random.default_rng(5)
    n = 2000
    t = np.cumsum(rng.uniform(0.01, 0.02, n))
    xy = np.cumsum(rng.uniform(-0.01, 0.01, (n, 2)), axis=0)
    theta = np.cumsum(rng.uniform(-0.05, 0.05, n))
    table = np.column_stack([t, xy, theta]).tolist()
    lines = [",".join(repr(v) for v in row) + (",1" if extra else "") for row in table]
    for name, prefix, end in (("plain.csv", "", "\n"), ("windows.csv", "\ufeff", "\r\n")):
        path = tmp_path / name
        path.write_bytes((prefix + end.join([H.strip() + extra, *lines]) + end).encode("utf-8"))
        ref = load_reference(path)
        expected = np.array([[float(v) for v in line.split(",")[:4]] for line in lines])
        assert (ref.t == expected[:, 0]).all()
        assert (ref.pose[:, :2] == expected[:, 1:3]).all()
