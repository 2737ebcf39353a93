"""``analyze`` says which singular configurations a held ``linkage`` cannot set (analysis/linkage_reach.py).

Before: a synchro drive (one ``parallel`` linkage of its three wheels) sensing only a.spin was reported
``singular (sensed: a.spin): with coordinated steering, when the ICR is at (0.200, 0.000) m``, though its chain
keeps the three wheels parallel, so the ICR is never at a point: the thesis's coordinated steering (every wheel
aimed at the ICR on its own) reaches it, the robot does not. The set is kept (the thesis's), a line says so. The
reference is geometry: parallel wheels (equal rest headings) have axles that meet at a finite ICR only where the
axles coincide, the line through the linked wheels when it is their common axle.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from wmrkit import Robot, catalog
from wmrkit.analysis.icr import steer_to_icr
from wmrkit.analysis.linkage_reach import unreachable
from wmrkit.analysis.singularity import SingularSet
from wmrkit.analysis.summary import analyze
from wmrkit.cli.main import main


def robot(points, linked, sensed_spin, actuated_spin, name="linked"):
    """Steerable wheels w0.. at `points`, heading 0; one parallel linkage over the wheels `linked`."""
    wheels = [{"name": f"w{k}", "type": "steerable", "position": list(p), "heading": 0, "r": 0.05,
               "actuated": ["spin", "steer"] if k == actuated_spin else ["steer"],
               "sensed": ["spin", "steer"] if k == sensed_spin else ["steer"]} for k, p in enumerate(points)]
    return Robot.from_dict({"name": name, "wheels": wheels, "couplings": [
        {"kind": "linkage", "joints": [f"w{k}.steer" for k in linked], "law": "parallel"}]})


SYNCHRO = [(0.2, 0.0), (-0.1, 0.173), (-0.1, -0.173)]
FOUR = [(0.5, 0.3), (0.5, -0.3), (-0.5, 0.3), (-0.5, -0.3)]  # w0, w1 the front pair, linked


def test_a_synchro_drive_s_singular_icr_at_a_wheel_is_said_to_be_out_of_its_reach(tmp_path, capsys):
    r = robot(SYNCHRO, [0, 1, 2], sensed_spin=0, actuated_spin=0, name="synchro")
    s = analyze(r).singular["sensed"]
    headings = np.degrees(r.heading_of_beta(s.configurations))
    assert len(headings) == 1 and abs(headings[0, 1] - headings[0, 2]) % 180 > 1.0  # b, c not parallel
    text = analyze(r).format_text()
    assert ("  singular (sensed: w0.spin): with coordinated steering, when the ICR is at (0.200, 0.000) m\n"
            "    not reachable: the steering linkage of wheels 'w0', 'w1' and 'w2' (law parallel) cannot set the "
            "steering of this singular configuration (the thesis's coordinated steering turns each wheel on its "
            "own)") in text
    path = tmp_path / "synchro.json"
    path.write_text(json.dumps(r.to_dict()))
    assert main(["analyze", str(path), "--json"]) == 0
    sensed = json.loads(capsys.readouterr().out)["singular"]["sensed"]
    assert sensed["unreachable"] == [True] and sensed["unreachable_note"].startswith("not reachable: linkage(w0")


def test_a_front_linked_four_wheel_steer_reaches_one_singular_icr_and_not_the_other():
    """ICR at w0 (front): w1 aimed at it heads 0, parallel to w0's kept 0: reachable. ICR at w2 (rear): the front
    pair aimed at it is not parallel."""
    r = robot(FOUR, [0, 1], sensed_spin=2, actuated_spin=0)
    a = analyze(r)
    assert a.singular["actuated"].reasons == ("ICR at (0.500, 0.300) m",)
    assert a.singular["sensed"].reasons == ("ICR at (-0.500, 0.300) m",)
    assert unreachable(r, a.singular["actuated"])[0].tolist() == [False]
    assert unreachable(r, a.singular["sensed"]) == ([True], ("linkage(w0.steer, w1.steer) (law parallel)",))
    assert a.format_text().count("not reachable") == 1


def test_the_catalog_car_s_singular_icr_is_on_its_ackermann_law():
    text = analyze(catalog.load("ackermann")).format_text()
    assert "when the ICR is at (0.000, 0.000) m" in text and "not reachable" not in text


@pytest.mark.parametrize("case", ["synchro", "four"])
def test_random_icrs_are_reachable_exactly_where_the_linked_axles_can_meet(case):
    """Brute force over ICRs: three synchro wheels (not collinear) meet only at infinity; the front pair of the
    four-wheel steer also on its common axle line x = 0.5 (any point of it, the pair heading 0)."""
    rng = np.random.default_rng(7)
    r = robot(SYNCHRO, [0, 1, 2], 0, 0) if case == "synchro" else robot(FOUR, [0, 1], 2, 0)
    points = rng.uniform(-2, 2, (40, 2))
    on_axle = np.c_[np.full(15, 0.5), rng.uniform(-2, 2, 15)]
    away = rng.uniform(-np.pi, np.pi, 15)
    h = np.concatenate([np.c_[points, np.ones(40)], np.c_[on_axle, np.ones(15)],
                        np.c_[np.cos(away), np.sin(away), np.zeros(15)]])
    expected = np.r_[np.ones(40, bool), np.full(15, case == "synchro"), np.zeros(15, bool)]
    s = SingularSet((), r.steer_names, False, steer_to_icr(r, h), False, coordinated=True)
    np.testing.assert_array_equal(unreachable(r, s)[0], expected)
