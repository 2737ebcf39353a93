"""Numbers in the user's text files (CSV and TUM tables), read strictly and the same way by every reader.

A field is a plain decimal number in ASCII: ``[-+]digits[.digits][e[-+]digits]``, with blanks around it. Python's
``float`` also reads digit separators (``'1_0'`` is 10), other scripts' digits (Arabic-Indic ``'\u0661'``, full-width
``'\uff14'``), ``'infinity'`` and ``' nan '``: none of them is data in a table of times, poses or torques. The same
grammar reads the numbers of quantities (:mod:`wmrkit.units`). The readers that go through numpy's ``loadtxt`` for
speed (which refuses separators and other digits too) use :func:`number_problem` on their error path, to name the
field.
"""

from __future__ import annotations

import math
import re
import sys

#: A decimal number in ASCII digits (``\\d`` would match '٣' and '１' too), without its sign's blanks.
NUMBER = r"[-+]?(?:[0-9]+\.?[0-9]*|\.[0-9]+)(?:[eE][-+]?[0-9]+)?"
_NUMBER = re.compile(NUMBER)
_NOT_FINITE = ("nan", "inf", "infinity")


def short(text: str, limit: int = 40) -> str:
    """`text` quoted for a message, cut to about `limit` characters."""
    return repr(text) if len(text) <= limit else repr(text[:limit]) + f"... ({len(text)} characters)"


def number_problem(field: str) -> str | None:
    """Why the text `field` is not a finite number of a table (a phrase for a message after the field's place), or
    None when it is one; blanks around it are allowed."""
    text = field.strip()
    if _NUMBER.fullmatch(text) is None:
        if text.lower().lstrip("+-") in _NOT_FINITE:
            return f"value {text} is not a finite number"
        return f"cannot read {short(text)} as a number"
    if math.isinf(float(text)):
        return f"{short(text)} is beyond the largest float ({sys.float_info.max:.2g}): not a finite number"
    return None


def read_number(field: str) -> float:
    """The finite number written in `field` (:func:`number_problem`'s grammar); ValueError with the problem else."""
    problem = number_problem(field)
    if problem is not None:
        raise ValueError(problem)
    return float(field)
