"""The compiled batch of ``ik``'s steering-gear check (:func:`wmrkit.kinematics.gear_check.steer_gears_hold`).

Imported on the first batch of at least :data:`~wmrkit.kinematics.gear_check.COMPILED_BATCH` twists and by the
``realtime`` ik. No formula is written here: :func:`~wmrkit.kinematics.gear_check.steer_breach`,
:func:`~wmrkit.kinematics.gear_check.steer_roots` (its candidate turns, then the linkages' compiled root choice) and
their loops are compiled as they are.
"""

from __future__ import annotations

import numba

from .._jit import compile_cached, drop_stale_cache, jit, with_globals
from . import _linkage_kernel, gear_check, linkage_check, linkage_law

drop_stale_cache([__file__, gear_check.__file__],
                 [linkage_law.__file__, linkage_check.__file__, _linkage_kernel.__file__])

_names = {"remainder": compile_cached(linkage_law.remainder),
          "gear_reference": compile_cached(gear_check.gear_reference)}
steer_breach = compile_cached(with_globals(gear_check.steer_breach, **_names))
_turned = compile_cached(with_globals(gear_check._turned, **_names))
_gear_turn = compile_cached(with_globals(gear_check._gear_turn, _turned=_turned))
steer_roots = compile_cached(with_globals(gear_check.steer_roots, **_names, _turned=_turned, _gear_turn=_gear_turn,
                                          _roots_at=_linkage_kernel._roots_at))

_INDEX = numba.types.Array(numba.int64, 1, "A", readonly=True)
_VECTOR = numba.types.Array(numba.float64, 1, "A", readonly=True)
_ROWS = numba.types.Array(numba.float64, 2, "A", readonly=True)
_OUT = numba.types.Array(numba.boolean, 2, "A")

#: ``_steer_holds(joint, ratio, start, rest, x, y, twist, beta, slip_tol, tol, out)``, compiled once the batches
#: given to it exceed the interpret budget (:func:`wmrkit._jit.jit`).
holds = jit((_INDEX, _VECTOR, _INDEX, _VECTOR, _VECTOR, _VECTOR, _ROWS, _ROWS, numba.float64, numba.float64, _OUT))(
    with_globals(gear_check._steer_holds, steer_breach=steer_breach))

#: ``_steer_turns(joint, ratio, start, rest, x, y, rows, turns, twist, beta, speed, slip_tol, tol, free, lo, width,
#: offset, out)``: the wheels ``ik`` turns onto the root their gear sets (:func:`~wmrkit.kinematics.gear_check.
#: steer_gear_turns`), compiled as ``holds``.
_TABLE = numba.types.Array(numba.float64, 2, "A", readonly=True)
_FLAGS = numba.types.Array(numba.boolean, 2, "A", readonly=True)
_TURNS = numba.types.Array(numba.int64, 2, "A", readonly=True)
turns = jit((_INDEX, _VECTOR, _INDEX, _VECTOR, _VECTOR, _VECTOR, _TABLE, _TURNS, _ROWS, _ROWS, _ROWS, numba.float64,
             numba.float64, _FLAGS, _VECTOR, _VECTOR, _VECTOR, _OUT))(
    with_globals(gear_check._steer_turns, steer_roots=steer_roots))
