"""Every public function of wmrkit and wmrkit.analysis whose first argument is `robot` names it when given a
catalog name (or anything that is not a Robot): "'str' object has no attribute 'steering'" came from deep inside
(wmrkit.robot.check_robot). The list is derived from ``__all__``, so a new function is held to it too."""

from __future__ import annotations

import inspect

import pytest

import wmrkit
import wmrkit.analysis
from wmrkit import ShapeError, catalog

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


FUNCTIONS = _robot_first(wmrkit) + _robot_first(wmrkit.analysis)


def _call(f, robot):
    """`f(robot, ...)` with a placeholder for each other required positional argument (the robot is checked first)."""
    required = [p for p in list(inspect.signature(f).parameters.values())[1:]
                if p.default is inspect.Parameter.empty and p.kind in (p.POSITIONAL_ONLY, p.POSITIONAL_OR_KEYWORD)]
    return f(robot, *([None] * len(required)))


def test_the_list_is_not_empty():
    names = {n for n, _ in FUNCTIONS}
    assert len(names) >= 25 and "wmrkit.wheel_commands" in names and "wmrkit.analysis.classify" in names


@pytest.mark.parametrize(("name", "f"), FUNCTIONS, ids=[n for n, _ in FUNCTIONS])
@pytest.mark.parametrize("given", ["diff-drive", {"name": "x", "wheels": []}, None])
def test_a_name_where_a_robot_goes_is_named(name, f, given):
    with pytest.raises(ShapeError, match=r"^robot: expected a Robot \(wmrkit\.catalog\.load\(name\), "):
        _call(f, given)


def test_a_robot_still_passes_the_check():
    assert wmrkit.analysis.classify(catalog.load("diff-drive")).type == 2
