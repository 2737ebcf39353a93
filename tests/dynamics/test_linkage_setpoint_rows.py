"""A table of heading set-points is judged every row at once (linkages.first_breach): the same first offending row,
wheel, reference and angle as the per-row checks it replaced, kept here as the oracle (a linkage's law by the
pre-vectorised ``_old_set_by_law``, a gear's ratios as ``gear_breach`` applied them), on random tables with
breaches at random rows; and the doors (a torque file, compiled inputs) no longer judge row by row."""

from __future__ import annotations

import math

import numpy as np
import pytest
from test_linkage_setpoints import _models, _old_set_by_law
from test_linked_servos import _geared_units

from wmrkit.dynamics import inputs as inputs_module
from wmrkit.dynamics import linkages, programs
from wmrkit.dynamics.inputs import compiled_inputs
from wmrkit.dynamics.linkages import SETPOINT_TOL
from wmrkit.dynamics.programs import read_torques, steering_gains
from wmrkit.dynamics.simulate import Inputs
from wmrkit.errors import WmrkitError


def _old_breach(model, headings, commanded):
    """The first breach of one row, as the per-row checks found it: ``('linkage', j, ref, law angle)`` or
    ``('gear', j, ref, heading)``; None."""
    beta = model.robot.beta_of_heading(headings)
    for j, ref, f in _old_set_by_law(model, beta, commanded):
        if abs(math.remainder(beta[j] - f, 2 * math.pi)) > SETPOINT_TOL:
            return "linkage", j, ref, f
    base, cols, rest, gears = model.pack[16], list(model.steer_columns), model.robot.heading, {}
    for k in sorted(commanded) if base.shape[1] else ():
        p = np.flatnonzero(base[cols[k]])
        if len(p) == 1:
            gears.setdefault(int(p[0]), []).append(k)
    for p, joints in gears.items():
        u = (headings[joints[0]] - rest[joints[0]]) / base[cols[joints[0]], p]
        for j in joints[1:]:
            if abs(headings[j] - (rest[j] + base[cols[j], p] * u)) > SETPOINT_TOL:
                return "gear", j, joints[0], float(rest[j] + base[cols[j], p] * u)
    return None


def _cases() -> dict:
    cases = {name: (model, commanded) for name, (model, commanded) in _models().items()}
    cases["gear 1:2"] = (_geared_units((1.0, 2.0)), {0, 1})
    cases["gear 3:-1"] = (_geared_units((3.0, -1.0)), {0, 1})
    return cases


def _table(model, commanded, rng, rows: int, moved: int = 4) -> np.ndarray:
    """`rows` heading set-points ``(rows, n_steer)`` on the law (the gear's ratios) in the commanded columns, rest
    headings elsewhere, then a few set-points moved off it by 0.3 to 100 SETPOINT_TOL at random rows."""
    rest = np.array(model.robot.heading, dtype=float)
    headings = np.tile(rest, (rows, 1))
    cols = sorted(commanded)
    headings[:, cols] = np.clip(np.cumsum(rng.uniform(-0.05, 0.05, (rows, len(cols))), axis=0), -1.2, 1.2)
    if not len(model.pack[17]):  # a gear (two joints): h_j - h_j0 = k_j u, from the first joint's
        ratios = next(c.ratios for c in model.robot.couplings if c.kind == "gear")
        headings[:, 1] = rest[1] + ratios[1] / ratios[0] * (headings[:, 0] - rest[0])
    else:
        beta = np.array(model.robot.beta_of_heading(headings), dtype=float)
        for k in range(rows):
            for j, _, f in _old_set_by_law(model, beta[k], commanded):
                beta[k, j] += math.remainder(f - beta[k, j], 2 * math.pi)
        headings = np.array(model.robot.heading_of_beta(beta), dtype=float)
        headings[:, [k for k in range(len(rest)) if k not in commanded]] = rest[[k for k in range(len(rest))
                                                                                 if k not in commanded]]
    for _ in range(rng.integers(0, moved)):
        headings[rng.integers(rows), rng.choice(cols)] += rng.choice([-1, 1]) * rng.uniform(0.3, 100) * SETPOINT_TOL
    return headings


@pytest.mark.parametrize("compiled", [False, True])
@pytest.mark.parametrize("name", list(_cases()))
def test_the_first_breach_of_every_row_at_once_is_the_per_row_one(name, compiled, monkeypatch):
    from wmrkit.dynamics import _setpoints

    monkeypatch.setattr(_setpoints, "COMPILED_WORK", 0 if compiled else 10**9)
    model, commanded = _cases()[name]
    rng, found = np.random.default_rng(11), 0
    for rows in (1, 2, 50, 400, 400, 400, 400, 400):
        headings = _table(model, commanded, rng, rows)
        old = [_old_breach(model, h, commanded) for h in headings]
        first = next((k for k, b in enumerate(old) if b), None)
        assert linkages.first_breach(model, headings, commanded) == first
        found += first is not None
        for k in {first, *rng.integers(rows, size=3).tolist()} - {None}:  # the row's own verdict, to the bit
            kind, *want = old[k] or (None, None, None, None)
            beta = model.robot.beta_of_heading(headings[k])
            link = linkages.setpoint_breach(model, beta, commanded)
            assert link == (tuple(want) if kind == "linkage" else None)
            if kind != "linkage":
                gear = linkages.gear_breach(model, headings[k], commanded)
                assert (gear and gear[:3]) == (tuple(want) if kind == "gear" else None)
    assert 3 <= found < 8  # tables with breaches and without


def _counting(monkeypatch, module) -> list[int]:
    calls, breach = [0], module.heading_breach

    def counted(*args):
        calls[0] += 1
        return breach(*args)

    monkeypatch.setattr(module, "heading_breach", counted)
    return calls


@pytest.mark.parametrize("name", ["pair", "inverse", "gear 1:2"])
def test_a_torque_file_and_compiled_inputs_judge_every_row_at_once(name, tmp_path, monkeypatch):
    """Before, ``_check_setpoints`` and ``compiled_inputs`` called heading_breach once per row in Python (4.6 s and
    5.1 s for 1e5 rows of a linked car); now at most once, for the first offending row's message, which names the
    same row, wheel and reference."""
    model, commanded = _cases()[name]
    steered, rows = model.robot.steer_names, 300
    headings = _table(model, commanded, np.random.default_rng(5), rows, moved=1)
    for k in (rows - 1, 137, None):  # a breach at the last row, at an inner row, none
        h = headings.copy()
        if k is not None:
            h[k, max(commanded)] += 50 * SETPOINT_TOL
        old = next(((r, b) for r, b in enumerate(_old_breach(model, row, commanded) for row in h) if b), None)
        assert (old and old[0]) == k
        path = tmp_path / "h.csv"
        cols = sorted(commanded)
        path.write_text("time," + ",".join(f"{steered[c]}.heading" for c in cols) + "\n" + "".join(
            f"{r}," + ",".join(repr(float(v)) for v in h[r, cols]) + "\n" for r in range(rows)))
        calls = _counting(monkeypatch, programs)
        if k is None:
            read_torques(model, path)
        else:
            _, j, ref, _ = old[1]
            by = "whatever the others do" if ref is None else f"with column '{steered[ref]}.heading' at"
            with pytest.raises(WmrkitError, match=rf"^{path}:{k + 2}: column '{steered[j]}\.heading': .* breaks "
                                                  rf".*, which sets {steered[j]} at heading .* rad {by}"):
                read_torques(model, path)
        assert calls[0] <= 1
        kp, kd = steering_gains(model, [model.steer_columns[c] for c in cols])
        n, t = model.n, np.arange(float(rows))
        given = Inputs(t, np.zeros((rows, n)), np.zeros((rows, n)), np.zeros(n), np.full(n, np.inf), h, kp, kd)
        calls = _counting(monkeypatch, inputs_module)
        if k is None:
            compiled_inputs(model, given)
        else:
            with pytest.raises(WmrkitError, match=rf"^heading_reference: at t = {k:g} s, {steered[j]}'s "):
                compiled_inputs(model, given)
        assert calls[0] <= 1
