"""The contract of a refusal at the CLI, shared by the hostile sweeps: exit 2, nothing on stdout, one line on stderr."""

from __future__ import annotations

import warnings

from wmrkit.cli.main import main


def one_line_error(argv: list[str], capsys) -> str:
    """Run `argv`: exit 2, nothing on stdout, one ``wmrkit: error:`` line on stderr and no Python warning before it
    (a RuntimeWarning would print its own lines there); return the line."""
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert main(argv) == 2
    out, err = capsys.readouterr()
    assert out == ""
    assert len(err.splitlines()) == 1, err
    assert err.startswith("wmrkit: error: ")
    return err
