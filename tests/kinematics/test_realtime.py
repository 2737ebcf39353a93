"""Single-call kinematics (issue 11, item 4): the same numbers as the batched path, outputs in caller arrays."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from circle import circular_gap
from strategies import robots
from wmrkit import ShapeError, catalog, forward_kinematics, wheel_commands
from wmrkit.kinematics.realtime import realtime
from wmrkit.odometry.model import odometry_model
from wmrkit.odometry.pipeline import odometry
from wmrkit.odometry.synthetic import TwistProfile, simulate

CATALOG = ["swerve-4", "mecanum-4", "diff-drive", "forklift", "ackermann", "omni-3", "thesis-steer-castor",
           "thesis-two-steer-castor", "thesis-omni-castor", "thesis-bicycle-castor"]


def _same_ik(robot, rt, twist, heading):
    ref = wheel_commands(robot, twist, heading=heading)
    rates, out = np.full(len(robot.rate_names), np.nan), np.full(len(robot.steer_names), np.nan)
    feasible = rt.ik(*map(float, twist), np.asarray(heading, dtype=float), rates, out)
    np.testing.assert_allclose(rates, ref.rates, rtol=1e-12, atol=1e-12)
    if len(out):
        assert circular_gap(out, robot.heading_of_beta(ref.beta)).diagonal().max() < 1e-12
    assert feasible == bool(ref.feasible)


@pytest.mark.parametrize("name", CATALOG)
def test_ik_equals_the_batched_ik(name):
    robot = catalog.load(name)
    rt = realtime(robot)
    rng = np.random.default_rng(1)
    for _ in range(40):
        _same_ik(robot, rt, rng.uniform(-1, 1, 3), rng.uniform(-np.pi, np.pi, len(robot.steer_names)))
    _same_ik(robot, rt, np.zeros(3), robot.heading)  # zero twist: angles held, spins 0


def test_ik_takes_the_root_within_the_steer_range_as_the_batched_ik():
    """Modules limited to +-90 deg at 80 deg asked for 100 deg: the other root (-80 deg, spin negated) is within
    the range and is taken, as by wheel_commands; it was the closest root, reported infeasible."""
    from wmrkit import Robot, Wheel

    robot = Robot("limited", tuple(Wheel(n, "steerable", 0.4, a, 0.0, 0.05, steer_range=(-np.pi / 2, np.pi / 2))
                                   for n, a in (("a", 0.8), ("b", -2.3))))
    rt = realtime(robot)
    rates, out = np.empty(2), np.empty(2)
    twist = (np.cos(np.radians(100)), np.sin(np.radians(100)), 0.0)
    assert rt.ik(*twist, np.radians([80.0, 80.0]), rates, out)
    np.testing.assert_allclose(np.degrees(out), [-80.0, -80.0]), np.testing.assert_allclose(rates, [-20.0, -20.0])
    rng = np.random.default_rng(3)
    for _ in range(100):
        _same_ik(robot, rt, rng.uniform(-1, 1, 3), rng.uniform(-np.pi / 2, np.pi / 2, 2))


@pytest.mark.parametrize("name", ["diff-drive", "swerve-4"])
def test_odometry_step_that_overflows_is_refused_and_writes_nothing(name):
    """Joint positions of 1e308 and -1e308 are finite, their difference is not: the pose became NaN."""
    rt = realtime(catalog.load(name))
    n = len(rt.rate_joints)
    pose, previous = np.array([1.0, 2.0, 0.5]), np.zeros(n)
    positions = np.where(np.arange(n) % 2, -1e308, 1e308)
    with pytest.raises(ValueError, match="overflows"):
        rt.odometry_step(pose, previous, positions, np.zeros(len(rt.steer_joints)))
    assert pose.tolist() == [1.0, 2.0, 0.5] and previous.tolist() == [0.0] * n


@settings(max_examples=10)
@given(robot=robots(max_wheels=3), data=st.data())
def test_ik_equals_the_batched_ik_on_random_robots(robot, data):
    """Ten robots, five twists each (a robot's kernel compiles in seconds: 25 robots of one twist cost a CI worker
    over a minute)."""
    rt = realtime(robot)
    n = len(robot.steer_names)
    for _ in range(5):
        twist = np.array(data.draw(st.lists(st.floats(-2, 2), min_size=3, max_size=3)))
        heading = np.array(data.draw(st.lists(st.floats(-3, 3), min_size=n, max_size=n)))
        _same_ik(robot, rt, twist, heading)


@pytest.mark.parametrize("name", ["diff-drive", "mecanum-4", "omni-4", "swerve-4", "forklift"])
def test_fk_equals_the_batched_least_squares(name):
    robot = catalog.load(name)
    rt = realtime(robot)
    model = odometry_model(robot)
    rng = np.random.default_rng(2)
    for _ in range(20):
        rates = rng.normal(size=len(rt.rate_joints))
        heading = rng.uniform(-1.5, 1.5, len(rt.steer_joints))
        twist = np.empty(3)
        rt.fk(rates, heading, twist)
        full = robot.heading.copy()
        full[[robot.steer_names.index(j.partition(".")[0]) for j in rt.steer_joints]] = heading
        ref, _ = forward_kinematics(robot, dict(zip(rt.rate_joints, rates, strict=True)), heading=full)
        np.testing.assert_allclose(twist, ref, rtol=1e-10, atol=1e-12)
    assert model.rate_joints == rt.rate_joints


@pytest.mark.parametrize("name", ["diff-drive", "mecanum-4", "omni-4"])
def test_odometry_steps_equal_the_batched_odometry(name):
    robot = catalog.load(name)
    profile = TwistProfile.from_segments([(2.0, 0.8, 0.0, 0.6), (2.0, 0.5, 0.0, -0.9)])
    log = simulate(robot, profile, 100.0).log
    rt = realtime(robot, log.joints)
    ref = odometry(robot, log)
    pose, previous = np.zeros(3), log.positions[0].copy()
    for k in range(1, len(log)):
        rt.odometry_step(pose, previous, log.positions[k], np.empty(0))
    np.testing.assert_allclose(pose, ref.poses[-1], rtol=0, atol=1e-12)


@pytest.mark.parametrize("name", ["swerve-4", "forklift", "diff-drive"])
def test_wrong_arrays_and_non_finite_input_are_refused_not_written_past(name):
    """The kernels write into caller-owned arrays: arrays shorter than the robot's were written past their ends (a
    neighbour's memory overwritten, once a glibc abort), an integer array truncated the rates, and a NaN twist gave
    'feasible' with zero rates. Each is refused with the shapes the robot needs, and the neighbour is untouched."""
    robot = catalog.load(name)
    rt = realtime(robot)
    n, ns = len(robot.rate_names), len(robot.steer_names)
    guard = np.full(2 * n + 2 * ns + 4, 7.0)
    short_rates, short_heading = guard[:max(n - 1, 0)], guard[n:n + max(ns - 1, 0)]
    ok = np.zeros(ns), np.empty(n), np.empty(ns)
    cases = [((1.0, 0.5, 0.3, np.zeros(ns), short_rates, ok[2]), "ik: heading and heading_out must be float64"),
             ((1.0, 0.5, 0.3, np.zeros(ns), np.empty(n, dtype=int), ok[2]), "rates_out one of shape"),
             ((np.nan, 0.0, 0.0, *ok), r"ik: the twist \(vx, vy, omega\) must be finite"),
             ((1e300, 0.0, 0.0, *ok), r"each at most 1e\+06"),
             ((1.0, 0.0, 0.0, np.zeros(ns + 1), ok[1], ok[2]), "heading and heading_out")]
    if ns:
        cases += [((1.0, 0.5, 0.3, np.zeros(ns), ok[1], short_heading), "heading and heading_out"),
                  ((1.0, 0.0, 0.0, np.full(ns, np.inf), ok[1], ok[2]), "ik: the headings must be finite")]
    for args, message in cases:
        with pytest.raises(ValueError, match=message):
            rt.ik(*args)
    assert (guard == 7.0).all()
    na, nsj = len(rt.rate_joints), len(rt.steer_joints)
    with pytest.raises(ValueError, match=r"fk: rates must have shape"):
        rt.fk(np.ones(na + 1), np.zeros(nsj), np.empty(3))
    with pytest.raises(ValueError, match=r"twist_out be a float64 array of shape \(3,\)"):
        rt.fk(np.ones(na), np.zeros(nsj), np.empty(3, dtype=np.float32))
    with pytest.raises(ValueError, match="fk: the rates must be finite"):
        rt.fk(np.full(na, np.nan), np.zeros(nsj), np.empty(3))
    pose, previous = np.zeros(3), np.zeros(na)
    with pytest.raises(ValueError, match=r"odometry_step: pose must be a float64 array of shape \(3,\)"):
        rt.odometry_step(guard[:2], previous, np.ones(na), np.zeros(nsj))
    with pytest.raises(ValueError, match="odometry_step: pose must be"):
        rt.odometry_step(pose, np.zeros(na, dtype=int), np.ones(na), np.zeros(nsj))
    with pytest.raises(ValueError, match="odometry_step: the pose and the joint positions must be finite"):
        rt.odometry_step(pose, previous, np.full(na, np.inf), np.zeros(nsj))
    assert (pose == 0).all() and (previous == 0).all() and (guard == 7.0).all()
    if nsj:
        with pytest.raises(ValueError, match=r"fk: the headings must be a finite array of shape \(\d+,\)"):
            rt.fk(np.ones(na), np.full(nsj, np.nan), np.empty(3))


def test_the_control_tick_refuses_non_finite_poses_and_wrong_twist_arrays():
    """control_tick wrote a NaN twist and said 'feasible' for a NaN pose."""
    from wmrkit.control.tick import control_tick

    robot = catalog.load("diff-drive")
    tick = control_tick(robot).tick
    n, ns = len(robot.rate_names), len(robot.steer_names)
    hd, rates, out = np.zeros(ns), np.empty(n), np.empty(ns)
    twist = np.empty(3)
    assert tick(0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.5, 0.0, 0.0, hd, twist, rates, out)
    with pytest.raises(ValueError, match="tick: the pose, the reference and its velocity must be finite"):
        tick(np.nan, 0.0, 0.0, 1.0, 0.0, 0.0, 0.5, 0.0, 0.0, hd, twist, rates, out)
    with pytest.raises(ValueError, match=r"tick: twist_out must be a float64 array of shape \(3,\)"):
        tick(0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.5, 0.0, 0.0, hd, np.empty(2), rates, out)


@pytest.mark.parametrize("heading", [1e7, -1e17, 1e300])
def test_headings_beyond_a_million_turns_are_refused_as_by_the_batched_ik(heading):
    """wheel_commands refuses a heading beyond 1e6 turns (its sine and cosine are round-off); the compiled IK took
    it and answered 'feasible' with headings of pi or 0 depending on the rounding, and the steering FK with a twist."""
    robot = catalog.load("swerve-4")
    with pytest.raises(ShapeError, match="at most 1e\\+06 turns"):
        wheel_commands(robot, [1.0, 0.0, 0.0], heading=np.full(4, heading))
    rt = realtime(robot)
    rates, out = np.full(4, 7.0), np.full(4, 7.0)
    with pytest.raises(ValueError, match="ik: the headings must be finite, at most 1e\\+06 turns"):
        rt.ik(1.0, 0.0, 0.0, np.full(4, heading), rates, out)
    assert (rates == 7.0).all() and (out == 7.0).all()
    with pytest.raises(ValueError, match="fk: the headings must be a finite array of shape \\(4,\\), at most 1e\\+06"):
        rt.fk(np.ones(len(rt.rate_joints)), np.full(len(rt.steer_joints), heading), np.empty(3))
    rt.ik(1.0, 0.0, 0.0, np.full(4, 2 * np.pi * 1e6), rates, out)  # the bound itself is an angle


#: A process calling one robot's ik, fk and odometry step, printing each kernel's numba cache hits and misses, then
#: its ik's rates for a twist and wheel_commands' (the numbers, whatever the cache gave).
_PROCESS = """
import json, sys
import numpy as np
from wmrkit import wheel_commands
from wmrkit.description import robot_from_dict
from wmrkit.kinematics.realtime import realtime
robot = robot_from_dict(json.loads(sys.argv[1]))
rt = realtime(robot)
n, m = len(robot.rate_names), len(rt.rate_joints)
rates = np.zeros(n)
rt.ik(0.3, 0.1, 0.4, np.zeros(0), rates, np.zeros(0))
rt.fk(np.ones(m), np.zeros(0), np.zeros(3))
rt.odometry_step(np.zeros(3), np.zeros(m), np.ones(m), np.zeros(0))
stats = {k: [sum(f.stats.cache_hits.values()), sum(f.stats.cache_misses.values())]
         for k, f in (("ik", rt.ik), ("fk", rt.fk), ("odometry_step", rt.odometry_step.kernel))}
print(json.dumps({"stats": stats, "rates": rates.tolist(),
                  "expected": wheel_commands(robot, [0.3, 0.1, 0.4]).rates.tolist()}))
"""


def test_a_second_process_loads_the_compiled_kernels_from_the_cache(tmp_path):
    """The single-call kernels were compiled in every process (cache=False): 3 to 6 s before the first tick of a
    diff drive. Now cached on disk: a second process loads all three (numba's cache hits, no miss), and a robot of
    other dimensions, the same code with other constants, compiles its own and gives its own numbers."""
    import json
    import os
    import subprocess
    import sys

    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path / "numba"), "WMRKIT_INTERPRET_BUDGET": "0"}

    def run(track: float) -> dict:
        wheels = [{"name": n, "type": "fixed", "position": [0.0, y], "heading": 0.0, "r": 0.1,
                   "actuated": ["spin"], "sensed": ["spin"]} for n, y in (("left", track / 2), ("right", -track / 2))]
        out = subprocess.run([sys.executable, "-c", _PROCESS, json.dumps({"name": "dd", "wheels": wheels})],
                             env=env, capture_output=True, text=True, timeout=600)
        assert out.returncode == 0, out.stderr[-800:]
        answer = json.loads(out.stdout)
        np.testing.assert_allclose(answer["rates"], answer["expected"], rtol=1e-12, atol=1e-12)
        return answer["stats"]

    first = run(0.4)
    assert all(hits == 0 and misses >= 1 for hits, misses in first.values()), first
    assert all(hits >= 1 and misses == 0 for hits, misses in run(0.4).values())
    other = run(0.6)  # the rates checked against wheel_commands: not the 0.4 m robot's kernel
    assert other["ik"][1] >= 1 and other["fk"][1] >= 1


#: A process compiling or loading the control tick of a differential drive of track `track` for the P law of gain
#: `gain`, printing its numba cache hits and misses, its twist and rates for one pose, and law_controller's twist
#: and wheel_commands' rates (the numbers, whatever the cache gave).
_TICK_PROCESS = """
import json, sys
import numpy as np
from wmrkit import wheel_commands
from wmrkit.control import PositionLaw, control_point, control_tick
from wmrkit.control.loop import law_controller
from wmrkit.control.references import Reference
from wmrkit.description import robot_from_dict
robot = robot_from_dict(json.loads(sys.argv[1]))
law = PositionLaw.uniform("p", float(sys.argv[2]))
tick = control_tick(robot, law).tick
twist, rates = np.zeros(3), np.zeros(2)
tick(0.0, 0.1, 0.2, 1.0, 0.0, 0.0, 0.5, 0.0, 0.0, np.zeros(0), twist, rates, np.zeros(0))
ref = Reference("still", np.array([0.0, 1.0]), np.array([[1.0, 0.0, 0.0]] * 2),
                np.array([[0.5, 0.0, 0.0]] * 2), np.zeros((2, 3)))
want, _ = law_controller(control_point(robot), law, ref)(0.0, np.array([0.0, 0.1, 0.2]), np.zeros(3))
print(json.dumps({"stats": [sum(tick.stats.cache_hits.values()), sum(tick.stats.cache_misses.values())],
                  "twist": twist.tolist(), "want": want.tolist(), "rates": rates.tolist(),
                  "expected": wheel_commands(robot, want).rates.tolist()}))
"""


def test_a_second_process_loads_the_control_tick_from_the_cache(tmp_path):
    """control_tick's kernel (the law around the robot's IK) was compiled in every process (cache=False; numba's
    key of a closure holding a kernel changes in every process). Now a second process loads it (a cache hit, no
    miss), and a robot of another track, or another gain, compiles its own and gives its own numbers."""
    import json
    import os
    import subprocess
    import sys

    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path / "numba"), "WMRKIT_INTERPRET_BUDGET": "0"}

    def run(track: float, gain: float) -> list[int]:
        wheels = [{"name": n, "type": "fixed", "position": [0.0, y], "heading": 0.0, "r": 0.1,
                   "actuated": ["spin"], "sensed": ["spin"]} for n, y in (("left", track / 2), ("right", -track / 2))]
        out = subprocess.run([sys.executable, "-c", _TICK_PROCESS, json.dumps({"name": "dd", "wheels": wheels}),
                              str(gain)], env=env, capture_output=True, text=True, timeout=600)
        assert out.returncode == 0, out.stderr[-800:]
        answer = json.loads(out.stdout)
        np.testing.assert_allclose(answer["twist"], answer["want"], rtol=1e-12, atol=1e-12)
        np.testing.assert_allclose(answer["rates"], answer["expected"], rtol=1e-12, atol=1e-12)
        return answer["stats"]

    hits, misses = run(0.4, 1.0)
    assert hits == 0 and misses == 1
    assert run(0.4, 1.0) == [1, 0]
    assert run(0.6, 1.0)[1] == 1 and run(0.4, 2.0)[1] == 1  # another IK, another law: not the first's kernel


def test_the_odometry_step_casts_its_positions_at_the_door():
    """Integer or float32 joint positions (encoder counts, a float32 bus), a list, or another heading_mid each compiled
    one more specialisation of the step (seconds, and a kernel held per dtype); now cast to float64 at the door: one
    compiled step serves them all, with the numbers of float64 positions."""
    from wmrkit.kinematics import realtime as rt_module

    rt = realtime(catalog.load("diff-drive"), ("left.spin", "right.spin"))
    kernel = getattr(rt.odometry_step, "kernel", rt.odometry_step)  # the compiled step behind the door
    pose, previous = np.zeros(3), np.zeros(2)
    rt.odometry_step(pose, previous, np.array([1.0, 2.0]), np.zeros(0))
    counts = len(kernel.signatures), len(rt_module._step.signatures)
    expected_pose, expected_previous = pose.copy(), previous.copy()
    for positions, heading_mid in ((np.array([2, 4], dtype=np.int64), np.zeros(0)),
                                   (np.array([3.0, 6.0], dtype=np.float32), np.zeros(0)),
                                   ([4.0, 8.0], None), (np.array([5, 10], dtype=np.int32), 0.0)):
        rt.odometry_step(pose, previous, positions, heading_mid)
        rt_float = realtime(catalog.load("diff-drive"), ("left.spin", "right.spin"))
        rt_float.odometry_step(expected_pose, expected_previous, np.asarray(positions, dtype=float), np.zeros(0))
        np.testing.assert_array_equal(pose, expected_pose)
        np.testing.assert_array_equal(previous, expected_previous)
    assert (len(kernel.signatures), len(rt_module._step.signatures)) == counts
    for args in ((pose, previous, np.ones((1, 2))), ([0.0, 0.0, 0.0], previous, np.ones(2))):
        with pytest.raises(ValueError, match=r"odometry_step: pose must be a float64 array of shape \(3,\)"):
            rt.odometry_step(*args, np.zeros(0))
