"""A closed loop through the dynamics whose state leaves the physical range (the Stepper's range stop:
runs.first_escape) keeps that stop's words when the re-check reproduces it: before, ``rechecked`` judged it as "the
state diverged before t" and advised a smaller step, which a range stop (torques or speeds too large) does not
bear out."""

from __future__ import annotations

import numpy as np
import pytest

from wmrkit.control.dynamic_plant import rechecked
from wmrkit.dynamics.runs import DivergedError, UnstableStepError

WHAT = ("the simulation left the physical range at t = 0.4 s (left.spin = 1.3e+04 rad/s moves a point of the robot "
        "at 1.0e+03 m/s, beyond 1000 m/s (limits.MAX_SPEED))")


def _escaping_loop(duration: float, step: float, rerun: bool) -> dict:
    raise DivergedError(f"{WHAT}; use smaller torques or speeds", 0.4, WHAT)


def test_a_reproduced_range_stop_keeps_its_words():
    with pytest.raises(DivergedError) as err:
        rechecked(_escaping_loop, 2.0, 1e-3, 0.01)
    message = str(err.value)
    assert message.startswith(WHAT), message
    assert "diverged before" not in message and "use a step" not in message, message
    assert err.value.t == 0.4


def test_a_range_stop_the_shorter_step_does_not_reproduce_is_named_as_such():
    """The re-run at the shorter step goes on to the end: the step is blamed, but the stop is still said as it was."""

    def loop(duration: float, step: float, rerun: bool) -> dict:
        if rerun:
            return {"t": np.array([0.0, duration])}
        return _escaping_loop(duration, step, rerun)

    with pytest.raises(UnstableStepError) as err:
        rechecked(loop, 2.0, 1e-3, 0.01)
    assert str(err.value).startswith("the simulation left the physical range at t = 0.4 s"), str(err.value)
