"""The dynamics tests import their robots from ``dynamics_robots`` (this folder on sys.path)."""

from __future__ import annotations

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parent))
