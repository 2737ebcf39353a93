"""The continuous loop's speed-ups change no result: fixed runs' poses against those the code gave before them.

The poses below were printed, with the code as of 7405d16 (before the loop's speed-ups), by::

    from wmrkit import catalog
    from wmrkit.control import builtin_reference, track
    run = track(catalog.load(robot), builtin_reference(reference), **options)
    idx = np.linspace(0, len(run.t) - 1, 7).round().astype(int)
    print([[float(v) for v in run.pose[i]] for i in idx])

for each entry of RUNS (its held front wheels, the hysteresis events, corners, castors, low-level loops).

They are compared to 1 nm, not to the last bit: numpy's float64 ``arctan2`` runs SIMD code on a CPU with AVX-512
(numpy's X86_V4 dispatch) that differs from the C library's ``atan2`` (the one these poses were printed with) by one
unit in the last place for 7 % of arguments, and the loop amplifies such differences: nudging the ackermann circle's
start by 2 ulp (1e-15 m) moves its poses by 3e-12 m after 12 s, and the per-step ulps move them by 2e-11 m. A
changed formula or a different discrete decision (a held wheel, a hysteresis flip) moves them by far more than 1 nm.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from wmrkit import Robot, catalog
from wmrkit.control import Plant, builtin_reference, forklift_real_loops, track
from wmrkit.control._loop_plant import AXLE_TOL
from wmrkit.control.loop import _Sim
from wmrkit.kinematics.loop_ik import checked_rates, checked_steering_config

RUNS = {"ackermann circle": ("ackermann", "circle", {"duration": 12.0}),
        "ackermann figure-eight gain 3": ("ackermann", "figure-eight", {"duration": 8.0, "gain": 3.0}),
        "diff-drive circle": ("diff-drive", "circle", {"duration": 5.0}),
        "swerve-4 square": ("swerve-4", "square", {"duration": 14.0}),
        "thesis-steer-castor circle": ("thesis-steer-castor", "circle", {"duration": 5.0}),
        "forklift figure-eight, loops": ("forklift", "figure-eight", {"duration": 4.0, "loops": "real"})}

POSE_TOL = 1e-9  # [m, rad]: platform ulps of atan2 amplified by the loop (module docstring), far below any change

BEFORE = {
    'ackermann circle': [
        [-2.8090256317805293, 0.0, 0.0],
        [-1.8235654648396813, 0.017613152146049214, 0.052539177820225],
        [-0.9052816388978707, 0.12189008223198808, 0.18635384155785817],
        [-0.09012977986413041, 0.3521142639956692, 0.3741320609270428],
        [0.5949582384138992, 0.7081442994956654, 0.5846385107717077],
        [1.1380081719794914, 1.155887551828655, 0.8047922558610943],
        [1.556403651768446, 1.6590134248781059, 1.0346365289424848],
    ],
    'ackermann figure-eight gain 3': [
        [-1.9862810727588383, -1.986281072758838, 0.7853981633974483],
        [-1.425755528972809, -1.42591967161297, 0.7848185992521076],
        [-0.8964585861515718, -0.8987196501809992, 0.7813005069556844],
        [-0.36696716236808663, -0.37768816323216964, 0.7722202468633257],
        [0.13399821343100332, 0.10304233588481809, 0.7557764381324986],
        [0.5830595960116647, 0.5168829364610483, 0.7315372130061836],
        [1.0092315157245682, 0.8870561647726488, 0.696234167539019],
    ],
    'diff-drive circle': [
        [-0.25, 0.0, 0.0],
        [0.17425542882318812, 0.01168709189860522, 0.07353329206811055],
        [0.5693631134482873, 0.06436273688245965, 0.19467397737084782],
        [0.977943221358541, 0.1747602496759074, 0.33380694442063163],
        [1.3669978478953555, 0.341245863980448, 0.47500805879631147],
        [1.7083039254126267, 0.5465881906433411, 0.6082578593033989],
        [2.0375925218400157, 0.8123705614955644, 0.7499071571749981],
    ],
    'swerve-4 square': [
        [0.0, 0.0, 0.0],
        [1.175, 0.0, 0.0],
        [2.325, 0.0, 0.0],
        [3.5, 0.0, 0.0],
        [4.675, 0.0, 0.0],
        [5.825, 0.0, 0.0],
        [5.999999999992267, 1.0000000000077334, 1.3582121573408272],
    ],
    'thesis-steer-castor circle': [
        [0.0, 0.0, 0.0],
        [0.42357984019244643, 0.03005385250891527, 0.14166666666666666],
        [0.8146408108683105, 0.11272440711586514, 0.275],
        [1.2141436906837668, 0.25667080021820643, 0.4166666666666667],
        [1.5893201068926406, 0.455582267430521, 0.5583333333333333],
        [1.9134651227182622, 0.6894478529707969, 0.6916666666666667],
        [2.2205305595867015, 0.9827632677525917, 0.8333333333333331],
    ],
    'forklift figure-eight, loops': [
        [0.0, 0.0, 0.7853981633974483],
        [0.06877198679539534, 0.06873700719516693, 0.7853742200526062],
        [0.41282776934388554, 0.4114220154169716, 0.7845648359084186],
        [0.8467587198548833, 0.8390862619239894, 0.7814427998501802],
        [1.1877198438380165, 1.1680614260741768, 0.7759778952672566],
        [1.421184059417318, 1.3860400411973806, 0.7690453391738427],
        [1.6197572665062663, 1.564448413408971, 0.7602605978428465],
    ],
}


@pytest.mark.parametrize("name", list(RUNS))
def test_the_continuous_loop_gives_the_poses_it_gave_before_its_speed_ups(name):
    """The car without its linkage: the poses were printed when the loop clipped each wheel on its own, as it still
    does a car whose front wheels no linkage holds (the kept linkage turns this car otherwise at its stops:
    tests/control/test_linked_ranges.py)."""
    robot, reference, options = RUNS[name]
    if options.get("loops") == "real":
        options = {**options, "loops": forklift_real_loops()}
    model = catalog.load(robot)
    model = replace(model, couplings=tuple(c for c in model.couplings if c.kind != "linkage"))
    run = track(model, builtin_reference(reference), **options)
    idx = np.linspace(0, len(run.t) - 1, 7).round().astype(int)
    np.testing.assert_allclose(run.pose[idx], BEFORE[name], rtol=0, atol=POSE_TOL)


def _ranged(name: str) -> Robot:
    """A catalog robot whose twist-steered wheels (steerable, double) get an uneven steering range."""
    robot = catalog.load(name)
    return replace(robot, wheels=tuple(replace(w, steer_range=(-1.1, 0.7)) if w.type in ("steerable", "double")
                                       else w for w in robot.wheels))


@pytest.mark.parametrize("robot", [catalog.load("ackermann"), _ranged("swerve-4"), _ranged("agv-drive-unit"),
                                   _ranged("thesis-steer-castor"), catalog.load("forklift")], ids=lambda r: r.name)
@settings(max_examples=200, deadline=None)
@given(twist=st.lists(st.floats(-3, 3), min_size=3, max_size=3), turns=st.lists(st.floats(-9, 9), min_size=4,
                                                                                  max_size=4), still=st.integers(0, 3))
def test_the_loops_plain_float_steering_is_the_ik_and_the_steering_choice_bit_for_bit(robot, twist, turns, still):
    """The continuous loop's plain-float shortcut (the IK's angles alone, then whether every steered wheel fits a
    root) gives checked_rates' configuration and commands' in_range (a twist at rest: held wheels). The same
    operations, but the shortcut's ``math.atan2`` (the C library's) and the batched path's ``np.arctan2`` (SIMD code
    on an AVX-512 CPU) may differ by one ulp of the angle, which a wrap by pi or 2 pi can carry to one ulp of 2 pi:
    equal to 2 ulp of 2 pi, and bit for bit where both use the same atan2 (CPUs without AVX-512). For a robot with a
    linkage (the car) the shortcut is sure, never wrong: where it says so, every wheel fits and the keeper leaves
    each axle where the IK puts it (mod pi), so the commanded twist is realised; elsewhere the long way decides."""
    twist = np.array(twist) * (still > 0)  # some twists at rest: every wheel held at its angle
    beta = np.array(turns[:len(robot.steer_names)])
    config = checked_steering_config(robot, twist, beta)
    want = checked_rates(robot, twist, beta)[1]
    np.testing.assert_allclose(config, want, rtol=0, atol=2 * np.spacing(2 * np.pi))
    sim = _Sim(robot, Plant())
    cmd = sim.commands(twist, beta)
    if sim.links is None:
        assert sim.all_fit(config) == bool(cmd.fits.all())
    elif sim.all_fit(config):
        off = np.remainder(cmd.target - np.array(config) + np.pi / 2, np.pi) - np.pi / 2
        assert cmd.fits.all() and np.abs(off).max() <= AXLE_TOL
