"""The compiled loops of :func:`wmrkit.dynamics.linkages.setpoint_knots` (:mod:`._setpoints`, compiled as they are,
each calling the others and the law compiled as ``ik``'s linkage check compiles them:
:mod:`wmrkit.kinematics._linkage_kernel`). Imported for a table of at least
:data:`~._setpoints.COMPILED_WORK` law evaluations (numba takes a moment to import)."""

from __future__ import annotations

from .._jit import compile_cached, drop_stale_cache, with_globals
from ..kinematics import _linkage_kernel, linkage_law
from . import _setpoints

drop_stale_cache([__file__, _setpoints.__file__], [linkage_law.__file__, _linkage_kernel.__file__])


def _compiled(name: str, names: dict):
    """:mod:`._setpoints`' function `name` compiled, its globals with `names` (compiled helpers) in place of its own."""
    return compile_cached(with_globals(getattr(_setpoints, name), **names))


_names = dict(_linkage_kernel._judge_names)
_names["angle"] = _compiled("angle", _names)
_names["project"] = _compiled("project", _names)
_names["between"] = _compiled("between", _names)
chord_errors = _compiled("chord_errors", _names)
_names["_turned"] = _compiled("_turned", _names)
continued = _compiled("continued", _names)
gear_continued = _compiled("gear_continued", _names)
knots = _compiled("knots", _names)
law_offs = _compiled("law_offs", _names)
