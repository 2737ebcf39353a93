"""Entry point of the ``wmrkit`` command. User mistakes print one line and exit 2; bugs keep their traceback."""

from __future__ import annotations

import argparse
import importlib
import sys

from ..errors import WmrkitError

#: Command modules of ``wmrkit.cli``, in the order ``wmrkit --help`` lists them; each has ``add_parsers``.
COMMAND_MODULES = ("robots", "kinematics", "ik", "analyze", "odometry")


def build_parser() -> argparse.ArgumentParser:
    """The argument parser of every ``wmrkit`` command."""
    parser = argparse.ArgumentParser(
        prog="wmrkit",
        description="Kinematic models, analysis and odometry for any wheeled mobile robot.",
    )
    parser.add_argument("--version", action="version", version=f"wmrkit {_version()}")
    commands = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    for name in COMMAND_MODULES:
        try:
            module = importlib.import_module(f"{__package__}.{name}")
        except ModuleNotFoundError as err:
            if err.name != f"{__package__}.{name}":
                raise
            continue  # a command group not built yet
        module.add_parsers(commands)
    return parser


def main(argv: list[str] | None = None) -> int:
    """Run ``wmrkit`` with `argv`; return the exit code (0 ok, 2 user error)."""
    args = build_parser().parse_args(argv)
    try:
        return int(args.run(args) or 0)
    except WmrkitError as err:
        print(f"wmrkit: error: {err}", file=sys.stderr)
        return 2
    except BrokenPipeError:  # e.g. `wmrkit robots | head`
        return 0


def _version() -> str:
    from .. import __version__

    return __version__


if __name__ == "__main__":
    sys.exit(main())
