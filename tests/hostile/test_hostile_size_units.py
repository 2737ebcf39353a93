"""A description over the size limit: the refusal gives the limit with its unit, as it gives the file's size (it read
`10500000 bytes: a description holds at most 262144`)."""

from __future__ import annotations

from wmrkit.cli.main import main
from wmrkit.limits import MAX_FILE_SIZE


def test_the_size_refusal_gives_both_numbers_their_unit(tmp_path, capsys):
    big = tmp_path / "big.yaml"
    big.write_text("name: big\n" + "# padding\n" * (MAX_FILE_SIZE // 10 + 1) + "wheels: []\n")
    assert main(["show", str(big)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1
    assert f"{big.stat().st_size} bytes: a description holds at most {MAX_FILE_SIZE} bytes (docs/limits.md)" in err
