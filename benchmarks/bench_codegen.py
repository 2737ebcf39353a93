"""Generated C against WPILib's C++, per call, in compiled loops: the code a controller embeds.

wmrkit: ``wmrkit kinematics ROBOT --codegen c``, ``NAME_forward`` (sensed spins and steering headings to the
least-squares twist with the rank decision of ``fk``; ``forward+slip`` also its slip residual, which WPILib does not
give) and ``NAME_inverse`` (twist to wheel rates at given headings), compiled with ``cc -O2 -flto`` (link-time
optimisation: inlined into the driver's loop as WPILib's header-defined kinematics are). WPILib (the C++ library
inside robotpy-wpimath, headers and shared libraries of its ``native`` packages, ``g++ -O2``):
``SwerveDriveKinematics<4>::ToChassisSpeeds`` from module states built from the angles (a ``Rotation2d`` each, as
from encoders), ``MecanumDriveKinematics`` and ``DifferentialDriveKinematics`` ``ToChassisSpeeds`` /
``ToWheelSpeeds``. Same catalog robots, same 1024 inputs cycled, the twists checked equal. No timing from Python:
each driver times its own loop (steady clock). Target: no slower than WPILib per call (ratio >= 1). The catalog's
diff-drive has a castor: its inverse gives the castor's rates too, where WPILib's template ignores the castor. The
forklift (no peer) is the run-time Jacobi SVD's case: its steered wheel's rows carry the twist.
"""

from __future__ import annotations

import importlib.util
import math
import os
import shutil
import subprocess
import tempfile
from pathlib import Path

import numpy as np

from wmrkit import catalog, wheel_commands
from wmrkit.kinematics.codegen import identifier, write_code
from wmrkit.kinematics.symbolic import sensed_rates

from ._harness import Result

SAMPLES = 1024
ROBOTS = ("swerve-4", "mecanum-4", "diff-drive", "forklift")  # the forklift (a tricycle) has no WPILib peer


def _inputs(robot_name: str) -> dict[str, np.ndarray]:
    """Random twists (|v| <= 1.5 m/s, |omega| <= 2 rad/s) and every joint's rate and heading for them."""
    robot = catalog.load(robot_name)
    rng = np.random.default_rng(7)
    twist = rng.uniform([-1.5, -1.5, -2.0], [1.5, 1.5, 2.0], size=(SAMPLES, 3))
    if robot_name == "diff-drive":
        twist[:, 1] = 0.0
    cmd = wheel_commands(robot, twist)
    return {"twist": twist, "spin": np.asarray(cmd.spin), "heading": np.asarray(cmd.heading),
            "r": np.array([w.r for w in robot.wheels])}


def _c_array(name: str, a: np.ndarray) -> str:
    assert np.isfinite(a).all(), name
    return f"static const double {name}[] = {{{', '.join(repr(float(v)) for v in np.ravel(a))}}};"


_LOOP = """
    {{
        double acc = 0.0;
        for (int i = 0; i < {warm}; ++i) {{ const int k = i & {mask}; {body} }}
        const double t0 = now();
        for (int i = 0; i < {n}; ++i) {{ const int k = i & {mask}; {body} }}
        printf("{label} %.3f %.17g\\n", (now() - t0) / {n} * 1e9, acc);
    }}"""


def _ours_driver(n: int) -> str:
    parts = ["#define _POSIX_C_SOURCE 199309L", "#include <stdio.h>", "#include <time.h>"]
    parts += [f'#include "{identifier(r)}_kinematics.h"' for r in ROBOTS]
    parts.append("static double now(void) { struct timespec t; clock_gettime(CLOCK_MONOTONIC, &t); "
                 "return t.tv_sec + 1e-9 * t.tv_nsec; }")
    loops = []
    for r in ROBOTS:
        x, p, data = identifier(r), identifier(r).upper(), _inputs(r)
        steered = np.flatnonzero([w.kind.steers for w in catalog.load(r).wheels])
        names = [w.name for w in catalog.load(r).wheels]
        sensed = [names.index(n.split(".")[0]) for n in sensed_rates(catalog.load(r))]  # spins, in its order
        parts += [_c_array(f"{x}_q", data["spin"][:, sensed]), _c_array(f"{x}_h", data["heading"][:, steered]),
                  _c_array(f"{x}_t", data["twist"])]
        h = f"{x}_h + k * {p}_N_STEER" if len(steered) else "NULL"
        loops.append(_LOOP.format(
            warm=n // 10, n=n, mask=SAMPLES - 1, label=f"{r}:forward", body=(
                f"double tw[3]; {x}_forward({x}_q + k * {p}_N_SENSED, {h}, tw, NULL); acc += tw[0] + tw[2];")))
        loops.append(_LOOP.format(
            warm=n // 10, n=n, mask=SAMPLES - 1, label=f"{r}:forward+slip", body=(
                f"double tw[3], res; {x}_forward({x}_q + k * {p}_N_SENSED, {h}, tw, &res); acc += tw[0] + res;")))
        loops.append(_LOOP.format(
            warm=n // 10, n=n, mask=SAMPLES - 1, label=f"{r}:inverse", body=(
                f"double q[{p}_N_RATES]; {x}_inverse({x}_t + 3 * k, {h}, q); acc += q[0];")))
        loops.append("    {" + f"double tw[3], res; {x}_forward({x}_q, {h.replace('k *', '0 *')}, tw, &res); "
                     f'printf("{r}:twist %.17g %.17g %.17g\\n", tw[0], tw[1], tw[2]);' + "}")
    return "\n".join([*parts, "int main(void)", "{", *loops, "    return 0;", "}", ""])


def _peer_driver(n: int) -> str:
    sw, me = catalog.load("swerve-4"), catalog.load("mecanum-4")
    track = 2 * catalog.load("diff-drive").wheels[0].position[1]
    pos = lambda robot: ", ".join(f"frc::Translation2d{{{x!r}_m, {y!r}_m}}" for x, y in  # noqa: E731
                                  (w.position for w in robot.wheels))
    parts = ["#include <frc/kinematics/SwerveDriveKinematics.h>", "#include <frc/kinematics/MecanumDriveKinematics.h>",
             "#include <frc/kinematics/DifferentialDriveKinematics.h>", "#include <chrono>", "#include <cstdio>",
             "static double now() { return std::chrono::duration<double>("
             "std::chrono::steady_clock::now().time_since_epoch()).count(); }"]
    for r in ROBOTS[:3]:
        data = _inputs(r)
        v = data["spin"] * data["r"]  # wheel speeds [m/s]
        parts += [_c_array(f"{identifier(r)}_v", v), _c_array(f"{identifier(r)}_t", data["twist"])]
    parts.append(_c_array("swerve_4_a", _inputs("swerve-4")["heading"]))
    mps = "units::meters_per_second_t"
    sw_state = ", ".join(f"frc::SwerveModuleState{{{mps}{{swerve_4_v[4 * k + {j}]}}, "
                         f"frc::Rotation2d{{units::radian_t{{swerve_4_a[4 * k + {j}]}}}}}}" for j in range(4))
    chassis = (f"frc::ChassisSpeeds{{{mps}{{{{x}}_t[3 * k]}}, {mps}{{{{x}}_t[3 * k + 1]}}, "
               "units::radians_per_second_t{{x}_t[3 * k + 2]}}")
    me_speeds = f"frc::MecanumDriveWheelSpeeds{{{', '.join(f'{mps}{{mecanum_4_v[4 * k + {j}]}}' for j in range(4))}}}"
    dd_speeds = f"frc::DifferentialDriveWheelSpeeds{{{mps}{{diff_drive_v[3 * k]}}, {mps}{{diff_drive_v[3 * k + 1]}}}}"
    bodies = {
        "swerve-4:forward": f"auto c = sw.ToChassisSpeeds(wpi::array<frc::SwerveModuleState, 4>{{{sw_state}}}); "
                            "acc += c.vx.value() + c.omega.value();",
        "mecanum-4:forward": f"auto c = me.ToChassisSpeeds({me_speeds}); acc += c.vx.value() + c.omega.value();",
        "mecanum-4:inverse": f"auto w = me.ToWheelSpeeds({chassis.replace('{x}', 'mecanum_4')}); "
                             "acc += w.frontLeft.value();",
        "diff-drive:forward": f"auto c = dd.ToChassisSpeeds({dd_speeds}); acc += c.vx.value() + c.omega.value();",
        "diff-drive:inverse": f"auto w = dd.ToWheelSpeeds({chassis.replace('{x}', 'diff_drive')}); "
                              "acc += w.left.value();",
    }
    loops = [_LOOP.format(warm=n // 10, n=n, mask=SAMPLES - 1, label=label, body=body)
             for label, body in bodies.items()]
    for r, obj, arg in (("swerve-4", "sw", f"wpi::array<frc::SwerveModuleState, 4>{{{sw_state}}}"),
                        ("mecanum-4", "me", me_speeds), ("diff-drive", "dd", dd_speeds)):
        loops.append("    { const int k = 0; " + f"auto c = {obj}.ToChassisSpeeds({arg}); "
                     f'printf("{r}:twist %.17g %.17g %.17g\\n", c.vx.value(), c.vy.value(), c.omega.value());' + "}")
    return "\n".join([*parts, "int main()", "{",
                      f"    frc::SwerveDriveKinematics<4> sw{{{pos(sw)}}};",
                      f"    frc::MecanumDriveKinematics me{{{pos(me)}}};",
                      f"    frc::DifferentialDriveKinematics dd{{{track!r}_m}};", *loops, "    return 0;", "}", ""])


def _parse(out: str) -> tuple[dict[str, float], dict[str, np.ndarray]]:
    times, twists = {}, {}
    for line in out.splitlines():
        label, *values = line.split()
        if label.endswith(":twist"):
            twists[label.split(":")[0]] = np.array([float(v) for v in values])
        else:
            times[label] = float(values[0]) * 1e-9
    return times, twists


def _native(name: str) -> Path | None:
    spec = importlib.util.find_spec(f"native.{name}") if importlib.util.find_spec("native") else None
    return Path(next(iter(spec.submodule_search_locations))) if spec and spec.submodule_search_locations else None


def _run_peer(work: Path, n: int) -> str | None:
    """The WPILib driver's output, or None when g++ or robotpy-wpimath's native packages are absent."""
    math_dir, util_dir, gxx = _native("wpimath"), _native("wpiutil"), shutil.which("g++")
    if math_dir is None or util_dir is None or gxx is None:
        return None
    (work / "peer.cpp").write_text(_peer_driver(n))
    subprocess.run([gxx, "-O2", "-std=c++20", f"-I{math_dir / 'include'}", f"-I{util_dir / 'include'}", "peer.cpp",
                    f"-L{math_dir / 'lib'}", f"-L{util_dir / 'lib'}", "-lwpimath", "-lwpiutil", "-o", "peer"],
                   check=True, cwd=work, capture_output=True)
    env = {**os.environ, "LD_LIBRARY_PATH": f"{math_dir / 'lib'}:{util_dir / 'lib'}"}
    return subprocess.run([str(work / "peer")], check=True, capture_output=True, text=True, env=env).stdout


def run(quick: bool) -> list[Result]:
    cc = shutil.which("cc") or shutil.which("gcc")
    if cc is None:
        print("bench_codegen: no C compiler (cc): skipped")
        return []
    n = 100_000 if quick else 2_000_000
    with tempfile.TemporaryDirectory() as tmp:
        work = Path(tmp)
        sources = [str(write_code(catalog.load(r), "c", work)[1].name) for r in ROBOTS]
        (work / "ours.c").write_text(_ours_driver(n))
        subprocess.run([cc, "-O2", "-flto", "-std=c99", "ours.c", *sources, "-lm", "-o", "ours"], check=True,
                       cwd=work, capture_output=True)
        ours, our_twists = _parse(subprocess.run([str(work / "ours")], check=True, capture_output=True,
                                                 text=True).stdout)
        peer_out = _run_peer(work, n)
    theirs, their_twists = _parse(peer_out) if peer_out is not None else ({}, {})
    for r, tw in their_twists.items():  # the same job: the same twist from the same wheel readings
        if not np.allclose(our_twists[r], tw, rtol=1e-9, atol=1e-9):
            raise AssertionError(f"{r}: generated C twist {our_twists[r]} but WPILib {tw}")
    return [Result(f"generated C: {label.replace(':', ' ')}", 1, seconds,
                   "WPILib C++" if label in theirs or peer_out is None else "none (no WPILib call)",
                   theirs.get(label), "ratio >= 1" if label in theirs or peer_out is None else "")
            for label, seconds in ours.items() if not math.isnan(seconds)]
