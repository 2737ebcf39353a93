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


def test_an_unknown_field_from_another_tool_gets_its_name_here(tmp_path, capsys):
    """`radius: 0.1` (URDF, WPILib habits) was refused as `unknown field 'radius'` with no suggestion: difflib finds
    nothing close to 'r'. Now the refusal names the field to write."""
    path = tmp_path / "radius.yaml"
    path.write_text("name: x\nwheels:\n  - {name: a, type: fixed, position: [0, 0.2], heading: 0, radius: 0.1}\n"
                    "  - {name: b, type: castor, position: [-0.3, 0], r: 0.02, offset: 0.04}\n")
    assert main(["show", str(path)]) == 2
    assert capsys.readouterr().err == (f"wmrkit: error: {path}:3: wheels[0].radius: unknown field 'radius' (did you "
                                       "mean 'r'?)\n")
    path.write_text(path.read_text().replace("radius", "r"))
    assert main(["show", str(path)]) == 2
    assert "wheels[1].offset: unknown field 'offset' (did you mean 'd'?)" in capsys.readouterr().err
