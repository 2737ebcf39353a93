"""Units written in a log's header (wmrkit.odometry.header)."""

from __future__ import annotations

import pytest

from wmrkit.odometry.header import HeaderError, merge_option, parse_header_units


def test_units_are_read():
    u = parse_header_units(["time [ms]", "left.spin [counts:s32]", "right.spin [counts:s32]", "c.steer [rad]", "x"])
    assert (u.time_unit, u.spin, u.steer, u.bits, u.signed) == ("ms", "counts", "angle", 32, True)
    assert dict(u.columns)["left.spin"] == "left.spin [counts:s32]" and "x" not in dict(u.columns)
    assert parse_header_units(["t", "a.spin [rad/s]"]).spin == "velocity"
    assert not parse_header_units(["time", "a.spin"]).declared


def test_steering_units_and_conventions():
    """Steering in degrees; ``[deg:beta]`` marks a file in the thesis's β (older wmrkit), ``:heading`` the default."""
    u = parse_header_units(["time", "a.spin [rad]", "s.steer [deg:beta]", "t.steer [deg:beta]"])
    assert (u.steer, u.steer_convention, dict(u.columns)["s.steer"]) == ("degrees", "beta", "s.steer [deg:beta]")
    assert parse_header_units(["s.steer [counts:heading]"]).steer_convention == "heading"
    plain = parse_header_units(["s.steer [rad]"])
    assert (plain.steer, plain.steer_convention) == ("angle", None)  # a unit alone says no convention


@pytest.mark.parametrize(("names", "message"), [
    (["a.spin [grad]"], "unknown unit 'grad'"),
    (["a.spin [deg]", "b.spin [rev]"], r"the spin columns mix units \(deg, rev\)"),
    (["a.spin [rad]", "b.spin [counts]"], "mix units"),
    (["a.spin [counts:u16]", "b.spin [counts:u32]"], "mix widths"),
    (["a.spin [counts:u99]"], "counter width 99"),
    (["time [h]"], "time units"),
    (["a.steer [rad/s]"], "for a steer joint"),
    (["a.steer [grad]"], r"for a steer joint: rad, deg, counts; files in the thesis's beta: deg:beta"),
    (["a.spin [rad:beta]"], "only steer columns have one"),
    (["a.steer [deg:beta]", "b.steer [deg:heading]"], "mix conventions"),
    (["a.steer [deg:alpha]"], "unknown unit 'deg:alpha'"),
])
def test_bad_units_name_the_column(names, message):
    with pytest.raises(HeaderError, match=message):
        parse_header_units(names, source="log.csv")


def test_options_and_header_must_agree():
    assert merge_option("--spin", None, "counts", "angle", "f") == "counts"
    assert merge_option("--spin", "counts", "counts", "angle", "f") == "counts"
    assert merge_option("--spin", None, None, "angle", "f") == "angle"
    with pytest.raises(HeaderError, match="the header says --spin counts, the option says angle"):
        merge_option("--spin", "angle", "counts", "angle", "f")


def test_only_the_time_column_gives_the_time_unit():
    """``time [s]`` next to ``latency [ms]``: the log's time was read in milliseconds (steps 1000 times short)."""
    assert parse_header_units(["time [s]", "a.spin", "latency [ms]"]).time_unit == "s"
    assert parse_header_units(["time", "a.spin", "latency [ms]"]).time_unit is None
    assert parse_header_units(["stamp [us]", "time [ms]"], time_column="stamp").time_unit == "us"


def test_units_of_other_columns_are_ignored_and_roles_are_read():
    """Columns that are not the log's (``battery [V]``, ``imu.yaw [deg]``) were refused for their units; renamed
    joint columns (``--column left.spin=enc_l``) and the heading columns had theirs read as time units."""
    u = parse_header_units(["time", "a.spin [rad]", "battery [V]", "imu.yaw [deg]"])
    assert (u.spin, u.time_unit) == ("angle", None)
    u = parse_header_units(["time", "enc_l [counts:u16]", "yaw [rad]", "w [rad/s]"],
                           roles={"enc_l": "spin", "yaw": "heading", "w": "gyro"})
    assert (u.spin, u.bits, dict(u.columns)["yaw"]) == ("counts", 16, "yaw [rad]")
    assert not u.external_degrees
    assert parse_header_units(["time", "yaw [deg]"], roles={"yaw": "heading"}).external_degrees
    assert parse_header_units(["time", "gz [deg/s]"], roles={"gz": "gyro"}).external_degrees
    with pytest.raises(HeaderError, match=r"column 'yaw': unknown unit 'deg/s' \(for a heading column: rad, deg\)"):
        parse_header_units(["time", "yaw [deg/s]"], source="log.csv", roles={"yaw": "heading"})


def _format(tmp_path, header, **options):
    from wmrkit.odometry.header import header_format

    path = tmp_path / "x.csv"
    path.write_text(header + "\n0,0,0\n")
    return header_format(path, "diff-drive", ("left.spin", "right.spin"), **options)


def test_a_column_named_with_its_unit_keeps_the_unit(tmp_path):
    """--time-column 'time [ms]' (the name as the header and the missing-column hint write it) read milliseconds
    as seconds, and --column left.spin='enc_l [rad/s]' velocities as angles: the unit was not the column's."""
    fmt = _format(tmp_path, "time [ms],left.spin,right.spin", time_column="time [ms]")
    assert (fmt.time_column, fmt.time_unit) == ("time [ms]", "ms")
    fmt = _format(tmp_path, "time,enc_l [rad/s],enc_r [rad/s]",
                  columns={"left.spin": "enc_l [rad/s]", "right.spin": "enc_r [rad/s]"})
    assert fmt.spin == "velocity" and dict(fmt.columns) == {"left.spin": "enc_l [rad/s]", "right.spin": "enc_r [rad/s]"}
    fmt = _format(tmp_path, "time,position[0],position[1]",  # brackets that hold no unit are part of the name
                  columns={"left.spin": "position[0]", "right.spin": "position[1]"})
    assert fmt.spin == "angle" and dict(fmt.columns) == {"left.spin": "position[0]", "right.spin": "position[1]"}
    with pytest.raises(HeaderError, match=r"x\.csv:1: no column 'time \[s\]' \(the header names it 'time \[ms\]'\)"):
        _format(tmp_path, "time [ms],left.spin,right.spin", time_column="time [s]")


def test_a_column_named_with_a_unit_wmrkit_does_not_read_is_refused(tmp_path):
    """--time-column 'time [min]' read the minutes as seconds, exit 0: the unknown unit was taken as part of the
    name, so the header's reader (which refuses 'min' without the option) never saw it as the time's unit."""
    with pytest.raises(HeaderError, match=r"x\.csv:1: column 'time': unknown unit 'min' \(time units: s, ms, us, ns\)"):
        _format(tmp_path, "time [min],left.spin,right.spin", time_column="time [min]")
    with pytest.raises(HeaderError, match=r"column 'enc_l': unknown unit 'grad/s' \(for a spin joint: rad, rad/s"):
        _format(tmp_path, "time,enc_l [grad/s],enc_r [grad/s]",
                columns={"left.spin": "enc_l [grad/s]", "right.spin": "enc_r [grad/s]"})
