"""The compiled batch of ``ik``'s linkage check (:func:`wmrkit.kinematics.linkage_check.linkage_holds`).

Imported on the first batch of at least :data:`~wmrkit.kinematics.linkage_check.COMPILED_BATCH` twists (numba takes a
moment to import). No formula is written here: :func:`~wmrkit.kinematics.linkage_check._holds`, the judge it calls and
the law (:mod:`.linkage_law`) are compiled as they are, each calling the others compiled.
"""

from __future__ import annotations

import numba

from .._jit import compile_cached, drop_stale_cache, jit, with_globals
from . import linkage_check, linkage_law

drop_stale_cache([__file__, linkage_check.__file__], [linkage_law.__file__])


_law_names = {"law": compile_cached(linkage_law.law), "remainder": compile_cached(linkage_law.remainder)}
_judge_names = {**_law_names, "leader_of": compile_cached(with_globals(linkage_law.leader_of, **_law_names))}
_breach = compile_cached(with_globals(linkage_check._breach, **_judge_names))

_TABLE = numba.types.Array(numba.float64, 2, "A", readonly=True)
_INDEX = numba.types.Array(numba.int64, 1, "A", readonly=True)
_ROWS = numba.types.Array(numba.float64, 2, "A", readonly=True)
_OUT = numba.types.Array(numba.boolean, 2, "A")

#: ``_holds(table, start, lead, coupling, beta, speed, slip_tol, tol, out)``, compiled once the batches given to it
#: exceed the interpret budget (:func:`wmrkit._jit.jit`).
holds = jit((_TABLE, _INDEX, _INDEX, _INDEX, _ROWS, _ROWS, numba.float64, numba.float64, _OUT))(
    with_globals(linkage_check._holds, _breach=_breach))
