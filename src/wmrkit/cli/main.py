"""Entry point of the ``wmrkit`` command. User mistakes print one line and exit 2; bugs keep their traceback."""

from __future__ import annotations

import argparse
import importlib
import sys

from ..errors import WmrkitError

#: Each command and the module of ``wmrkit.cli`` that registers it (``add_parsers``), in ``--help`` order.
COMMANDS = {
    "robots": "robots", "show": "robots", "kinematics": "kinematics", "ik": "ik", "fk": "ik",
    "analyze": "analyze", "odometry": "odometry",
}


def build_parser(command: str | None = None) -> argparse.ArgumentParser:
    """The argument parser; with `command`, only that command's module is imported (a fast start)."""
    parser = argparse.ArgumentParser(
        prog="wmrkit",
        description="Kinematic models, analysis and odometry for any wheeled mobile robot.",
    )
    parser.add_argument("--version", action="version", version=f"wmrkit {_version()}")
    commands = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    wanted = [COMMANDS[command]] if command in COMMANDS else list(dict.fromkeys(COMMANDS.values()))
    for name in wanted:
        importlib.import_module(f"{__package__}.{name}").add_parsers(commands)
    return parser


def main(argv: list[str] | None = None) -> int:
    """Run ``wmrkit`` with `argv`; return the exit code (0 ok, 2 user error)."""
    argv = sys.argv[1:] if argv is None else argv
    command = next((a for a in argv if not a.startswith("-")), None)
    args = build_parser(command).parse_args(argv)
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
