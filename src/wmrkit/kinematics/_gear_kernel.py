"""The compiled batch of ``ik``'s steering-gear check (:func:`wmrkit.kinematics.gear_check.steer_gears_hold`).

Imported on the first batch of at least :data:`~wmrkit.kinematics.gear_check.COMPILED_BATCH` twists and by the
``realtime`` ik. No formula is written here: :func:`~wmrkit.kinematics.gear_check.steer_breach` and its loop are
compiled as they are.
"""

from __future__ import annotations

import numba

from .._jit import compile_cached, drop_stale_cache, jit, with_globals
from . import gear_check, linkage_law

drop_stale_cache([__file__, gear_check.__file__], [linkage_law.__file__])

steer_breach = compile_cached(with_globals(gear_check.steer_breach, remainder=compile_cached(linkage_law.remainder)))

_INDEX = numba.types.Array(numba.int64, 1, "A", readonly=True)
_VECTOR = numba.types.Array(numba.float64, 1, "A", readonly=True)
_ROWS = numba.types.Array(numba.float64, 2, "A", readonly=True)
_OUT = numba.types.Array(numba.boolean, 2, "A")

#: ``_steer_holds(joint, ratio, start, rest, x, y, twist, beta, slip_tol, tol, out)``, compiled once the batches
#: given to it exceed the interpret budget (:func:`wmrkit._jit.jit`).
holds = jit((_INDEX, _VECTOR, _INDEX, _VECTOR, _VECTOR, _VECTOR, _ROWS, _ROWS, numba.float64, numba.float64, _OUT))(
    with_globals(gear_check._steer_holds, steer_breach=steer_breach))
