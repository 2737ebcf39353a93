"""Lazy numba compilation shared by the compiled kernels (constraint matrices, odometry).

A kernel is compiled for one explicit signature on its first call, cached on disk when a cache directory is
writable and compiled in memory otherwise (a read-only installation). ``.py_func`` keeps the Python source.
"""

from __future__ import annotations

import functools
from collections.abc import Callable

import numba


def jit(signature) -> Callable[[Callable], Callable]:
    """Compile the decorated function for `signature` on its first call."""
    def decorate(fn: Callable) -> Callable:
        compiled = None

        @functools.wraps(fn)
        def call(*args):
            nonlocal compiled
            if compiled is None:
                compiled = compile_cached(fn, signature)
            return compiled(*args)

        call.py_func = fn
        return call
    return decorate


def compile_cached(fn: Callable, signature) -> Callable:
    """``numba.njit`` cached on disk when a cache directory is writable, else in memory only."""
    args = () if signature is None else (signature,)  # None: compiled for the types of its first call
    try:
        return numba.njit(*args, cache=True)(fn)
    except RuntimeError:  # numba: "cannot cache function ...: no locator available for file ..."
        return numba.njit(*args)(fn)
