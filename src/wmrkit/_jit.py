"""Lazy numba compilation shared by the compiled kernels (constraint matrices, odometry).

A kernel is compiled for one explicit signature when the work it is given first exceeds a small budget, cached on
disk where numba finds a writable cache directory (``NUMBA_CACHE_DIR``, else the ``__pycache__`` beside the source,
else the user's cache directory, ``~/.cache/numba`` on Linux: a read-only installation) and compiled in memory in
each process when none is. Below the budget its Python source runs as plain Python (with every numba helper it calls
replaced by that helper's Python source): a command on a small robot or a short log answers at once instead of
spending seconds compiling kernels it barely uses (issue 8: the first run of every command under 2 s). ``.py_func``
keeps the Python source.
"""

from __future__ import annotations

import functools
import hashlib
import os
import pickle
import types
from collections.abc import Callable, Sequence
from pathlib import Path

import numba
import numpy as np
from numba.core.caching import FunctionCache, IndexDataCacheFile
from numba.core.dispatcher import Dispatcher
from numba.core.serialize import dumps
from numba.extending import overload

#: Array elements a kernel may process as plain Python, over the whole process, before it is compiled. Set the
#: environment variable ``WMRKIT_INTERPRET_BUDGET`` (0: always compile) to change it.
INTERPRET_BUDGET = int(os.environ.get("WMRKIT_INTERPRET_BUDGET", "200000"))


def jit(signature) -> Callable[[Callable], Callable]:
    """Compile the decorated function for `signature` once the work given to it exceeds the interpret budget."""
    def decorate(fn: Callable) -> Callable:
        compiled = None
        interpreted = None
        spent = 0

        @functools.wraps(fn)
        def call(*args):
            nonlocal compiled, interpreted, spent
            if compiled is None:
                size = sum(a.size for a in args if isinstance(a, np.ndarray))
                if spent + size <= INTERPRET_BUDGET:
                    spent += size
                    if interpreted is None:
                        interpreted = as_python(fn)
                    with np.errstate(all="ignore"):  # as compiled code: NaN and inf propagate silently
                        return interpreted(*args)
                compiled = compile_cached(fn, signature)
            return compiled(*args)

        call.py_func = fn
        call.is_compiled = lambda: compiled is not None
        return call
    return decorate


def as_python(fn: Callable) -> Callable:
    """`fn` with every numba-compiled function it can reach through its module replaced by its Python source (each
    helper running in its own module's namespace, so that the names it uses are its module's)."""
    return _rebind(fn, _python_namespace(fn.__globals__, {}))


def _python_namespace(module_globals: dict, made: dict[int, dict]) -> dict:
    """A copy of `module_globals` with its compiled functions replaced by their Python source, each rebound in its
    own module's such namespace (built once per module in `made`, so import cycles end)."""
    namespace = made.get(id(module_globals))
    if namespace is None:
        namespace = made[id(module_globals)] = dict(module_globals)
        for name, value in module_globals.items():
            source = getattr(value, "py_func", None)
            if isinstance(source, types.FunctionType):
                namespace[name] = _rebind(source, _python_namespace(source.__globals__, made))
    return namespace


def with_globals(fn: types.FunctionType, **names) -> types.FunctionType:
    """`fn` with `names` (compiled helpers) in place of its module's globals of those names: a kernel compiled as it
    is, calling the others compiled."""
    return _rebind(fn, {**fn.__globals__, **names})


def _rebind(fn: types.FunctionType, namespace: dict) -> types.FunctionType:
    out = types.FunctionType(fn.__code__, namespace, fn.__name__, fn.__defaults__, fn.__closure__)
    out.__kwdefaults__ = fn.__kwdefaults__
    return out


#: The kernels compiled in memory, for no writable cache directory: compiled again in every process (the CLI's notice
#: of a long compilation says so).
UNCACHED: set[str] = set()


def compile_cached(fn: Callable, signature=None, **options) -> Callable:
    """``numba.njit(signature, **options)`` cached on disk where numba finds a writable cache directory (module
    docstring), else in memory only. The one place a wmrkit kernel asks for caching: ``cache=True`` itself raises
    at import when no directory is writable."""
    args = () if signature is None else (signature,)  # None: compiled for the types of its first call
    if fn.__closure__:  # named by what it computes: see _content_named
        try:
            fn.__qualname__ = _content_named(fn)
        except (pickle.PicklingError, TypeError, AttributeError):  # a cell numba cannot pickle either: no disk cache
            pass
    try:
        kernel = numba.njit(*args, cache=True, **options)(fn)
    except RuntimeError:  # numba: "cannot cache function ...: no locator available for file ..."
        UNCACHED.add(f"{fn.__module__}.{fn.__qualname__}")
        return numba.njit(*args, **options)(fn)
    nested = any(isinstance(c.cell_contents, Dispatcher) for c in fn.__closure__ or ())
    kernel._cache = (_KernelsKeyedCache if nested else _KeyedCache)(fn)
    return kernel


def _content_named(fn: types.FunctionType) -> str:
    """`fn`'s qualified name followed by a digest of its code and closure (:func:`_closure_key`).

    Numba names a compiled function's symbol by its qualified name and a number counted in each process, and a kernel
    loaded from the disk cache keeps the symbols of the process that compiled it: the control ticks of three robots,
    each compiled in its own process (each robot's IK there the first IK compiled), all called the first tick's IK
    when a later process loaded them (the same symbol, linked once: swerve-4's and the Ackermann car's ticks refused
    their headings as the forklift's IK's; robots of as many wheels would have answered with its geometry). Named by
    their content, kernels of different constants never share a symbol; those of the same share the same code."""
    return f"{fn.__qualname__}_{hashlib.sha256(_closure_key(fn)).hexdigest()[:16]}"


class _KeyedFile(IndexDataCacheFile):
    """Numba's index and data files, each entry's data file named by its key and holding the key, checked on load.

    Numba names a new entry's data file by the first number its index does not use, read, changed and written back
    without a lock: two processes saving one kernel with different constants at once could both take number 1, and
    the index keep one's key over the other's code, which later processes would load as theirs
    (``tests/test_jit_cache_race.py`` plays that interleaving). Named by the key, two keys never share a file; a
    lost index entry costs a compile, and a file holding another key (or written by numba's own scheme) is not
    loaded. (Kernels of different constants also have index files of their own: :func:`_content_named`.)"""

    def save(self, key, data):
        name = self._data_name(int(hashlib.sha256(repr(key).encode()).hexdigest()[:15], 16))
        overloads = self._load_index()
        if overloads.get(key) != name:
            overloads[key] = name
            self._save_index(overloads)
        self._save_data(name, (key, data))

    def load(self, key):
        stored = super().load(key)
        return stored[1] if isinstance(stored, tuple) and len(stored) == 2 and stored[0] == key else None


class _KeyedCache(FunctionCache):
    """Numba's disk cache of a kernel, its entries in :class:`_KeyedFile`."""

    def __init__(self, py_func) -> None:
        super().__init__(py_func)
        self._cache_file = _KeyedFile(self._cache_path, self._impl.filename_base, self._impl.locator.get_source_stamp())


class _KernelsKeyedCache(_KeyedCache):
    """Numba's disk cache of a kernel whose closure holds other kernels (``control.tick``: the robot's IK), keyed by
    what they compute: numba keys a closure by the pickle of its cells, and a kernel pickles with an identifier drawn
    at random in each process, so that such a kernel was compiled again in every process (and its cache grew by one
    entry each time). Their source files are the kernel's helpers for :func:`drop_stale_cache`."""

    def _index_key(self, sig, codegen):
        return sig, codegen.magic_tuple(), hashlib.sha256(_closure_key(self._py_func)).hexdigest()


def _closure_key(fn: types.FunctionType) -> bytes:
    """`fn`'s bytecode and its closure's contents, each kernel among them by its own such key."""
    parts = [fn.__qualname__.encode(), fn.__code__.co_code]
    for cell in fn.__closure__ or ():
        value = cell.cell_contents
        parts.append(_closure_key(value.py_func) if isinstance(value, Dispatcher) else dumps(value))
    return b"".join(hashlib.sha256(part).digest() for part in parts)


def disk_cached(kernel: Dispatcher) -> bool | None:
    """Whether numba's disk cache holds compiled code of `kernel` (a dispatcher of :func:`compile_cached`) for its
    current source, so that its first call loads it rather than compiles it; None when the kernel has no disk cache
    (:data:`UNCACHED`) or numba's cache is not laid out as this reads it (its index: numba's private API)."""
    index = getattr(getattr(kernel, "_cache", None), "_cache_file", None)
    try:
        return None if index is None else bool(index._load_index())
    except (AttributeError, OSError, EOFError, ValueError, pickle.UnpicklingError):
        return None


def cache_dir(source: str | Path) -> Path | None:
    """The directory numba caches the kernels of the file `source` in (its cache locators' choice: ``NUMBA_CACHE_DIR``,
    the file's ``__pycache__``, the user's cache directory), None when none is writable."""
    stub = types.FunctionType(_stub.__code__.replace(co_filename=str(source)), {})  # numba reads only its file
    try:
        return Path(FunctionCache(stub).cache_path)
    except RuntimeError:
        return None


def _stub() -> None:
    """A function that :func:`cache_dir` moves into another file."""


def drop_stale_cache(kernels: Sequence[str], helpers: Sequence[str] = ()) -> None:
    """Numba checks a cached kernel against its own file only, not against the compiled helpers it calls from other
    files: drop the cached kernels of the `kernels` files when any of them or of the `helpers` files changed (a
    fingerprint of their contents kept beside the cache), in the directory numba caches them in (:func:`cache_dir`:
    a working copy's ``__pycache__``, ``NUMBA_CACHE_DIR``, or the user's cache directory of a read-only
    installation, which an upgrade in place changes). Call at the import of a kernel module, before any of its
    kernels loads."""
    files = [Path(f) for f in kernels]
    try:
        digest = hashlib.sha256(b"".join(p.read_bytes() for p in (*files, *map(Path, helpers)))).hexdigest()
        dirs = [cache_dir(f) for f in files]
        if dirs[0] is None:  # no writable cache directory: numba compiles in memory
            return
        stamp = dirs[0] / f"{files[0].stem}.numba-stamp"
        if stamp.exists() and stamp.read_text() == digest:
            return
        for f, cache in zip(files, dirs, strict=True):
            for cached in cache.glob(f"{f.stem}.*.nb[ic]") if cache else ():
                cached.unlink(missing_ok=True)
        scratch = dirs[0] / f"{stamp.name}.{os.getpid()}"
        scratch.write_text(digest)
        os.replace(scratch, stamp)  # atomic: processes starting together read a whole stamp or none
    except OSError:  # a cache directory that turned read-only: nothing cached there to go stale
        pass


def drop_oversized_cache(kernel: str, limit: int) -> None:
    """Numba caches one compiled copy per robot of a kernel whose constants are a robot's (``kinematics.realtime``,
    about 0.2 MB each): drop the cached kernels of the file `kernel` when together they exceed `limit` bytes, so that
    a cache fed by many robots (random robots in tests, a studio session) stays bounded; they are compiled again when
    next used. Call at the import of the kernel module, as :func:`drop_stale_cache`."""
    try:
        cache = cache_dir(kernel)
        if cache is None:
            return
        cached = list(cache.glob(f"{Path(kernel).stem}.*.nb[ic]"))
        if sum(f.stat().st_size for f in cached) > limit:
            for f in cached:
                f.unlink(missing_ok=True)
    except OSError:  # a file removed by another process meanwhile, a directory turned read-only: nothing to bound
        pass


def float64_vector(a) -> bool:
    """In compiled code: whether `a` is a 1-D float64 array, decided when the caller is compiled (a kernel writing
    its results into an integer or float32 array would truncate or round them silently)."""
    return isinstance(a, np.ndarray) and a.dtype == np.float64 and a.ndim == 1


@overload(float64_vector)
def _float64_vector(a):
    answer = isinstance(a, numba.types.Array) and a.dtype == numba.types.float64 and a.ndim == 1
    return lambda a: answer


def runtime_value(x):
    """`x` as a value known only at run time, in compiled code: numba compiles a called kernel once per constant it
    is given (``Literal[bool](True)``), so a flag passed as a constant by one caller and as a variable by another
    compiled the kernel twice; through this, once, for the constant's type."""
    return x


@overload(runtime_value)
def _runtime_value(x):
    return lambda x: x  # typed for the argument's type without its constant value (numba tries that first)
