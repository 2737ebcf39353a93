"""The engine without a cluster: order, failures as data, the serial fallback and its messages."""

from __future__ import annotations

import itertools
import sys

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from wmrkit.batch.engine import BatchError, TaskFailure, chunk_spans, engine


def _square(x):
    if x == 3:
        raise ValueError("three is bad")
    return x * x


def test_serial_map_keeps_order_and_returns_failures():
    with engine(workers=0) as e:
        assert e.mode == "serial" and e.workers == 1
        out = e.map(_square, range(6), errors="return")
        assert out[:3] == [0, 1, 4] and out[4:] == [16, 25]
        assert isinstance(out[3], TaskFailure) and out[3].index == 3 and "three is bad" in str(out[3])
        with pytest.raises(BatchError, match="task 3 failed"):
            e.map(_square, range(6))
        assert sorted(i for i, _ in e.as_completed(_square, range(5), chunk=2)) == list(range(5))


def test_bad_worker_count():
    with pytest.raises(BatchError, match="--workers"):
        engine(workers=-1)


def test_without_dask_serial_fallback_and_scheduler_error(monkeypatch, capsys):
    monkeypatch.setitem(sys.modules, "distributed", None)  # an import of it now raises ImportError
    e = engine()
    assert e.mode == "serial"
    assert "the 'batch' extra is needed" in capsys.readouterr().err
    assert e.map(_square, [2]) == [4]
    with pytest.raises(BatchError, match=r"pip install 'wmrkit\[batch\]'"):
        engine("tcp://127.0.0.1:8786")


@settings(max_examples=300)
@given(st.integers(0, 3000), st.integers(1, 100), st.integers(1, 8))
def test_chunk_spans_cover_the_items_in_shrinking_tasks(n, chunk, workers):
    spans = chunk_spans(n, chunk, workers)
    ends = [0, *(b for _, b in spans)]
    assert [a for a, _ in spans] == ends[:-1] and ends[-1] == n  # contiguous, from 0 to n
    sizes = [b - a for a, b in spans]
    assert all(1 <= s <= chunk for s in sizes)
    assert all(a >= b for a, b in itertools.pairwise(sizes))  # never growing
    # the guided part: at the end a task holds at most a quarter of the remaining items per worker (or chunk // 8)
    for a, b in spans:
        assert b - a <= max(chunk // 8, 1, -(-(n - a) // (4 * workers)))
    if n >= 16 * chunk * workers:  # a large batch is mostly full tasks: few round trips
        assert len(spans) <= n / chunk + 8 * 4 * workers


def test_a_worker_count_must_be_a_whole_number():
    """engine(workers=2.5) reached Dask's TypeError, and workers=True started a LocalCluster that failed ('Nanny
    failed to start') instead of naming the argument."""
    for workers in (2.5, True, "2"):
        with pytest.raises(BatchError, match="--workers must be in"):
            engine(workers=workers)


def test_a_worker_count_with_a_scheduler_is_refused():
    """--scheduler ADDRESS --workers 2 (or 0: serial) connected to the scheduler and ignored the count without a
    word (rule 8)."""
    for workers in (0, 2):
        with pytest.raises(BatchError, match="--workers sets the size of the embedded cluster"):
            engine("tcp://127.0.0.1:1", workers)
