"""Every public function of wmrkit, wmrkit.analysis, .batch, .control and .slip whose first argument is `robot`
names it when given a catalog name (or anything that is not a Robot): "'str' object has no attribute 'steering'"
came from deep inside (wmrkit.robot.check_robot; batch's as a BatchError). The list is derived from ``__all__``,
so a new function is held to it too."""

from __future__ import annotations

import inspect

import pytest

import wmrkit
import wmrkit.analysis
import wmrkit.batch
import wmrkit.control
import wmrkit.slip
from wmrkit import WmrkitError, catalog

_SKIP = {"robot_to_dict"}  # writes what it is given (a Robot's fields); its own test refuses other objects


def _robot_first(module) -> list[tuple[str, object]]:
    out = []
    for name in module.__all__:
        f = getattr(module, name)
        if callable(f) and not inspect.isclass(f) and name not in _SKIP:
            params = list(inspect.signature(f).parameters.values())
            if params and params[0].name == "robot":
                out.append((f"{module.__name__}.{name}", f))
    return out


FUNCTIONS = [f for m in (wmrkit, wmrkit.analysis, wmrkit.batch, wmrkit.control, wmrkit.slip) for f in _robot_first(m)]


def _call(f, robot):
    """`f(robot, ...)` with a placeholder for each other required argument (the robot is checked first)."""
    params = list(inspect.signature(f).parameters.values())[1:]
    required = [p for p in params if p.default is inspect.Parameter.empty]
    positional = [p for p in required if p.kind in (p.POSITIONAL_ONLY, p.POSITIONAL_OR_KEYWORD)]
    keywords = {p.name: None for p in required if p.kind == p.KEYWORD_ONLY}
    return f(robot, *([None] * len(positional)), **keywords)


def test_the_list_is_not_empty():
    names = {n for n, _ in FUNCTIONS}
    assert len(names) >= 50 and {"wmrkit.wheel_commands", "wmrkit.analysis.classify", "wmrkit.batch.sweep",
                                 "wmrkit.control.simulate", "wmrkit.slip.wls"} <= names


@pytest.mark.parametrize(("name", "f"), FUNCTIONS, ids=[n for n, _ in FUNCTIONS])
@pytest.mark.parametrize("given", ["diff-drive", {"name": "x", "wheels": []}, None])
def test_a_name_where_a_robot_goes_is_named(name, f, given):
    with pytest.raises(WmrkitError, match=r"^robot: expected a Robot \(wmrkit\.catalog\.load\(name\), "):
        _call(f, given)


def test_a_robot_still_passes_the_check():
    assert wmrkit.analysis.classify(catalog.load("diff-drive")).type == 2
