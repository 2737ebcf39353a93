"""Numba's disk cache shared by processes compiling one kernel with different constants (one per robot): each
process loads its own robot's code, whatever order their writes interleave in."""

from __future__ import annotations

import numba
import pytest

import wmrkit._jit as jit


def _scaled(c: float):
    """A kernel whose constant is `c`, as the realtime kernels' are a robot's geometry (one source, many caches)."""
    def scaled(x):
        return c * x

    return jit.compile_cached(scaled)


@pytest.fixture
def cache(tmp_path, monkeypatch):
    monkeypatch.setattr(numba.config, "CACHE_DIR", str(tmp_path / "numba-cache"))


def _file(kernel):
    return kernel._cache._cache_file


def test_two_writers_that_read_the_index_before_either_wrote_keep_each_its_own_data(tmp_path):
    """Process A reads the index (empty), writes it with its key; before A writes its data, B, which read the index
    before A wrote it, saves: numba numbered both data files 1, its index kept B's key, and the file A wrote last,
    so every later process loaded A's code as B's (swerve-4's control tick got the Ackermann car's IK)."""
    a, b = (jit._KeyedFile(str(tmp_path), "kern-1.py311", "stamp") for _ in range(2))
    key_a, key_b = ("f8(f8)", ("x86_64",), ("code", "c=2")), ("f8(f8)", ("x86_64",), ("code", "c=3"))
    b._load_index = dict  # B's read of the index came before A's write
    save_data = a._save_data
    a._save_data = lambda name, data: (b.save(key_b, "B's code"), save_data(name, data))
    a.save(key_a, "A's code")
    later = jit._KeyedFile(str(tmp_path), "kern-1.py311", "stamp")
    assert later.load(key_b) == "B's code"
    assert later.load(key_a) in ("A's code", None)  # its index entry lost to B's write: compiled again, not wrong


def test_an_index_entry_naming_another_kernels_data_is_not_loaded(cache):
    """Whatever wrote the index (a race, numba's own numbering in an older cache), the data file names its key: an
    entry pointing at another constant's code compiles again instead of loading it."""
    two, three = _scaled(2.0), _scaled(3.0)
    assert (two(1.0), three(1.0)) == (2.0, 3.0)
    (k2, n2), = _file(two)._load_index().items()
    (k3, n3), = _file(three)._load_index().items()
    assert n2 != n3
    _file(two)._save_index({k2: n3})  # each key pointing at the other's code
    _file(three)._save_index({k3: n2})
    assert _scaled(2.0)(1.0) == 2.0 and _scaled(3.0)(1.0) == 3.0


def test_a_kernel_saved_then_loaded_in_a_later_process_is_loaded_not_compiled(cache):
    """The check costs nothing to a sound cache: a new dispatcher of the same constants finds its entry."""
    assert _scaled(5.0)(2.0) == 10.0
    again = _scaled(5.0)
    assert jit.disk_cached(again) is True
    assert again(2.0) == 10.0 and again.stats.cache_hits
