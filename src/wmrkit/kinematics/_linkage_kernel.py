"""The compiled batches of ``ik``'s linkage check and root choice (:func:`wmrkit.kinematics.linkage_check.
linkage_holds`, :func:`~wmrkit.kinematics.linkage_check.linkage_turns`).

Imported on the first batch of at least :data:`~wmrkit.kinematics.linkage_check.COMPILED_BATCH` twists (numba takes a
moment to import). No formula is written here: :func:`~wmrkit.kinematics.linkage_check._holds`, ``_turns``, the
judge and root choice they call and the law (:mod:`.linkage_law`) are compiled as they are, each calling the others
compiled.
"""

from __future__ import annotations

import numba

from .._jit import compile_cached, drop_stale_cache, jit, with_globals
from . import linkage_check, linkage_law

drop_stale_cache([__file__, linkage_check.__file__], [linkage_law.__file__])


_law_names = {"law": compile_cached(linkage_law.law), "remainder": compile_cached(linkage_law.remainder)}
_judge_names = {**_law_names, "leader_of": compile_cached(with_globals(linkage_law.leader_of, **_law_names))}
_reference = compile_cached(with_globals(linkage_check._reference, **_judge_names))
_breach_at = compile_cached(with_globals(linkage_check._breach_at, **_judge_names))
_breach = compile_cached(with_globals(linkage_check._breach, _reference=_reference, _breach_at=_breach_at))
in_range_at = compile_cached(linkage_check.in_range_at)
_set_roots = compile_cached(with_globals(linkage_check._set_roots, **_judge_names, in_range_at=in_range_at))
_roots_at = compile_cached(with_globals(linkage_check._roots_at, _set_roots=_set_roots))
_roots = compile_cached(with_globals(linkage_check._roots, _reference=_reference, _roots_at=_roots_at))

_TABLE = numba.types.Array(numba.float64, 2, "A", readonly=True)
_INDEX = numba.types.Array(numba.int64, 1, "A", readonly=True)
_ROWS = numba.types.Array(numba.float64, 2, "A", readonly=True)
_OUT = numba.types.Array(numba.boolean, 2, "A")

#: ``_holds(table, start, lead, coupling, beta, speed, slip_tol, tol, out)``, compiled once the batches given to it
#: exceed the interpret budget (:func:`wmrkit._jit.jit`).
holds = jit((_TABLE, _INDEX, _INDEX, _INDEX, _ROWS, _ROWS, numba.float64, numba.float64, _OUT))(
    with_globals(linkage_check._holds, _breach=_breach))

#: ``_turns(table, start, lead, beta, speed, out)``: the wheels ``ik`` turns onto the root their linkage sets
#: (:func:`~wmrkit.kinematics.linkage_check.linkage_turns`), compiled as ``holds``.
_FLAGS = numba.types.Array(numba.boolean, 2, "A", readonly=True)
_VECTOR = numba.types.Array(numba.float64, 1, "A", readonly=True)
turns = jit((_TABLE, _INDEX, _INDEX, _ROWS, _ROWS, _FLAGS, _VECTOR, _VECTOR, _VECTOR, _OUT))(
    with_globals(linkage_check._turns, _roots=_roots))
