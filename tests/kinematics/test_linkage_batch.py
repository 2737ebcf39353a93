"""``ik``'s linkage check over a batch is compiled (kinematics/_linkage_kernel.py) and gives the verdicts the scalar
judge gives twist by twist.

Before: ``linkage_holds`` judged a batch twist by twist in Python (about 8 us a twist: a 1e4-twist ``wheel_commands``
on the catalog ``ackermann`` took 39 ms against 1.8 ms without its linkage). The reference here is the scalar rule as
first written (kept below: ``math.remainder``, Python's ``max``, the first of the fastest wheels), on random robots,
twists and angles, with the cases at the rule's edges: ties between the fastest wheels (a translation), a wheel at the
ICR, zero twists, angles off the law by exactly 90 deg (the tie of ``remainder`` mod pi) and by round-off.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import wmrkit._jit
from wmrkit import Robot, catalog
from wmrkit.kinematics import linkage_check
from wmrkit.kinematics.linkage_check import _judge, _plan, _speeds, linkage_holds
from wmrkit.kinematics.linkage_law import LINKAGE_TOL, law, leader_of, remainder
from wmrkit.kinematics.wheel_ik import SLIP_TOL, wheel_commands

from .test_linkage_ik import ackermann_car, synchro


def reference_broken(plan, beta: list[float], speed: list[float], slip_tol: float) -> set[int]:
    """The couplings the first scalar rule (linkage_check as written before the batch kernel) finds broken."""
    out = set()
    for g in range(len(plan.lead)):
        rows = plan.table[plan.start[g]:plan.start[g + 1]].tolist()
        lead = int(plan.lead[g])
        members = [lead, *(int(r[0]) for r in rows)]
        able = [(lead, None), *((int(r[0]), r) for r in rows if r[3] == 0.0 or r[5] != 0.0)]
        if max(speed[k] for k in members) == 0.0:
            continue
        ref, ref_row = max(able, key=lambda a: speed[a[0]])
        b = beta[lead] if ref_row is None else leader_of(ref_row, beta[ref])
        for k, want in zip(members, [b, *(law(r, b)[0] for r in rows)], strict=True):
            off = math.remainder(beta[k] - want, math.pi)
            if abs(off) > LINKAGE_TOL and speed[k] * abs(math.sin(off)) > slip_tol:
                out.add(int(plan.coupling[g]))
                break
    return out


def robots() -> list[Robot]:
    rng = np.random.default_rng(7)
    found = [catalog.load("ackermann"), synchro(), synchro([(0.2, 0.0), (-0.2, 0.0)])]
    for _ in range(6):
        found.append(ackermann_car(*rng.uniform([0.3, 0.2, -2, -math.pi], [5, 3, 2, math.pi])))
        points = rng.uniform(-1, 1, size=(int(rng.integers(2, 5)), 2))
        wheels = [{"name": f"w{k}", "type": "steerable", "position": p.tolist(), "heading": float(h), "r": 0.1}
                  for k, (p, h) in enumerate(zip(points, rng.uniform(-3, 3, len(points)), strict=True))]
        found.append(Robot.from_dict({"name": "synchro", "wheels": wheels, "couplings": [
            {"kind": "linkage", "joints": [f"w{k}.steer" for k in range(len(points))], "law": "parallel"}]}))
    return found


ROBOTS = robots()


def edge_cases(robot: Robot, plan, rng) -> tuple[np.ndarray, np.ndarray]:
    """Twists ``(N, 3)`` and steering angles ``(N, n_steer)`` at the rule's edges and at random."""
    n = len(plan.x)
    twists = [rng.normal(size=(200, 3)), np.zeros((4, 3)), np.c_[rng.normal(size=(50, 2)), np.zeros(50)],
              1e-9 * rng.normal(size=(50, 3))]
    for x, y in zip(plan.x, plan.y, strict=True):  # the ICR at each steering axis
        w = rng.normal(size=(10, 1))
        twists.append(np.c_[w * y, -w * x, w])
    twist = np.concatenate(twists)
    ik_beta = wheel_commands(robot, twist).beta  # ik's own angles
    on_law = np.repeat(rng.uniform(-3, 3, size=(len(twist), 1)), n, axis=1)
    for g in range(len(plan.lead)):  # the law's angles from a random leader's
        for r in plan.table[plan.start[g]:plan.start[g + 1]]:
            on_law[:, int(r[0])] = [law(r, b)[0] for b in on_law[:, int(plan.lead[g])]]
    quarter = on_law + np.where(rng.random(on_law.shape) < 0.3, math.pi / 2, 0.0)  # off by 90 deg: remainder's tie
    nudged = on_law + rng.choice([0.0, 1e-9, -2e-9, 1e-12], size=on_law.shape)
    angles = [ik_beta, on_law, quarter, nudged, rng.uniform(-4, 4, size=on_law.shape)]
    return np.tile(twist, (len(angles), 1)), np.concatenate(angles)


@pytest.mark.parametrize("budget", [0, 10**9], ids=["compiled", "python"])
@pytest.mark.parametrize("index", range(len(ROBOTS)))
def test_the_batch_verdicts_are_the_scalar_rule_s(index, budget, monkeypatch):
    monkeypatch.setattr(wmrkit._jit, "INTERPRET_BUDGET", budget)
    robot = ROBOTS[index]
    plan = _plan(robot)
    rng = np.random.default_rng(index)
    twist, beta = edge_cases(robot, plan, rng)
    assert len(twist) >= linkage_check.COMPILED_BATCH
    for slip_tol in (SLIP_TOL, 1e-3, 0.0):
        held = linkage_holds(robot, twist, beta, slip_tol)
        speed = _speeds(plan, twist)
        want = [reference_broken(plan, b, s, slip_tol) for b, s in zip(beta.tolist(), speed.tolist(), strict=True)]
        got = [set(np.flatnonzero(~h).tolist()) for h in held]
        assert got == want
        one = [{b.coupling for b in _judge(plan, b, s, slip_tol, LINKAGE_TOL)}
               for b, s in zip(beta, speed, strict=True)]
        assert one == want  # the scalar judge (ik_breaches, the messages) agrees
        small = linkage_holds(robot, twist[:5], beta[:5], slip_tol)  # below COMPILED_BATCH: Python
        assert (small == held[:5]).all()
    assert any(want) and not all(want)


def test_the_compiled_kernel_is_used_from_the_batch_size_on(monkeypatch):
    monkeypatch.setattr(wmrkit._jit, "INTERPRET_BUDGET", 0)
    from wmrkit.kinematics import _linkage_kernel

    robot = synchro()
    twist = np.tile([1.0, 0.0, 0.5], (linkage_check.COMPILED_BATCH, 1))
    assert not wheel_commands(robot, twist).feasible.any()
    assert _linkage_kernel.holds.is_compiled()
    python = wmrkit._jit.as_python(_linkage_kernel.holds.py_func)  # below the budget: nothing compiled is called
    breach = python.__globals__["_breach"]
    assert not hasattr(breach, "py_func") and not hasattr(breach.__globals__["leader_of"], "py_func")
    assert not any(hasattr(breach.__globals__[n], "py_func") for n in ("law", "remainder"))


@settings(max_examples=500, deadline=None)
@given(x=st.one_of(st.floats(-1e6, 1e6), st.integers(-60, 60).map(lambda k: k * math.pi / 2),
                   st.integers(-60, 60).map(lambda k: k * math.pi), st.floats(-1e300, 1e300),
                   st.sampled_from([0.0, -0.0, 5e-324, -5e-324])),
       y=st.sampled_from([math.pi, 2 * math.pi, 0.1, 1.0, 3.0]))
def test_remainder_is_math_remainder_compiled_and_not(x, y):
    from wmrkit.kinematics._linkage_kernel import _law_names

    want = math.remainder(x, y)
    for got in (remainder(x, y), _law_names["remainder"](x, y)):
        assert got == want and math.copysign(1.0, got) == math.copysign(1.0, want)
