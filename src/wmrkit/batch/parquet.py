"""Parquet tables of batch results, written so that an interrupted batch resumes (pyarrow, the ``batch`` extra).

While a batch runs, finished rows are flushed every few seconds to part files in ``<out>.parts/``; at the end
the whole table is written to ``<out>`` (a temporary file renamed into place, so a reader never sees half a
file) and the parts are removed. :func:`read_rows` reads the table and any parts left by a run that stopped,
which is what a rerun uses to skip the work already done.
"""

from __future__ import annotations

import os
import shutil
import time
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

from .._atomic import atomic_path
from .engine import BatchError, need_extra

#: Columns ``(name, type)``: pyarrow type names, with an optional unit after a space (``"float64 m"``), written
#: as the field's ``unit`` metadata (as the sweep's table).
Schema = Sequence[tuple[str, str]]


def _schema(schema: Schema):
    pa = need_extra("pyarrow")
    types = {"string": pa.string(), "float64": pa.float64(), "int64": pa.int64(), "bool": pa.bool_()}
    fields = []
    for name, kind in schema:
        kind, _, unit = kind.partition(" ")
        fields.append(pa.field(name, types[kind], metadata={"unit": unit} if unit else None))
    return pa.schema(fields)


def stored_text(value: Any) -> Any:
    """`value` as a string column holds it: a file name's bytes that are not UTF-8 (read as lone surrogates, which
    Parquet's UTF-8 strings cannot hold: pyarrow raised UnicodeEncodeError) written as escapes (``cami\\xf3n.csv``);
    any other value unchanged."""
    if isinstance(value, str):
        return value.encode("utf-8", "surrogateescape").decode("utf-8", "backslashreplace")
    return value


def write_rows(path: str | os.PathLike[str], rows: Sequence[Mapping[str, Any]], schema: Schema) -> None:
    """Write `rows` (mappings of column -> value, None for null) as one Parquet file, atomically; text that is not
    UTF-8 is written as escapes (:func:`stored_text`)."""
    pa = need_extra("pyarrow")
    pq = need_extra("pyarrow.parquet")
    sch = _schema(schema)
    table = pa.Table.from_pylist([{name: stored_text(row.get(name)) for name, _ in schema} for row in rows],
                                 schema=sch)
    path = Path(path)
    if path.parent and not path.parent.exists():
        raise BatchError(f"{path}: the folder {path.parent} does not exist")
    try:
        with atomic_path(path) as tmp:
            pq.write_table(table, tmp)
    except OSError as err:  # pyarrow's errors carry no file name: the command would end in a traceback
        raise BatchError(f"{path}: cannot write the table ({' '.join(str(err.strerror or err).split())})") from None


def check_table(path: str | os.PathLike[str], schema: Schema, keys: Sequence[str]) -> bool:
    """Refuse a Parquet file at `path` that is not a table of `schema` (a table of another command, which the
    batch would overwrite, or columns of other types, on which it would fail); True when it has every column of
    `schema` (its rows can be resumed), False when it lacks some but has the `keys` (an older table: redone)."""
    pq = need_extra("pyarrow.parquet")
    try:
        found = pq.read_schema(path)
    except Exception as err:
        raise BatchError(f"{path}: not a readable Parquet table ({' '.join(str(err).split())})") from None
    want = _schema(schema)
    missing = [k for k in keys if k not in found.names]
    if missing:
        raise BatchError(f"{path}: not a table of this command (no column '{missing[0]}'; columns: "
                         f"{', '.join(found.names[:6])}{', ...' if len(found.names) > 6 else ''}); remove it or "
                         "choose another output file")
    for name in found.names:
        if name in want.names and not found.field(name).type.equals(want.field(name).type):
            raise BatchError(f"{path}: column '{name}' is {found.field(name).type}, expected "
                             f"{want.field(name).type}; remove it or choose another output file")
    return all(name in found.names for name in want.names)


def read_rows(path: str | os.PathLike[str]) -> list[dict[str, Any]]:
    """Rows of the table at `path` and of its part files (empty when neither exists). Later rows of the same
    table come after earlier ones; a reader keeps the last row per key."""
    pq = need_extra("pyarrow.parquet")
    path = Path(path)
    files = ([path] if path.exists() else []) + sorted(parts_dir(path).glob("part-*.parquet"))
    rows: list[dict[str, Any]] = []
    for f in files:
        try:
            rows.extend(pq.read_table(f).to_pylist())
        except Exception as err:
            if f == path:
                raise BatchError(f"{path}: not a readable Parquet table ({' '.join(str(err).split())})") from None
            # a part cut short by a crash holds nothing we can trust: its rows are simply redone
    return rows


def parts_dir(path: str | os.PathLike[str]) -> Path:
    """Folder of the part files of the table at `path`."""
    p = Path(path)
    return p.with_name(p.name + ".parts")


class RowSink:
    """Collects rows as they finish; flushes them to a new part file every `every` seconds (resume points)."""

    def __init__(self, path: str | os.PathLike[str] | None, schema: Schema, every: float = 5.0) -> None:
        self.path, self.schema, self.every = None if path is None else Path(path), schema, every
        self._pending: list[Mapping[str, Any]] = []
        self._last = time.monotonic()
        self._parts = 0

    def add(self, row: Mapping[str, Any]) -> None:
        """Record one finished row."""
        self._pending.append(row)
        if self.path is not None and time.monotonic() - self._last > self.every:
            self.flush()

    def flush(self) -> None:
        """Write the pending rows to a new part file."""
        self._last = time.monotonic()
        if self.path is None or not self._pending:
            return
        folder = parts_dir(self.path)
        folder.mkdir(exist_ok=True)
        while (folder / f"part-{self._parts:06d}.parquet").exists():
            self._parts += 1
        write_rows(folder / f"part-{self._parts:06d}.parquet", self._pending, self.schema)
        self._pending = []

    def finish(self, rows: Sequence[Mapping[str, Any]]) -> None:
        """Write the complete table (`rows`) and remove the part files."""
        if self.path is None:
            return
        write_rows(self.path, rows, self.schema)
        shutil.rmtree(parts_dir(self.path), ignore_errors=True)
        self._pending = []
