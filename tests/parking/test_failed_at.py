"""A failed plan says at which stage it failed (``ParkingPlan.failed_at``), and plan_parking's retry with a gentler
first manoeuvre reads that stage, not the words of the reason."""

from __future__ import annotations

import math
from dataclasses import replace

import pytest
from parking_cases import WIDE_CAR as CAR
from parking_cases import WIDE_SLOT as SLOT

from wmrkit.parking import planner
from wmrkit.parking.planner import plan_thesis


@pytest.mark.parametrize(("space", "stage"), [
    (replace(SLOT, H=CAR.length), "slot"),  # no room left behind the car
    (replace(SLOT, J=0.9 * CAR.c1), "slot"),  # narrower than the car
    (replace(SLOT, J=1.8), "pass"),  # test_wide_slots: Algorithm 4 cannot reach the approach point
    (SLOT, ""),
])
def test_each_stage_is_named(space, stage):
    plan = plan_thesis(CAR, space)
    assert plan.failed_at == stage and plan.feasible is (stage == "")


def test_phase_3_failure_is_named():
    plan = plan_thesis(CAR, SLOT, max_maneuvers=1)
    assert plan.failed_at == "maneuvers" and "more than 1 manoeuvres" in plan.reason


def test_the_gentler_retry_does_not_take_an_approach_failure_for_a_phase_3_one(monkeypatch):
    """Algorithm 3's reasons speak of "the first backward manoeuvre" too: the retry matched the word "manoeuvre" and
    gave back the gentler angle's Algorithm-3 failure instead of the plan it was retrying."""
    failed = plan_thesis(CAR, replace(SLOT, J=1.8))
    approach = replace(failed, reason="no steering angle lets the first backward manoeuvre enter the slot ...",
                       failed_at="approach")
    monkeypatch.setattr(planner, "plan_thesis", lambda *a, **k: approach)
    assert planner._gentler_first(CAR, replace(SLOT, J=1.8), failed, math.radians(1.0), 100) is failed
