"""Shared test setup: a hypothesis profile, and the test root on sys.path for ``from strategies import ...``."""

from __future__ import annotations

import math
import sys
from pathlib import Path

import pytest
from hypothesis import HealthCheck, settings

sys.path.insert(0, str(Path(__file__).parent))
# Helper modules beside the tests of one folder (thesis_vehicles, helpers, ...) are imported by name: with
# --import-mode=importlib pytest does not put a test's folder on sys.path, so every test folder goes on it here.
sys.path[1:1] = [str(p) for p in sorted(Path(__file__).parent.iterdir()) if p.is_dir() and not p.name.startswith("_")]

# CPUs are shared: no per-example deadline; sizes are kept small in the tests themselves. The default profile is
# derandomized (the README's `pytest` draws the examples CI draws: a fresh clone fails on a change, never on a draw);
# `pytest --hypothesis-profile=explore` draws new examples on every run, for finding new failures while developing.
# Hypothesis also draws the literal constants of "local" modules (any not under site-packages): an editable install
# (`pip install -e`) makes wmrkit's own source local, so a developer's checkout draws other examples than the README's
# `pip install .` and CI do (test_hostile_slip_roundoff passed here and failed on a fresh clone, 2026-11-30). To see
# CI's draws, run the README's two commands in a fresh clone.
settings.register_profile("wmrkit", deadline=None, suppress_health_check=[HealthCheck.too_slow], derandomize=True,
                          database=None, print_blob=True)
settings.register_profile("explore", deadline=None, suppress_health_check=[HealthCheck.too_slow], derandomize=False,
                          print_blob=True)
settings.load_profile("wmrkit")


@pytest.fixture(autouse=True)
def _no_compile_notice(request, monkeypatch):
    """In-process CLI runs print their answer alone: the notice that numba is compiling (a cold kernel cache, as in a
    fresh clone, or a kernel's source just changed) added a line to stderr in whichever test compiled first. Modules
    with ``KEEP_COMPILE_NOTICE = True`` keep it (they time refusals and strip it); tests of it set their own delay."""
    if not getattr(request.module, "KEEP_COMPILE_NOTICE", False):
        import wmrkit.cli.main as cli

        monkeypatch.setattr(cli, "COMPILE_NOTICE_AFTER", math.inf)
        monkeypatch.setattr(cli, "DYNAMICS_NOTICE_AFTER", math.inf)


@pytest.fixture(autouse=True)
def _uncached_kernels_of_this_test(monkeypatch):
    """A kernel compiled while a test refuses the file system (every ``os.makedirs`` failing: a report folder that
    cannot be made) finds no cache directory and is named in ``wmrkit._jit.UNCACHED``, which named it for the rest
    of the xdist worker: the CLI's compile notice in a later test said "again at every run" (a fresh clone's run).
    Each test gets its own copy."""
    import wmrkit._jit as jit

    monkeypatch.setattr(jit, "UNCACHED", set(jit.UNCACHED))
