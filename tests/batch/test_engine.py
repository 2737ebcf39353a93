"""The engine without a cluster: order, failures as data, the serial fallback and its messages."""

from __future__ import annotations

import sys

import pytest

from wmrkit.batch.engine import BatchError, TaskFailure, engine


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
