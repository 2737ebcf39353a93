"""The studio's live condition number, natural length and κ map hold the robot's gears, as ``analyze`` does (one
function, ``isotropy.described_condition``, serves both). Before: omni-3 with front_left.spin and back.spin on a
1:2 gear showed D = 0.2828 m (the wheels' model) where ``wmrkit analyze`` printed 0.2928 m, and "ICR anywhere in
the plane". Checked against an SVD done here: the kernel of the no-slip rows (3.22) plus the gear's row, the joint
rates as a map of the twists (vx, vy, D omega) it holds, and the natural length by a dense scan of D."""

from __future__ import annotations

import numpy as np
import pytest

from geared import held_constraints
from wmrkit import catalog
from wmrkit.analysis.summary import analyze
from wmrkit.description import robot_from_dict
from wmrkit.robot import Robot
from wmrkit.studio import api


def geared(name: str, joints: list[str], ratios: list[float], actuated: dict[str, list[str]] | None = None) -> dict:
    """The description of catalog robot `name` with `joints` on one gear at `ratios`."""
    d = catalog.load(name).to_dict()
    for w in d["wheels"]:
        w["actuated"] = (actuated or {}).get(w["name"], w.get("actuated", []))
    d["couplings"] = [{"kind": "gear", "joints": joints, "ratios": ratios}]
    return d


def geared_kernel(robot: Robot, beta: np.ndarray) -> np.ndarray:
    """The (twist, joint rates) the robot with its gear admits at `beta`, one per row: the kernel of the no-slip
    rows (3.22) plus the gear's rows, by an SVD done here."""
    a = held_constraints(robot, beta)
    _, s, vh = np.linalg.svd(a)
    return vh[int(np.sum(s > 1e-10 * s[0])):]


def brute_kappa(robot: Robot, beta: np.ndarray, joints: tuple[str, ...], lengths: np.ndarray) -> np.ndarray:
    """kappa of `joints` as a function of the twists the geared robot admits at `beta` (m = 2: a line of ICRs), in
    (v, D omega) at the foot P of the perpendicular from the origin to that line, the thesis's pair (5.47)."""
    kernel = geared_kernel(robot, beta)  # (twist, rates) the robot can have, one per row
    assert len(kernel) == 2
    rates = kernel[:, [robot.velocity_index(j) for j in joints]]
    n = np.cross(kernel[0, :3], kernel[1, :3])  # n . twist = 0: the ICR (x, y) obeys n0 y - n1 x + n2 = 0
    px, py = np.array([-n[1], n[0]]) * -n[2] / (n[0] ** 2 + n[1] ** 2)  # its point nearest the origin
    assert abs(n[0] * py - n[1] * px + n[2]) < 1e-12
    at_p = kernel[:, :3] + kernel[:, 2:3] * np.array([-py, px, 0.0])  # the velocity of P: v + omega z x P
    twist = at_p[None] * np.stack([np.ones_like(lengths), np.ones_like(lengths), lengths], -1)[:, None, :]
    h = np.swapaxes(rates, -1, -2)[None] @ np.linalg.pinv(np.swapaxes(twist, -1, -2))  # joint rates of the twist
    sv = np.linalg.svd(h, compute_uv=False)[:, :2]  # the map on the admitted twists (rank 2)
    return sv[:, 0] / sv[:, -1]


@pytest.mark.parametrize("ratios", [[1.0, 2.0], [1.0, 1.0], [-3.0, 0.5]])
def test_the_live_analysis_of_a_geared_omni_robot_is_analyze_s(ratios):
    d = geared("omni-3", ["front_left.spin", "back.spin"], ratios)
    robot = robot_from_dict(d)
    live = api.analyze_live({"description": d})["analysis"]
    full = analyze(robot, resolution=8).to_dict()
    for key in ("condition_number", "characteristic_length", "condition_joints", "coupled_mobility", "mobility"):
        assert live[key] == full[key], key
    assert live["icr"]["text"] == full["icr"] and live["icr"]["kind"] == "line"
    lengths = np.geomspace(1e-2, 10.0, 100001)
    kappa = brute_kappa(robot, robot.beta, tuple(live["condition_joints"]), lengths)
    assert live["characteristic_length"] == pytest.approx(lengths[int(np.argmin(kappa))], rel=1e-3)
    at_d = brute_kappa(robot, robot.beta, tuple(live["condition_joints"]), np.array([live["characteristic_length"]]))
    assert live["condition_number"] == pytest.approx(at_d[0], rel=1e-9) and at_d[0] <= kappa.min() * (1 + 1e-12)


def test_the_1_to_2_omni_s_natural_length_is_not_the_wheels_one():
    live = api.analyze_live({"description": geared("omni-3", ["front_left.spin", "back.spin"], [1.0, 2.0])})
    assert live["analysis"]["characteristic_length"] == pytest.approx(0.2928, abs=1e-4)  # not sqrt(2) 0.2 = 0.2828


def test_the_kappa_map_of_a_geared_castor_robot_holds_the_gear():
    """thesis-omni-castor with c1.spin and c2.spin on a 1:2 gear: the map's length is analyze's natural length and
    each cell the geared kappa at that steering (the castors' headings)."""
    d = geared("thesis-omni-castor", ["c1.spin", "c2.spin"], [1.0, 2.0])
    robot = robot_from_dict(d)
    m = api.kappa_map({"description": d, "resolution": 12})
    full = analyze(robot, resolution=8)
    assert m["length"] == full.characteristic_length
    kappa = np.array(m["kappa"], dtype=object).reshape(m["shape"])
    axis = np.array(m["axis"])
    for i, j in np.ndindex(*kappa.shape):
        headings = robot.heading.copy()
        headings[:2] = axis[i], axis[j]
        want = brute_kappa(robot, robot.beta_of_heading(headings), full.joints, np.array([m["length"]]))[0]
        if want > 1e12:  # singular: the map's null (infinite kappa)
            assert kappa[i, j] is None, (i, j, want)
        else:
            assert kappa[i, j] == pytest.approx(want, rel=1e-8), (i, j)


@pytest.mark.parametrize("ratios", [[1.0, 1.0], [1.0, -1.0]])
def test_gears_that_leave_one_motion_say_isotropy_does_not_apply(ratios):
    """diff-drive with left.spin and right.spin on one gear (1:1, a solid axle: straight only; 1:-1, turning on the
    spot only). The page said 'κ infinite (these joints do not determine the twist)' from the null condition
    number, yet the joints determine the twist; `wmrkit analyze` says isotropy does not apply. Checked by an SVD
    done here: one motion is left, and the geared joints turn on it (their rates are not all zero)."""
    d = geared("diff-drive", ["left.spin", "right.spin"], ratios)
    robot = robot_from_dict(d)
    kernel = geared_kernel(robot, robot.beta)
    assert len(kernel) == 1
    rates = kernel[0, [robot.velocity_index(j) for j in ("left.spin", "right.spin")]]
    assert np.abs(rates).max() > 0.1 * np.abs(kernel[0]).max()  # they see the one motion: the twist is determined
    live = api.analyze_live({"description": d})["analysis"]
    assert live["condition_number"] is None and live["characteristic_length"] is None
    assert live["isotropy_note"] == "does not apply (its gear couplings leave m = 1: no two motions to balance)"


@pytest.mark.parametrize(("name", "note"), [("omni-3", None), ("diff-drive", None),
                                            ("ackermann", "does not apply (m = 1: no two motions to balance)")])
def test_the_isotropy_note_is_analyze_s(name, note):
    """Without gears: m = 1 (ackermann) leaves no two motions to balance, m >= 2 has a condition number (no note)."""
    robot = catalog.load(name)
    assert api.analyze_live({"description": robot.to_dict()})["analysis"]["isotropy_note"] == note
    assert analyze(robot, resolution=8).isotropy_note() == note
