"""The compiled twist of a coupled-steering robot (:func:`.coupled_solve.twist`), for the single-call tick
(:func:`.tick.control_tick`). No formula is written here: :mod:`.coupled_solve`'s functions are compiled as they are,
each calling the others compiled; the robot enters as arrays, so they compile once (cached on disk), not per robot.
"""

from __future__ import annotations

from .._jit import compile_cached, drop_stale_cache, with_globals
from ..kinematics import _linkage_kernel, linkage_law
from . import coupled_solve

drop_stale_cache([__file__, coupled_solve.__file__], [linkage_law.__file__])

_names = {"remainder": _linkage_kernel._law_names["remainder"]}
for _name in ("rotated_lines", "direction", "newton", "solve"):
    _names[_name] = compile_cached(with_globals(getattr(coupled_solve, _name), **_names))
#: ``twist(vx, vy, px, py, sign, u0, lines, pivots, ratios, null, turns, angles) -> (vx, vy, omega)``.
twist = compile_cached(with_globals(coupled_solve.twist, **_names))
