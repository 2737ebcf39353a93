"""Robots with mass properties for the dynamics tests (imported by the test modules)."""

from __future__ import annotations

import math

import numpy as np

from wmrkit import Robot


def tricycle(beta3: float = 0.0, tyre: str | dict = "pacejka") -> Robot:
    """The forklift in the thesis's ch. 7 frame (7.60): x lateral (right), y forward, R at the drive-axle middle."""
    return Robot.from_dict({
        "name": "tricycle-ch7",
        "body": {"mass": 2500, "inertia": 1500, "com": [0, -0.45], "com_height": 0.7},
        "wheels": [
            {"name": "w1", "type": "fixed", "position": [0.45, 0], "beta": 0, "r": 0.23, "actuated": ["spin"],
             "inertia": {"spin": 1.0}, "tyre": tyre},
            {"name": "w2", "type": "fixed", "position": [-0.45, 0], "beta": 0, "r": 0.23, "actuated": ["spin"],
             "inertia": {"spin": 1.0}, "tyre": tyre},
            {"name": "w3", "type": "steerable", "position": [0, -1.35], "beta": beta3, "r": 0.23,
             "actuated": ["steer"], "inertia": {"spin": 1.5, "steer": 0.8}, "tyre": tyre},
        ],
    })


def castor_robot(tyre: dict | str = "dugoff") -> Robot:
    """A differential robot with a heavy castor (its CM moves with the steering angle) and an off-centre CM."""
    return Robot.from_dict({
        "name": "castor-bot",
        "body": {"mass": 20, "inertia": 1.2, "com": [-0.08, 0.02], "com_height": 0.15},
        "wheels": [
            {"name": "left", "type": "fixed", "position": [0, 0.2], "beta": "90 deg", "r": 0.08,
             "actuated": ["spin"], "inertia": {"spin": 0.004}, "tyre": tyre},
            {"name": "right", "type": "fixed", "position": [0, -0.2], "beta": "90 deg", "r": 0.08,
             "actuated": ["spin"], "inertia": {"spin": 0.004}, "tyre": tyre},
            {"name": "caster", "type": "castor", "position": [-0.3, 0], "d": 0.06, "beta": "80 deg", "r": 0.04,
             "inertia": {"spin": 0.0005, "steer": 0.002}, "mass": 1.5, "tyre": tyre},
        ],
    })


def double_unit_robot(steer_range: list | None = None, actuated: tuple = ("spin1", "spin2")) -> Robot:
    """A double wheel (a differential steering unit) in front, two castors behind (an AGV layout)."""
    castor = {"type": "castor", "beta": "90 deg", "d": 0.05, "r": 0.05, "inertia": {"spin": 0.002, "steer": 0.001},
              "tyre": {"model": "dugoff", "cs": 2000, "calpha": 1500, "mu": 0.8}}
    drive = {"name": "drive", "type": "double", "position": [0.3, 0], "heading": 0, "b": 0.06, "r": 0.08,
             "actuated": list(actuated), "sensed": ["steer", "spin1", "spin2"],
             "inertia": {"spin": 0.01, "steer": 0.05},
             "tyre": {"model": "dugoff", "cs": 2000, "calpha": 1500, "mu": 0.8}}
    if steer_range is not None:
        drive["steer_range"] = steer_range
    return Robot.from_dict({
        "name": "double-unit", "body": {"mass": 50, "inertia": 2.0, "com": [0, 0], "com_height": 0.2},
        "wheels": [drive, {"name": "left", "position": [-0.3, 0.2], **castor},
                   {"name": "right", "position": [-0.3, -0.2], **castor}],
    })


def linked_car(linkage: bool = True, front_heading: float = 0.0, tyre: dict | str = "dugoff") -> Robot:
    """A small car (wheelbase 0.6 m, track 0.4 m, origin at the rear axle's middle): fixed rear wheels, steerable
    front wheels at Ackermann headings for `front_heading` [rad] of the left one, held by a ``linkage``."""
    wheelbase, half = 0.6, 0.2
    icr = half + wheelbase / math.tan(front_heading) if front_heading else math.inf  # the ICR's y on the rear axle
    right = math.atan2(wheelbase, icr + half) if front_heading else 0.0
    wheel = {"r": 0.1, "tyre": tyre}
    front = {**wheel, "type": "steerable", "actuated": ["steer"], "inertia": {"spin": 0.01, "steer": 0.05}}
    data = {
        "name": "linked-car",
        "body": {"mass": 30, "inertia": 1.5, "com": [0.25, 0.0], "com_height": 0.2},
        "wheels": [
            {**wheel, "name": "rl", "type": "fixed", "position": [0, half], "heading": 0, "actuated": ["spin"],
             "inertia": {"spin": 0.02}},
            {**wheel, "name": "rr", "type": "fixed", "position": [0, -half], "heading": 0, "actuated": ["spin"],
             "inertia": {"spin": 0.02}},
            {**front, "name": "fl", "position": [wheelbase, half], "heading": f"{front_heading} rad"},
            {**front, "name": "fr", "position": [wheelbase, -half], "heading": f"{right} rad"},
        ],
    }
    if linkage:
        data["couplings"] = [{"kind": "linkage", "joints": ["fl.steer", "fr.steer"]}]
    return Robot.from_dict(data)


def least_energy_inertia(model, rows, c):
    """The inertia a servo on column `c` moves, by another method than ``steering_inertia``'s null space: the
    KKT system of ``min nu' M nu`` subject to ``rows nu = 0`` and ``nu_c = 1``; returns ``nu* ' M nu*`` (twice the
    kinetic energy (7.17) of that motion, from ``model.kinetic_energy``) and the motion ``nu*``."""
    m = model.mass_matrix()
    con = np.vstack([rows, np.eye(model.n)[c]])
    kkt = np.block([[2 * m, con.T], [con, np.zeros((len(con), len(con)))]])
    rhs = np.zeros(len(kkt))
    rhs[-1] = 1.0
    nu = np.linalg.lstsq(kkt, rhs, rcond=None)[0][:model.n]
    return 2 * model.kinetic_energy(None, nu), nu


def frictionless_coast(model, s0: np.ndarray, periods: int = 10):
    """The states every 0.1 s of `model` (frozen tyres) coasting without torque from `s0` (rk4, 1e-4 s steps), each
    with its kinetic energy: the checks that a constraint does no work."""
    from wmrkit.dynamics.simulate import Inputs, Stepper

    stepper = Stepper(model, s0.copy(), step=1e-4, method="rk4", allow_lift_off=True)
    steer, n = list(model.steer_columns), model.n
    for _ in range(periods):
        s = stepper.advance(Inputs.torques_only(model, [0.0], {}), 0.1)
        yield s, model.kinetic_energy(s[steer], s[n:])
