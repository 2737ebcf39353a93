"""A joint log's field that Python reads as a number but numpy's reader does not is named with its line and column.

'0.01,1_0,0' (a digit separator) or an Arabic-Indic digit: numpy's loadtxt refuses the chunk, and the search for the
bad field used Python's float, which reads both, so the refusal named no field: 'LOG:2: cannot read the rows that
start here' (a line marked unreachable)."""

from __future__ import annotations

import pytest

from wmrkit.cli.main import main


@pytest.mark.parametrize("field", ["1_0", "\u0661", "\uff13", "1_000.5"])
@pytest.mark.parametrize("row", [1, 40])
def test_a_field_numpy_cannot_read_is_named(tmp_path, capsys, field, row):
    rows = [f"{0.01 * k:.2f},{0.1 * k:.1f},{0.1 * k:.1f}" for k in range(60)]
    rows[row] = f"{0.01 * row:.2f},{field},{0.1 * row:.1f}"
    path = tmp_path / "log.csv"
    path.write_text("time,left.spin,right.spin\n" + "\n".join(rows) + "\n", encoding="utf-8")
    assert main(["odometry", "diff-drive", str(path)]) == 2
    err = capsys.readouterr().err
    line = 2 + row  # the header is line 1
    assert err == f"wmrkit: error: {path}:{line}: column 'left.spin': cannot read {field!r} as a number (field 2)\n"
