"""Shared test setup: a hypothesis profile, and the test root on sys.path for ``from strategies import ...``."""

from __future__ import annotations

import sys
from pathlib import Path

from hypothesis import HealthCheck, settings

sys.path.insert(0, str(Path(__file__).parent))

from strategies import robots, wheels  # noqa: F401  (re-exported for older imports)

# CPUs are shared: no per-example deadline; sizes are kept small in the tests themselves.
settings.register_profile("wmrkit", deadline=None, suppress_health_check=[HealthCheck.too_slow])
settings.load_profile("wmrkit")
