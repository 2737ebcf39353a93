"""Issue 9: random corruptions of a valid joint log always give a clean one-line error or the correct answer.

The oracle is independent of the reader: a plain-Python parser (split, float) that accepts a file only when every
line is complete (ends with a newline), has the header's field count, holds finite numbers, increasing time and
plausible wheel steps; the pose is then the odometry of those numbers given in memory.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from wmrkit import catalog
from wmrkit.errors import WmrkitError
from wmrkit.odometry.files import odometry_file
from wmrkit.odometry.logs import MAX_RATE, JointLog
from wmrkit.odometry.pipeline import odometry

ROBOT = catalog.load("diff-drive")
JOINTS = ("left.spin", "right.spin")
HEADER = "time,left.spin,right.spin\n"


def _valid_log(n: int) -> str:
    t = np.arange(n) * 0.05
    left, right = np.cumsum(np.full(n, 0.4)), np.cumsum(np.linspace(0.3, 0.5, n))
    rows = zip(t.tolist(), left.tolist(), right.tolist(), strict=True)
    return HEADER + "".join(f"{a!r},{b!r},{c!r}\n" for a, b, c in rows)


def _reference(data: bytes) -> JointLog | None:
    """The log as the documented rules read it, or None when they refuse it."""
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError:
        return None
    if any((ord(c) < 32 and c not in "\t\n\r") or ord(c) == 127 for c in text):
        return None
    lines = text.splitlines(keepends=True)
    if not lines or [h.strip() for h in lines[0].strip("\r\n").split(",")] != list(("time", *JOINTS)):
        return None
    rows = []
    for ln in lines[1:]:
        if not ln.strip():
            continue
        if not ln.endswith(("\n", "\r")):
            return None
        fields = ln.strip("\r\n").split(",")
        if len(fields) != 3:
            return None
        try:
            values = [float(f) for f in fields]
        except ValueError:
            return None
        if not all(math.isfinite(v) for v in values) or any("_" in f for f in fields):
            return None
        rows.append(values)
    if not rows:
        return None
    raw = np.array(rows)
    with np.errstate(over="ignore", invalid="ignore"):
        dt = np.diff(raw[:, 0])
        steps = np.abs(np.diff(raw[:, 1:], axis=0))
        if not (np.all(dt > 0) and np.all(np.isfinite(dt)) and np.all(steps <= MAX_RATE * dt[:, None])):
            return None
    return JointLog(raw[:, 0], JOINTS, raw[:, 1:])


_CORRUPTIONS = st.one_of(
    st.tuples(st.just("delete"), st.integers(0, 10**6)),
    st.tuples(st.just("insert"), st.integers(0, 10**6), st.binary(min_size=1, max_size=4)),
    st.tuples(st.just("insert"), st.integers(0, 10**6), st.sampled_from([b",", b"\n", b"\r", b"\x00", b"\xff",
                                                                           b"nan", b"1e308", b"-", b"e9", b" "])),
    st.tuples(st.just("truncate"), st.integers(0, 10**6)),
    st.tuples(st.just("duplicate-line"), st.integers(0, 10**6)),
)


def _corrupt(data: bytes, op: tuple) -> bytes:
    kind, where = op[0], op[1] % (len(data) + 1)
    if kind == "delete":
        return data[:where] + data[where + 1:]
    if kind == "insert":
        return data[:where] + op[2] + data[where:]
    if kind == "truncate":
        return data[:where]
    lines = data.split(b"\n")
    k = op[1] % len(lines)
    return b"\n".join(lines[:k + 1] + lines[k:])


@settings(max_examples=400)
@given(n=st.integers(2, 12), ops=st.lists(_CORRUPTIONS, min_size=1, max_size=3))
def test_a_corrupted_log_gives_a_clean_error_or_the_correct_pose(tmp_path_factory, n, ops):
    data = _valid_log(n).encode()
    for op in ops:
        data = _corrupt(data, op)
    path = tmp_path_factory.mktemp("log") / "corrupt.csv"
    path.write_bytes(data)
    expected = _reference(data)
    try:
        summary = odometry_file(ROBOT, path)
    except WmrkitError as err:
        message = str(err)
        assert "\n" not in message and "\r" not in message and str(path) in message
        return
    assert expected is not None, f"accepted a log the rules refuse: {data!r}"
    assert all(math.isfinite(v) for v in summary.final_pose)
    pose = odometry(ROBOT, expected).poses[-1]
    np.testing.assert_allclose(summary.final_pose, pose, rtol=1e-9, atol=1e-9)


def test_the_oracle_accepts_the_valid_log_and_the_reader_agrees(tmp_path):
    data = _valid_log(8).encode()
    path = tmp_path / "ok.csv"
    path.write_bytes(data)
    expected = _reference(data)
    assert expected is not None
    np.testing.assert_allclose(odometry_file(ROBOT, path).final_pose, odometry(ROBOT, expected).poses[-1])


@pytest.mark.parametrize("chunk_size", [1, 2, 3, 7])
def test_field_counts_are_checked_on_every_row_whatever_the_chunking(tmp_path, chunk_size):
    rows = _valid_log(9).splitlines(keepends=True)
    for k in range(1, len(rows)):
        bad = [*rows[:k], rows[k].rstrip("\n") + ",0.12\n", *rows[k + 1:]]
        path = tmp_path / f"bad{k}.csv"
        path.write_text("".join(bad))
        with pytest.raises(WmrkitError, match=rf"bad{k}\.csv:{k + 1}: expected 3 fields, got 4"):
            odometry_file(ROBOT, path, chunk_size=chunk_size)


def test_reading_a_bag_without_the_bags_extra_names_the_extra(monkeypatch, tmp_path):
    import sys

    from wmrkit.odometry.bags import bag_message_count, read_joint_states

    monkeypatch.setitem(sys.modules, "rosbags.rosbag2", None)  # as if rosbags were not installed
    with pytest.raises(WmrkitError, match=r"the 'bags' extra: pip install 'wmrkit\[bags\]'"):
        bag_message_count(tmp_path, "/joint_states")
    with pytest.raises(WmrkitError, match=r"pip install 'wmrkit\[bags\]'"):
        list(read_joint_states(tmp_path, JOINTS))


@pytest.mark.parametrize("chunk_size", [2, 64])
def test_max_gap_names_the_first_gap(tmp_path, chunk_size):
    """The largest step was named: a 1 s gap at line 4 was reported at a later, longer one (and, of equal steps, at
    whichever rounding made longest)."""
    from wmrkit.odometry.logs import LogFormat

    rows = _valid_log(12).splitlines(keepends=True)
    times = [0.0, 0.05, 1.05, 1.1, 1.15, 4.15, 4.2, 4.25, 4.3, 4.35, 4.4]
    text = rows[0] + "".join(f"{t!r}," + r.split(",", 1)[1] for t, r in zip(times, rows[1:], strict=False))
    path = tmp_path / "gaps.csv"
    path.write_text(text)
    with pytest.raises(WmrkitError, match=r"gaps\.csv:4: time step of 1 s exceeds max_gap = 0\.5 s"):
        odometry_file(ROBOT, path, fmt=LogFormat(max_gap=0.5), chunk_size=chunk_size)
