"""The forklift study (§7.5) against the dynamic model, and the J indices (7.78), (7.80)."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from wmrkit.cli.main import main
from wmrkit.odometry.integrators import integrate_increments
from wmrkit.slip.metrics import closure_error, j_closure, j_model


def test_j_model_is_the_mean_absolute_twist_error():
    a = np.zeros((4, 3))
    b = np.array([[0.1, 0, 0], [0, -0.2, 0], [0, 0, 0.3], [0, 0, 0]])
    assert math.isclose(j_model(a, b), 0.6 / 12)


def test_closure_index_of_a_circle_with_a_known_defect():
    """A full circle of radius 1 whose heading gains 0.1 rad: position error 0, heading error 0.1 over 2 pi + 0.1."""
    n = 1000
    inc = np.tile([2 * np.pi / n, 0.0, (2 * np.pi + 0.1) / n], (n, 1))
    poses = np.vstack([[0, 0, 0], integrate_increments([0, 0, 0], inc)])
    pos, head = closure_error(poses)
    assert head == pytest.approx(0.1 / (2 * np.pi + 0.1), rel=1e-9)
    exact = np.vstack([[0, 0, 0], integrate_increments([0, 0, 0], inc * [1, 1, 2 * np.pi / (2 * np.pi + 0.1)])])
    assert closure_error(exact)[0] < 1e-12 and pos > 0.01
    assert j_closure([poses, exact]) == pytest.approx((pos + head + sum(closure_error(exact))) / 4)


@pytest.fixture(scope="module")
def study(tmp_path_factory):
    import contextlib
    import io

    d = tmp_path_factory.mktemp("study")
    buf = io.StringIO()
    with contextlib.redirect_stdout(buf):
        assert main(["slip-study", "forklift", "--quick", "--json", "--report", str(d)]) == 0
    return json.loads(buf.getvalue()), d


def test_examples_rank_the_models_as_the_thesis(study):
    """J_MQE < J_MCD < J_WLS against the dynamic model (Table of §7.5.3), with the quick sweep's weights."""
    result, _ = study
    assert len(result["examples"]) == 2
    for e in result["examples"]:
        j = e["J"]
        assert j["MQE"] < j["MCD"] < j["WLS"]
        assert j["WLS"] < 0.05  # every model within a few cm/s of the dynamics


def test_study_output_and_figures(study):
    result, d = study
    assert set(result) >= {"examples", "paths", "sweep", "settings", "figures"}
    assert result["sweep"]["converged"] > 0.7 * result["sweep"]["points"]
    for name, run in result["paths"].items():
        if name not in ("mean_J_k", "optimised"):
            assert set(run["J_k"]) == {"WLS", "WLS (thesis k)", "FK1", "FK2", "differential"}
            assert all(0 <= v < 0.2 for v in run["J_k"].values())
    assert all((d / p.rsplit("/", 1)[-1]).exists() for p in result["figures"])
    opt = result["paths"]["optimised"]
    for name in ("WLS", "FK1", "FK2"):  # tuning never does worse than the thesis's values it starts from
        start = result["paths"]["mean_J_k"]["WLS (thesis k)" if name == "WLS" else name]
        assert opt[name]["J_k"] <= start + 1e-12
