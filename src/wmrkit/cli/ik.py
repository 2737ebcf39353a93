"""``wmrkit ik`` (per-wheel commands for a body twist, thesis §8.4) and ``wmrkit fk`` (twist from joint rates, 4.11)."""

from __future__ import annotations

import argparse
import math

import numpy as np

from ..couplings import GearWarning
from ..description import described_type
from ..errors import WmrkitError, said_warnings
from ..kinematics.gear_check import steer_breaches
from ..kinematics.linalg import characteristic_length
from ..kinematics.linkage_check import LinkageAngleWarning, ik_breaches
from ..kinematics.wheel_ik import (
    SLIP_TOL,
    WheelCommands,
    forward_kinematics_check,
    rate_kind,
    twist_is_determined,
    wheel_commands,
)
from ..limits import MAX_QUERY_RATE
from ..robot import TWIST_NAMES, Robot
from ._common import (
    add_json_flag,
    add_robot_argument,
    add_steer_option,
    load_robot,
    parse_assignments,
    parse_value,
    print_json,
    renaming,
    warn,
    wheel_column_width,
    with_steer,
)
from ._shown import cell, tidy, tidy_twist, twist_speed

#: slipping wheels a not-feasible warning names, the fastest first (a robot of 64 fixed wheels: the rest counted)
MAX_NAMED = 4


def add_parsers(commands: argparse._SubParsersAction) -> None:
    """Register ``ik`` and ``fk``."""
    p = commands.add_parser("ik", help="per-wheel steering angles and rates for a body twist (thesis 8.4)")
    add_robot_argument(p)
    p.add_argument("--twist", nargs=3, required=True, metavar=("VX", "VY", "OMEGA"),
                   help="body twist: vx, vy [m/s], omega [rad/s] (x forward, y left; or with a unit: '500 mm/s', "
                        "'3.6 km/h', '30 deg/s')")
    add_steer_option(p, "current heading of a steered wheel (default: as described)",
                     "; a steerable wheel keeps, of its two solutions (h, spin) and (h + 180 deg, -spin), the one "
                     "closest to it; a castor's is the angle it is at")
    add_json_flag(p)
    p.set_defaults(run=run_ik)

    p = commands.add_parser("fk", help="body twist from joint rates by least squares (thesis 4.11)")
    add_robot_argument(p)
    p.add_argument("--spin", action="append", metavar="NAME=RATE", default=[],
                   help="a joint rate [rad/s, or with a unit: '120 rpm', '30 deg/s']: a wheel name means its spin, "
                        "or 'wheel.joint'; also vx, vy [m/s] or omega [rad/s] (a gyro) (repeat)")
    add_steer_option(p, "heading of a steered wheel (default: as described)")
    add_json_flag(p)
    p.set_defaults(run=run_fk)


def run_ik(args: argparse.Namespace) -> int:
    """Print the per-wheel commands; warn when the twist makes a fixed wheel slip or a wheel steer out of range, and
    exit 1 then (the answer is no: the commands printed do not give the twist)."""
    robot = load_robot(args.robot)  # as described: its linkages' rest angles (with_steer)
    twist = _twist(args.twist)
    commands = wheel_commands(robot, twist, with_steer(robot, args.steer).beta)
    _check_finite("ik", commands.rates, commands.slip)
    for why in _infeasible(robot, commands, twist):
        warn(f"twist not feasible for robot '{robot.name}': {why}")
    if args.json:
        print_json({"robot": robot.name, **commands.to_dict()})
    else:
        print(format_commands(robot, commands, twist))
    return 0 if commands.feasible else 1  # an answer that is no (docs/limits.md, Exit codes)


def run_fk(args: argparse.Namespace) -> int:
    """Print the twist and the slip residual; warn when the rates do not fix the twist or contradict each other."""
    robot = load_robot(args.robot)  # as described: its linkages' rest angles (with_steer)
    beta = with_steer(robot, args.steer).beta
    given = parse_assignments(args.spin, "--spin")
    if not given:  # the library's "rates: ... got none" would name no option
        spins = [w.name for w in robot.wheels if "spin" in w.kind.rates]
        raise WmrkitError(f"--spin: give at least one joint rate of robot '{robot.name}' as NAME=RATE, e.g. --spin "
                          f"{spins[0] if spins else robot.rate_names[0]}=10 (names: {', '.join(robot.rate_names)})")
    rates = {name: parse_value(value, rate_kind(name), f"--spin {name}") for name, value in given.items()}
    for name, value in rates.items():
        if abs(value) > MAX_QUERY_RATE:
            raise WmrkitError(f"--spin {name}: {value:g} is beyond {MAX_QUERY_RATE:g} rad/s (m/s), no wheel turns so "
                              "fast")
    unknown = f"robot '{robot.name}' has no joint rate "
    with renaming({unknown: f"--spin: {unknown}"}):
        fk, lines = said_warnings(lambda: forward_kinematics_check(robot, rates, beta),
                                  (GearWarning, LinkageAngleWarning))
    _check_finite("fk", fk.twist, fk.residual)
    twist, determined = fk.twist, bool(twist_is_determined(robot, list(rates), beta))
    if not determined:
        warn(f"these rates do not determine the twist of robot '{robot.name}'; printing the minimum-norm one")
    for line in lines:  # given joints of a gear out of its ratios (fk.out_of_gear), headings off a linkage
        warn(line)
    if fk.residual > fk.tolerance:  # the wheels slip (fk.consistent is also False for a gear broken)
        names = fk.slipping or [robot.wheel_names[i] for i in np.argsort(-fk.wheel_slip) if fk.wheel_slip[i] > 0]
        worst = ", ".join(f"{n} {fk.wheel_slip[robot.wheel_names.index(n)]:.3g} m/s" for n in names)
        warn(f"the rates contradict each other: the wheels slip ({worst}; residual {fk.residual:.3g} m/s > "
             f"tolerance {fk.tolerance:.3g} m/s); check units, signs and --steer headings")
    if args.json:
        print_json({"robot": robot.name, "twist": twist.tolist(), "determined": determined, "residual": fk.residual,
                    "consistent": fk.consistent, "slipping": list(fk.slipping)})
    else:
        size = characteristic_length(robot)  # round-off printed as 0 (._shown), the residual's in the twist's speed
        vx, vy, omega = tidy_twist(twist, size)
        residual = tidy(fk.residual, twist_speed(twist, size))
        print(f"twist (robot frame): vx = {vx:.6g} m/s, vy = {vy:.6g} m/s, omega = {omega:.6g} rad/s")
        print(f"residual (slip norm): {residual:.3g} m/s ({'consistent' if fk.consistent else 'INCONSISTENT'})")
    return 0


def _twist(texts: list[str]) -> np.ndarray:
    """``--twist VX VY OMEGA``: SI, or each with a unit of its kind (``500 mm/s``, ``30 deg/s``), within
    :data:`MAX_QUERY_RATE`; a refusal names the component."""
    twist = []
    for name, text in zip(TWIST_NAMES, texts, strict=True):
        twist.append(parse_value(text, rate_kind(name), f"ik: --twist {name.upper()}"))
        if abs(twist[-1]) > MAX_QUERY_RATE:
            raise WmrkitError(f"ik: --twist {name.upper()} {text}: beyond {MAX_QUERY_RATE:g} (m/s or rad/s), no "
                              "wheeled robot moves so fast")
    return np.array(twist)


def _check_finite(what: str, *arrays) -> None:
    """A result that overflowed is an error, never a printed inf or nan."""
    import numpy as np

    if not all(np.all(np.isfinite(np.nan_to_num(np.asarray(a, dtype=float), nan=0.0))) for a in arrays):
        raise WmrkitError(f"{what}: the result overflows for this robot; give smaller rates")


def format_commands(robot: Robot, commands: WheelCommands, twist) -> str:
    """Human-readable table of one twist's wheel commands: heading in degrees (0 = rolling straight ahead). Round-off
    printed as 0 (:mod:`._shown`): a heading's scale is 180 deg, a rate's the largest joint rate, a slip's the
    twist's speed."""
    data, width = commands.to_dict(), wheel_column_width(robot)
    rates, speed = _rate_scale(commands), twist_speed(twist, characteristic_length(robot))
    lines = [f"{'wheel':<{width}}{'type':<14}{'heading [deg]':>14}{'spin [rad/s]':>14}{'steer rate [rad/s]':>20}"
             f"{'slip [m/s]':>12}  other rates [rad/s]"]
    for w in robot.wheels:
        entry = data["wheels"][w.name]
        other = ", ".join(f"{k} {cell(v, rates)}" for k, v in entry.items()
                          if k not in ("heading", "spin", "steer_rate"))
        heading = math.degrees(entry.get("heading", math.nan))
        lines.append(f"{w.name:<{width}}{described_type(w):<14}{cell(heading, 180.0):>14}"
                     f"{cell(entry['spin'], rates):>14}{cell(entry['steer_rate'], rates):>20}"
                     f"{cell(data['slip'][w.name], speed):>12}  {other}".rstrip())
    reasons = dict.fromkeys(why.split(":")[0] for why in _infeasible(robot, commands, twist))  # each reason once
    lines.append("feasible: " + ("yes" if data["feasible"] else f"NO ({'; '.join(reasons)})"))
    return "\n".join(lines)


def _infeasible(robot, commands: WheelCommands, twist) -> list[str]:
    """Why the commands for one `twist` are not feasible: a fixed wheel that slips sideways, a gear coupling whose
    joints would turn out of its ratios, a linkage whose law the headings break, steered wheels whose heading is
    outside their steer_range (each ``"reason: detail"``)."""
    out = []
    slipping = np.flatnonzero(np.abs(commands.slip) > 1e-9)
    if slipping.size:  # every one, the fastest first (a diff drive asked for vy: both wheels, not one)
        order = slipping[np.argsort(-np.abs(commands.slip[slipping]), kind="stable")]
        named = ", wheel ".join(f"'{robot.wheel_names[i]}'{' slips' * (k == 0)} at {commands.slip[i]:+.6g} m/s"
                                for k, i in enumerate(order[:MAX_NAMED]))
        more = f" and {order.size - MAX_NAMED} more" if order.size > MAX_NAMED else ""
        out.append(f"a fixed wheel would slip sideways: wheel {named}{more} (fixed wheels allow no lateral motion)")
    scale = _rate_scale(commands)
    for c, ok in zip(robot.couplings, commands.in_gear.tolist(), strict=True):
        if not ok:
            asked = ", ".join(f"{j} {cell(commands.rates[robot.rate_names.index(j)], scale)}"
                              for j in c.joints)
            out.append(f"a gear coupling cannot turn its joints so: {c.words()} turns them in the ratios "
                       f"{', '.join(f'{k:g}' for k in c.ratios)}, the twist needs {asked} rad/s")
    if not commands.in_steer_gear.all():
        for b in steer_breaches(robot, np.asarray(twist, dtype=float), commands.beta, SLIP_TOL):
            out.append(f"a steering gear cannot set these headings: {b.describe(robot)}")
    if not commands.in_linkage.all():
        for b in ik_breaches(robot, np.asarray(twist, dtype=float), commands.beta, SLIP_TOL):
            out.append(f"a steering linkage cannot set these headings: {b.describe(robot)}, which the "
                       f"twist needs (set by the linkage, the wheel would slip sideways at {b.slip:.3g} m/s)")
    for i in np.flatnonzero(~commands.in_range):
        lo, hi = (math.degrees(a) for a in robot.wheels[i].steer_range)
        out.append(f"a wheel cannot steer there: wheel '{robot.wheel_names[i]}' would steer to heading "
                   f"{math.degrees(commands.heading[i]):.6g} deg, outside its steer_range [{lo:g}, {hi:g}] deg")
    return out


def _rate_scale(commands: WheelCommands) -> float:
    """The largest joint rate of `commands` [rad/s], the scale of each rate's round-off."""
    return float(np.max(np.abs(np.nan_to_num(commands.rates)), initial=0.0))
