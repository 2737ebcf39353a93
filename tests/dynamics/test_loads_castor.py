"""Normal loads when the contacts move with the steering (castor units): the allocation-free least-norm solve of the
compiled kernel balances the weight about the centre of mass of body and castor unit (unique for three contacts)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from dynamics_robots import castor_robot

from wmrkit.dynamics.model import DynamicModel


@pytest.mark.parametrize("beta", [0.0, 1.4, 2.5, -2.0, math.pi])
def test_static_loads_with_a_castor_balance_the_weight_about_the_moving_centre_of_mass(beta):
    robot = castor_robot()
    model = DynamicModel.of(robot)
    loads = model.normal_loads([beta])
    body, caster = robot.body, robot.wheel("caster")
    # contacts: fixed wheels below their centres; the castor's contact trails its steering axis by d at angle beta
    contacts = np.array([robot.wheel("left").position, robot.wheel("right").position,
                         np.add(caster.position, caster.d * np.array([-math.sin(beta), math.cos(beta)]))])
    mass = body.mass + caster.mass
    com = (body.mass * np.asarray(body.com) + caster.mass * contacts[2]) / mass  # castor mass at its wheel centre
    assert loads.sum() == pytest.approx(mass * 9.81, rel=1e-12)
    np.testing.assert_allclose(loads @ contacts, mass * 9.81 * com, rtol=0, atol=1e-9)  # no moment about the CM
    g = np.vstack([np.ones(3), (contacts - com).T])  # three contacts: the balance alone fixes the loads
    np.testing.assert_allclose(loads, np.linalg.pinv(g) @ np.array([mass * 9.81, 0.0, 0.0]), rtol=1e-12, atol=1e-9)
