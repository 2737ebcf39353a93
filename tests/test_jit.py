"""Kernels run as plain Python below the interpret budget and compiled above it: the same numbers either way."""

from __future__ import annotations

import numpy as np
import pytest

import wmrkit._jit as jit
from wmrkit import catalog
from wmrkit.odometry.pipeline import odometry
from wmrkit.odometry.synthetic import TwistProfile, simulate

pytest_plugins = ["pytester"]  # a session of two tests run in this one (its conftest: tests/conftest.py)


def _fresh(monkeypatch, budget: int):
    """Reload the kernel modules so their lazy wrappers start uncompiled, under `budget`."""
    import importlib

    import wmrkit._constraint_kernel
    import wmrkit.odometry._kernels

    monkeypatch.setattr(jit, "INTERPRET_BUDGET", budget)
    importlib.reload(wmrkit._constraint_kernel)
    importlib.reload(wmrkit.odometry._kernels)


@pytest.mark.parametrize("name", ["forklift", "mecanum-4", "thesis-steer-castor", "swerve-4"])
def test_constraint_matrix_interpreted_equals_compiled(monkeypatch, name):
    robot = catalog.load(name)
    beta = np.random.default_rng(0).uniform(-3, 3, (50, len(robot.steer_names)))
    _fresh(monkeypatch, 10**9)
    interpreted = robot.constraint_matrix(beta)
    from wmrkit._constraint_kernel import fill_constraint_rows

    assert not fill_constraint_rows.is_compiled()
    _fresh(monkeypatch, 0)
    compiled = robot.constraint_matrix(beta)
    from wmrkit._constraint_kernel import fill_constraint_rows

    assert fill_constraint_rows.is_compiled()
    np.testing.assert_allclose(interpreted, compiled, rtol=0, atol=1e-15)


def test_odometry_interpreted_equals_compiled(monkeypatch):
    robot = catalog.load("forklift")
    run = simulate(robot, TwistProfile.from_segments([(5.0, 1.0, 0.0, 0.2)]).about((-1.0, 0.0)), 100.0)
    _fresh(monkeypatch, 10**9)
    slow = odometry(robot, run.log)
    _fresh(monkeypatch, 0)
    fast = odometry(robot, run.log)
    np.testing.assert_allclose(slow.poses, fast.poses, rtol=0, atol=1e-12)


def test_the_python_source_calls_no_compiled_helper():
    """as_python rebinds every numba helper to its source: nothing compiles while the budget lasts."""
    from wmrkit.odometry import _kernels

    py = jit.as_python(_kernels.odometry_chunk.py_func)
    helpers = [v for v in py.__globals__.values() if hasattr(v, "py_func")]
    assert helpers == []


def test_a_changed_helper_file_drops_the_cached_kernels_that_call_it(tmp_path, monkeypatch):
    import numba

    from wmrkit._jit import drop_stale_cache

    monkeypatch.setattr(numba.config, "CACHE_DIR", "")  # numba caches beside the sources (a working copy)

    kernel, helper, other = tmp_path / "kern.py", tmp_path / "help.py", tmp_path / "other.py"
    for f in (kernel, helper, other):
        f.write_text("x = 1\n")
    cache = tmp_path / "__pycache__"
    cache.mkdir()

    def cached(module):  # as numba names them: module.qualname-line.pyXY.nbi/.nbc
        files = [cache / f"{module}.f-3.py311.nbi", cache / f"{module}.f-3.py311.1.nbc"]
        for f in files:
            f.write_bytes(b"")
        return files

    first = cached("kern")
    drop_stale_cache([str(kernel)], [str(helper)])  # no fingerprint yet: dropped
    assert not any(f.exists() for f in first)
    kept, unrelated = cached("kern"), cached("other")
    drop_stale_cache([str(kernel)], [str(helper)])  # nothing changed: kept
    assert all(f.exists() for f in kept)
    helper.write_text("x = 2\n")
    drop_stale_cache([str(kernel)], [str(helper)])  # the helper changed: dropped, other modules' caches kept
    assert not any(f.exists() for f in kept) and all(f.exists() for f in unrelated)


def test_every_kernel_module_runs_with_no_writable_cache_directory(tmp_path):
    """A read-only installation whose user has no writable cache directory either (a container's system install):
    numba cannot cache, every kernel module still imports and compiles in memory. ``kinematics/realtime.py`` asked
    numba for ``cache=True`` itself: its import raised "cannot cache function '_step': no locator available" (a
    traceback from ``wmrkit track ... --dynamics``). A diff drive's realtime odometry step then gives the arc's
    closed form."""
    import os
    import shutil
    import subprocess
    import sys
    from pathlib import Path

    copy = tmp_path / "site"
    shutil.copytree(Path(jit.__file__).parent, copy / "wmrkit", ignore=shutil.ignore_patterns("__pycache__"))
    for d in [copy / "wmrkit", *(p for p in (copy / "wmrkit").rglob("*") if p.is_dir())]:
        (d / "__pycache__").write_text("a file where numba would make its cache directory")
    blocker = copy / "wmrkit" / "__pycache__"
    env = {**os.environ, "PYTHONPATH": str(copy), "PYTHONDONTWRITEBYTECODE": "1",
           "XDG_CACHE_HOME": str(blocker / "cache"), "HOME": str(blocker / "home")}
    env.pop("NUMBA_CACHE_DIR", None)
    modules = ("_constraint_kernel", "control._jump_kernels", "dynamics._integrate", "dynamics._kernels",
               "kinematics._linkage_kernel", "kinematics.realtime", "odometry._kernels", "odometry._steering_kernels",
               "slip._kalman_kernel")
    code = (f"import importlib, numpy as np; [importlib.import_module('wmrkit.' + m) for m in {modules!r}]; "
            "from wmrkit import catalog; from wmrkit.kinematics.realtime import realtime; "
            "rt = realtime(catalog.load('diff-drive')); pose = np.zeros(3); "
            "rt.odometry_step(pose, np.zeros(2), np.array([4.0, 6.0]), np.zeros(0)); print(*pose)")
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr[-500:]
    # wheels 0.2 m left and right of the axle's middle, radius 0.075 m, turned 4 and 6 rad: an arc
    v, turn = 0.075 * (4 + 6) / 2, 0.075 * (6 - 4) / 0.4
    np.testing.assert_allclose([float(x) for x in out.stdout.split()],
                               [v / turn * np.sin(turn), v / turn * (1 - np.cos(turn)), turn], rtol=0, atol=1e-15)
    assert [p for p in copy.rglob("*") if p.suffix in (".nbi", ".nbc")] == []


def test_a_changed_helper_file_drops_the_kernels_cached_outside_the_sources(tmp_path, monkeypatch):
    """Under ``NUMBA_CACHE_DIR`` (and in the user's cache directory, a read-only installation's, which an upgrade in
    place changes) numba caches a kernel away from its ``__pycache__``: drop_stale_cache looked only there, and a
    kernel whose helper file changed came back from the cache with the old helper's arithmetic (2.0 for 3.0)."""
    import importlib
    import sys

    import numba

    monkeypatch.setattr(numba.config, "CACHE_DIR", str(tmp_path / "numba-cache"))
    monkeypatch.syspath_prepend(str(tmp_path))
    (tmp_path / "stale_help.py").write_text("import numba\n\n@numba.njit\ndef bump(x):\n    return x + 1.0\n")
    (tmp_path / "stale_kern.py").write_text(
        "import stale_help\nfrom stale_help import bump\nfrom wmrkit._jit import compile_cached, drop_stale_cache\n\n"
        "drop_stale_cache([__file__], [stale_help.__file__])\n\n@compile_cached\ndef kernel(x):\n    return bump(x)\n")

    def kernel_of_fresh_modules():
        for name in ("stale_kern", "stale_help"):
            sys.modules.pop(name, None)
        importlib.invalidate_caches()
        return importlib.import_module("stale_kern").kernel

    first = kernel_of_fresh_modules()
    assert first(1.0) == 2.0 and first.stats.cache_misses  # compiled, and cached under CACHE_DIR
    assert kernel_of_fresh_modules()(1.0) == 2.0
    (tmp_path / "stale_help.py").write_text("import numba\n\n@numba.njit\ndef bump(x):\n    return x + 2.0\n")
    assert kernel_of_fresh_modules()(1.0) == 3.0
    for name in ("stale_kern", "stale_help"):
        sys.modules.pop(name, None)


def test_a_kernel_numba_cannot_cache_is_named_and_the_notice_says_it_compiles_at_every_run(monkeypatch, capsys):
    """No writable cache directory: compile_cached compiles in memory and names the kernel, and the CLI's notice of
    a long compilation says it happens again at every run, naming NUMBA_CACHE_DIR (it said "first run only; cached
    for the next runs")."""
    import threading

    from numba.core.caching import FunctionCache

    import wmrkit.cli.main as cli

    monkeypatch.setattr(FunctionCache._impl_class, "_locator_classes", [])  # numba finds no cache directory
    monkeypatch.setattr(jit, "UNCACHED", set())

    def twice(x):
        return 2.0 * x

    assert jit.compile_cached(twice)(1.5) == 3.0
    assert [n.rsplit(".", 2)[1:] for n in jit.UNCACHED] == [["<locals>", "twice"]]
    monkeypatch.setattr(cli, "COMPILE_NOTICE_AFTER", 0.05)
    monkeypatch.setattr(cli, "_compiling", lambda: True)
    watcher = threading.Thread(target=cli._compile_notice, args=(threading.Event(), 0.01))
    watcher.start()
    watcher.join(5)
    err = capsys.readouterr().err
    assert err == cli.COMPILE_NOTICE_UNCACHED + "\n" and "NUMBA_CACHE_DIR" in err and "first run only" not in err


def test_disk_cached_tells_a_kernel_numba_will_load_from_one_it_will_compile(tmp_path, monkeypatch):
    """The CLI announces the dynamics' first compile at once when their step loop is not in numba's disk cache
    (:func:`jit.disk_cached`, which reads numba's private index): False before the first call, True after it, for
    a new dispatcher of the same source too (a later process), None with no cache directory."""
    import numba
    from numba.core.caching import FunctionCache

    monkeypatch.setattr(numba.config, "CACHE_DIR", str(tmp_path / "numba-cache"))

    def thrice(x):
        return 3.0 * x

    kernel = jit.compile_cached(thrice)
    assert jit.disk_cached(kernel) is False
    assert kernel(1.5) == 4.5
    assert jit.disk_cached(kernel) is True and jit.disk_cached(jit.compile_cached(thrice)) is True
    monkeypatch.setattr(FunctionCache._impl_class, "_locator_classes", [])  # numba finds no cache directory
    monkeypatch.setattr(jit, "UNCACHED", set())
    assert jit.disk_cached(jit.compile_cached(thrice)) is None


def test_a_kernel_cache_past_its_limit_is_dropped_and_no_other(tmp_path, monkeypatch):
    """Numba caches one copy per robot of the realtime kernels (their constants are the robot's): drop_oversized_cache
    drops a file's cached kernels once together they pass the limit, and keeps them below it and other files'."""
    import numba

    monkeypatch.setattr(numba.config, "CACHE_DIR", str(tmp_path / "numba-cache"))
    kernel = tmp_path / "kern.py"
    kernel.write_text("")
    cache = jit.cache_dir(kernel)
    cache.mkdir(parents=True, exist_ok=True)
    mine = [cache / f"kern.f-{k}.py311.{s}" for k in range(3) for s in ("nbi", "1.nbc")]
    other = cache / "kernel2.f-1.py311.1.nbc"  # another file's, its name starting as this one's
    for f in (*mine, other):
        f.write_bytes(b"x" * 100)
    jit.drop_oversized_cache(str(kernel), 600)  # 600 bytes: kept
    assert all(f.exists() for f in (*mine, other))
    jit.drop_oversized_cache(str(kernel), 599)
    assert not any(f.exists() for f in mine) and other.exists()


#: Two tests in one session: the first refuses every ``os.makedirs``, as a test of a folder that cannot be made does
#: (tests/hostile/test_hostile_sweep6.py, mkdir failing late), while a kernel compiles: numba finds no cache
#: directory it can make and compile_cached names the kernel uncached; the second runs after it.
_LEAKING_SESSION = """\
import os

import wmrkit._jit as jit


def twice(x):
    return 2.0 * x


def test_a_kernel_compiles_while_no_folder_can_be_made(monkeypatch):
    def refuse(name, *args, **kwargs):
        raise OSError(2, "No such file or directory", str(name))

    monkeypatch.setattr(os, "makedirs", refuse)
    jit.compile_cached(twice)
    assert jit.UNCACHED


def test_a_later_test_of_the_worker_sees_no_uncached_kernel():
    assert jit.UNCACHED == set()
"""


def test_a_kernel_one_test_leaves_uncached_is_not_another_test_s(pytester):
    """A test that made every folder fail to be made (a report folder that cannot be made, mkdir failing late)
    while the skid steer's study compiled the odometry kernel left ``_jit.UNCACHED`` naming it for the rest of its
    xdist worker: a later test of the CLI's compile notice read "again at every run" (a fresh clone's full run at
    df7a707; ``pip install .`` itself leaves no kernel uncached). tests/conftest.py gives each test its own."""
    from pathlib import Path

    pytester.makeconftest(Path(__file__).with_name("conftest.py").read_text())
    pytester.makepyfile(test_two=_LEAKING_SESSION)
    pytester.runpytest_inprocess("-p", "no:cacheprovider", "-o", "addopts=").assert_outcomes(passed=2)
