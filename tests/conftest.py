"""Shared test setup: a hypothesis profile, and the test root on sys.path for ``from strategies import ...``."""

from __future__ import annotations

import sys
from pathlib import Path

from hypothesis import HealthCheck, settings

sys.path.insert(0, str(Path(__file__).parent))
# Helper modules beside the tests of one folder (thesis_vehicles, helpers, ...) are imported by name: with
# --import-mode=importlib pytest does not put a test's folder on sys.path, so every test folder goes on it here.
sys.path[1:1] = [str(p) for p in sorted(Path(__file__).parent.iterdir()) if p.is_dir() and not p.name.startswith("_")]

# CPUs are shared: no per-example deadline; sizes are kept small in the tests themselves.
settings.register_profile("wmrkit", deadline=None, suppress_health_check=[HealthCheck.too_slow])
settings.load_profile("wmrkit")
