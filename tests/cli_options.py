"""Every option of every ``wmrkit`` command, for the tests that check them all (``from cli_options import
options``; the test root is on ``sys.path``, see ``tests/conftest.py``)."""

from __future__ import annotations

import argparse
from collections.abc import Iterator

from wmrkit.cli.main import build_parser


def options(parser: argparse.ArgumentParser | None = None, command: tuple[str, ...] = ()
            ) -> Iterator[tuple[tuple[str, ...], argparse.Action]]:
    """``(command words, action)`` of every optional argument of `parser` (default: wmrkit's) and its subcommands,
    help and version included."""
    for action in (build_parser() if parser is None else parser)._actions:
        if isinstance(action, argparse._SubParsersAction):
            for name, sub in action.choices.items():
                yield from options(sub, (*command, name))
        elif action.option_strings:
            yield command, action
