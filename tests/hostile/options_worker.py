"""Worker of test_hostile_options.py: reads one JSON command line per input line, runs ``wmrkit.cli.main.main`` on it
in this process and answers one JSON line: the exit code (98 for an exception that escaped main), the output and
whether the output is valid JSON without NaN or infinities (under ``--json``)."""

from __future__ import annotations

import contextlib
import io
import json
import math
import os
import sys
import traceback


def _strict_json(text: str) -> str | None:
    """Why `text` is not one JSON value with finite numbers, or None."""

    def refuse(constant: str) -> None:
        raise ValueError(f"{constant} in the JSON output")

    try:
        json.loads(text, parse_constant=refuse)
    except ValueError as err:
        return str(err)[:200]
    return None


def _spy_on_nulls(common) -> list[str]:
    """Record the JSON path of every number that ``print_json`` turns into null (NaN, infinities) in the returned
    list, which the caller empties before each case."""
    seen: list[str] = []
    convert, outermost = common.json_values, [True]

    def walk(x, path: str) -> None:
        if isinstance(x, float) and not math.isfinite(x):
            seen.append(path)
        elif isinstance(x, dict):
            for k, v in x.items():
                walk(v, f"{path}.{k}")
        elif isinstance(x, list | tuple):
            for i, v in enumerate(x):
                walk(v, f"{path}[{i}]")

    def finite(x):  # the conversion recurses through this name: walk the output once, at the outermost call
        if not outermost[0]:
            return convert(x)
        walk(x, "$")
        outermost[0] = False
        try:
            return convert(x)
        finally:
            outermost[0] = True

    common.json_values = finite
    return seen


def serve() -> None:
    os.environ.setdefault("MPLBACKEND", "Agg")
    import wmrkit.cli._common as common
    from wmrkit.cli.main import main

    nulls = _spy_on_nulls(common)

    for line in sys.stdin:
        argv = json.loads(line)
        out, err = io.StringIO(), io.StringIO()
        escaped = None
        nulls.clear()
        try:
            with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
                code = main(argv)
        except SystemExit as exc:
            code = exc.code if isinstance(exc.code, int) else 99
        except BaseException:  # what the test looks for: an exception that escaped main
            code, escaped = 98, traceback.format_exc()[-1500:]
        text = out.getvalue()
        answer = {"code": code, "out": text[-2000:], "err": err.getvalue()[-2000:], "escaped": escaped,
                  "json": _strict_json(text) if code in (0, 1) and "--json" in argv else None,
                  "nulls": sorted(set(nulls))}
        sys.__stdout__.write(json.dumps(answer) + "\n")
        sys.__stdout__.flush()


if __name__ == "__main__":  # the spawned worker processes of a Dask cluster import this module too
    serve()
