"""Run every benchmark: ``python -m benchmarks [--quick] [MODULE ...]``.

Each module ``bench_*.py`` has ``run(quick) -> list[Result]``.

Peers come from the optional ``bench`` extra (``pip install -e ".[bench]"``); an absent peer is reported, not hidden.
"""

from __future__ import annotations

import argparse
import importlib
import pkgutil
import sys
from pathlib import Path


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m benchmarks")
    parser.add_argument("--quick", action="store_true", help="smaller sizes (a smoke run)")
    parser.add_argument("only", nargs="*", help="run only these modules (e.g. bench_kinematics)")
    args = parser.parse_args(argv)
    here = Path(__file__).parent
    names = sorted(m.name for m in pkgutil.iter_modules([str(here)]) if m.name.startswith("bench_"))
    for name in names:
        if args.only and name not in args.only:
            continue
        print(f"== {name}")
        module = importlib.import_module(f"benchmarks.{name}")
        for result in module.run(args.quick):
            print(result.line(), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
