"""A torque file's heading set-points for the wheels of one held linkage must agree with its law (within
``SETPOINT_TOL``), or the steering servos fight the constraint (docs/dynamics.md, Couplings). The law is written
here independently, as the Ackermann ICR geometry (every axle through one point of the rear axle line) and a
synchro chain's common turn."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
from dynamics_robots import linked_car
from test_linkage_law import four_wheel_steer

from wmrkit import Robot
from wmrkit.cli.main import main
from wmrkit.dynamics.inputs import compiled_inputs
from wmrkit.dynamics.linkages import SETPOINT_TOL
from wmrkit.dynamics.model import DynamicModel
from wmrkit.dynamics.programs import read_torques
from wmrkit.errors import WmrkitError

CATALOG = Path(__file__).parents[2] / "src" / "wmrkit" / "catalog" / "ackermann.yaml"


def icr_heading(x: float, y: float, yc: float) -> float:
    """The heading of a wheel at ``(x, y)`` whose axle passes through the ICR ``(0, yc)`` on the rear axle line,
    rolling forward (the body turns left for ``yc > y``)."""
    return math.atan2(x, yc - y) if yc > y else math.atan2(-x, y - yc)


def _car(tmp_path: Path) -> Path:
    """The catalog's Ackermann car (wheelbase 2.70 m, track 1.55 m) with the mass properties the dynamics need."""
    text = CATALOG.read_text().replace("r: 0.33, actuated", "r: 0.33, inertia: {spin: 1.0}, actuated").replace(
        "r: 0.33, steer_range", "r: 0.33, inertia: {spin: 1.0, steer: 0.5}, steer_range")
    path = tmp_path / "car.yaml"
    path.write_text(text + "body: {mass: 1500, inertia: 2500, com: [1.2, 0], com_height: 0.5}\n")
    return path


def test_a_follower_off_the_ackermann_law_is_refused_at_its_row_and_columns(tmp_path, capsys):
    """Before, ``simulate car --torques`` with front_left at 0.3 rad and front_right at 0 ran (exit 0) while the
    two steering servos fought the linkage."""
    car, torques = _car(tmp_path), tmp_path / "h.csv"
    torques.write_text("time,front_left.heading,front_right.heading\n0,0,0\n1,0.3,0\n")
    right = icr_heading(2.70, -0.775, 0.775 + 2.70 / math.tan(0.3))
    argv = ["simulate", str(car), "--torques", str(torques), "--duration", "0.01"]
    assert main(argv) == 2
    out, err = capsys.readouterr()
    assert out == "" and len(err.splitlines()) == 1
    assert err.startswith(f"wmrkit: error: {torques}:3: column 'front_right.heading': 0 rad breaks "
                          f"the steering linkage of wheels 'front_left' and 'front_right', which sets front_right at "
                          f"heading {right:.6g} rad with column 'front_left.heading' at 0.3 rad")
    assert main([*argv, "--json"]) == 2
    data = json.loads(capsys.readouterr().err)
    assert (data["file"], data["line"], data["field"]) == (str(torques), 3, "front_right.heading")


def test_set_points_on_the_ackermann_law_are_accepted(tmp_path, capsys):
    car, torques = _car(tmp_path), tmp_path / "h.csv"
    rows = [(0.0, 0.0), *((h, icr_heading(2.70, -0.775, 0.775 + 2.70 / math.tan(h))) for h in (0.3, -0.5, 0.6))]
    torques.write_text("time,front_left.heading,front_right.heading\n" +
                       "".join(f"{k},{a!r},{b!r}\n" for k, (a, b) in enumerate(rows)))
    assert main(["simulate", str(car), "--torques", str(torques), "--duration", "0.01"]) == 0
    assert "front_right" not in capsys.readouterr().err


@pytest.mark.parametrize("heading", [-0.5, -0.1, 0.2, 0.6])
def test_the_tolerance_is_the_documented_one(heading, tmp_path):
    model = DynamicModel.of(linked_car())
    right = icr_heading(0.6, -0.2, 0.2 + 0.6 / math.tan(heading))
    path = tmp_path / "h.csv"
    for off, ok in ((0.5 * SETPOINT_TOL, True), (2 * SETPOINT_TOL, False), (-2 * SETPOINT_TOL, False)):
        path.write_text(f"time,fl.heading,fr.heading\n0,0,0\n1,{heading!r},{right + off!r}\n2,0,0\n")
        if ok:
            read_torques(model, path)
        else:
            with pytest.raises(WmrkitError, match=r"h\.csv:3: column 'fr\.heading': .* breaks the steering linkage"):
                read_torques(model, path)


def _three_wheel_ackermann() -> DynamicModel:
    """linked_car with a third steered wheel, ``ml`` at (0.3, 0.2), on the front pair's linkage (leader fl)."""
    wheel = {"r": 0.1, "tyre": "dugoff"}
    steer = {**wheel, "type": "steerable", "actuated": ["steer"], "inertia": {"spin": 0.01, "steer": 0.05}}
    fixed = {**wheel, "type": "fixed", "heading": 0, "actuated": ["spin"], "inertia": {"spin": 0.02}}
    return DynamicModel.of(Robot.from_dict({
        "name": "three", "body": {"mass": 30, "inertia": 1.5, "com": [0.25, 0.0], "com_height": 0.2},
        "wheels": [{**fixed, "name": "rl", "position": [0, 0.2]}, {**fixed, "name": "rr", "position": [0, -0.2]},
                   {**steer, "name": "fl", "position": [0.6, 0.2]}, {**steer, "name": "fr", "position": [0.6, -0.2]},
                   {**steer, "name": "ml", "position": [0.3, 0.2]}],
        "couplings": [{"kind": "linkage", "joints": ["fl.steer", "fr.steer", "ml.steer"]}]}))


@pytest.mark.parametrize("yc", [2.0, 0.9, -1.5, -0.7])
def test_followers_without_their_leader_are_checked_against_each_other(yc, tmp_path):
    """fr and ml commanded, the leader fl not: the leader's angle is found from fr (the law's inverse)."""
    model, path = _three_wheel_ackermann(), tmp_path / "h.csv"
    fr, ml = icr_heading(0.6, -0.2, yc), icr_heading(0.3, 0.2, yc)
    path.write_text(f"time,fr.heading,ml.heading\n0,0,0\n1,{fr!r},{ml!r}\n")
    read_torques(model, path)
    path.write_text(f"time,fr.heading,ml.heading\n0,0,0\n1,{fr!r},{ml + 1e-3!r}\n")
    with pytest.raises(WmrkitError, match=r":3: column 'ml\.heading': .* with column 'fr\.heading' at"):
        read_torques(model, path)


def test_a_synchro_chain_commanded_apart_is_refused(tmp_path):
    model = DynamicModel.of(Robot.from_dict(four_wheel_steer(linkages=[("fl", "fr", "rl", "rr")])))
    path = tmp_path / "h.csv"
    path.write_text("time,fr.heading,rl.heading\n0,0,0\n1,0.4,0.4\n")
    read_torques(model, path)
    path.write_text("time,fr.heading,rl.heading\n0,0,0\n1,0.4,0.4\n2,0.4,0.35\n")
    with pytest.raises(WmrkitError, match=r":4: column 'rl\.heading': 0\.35 rad breaks .* sets rl at heading 0\.4 "
                                          r"rad with column 'fr\.heading' at 0\.4 rad"):
        read_torques(model, path)


def test_a_follower_on_the_axle_line_keeps_its_rest_heading_whatever_is_commanded(tmp_path):
    """An Ackermann follower on the fixed wheels' axle line is held at its rest heading (its axle is that line):
    a set-point elsewhere fights the linkage even as the linkage's only servo."""
    data = linked_car().to_dict()
    data["wheels"].append({"name": "side", "type": "steerable", "position": [0, 0.5], "heading": 0, "r": 0.1,
                           "inertia": {"spin": 0.01, "steer": 0.05}, "tyre": "dugoff", "actuated": ["steer"]})
    data["couplings"] = [{"kind": "linkage", "joints": ["fl.steer", "fr.steer", "side.steer"]}]
    model, path = DynamicModel.of(Robot.from_dict(data)), tmp_path / "h.csv"
    path.write_text("time,fl.heading,side.heading\n0,0.3,0\n")
    read_torques(model, path)
    path.write_text("time,side.heading\n0,0\n1,0.2\n")
    with pytest.raises(WmrkitError, match=r":3: column 'side\.heading': 0\.2 rad breaks .* sets side at heading 0 "
                                          r"rad whatever the others do"):
        read_torques(model, path)


def _compiled(model, inputs):
    """The knots, headings and torques the kernels interpolate linearly (``compiled_inputs``)."""
    time, torques, *_ = compiled = compiled_inputs(model, inputs)
    return time, model.robot.heading_of_beta(compiled[5]), torques


def _interpolated(compiled, column: int, t):
    return np.interp(t, compiled[0], compiled[1][:, column])


def test_between_rows_the_follower_set_point_follows_the_law_of_the_interpolated_leader(tmp_path):
    """Before, the rows 0 and 0.5 rad (fr on the law at each) were interpolated linearly, fr too: half-way fr's
    set-point was 0.0246 rad off the law of fl's, the servos fighting the linkage between every two rows. Now the
    simulator interpolates fr through knots on the law of fl's interpolation, the torques as they were."""
    model, path = DynamicModel.of(linked_car()), tmp_path / "h.csv"
    rows = [(0.0, 0.0, 5.0), (1.0, 0.5, -3.0), (3.0, -0.4, 1.0)]
    path.write_text("time,fl.heading,fr.heading,rl.spin\n" + "".join(
        f"{t!r},{h!r},{icr_heading(0.6, -0.2, 0.2 + 0.6 / math.tan(h)) if h else 0.0!r},{tau!r}\n"
        for t, h, tau in rows))
    inputs = _compiled(model, read_torques(model, path))
    t = np.linspace(0.0, 3.0, 3001)
    times, fl, tau = (np.array(c) for c in zip(*rows, strict=True))
    assert _interpolated(inputs, 0, t) == pytest.approx(np.interp(t, times, fl), abs=1e-12)  # fl: its rows
    law = [icr_heading(0.6, -0.2, 0.2 + 0.6 / math.tan(h)) if h else 0.0 for h in _interpolated(inputs, 0, t)]
    assert np.abs(_interpolated(inputs, 1, t) - law).max() <= SETPOINT_TOL
    rl = list(model.names).index("rl.spin")
    assert np.interp(t, inputs[0], inputs[2][:, rl]) == pytest.approx(np.interp(t, times, tau), abs=1e-12)


def test_between_rows_followers_without_their_leader_stay_on_the_law(tmp_path):
    """fr and ml commanded, the leader fl not: ml follows the law of the leader angle fr's interpolation gives."""
    model, path = _three_wheel_ackermann(), tmp_path / "h.csv"
    rows = [(0.0, 2.0), (2.0, -0.9)]  # ICRs on the rear axle line at y = yc
    path.write_text("time,fr.heading,ml.heading\n" + "".join(
        f"{t!r},{icr_heading(0.6, -0.2, yc)!r},{icr_heading(0.3, 0.2, yc)!r}\n" for t, yc in rows))
    inputs = _compiled(model, read_torques(model, path))
    t = np.linspace(0.0, 2.0, 2001)
    fr, ml = _interpolated(inputs, 1, t), _interpolated(inputs, 2, t)
    yc = -0.2 + 0.6 / np.tan(fr)  # fr's axle meets the rear axle line there
    law = [icr_heading(0.3, 0.2, y) for y in yc]
    assert np.abs(np.remainder(ml - law + np.pi, 2 * np.pi) - np.pi).max() <= SETPOINT_TOL


# The knots between rows, as setpoint_knots made them row by row before it was vectorised (the oracle of the tests
# below: the same knots and values, bit for bit, from every row at once, plain or compiled).

def _old_set_by_law(model, beta, commanded):
    from wmrkit.kinematics.linkage_law import law, leader_of
    table, cols, out = model.pack[17], list(model.steer_columns), []
    for lead in dict.fromkeys(int(r[1]) for r in table):
        rows = [r for r in table if int(r[1]) == lead and cols.index(int(r[0])) in commanded]
        ref = cols.index(lead)
        if ref in commanded:
            b = beta[ref]
        else:
            first = next((r for r in rows if r[3] == 0.0 or r[5] != 0.0), None)
            ref = None if first is None else cols.index(int(first[0]))
            b = beta[cols.index(lead)] if first is None else leader_of(first, beta[ref])
        out += [(cols.index(int(r[0])), ref, law(r, b)[0]) for r in rows if cols.index(int(r[0])) != ref]
    return out


def _old_on_law(model, beta, commanded):
    beta = np.array(beta, dtype=float)
    for j, _, f in _old_set_by_law(model, beta, commanded):
        beta[j] += math.remainder(f - beta[j], 2 * math.pi)
    return beta


def _old_setpoint_knots(model, t, beta, commanded, tol=SETPOINT_TOL):
    if len(t) < 2 or not _old_set_by_law(model, beta[0], commanded):
        return t, beta
    times, rows = [t[:1]], [_old_on_law(model, beta[0], commanded)[None]]
    for k in range(len(t) - 1):
        pieces = 1
        while True:
            s = np.linspace(0.0, 1.0, 2 * pieces + 1)
            on = np.array([_old_on_law(model, (1 - a) * beta[k] + a * beta[k + 1], commanded) for a in s])
            off = np.abs(on[1:-1:2] - (on[:-2:2] + on[2::2]) / 2).max()
            if off <= tol / 2:
                break
            pieces = max(2 * pieces, math.ceil(pieces * math.sqrt(2 * off / tol)))
        times.append(np.append(t[k] + (t[k + 1] - t[k]) * s[2:-1:2], t[k + 1]))
        rows.append(on[2::2])
    return np.concatenate(times), np.concatenate(rows)


def _models() -> dict:
    """Robots and servoed steering indices: a leader and its follower; followers without their leader (the law's
    inverse); a synchro chain; a follower on the axle line."""
    side = linked_car().to_dict()
    side["wheels"].append({"name": "side", "type": "steerable", "position": [0, 0.5], "heading": 0, "r": 0.1,
                           "inertia": {"spin": 0.01, "steer": 0.05}, "tyre": "dugoff", "actuated": ["steer"]})
    side["couplings"] = [{"kind": "linkage", "joints": ["fl.steer", "fr.steer", "side.steer"]}]
    three = _three_wheel_ackermann()
    synchro = DynamicModel.of(Robot.from_dict(four_wheel_steer(linkages=[("fl", "fr", "rl", "rr")])))
    return {"pair": (DynamicModel.of(linked_car()), {0, 1}), "inverse": (three, {1, 2}), "three": (three, {0, 1, 2}),
            "synchro": (synchro, {1, 2, 3}), "axle": (DynamicModel.of(Robot.from_dict(side)), {0, 1, 2})}


def _random_rows(model, commanded, rng, k: int, step: float):
    """`k` rows of set-points on the law (the oracle's projection, each follower's turn nearest its last row's), the
    headings a random walk of steps up to `step` [rad] (some rows repeated), at random increasing times."""
    walk = np.cumsum(rng.uniform(-step, step, (k, len(model.steer_columns))) * (rng.random((k, 1)) > 0.1), axis=0)
    beta = np.array(model.robot.beta_of_heading(np.clip(walk, -1.3, 1.3)), dtype=float)
    followers = [j for j, _, _ in _old_set_by_law(model, beta[0], commanded)]
    for row in range(k):
        if row:
            beta[row, followers] = beta[row - 1, followers]
        beta[row] = _old_on_law(model, beta[row], commanded)
    return np.cumsum(rng.uniform(0.01, 2.0, k)), beta


@pytest.mark.parametrize("compiled", [False, True])
@pytest.mark.parametrize("name", ["pair", "inverse", "three", "synchro", "axle"])
def test_the_knots_of_every_row_at_once_are_those_made_row_by_row(name, compiled, monkeypatch):
    """setpoint_knots looped over the rows in Python, a law evaluation per call (1.5 s for a 2001-knot twist
    program; minutes for a torque file near the table limit): now its loops run over every row at once, compiled
    for large tables. The same knots and values, bit for bit, including steps cut into hundreds of pieces."""
    from wmrkit.dynamics import _setpoints, linkages

    monkeypatch.setattr(_setpoints, "COMPILED_WORK", 0 if compiled else 10**9)
    model, commanded = _models()[name]
    rng = np.random.default_rng(7)
    for k, step in ((2, 1.2), (30, 0.05), (40, 0.8)):
        t, beta = _random_rows(model, commanded, rng, k, step)
        at, on = linkages.setpoint_knots(model, t, beta, commanded)
        want_at, want_on = _old_setpoint_knots(model, t, beta, commanded)
        assert np.array_equal(at, want_at) and np.array_equal(on, want_on)
        assert len(at) > k or name in ("synchro", "axle")  # knots were inserted (a chain's law is linear)


def _counted(monkeypatch) -> list[int]:
    """The law evaluations of setpoint_knots (its loops as plain Python), counted."""
    from wmrkit.dynamics import _setpoints

    count, law = [0], _setpoints.law

    def counting(row, beta):
        count[0] += 1
        return law(row, beta)

    monkeypatch.setattr(_setpoints, "COMPILED_WORK", 10**12)
    monkeypatch.setattr(_setpoints, "law", counting)
    return count


@pytest.mark.parametrize("swing", [0.02, 0.3, 0.9])
def test_the_work_is_bounded_by_the_rows_and_the_knots_inserted(swing, monkeypatch):
    """At most ``5 (rows - 1) + 12 knots + 1`` law evaluations (a follower, its leader commanded): each step puts one
    (its middle, the turn its law reaches: _setpoints.continued) and then 3
    set-points on the law at first and, cut into p > 1 pieces, ``2 p + 1`` in each round, p at least doubling (at
    most 5 P for its last P), then P knots; P - 1 >= P / 2 knots inserted. At the cap (linkages.MAX_SETPOINT_KNOTS)
    that is at most 1.2e7 evaluations past the rows' (about a second compiled, 0.1 us each); before, the cap was 1e7
    knots (1.2e8 evaluations at 13 us each in Python: half an hour)."""
    from wmrkit.dynamics import linkages

    count = _counted(monkeypatch)
    model = DynamicModel.of(linked_car())
    t = np.arange(200.0)
    fl = swing * np.where(np.arange(200) % 2, 1.0, -1.0) * np.random.default_rng(3).random(200)
    rows = [(h, icr_heading(0.6, -0.2, 0.2 + 0.6 / math.tan(h))) for h in fl]
    at, _ = linkages.setpoint_knots(model, t, np.array(model.robot.beta_of_heading(np.array(rows))), {0, 1})
    inserted = len(at) - len(t)
    assert 0 < count[0] <= 5 * (len(t) - 1) + 12 * inserted + 1
    assert 12 * linkages.MAX_SETPOINT_KNOTS <= 1.2e7


def test_the_knot_cap_is_reached_before_its_knots_are_computed(monkeypatch):
    """Beyond MAX_SETPOINT_KNOTS inserted knots, a one-line WmrkitError saying what to do, the law evaluated at
    most ``5 (rows - 1) + 12 cap + 1`` times; just within the cap, the knots. Before, the cap counted the rows too,
    was checked only while a step was cut (a million rows passed it unchecked) and said to give rows closer
    together (which inserts as many knots)."""
    from wmrkit.dynamics import linkages

    model = DynamicModel.of(linked_car())
    t = np.arange(50.0)
    fl = np.where(np.arange(50) % 2, 0.7, -0.7)
    rows = [(h, icr_heading(0.6, -0.2, 0.2 + 0.6 / math.tan(h))) for h in fl]
    beta = np.array(model.robot.beta_of_heading(np.array(rows)))
    inserted = len(linkages.setpoint_knots(model, t, beta, {0, 1})[0]) - len(t)
    monkeypatch.setattr(linkages, "MAX_SETPOINT_KNOTS", inserted)
    assert len(linkages.setpoint_knots(model, t, beta, {0, 1})[0]) == len(t) + inserted
    monkeypatch.setattr(linkages, "MAX_SETPOINT_KNOTS", inserted - 1)
    count = _counted(monkeypatch)
    with pytest.raises(WmrkitError) as err:
        linkages.setpoint_knots(model, t, beta, {0, 1})
    assert count[0] <= 5 * (len(t) - 1) + 12 * (inserted - 1) + 1
    assert "\n" not in str(err.value)
    assert str(err.value).startswith(
        f"heading set-points: keeping a held linkage's followers on its law between the rows would insert more than "
        f"{inserted - 1:.0e} knots (the step from t = 0 s to 1 s alone at least ")
    assert str(err.value).endswith("give the heading of one wheel per linkage (the linkage turns the others) or "
                                   "smaller heading steps between rows")


def test_the_cli_names_the_torque_file_past_the_knot_cap(tmp_path, capsys, monkeypatch):
    """Before, ``simulate car --torques h.csv`` past the cap printed the error without the file (JSON file null)."""
    from wmrkit.dynamics import linkages

    monkeypatch.setattr(linkages, "MAX_SETPOINT_KNOTS", 3)
    car, torques = tmp_path / "car.json", tmp_path / "h.csv"
    car.write_text(json.dumps(linked_car().to_dict()))
    right = icr_heading(0.6, -0.2, 0.2 + 0.6 / math.tan(0.5))
    torques.write_text(f"time,fl.heading,fr.heading\n0,0,0\n1,0.5,{right!r}\n")
    argv = ["simulate", str(car), "--torques", str(torques), "--duration", "0.01"]
    assert main(argv) == 2
    out, err = capsys.readouterr()
    assert out == "" and len(err.splitlines()) == 1
    assert err.startswith(f"wmrkit: error: {torques}: heading set-points: keeping a held linkage's followers on its "
                          "law between the rows would insert more than 3e+00 knots (the step from t = 0 s to 1 s ")
    assert main([*argv, "--json"]) == 2
    data = json.loads(capsys.readouterr().err)
    assert data["file"] == str(torques) and data["error"].startswith("heading set-points: keeping")
