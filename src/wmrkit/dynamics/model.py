"""The dynamic model (thesis §7.2, Tables 7.1-7.2) of any described robot, generated from its description.

Generalized velocities ``nu`` (``DynamicModel.names``): the body twist ``(vx, vy, omega)`` in the robot frame, the
wheel rates of ``Robot.rate_names`` (the columns of the slip matrix (3.22)), then the steering rate of every
steerable wheel (``wheel.steer``: a degree of freedom with inertia and torque (7.24) that the slip matrix does not
see). Configuration: the pose, the steering angles β (the thesis's, ``Robot.steer_names`` order) and the wheel
angles. With the kinetic energy ``T = nu' M(beta) nu / 2`` of (7.17) the equations are the Lagrange equations (7.9)
in the body-fixed (Lagrange-Poincaré / Hamel) form, which for the twist read ``d/dt p = ad*_xi p + F`` (SE(2)):

    M(beta) nu' = tau + A(beta)' F_fric + b(beta, nu)          (7.11), (7.16), (7.21)-(7.26)

``A`` is ``Robot.constraint_matrix(beta)`` (frame Ē) with zero columns for the steerable steering rates, so
``v_slip = A nu`` and the virtual power of the contact forces is ``F' A nu`` (7.16); ``F_fric`` comes from each
wheel's tyre model (:mod:`.tyres`) on those slips, with normal loads from (7.64) generalised
(:meth:`DynamicModel.normal_loads`). R need not be at the centre of mass (the thesis puts it there, §7.2): the body
term is ``M_T |v + omega x c|^2 / 2 + I_T omega^2 / 2``. Castor units are bodies of their own with their CM at
the wheel centre (7.18)-(7.20), exact (no (7.21) approximation, ``docs/errata.md``).
"""

from __future__ import annotations

import functools
import math
import warnings
from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from .._shapes import as_angles, readonly, real_number
from ..couplings import gear_free
from ..errors import DescriptionError, ShapeError, WmrkitError
from ..kinematics.linkage_law import linkage_table
from ..robot import Robot, check_robot, element_table
from .linkages import LinkageWarning, coupling_basis, linkage_breach, reduced, unheld
from .mass import CASTOR_TYPES, Body, body_problem
from .tyres import Tyre

GRAVITY = 9.81


@dataclass(frozen=True, eq=False)
class DynamicModel:
    """A robot with mass properties and tyres, ready for the kernels. Build it with :meth:`of`.

    ``names`` (n,): the generalized velocities; ``contacts`` (E,): one name per contact point (``wheel`` or
    ``wheel.1``/``wheel.2`` for double wheels); ``steer_columns`` (n_steer,): column of each steering rate;
    ``tyres`` (E,): the tyre of each contact; ``gravity`` [m/s^2]. The methods take one state at a time (finite
    numbers; only :meth:`slip_matrix` is batched).
    """

    robot: Robot
    names: tuple[str, ...]
    contacts: tuple[str, ...]
    steer_columns: tuple[int, ...]
    tyres: tuple[Tyre, ...]
    gravity: float
    pack: tuple  # arrays of the compiled kernels (see wmrkit.dynamics._kernels)

    @classmethod
    def of(cls, robot: Robot, tyre: Tyre | str | None = None, *, gravity: float = GRAVITY) -> DynamicModel:
        """The model of `robot`; `tyre` (a :class:`Tyre` or a model name) replaces every wheel's own tyre.

        Wheels without a tyre get ``pacejka`` (appendix 7.A1). Raises :class:`WmrkitError` when the description
        lacks what the dynamics needs (``body``, a spin inertia, a roller or castor-steering inertia). A ``linkage``
        the dynamics do not hold (no ``law`` and none to default to) gives a
        :class:`~wmrkit.dynamics.linkages.LinkageWarning` each (:func:`~wmrkit.dynamics.linkages.unheld`).
        """
        check_robot(robot, TypeError)  # a catalog name raised "'str' object has no attribute 'body'"
        if isinstance(tyre, str):
            tyre = Tyre.of(tyre)
        elif not (tyre is None or isinstance(tyre, Tyre)):
            raise TypeError(f"tyre: expected a Tyre, a tyre model's name or None, got {type(tyre).__name__}")
        if not (real_number(gravity) and 0 < gravity < math.inf):  # NaN included; "9.81" was read as a number
            raise ShapeError(f"gravity: expected a finite number > 0 m/s^2, got {gravity!r}")
        model = _build(robot, tyre, float(gravity))
        for message in unheld(robot):  # here, not in the cached _build: every model built says it
            warnings.warn(message, LinkageWarning, stacklevel=2)
        return model

    @property
    def n(self) -> int:
        """Number of generalized velocities."""
        return len(self.names)

    def is_actuated(self, column: int) -> bool:
        """Whether generalized velocity `column` is a joint its wheel's motors drive (``actuated`` in the
        description: ``spin``, ``steer``, a double wheel's ``spin1``/``spin2``)."""
        wheel, _, joint = self.names[column].partition(".")
        return bool(joint) and joint in self.robot.wheel(wheel).actuated

    @property
    def body(self) -> Body:
        """The robot's mass properties."""
        return self.robot.body  # type: ignore[return-value]

    def velocity(self, twist: ArrayLike, rates: ArrayLike | None = None) -> np.ndarray:
        """A velocity vector ``(n,)`` from a twist and the other velocities (default 0)."""
        nu = np.zeros(self.n)
        nu[:3] = _one(twist, 3, "twist")
        if rates is not None:
            nu[3:] = _one(rates, self.n - 3, "rates")
        return nu

    def slip_matrix(self, beta: ArrayLike | None = None) -> np.ndarray:
        """``A (..., 2E, n)``: :meth:`Robot.constraint_matrix` (frame Ē), zero columns for steerable steering rates."""
        a = self.robot.constraint_matrix(beta)  # batched (..., n_steer) as the robot's
        return readonly(np.concatenate([a, np.zeros((*a.shape[:-1], self.n - a.shape[-1]))], axis=-1))

    def mass_matrix(self, beta: ArrayLike | None = None) -> np.ndarray:
        """Mass matrix ``M (n, n)`` of the kinetic energy (7.17) at steering angles `beta`."""
        from ._kernels import mass_matrix

        m, dm = np.zeros((self.n, self.n)), np.zeros((len(self.steer_columns), self.n, self.n))
        mass_matrix(self._beta(beta), self.pack, self.n, m, dm)
        return readonly(m)

    def kinetic_energy(self, beta: ArrayLike | None, nu: ArrayLike) -> float:
        """``T = nu' M nu / 2`` [J] (7.17)."""
        nu = _one(nu, self.n, "nu")
        return float(0.5 * nu @ self.mass_matrix(beta) @ nu)

    def normal_loads(self, beta: ArrayLike | None = None, nu: ArrayLike | None = None,
                     acceleration: ArrayLike | None = None) -> np.ndarray:
        """Normal loads ``(E,)`` [N], (7.64) generalised to any contacts (least-norm: equal-spring suspension).

        `acceleration` is ``d nu / dt`` (n,) (default 0: the static loads, as MCD/WLS use; MQE passes the
        centripetal state through `nu`). Load transfer uses ``com_height``; the wheels' spin accelerations
        enter through their angular momentum (the thesis's ``tau_r`` terms, corrected in ``docs/errata.md``).
        """
        from ._kernels import normal_loads

        out = np.zeros(len(self.contacts))
        nu = np.zeros(self.n) if nu is None else _one(nu, self.n, "nu")
        acc = np.zeros(self.n) if acceleration is None else _one(acceleration, self.n, "acceleration")
        normal_loads(self._beta(beta), nu, acc, self.pack, out)
        return readonly(out)

    def contact_forces(self, beta: ArrayLike | None, nu: ArrayLike, loads: ArrayLike | None = None) -> np.ndarray:
        """Tyre forces ``(E, 2)`` [N] (lateral, longitudinal; frame Ē) at velocities `nu` (default: static loads)."""
        from ._kernels import contact_forces

        nu = _one(nu, self.n, "nu")
        e = len(self.contacts)
        if loads is None:
            loads = self.normal_loads(beta)
        else:
            loads = _one(loads, e, "loads")
            if not (loads >= 0).all():
                raise ShapeError(f"loads: expected normal loads >= 0 N, got {loads.tolist()}")
        f, g, vw = np.zeros((e, 2)), np.zeros((e, 2, 2)), np.zeros(e)
        contact_forces(np.array(self.slip_matrix(beta)), nu, self.pack, np.array(loads, dtype=float),
                       f, g, vw, False)
        return readonly(f)

    def accelerations(self, beta: ArrayLike | None, nu: ArrayLike, torques: ArrayLike | None = None,
                      forces: ArrayLike | None = None) -> np.ndarray:
        """``d nu / dt`` ``(n,)`` from the equations of motion, for given contact `forces` ``(E, 2)`` or flat
        ``(2E,)`` (default: the tyres at static loads) and generalized `torques` ``(n,)`` (default 0)."""
        from ._kernels import bias, mass_matrix

        beta = self._beta(beta)
        nu = _one(nu, self.n, "nu")
        e = len(self.contacts)
        f = self.contact_forces(beta, nu) if forces is None else np.asarray(forces, dtype=float)
        f = _one(f.reshape(e, 2) if f.shape == (2 * e,) else f, e, "forces", 2)
        tau = np.zeros(self.n) if torques is None else _one(torques, self.n, "torques")
        m, dm = np.zeros((self.n, self.n)), np.zeros((len(self.steer_columns), self.n, self.n))
        mass_matrix(beta, self.pack, self.n, m, dm)
        b = np.zeros(self.n)
        bias(nu, nu[list(self.steer_columns)].copy(), m, dm, self.pack[5], self.pack[6], b)
        rhs = tau + self.slip_matrix(beta).T @ f.reshape(-1) + b
        if self.pack[16].shape[1] == 0:
            return readonly(np.linalg.solve(m, rhs))
        breach = linkage_breach(self, beta, nu)
        if breach:
            raise WmrkitError(f"beta, nu: {breach}: the dynamics hold the linkage")
        t, c = self._basis(beta, nu)  # held gears and linkages: nu' = T p' + c
        return readonly(t @ np.linalg.solve(t.T @ m @ t, t.T @ (rhs - m @ c)) + c)

    def steering_inertia(self, held: Iterable[int] = ()) -> np.ndarray:
        """Inertia [kg m^2] that each steering joint's servo moves at the described configuration ``(n_steer,)``.

        The least kinetic energy ``nu' M nu`` (7.17) over the motions with unit steering rate in which the wheels
        roll without slip (``A nu = 0``) and the columns `held` (the other servoed joints) stay at rest. A
        steerable wheel turns alone (its ``inertia.steer``); a double wheel whose spins are held turns the body
        about its pivot (``I + m x^2`` and more); where the constraints lock the joint (no such motion: the tyres
        would have to slip) it is the wheel's own ``inertia.steer``. The motions hold the gears (``gear_basis``):
        the joints geared to a steering joint turn with it, their inertias reflected through the ratios, and holding
        one joint of a gear holds the whole gear.
        """
        from scipy.linalg import null_space

        held = sorted(set(held))
        bad = [j for j in held if not (isinstance(j, int | np.integer) and 3 <= j < self.n)]
        if bad:
            raise ShapeError(f"held: expected joint columns of model.names (3 to {self.n - 1}), got {bad}")
        t = self._basis(self.robot.beta)[0]  # the motions the couplings allow
        a, m = self.slip_matrix() @ t, self.mass_matrix()
        out = np.zeros(len(self.steer_columns))
        own = [w.steer_inertia for w in self.robot.wheels if w.kind.steers]
        for k, c in enumerate(self.steer_columns):
            basis = t @ null_space(np.vstack([a, t[[j for j in held if j != c]]]))
            g = basis[c]
            if g @ g < 1e-18:  # locked: no rolling motion turns it
                out[k] = own[k]
                continue
            out[k] = 1.0 / float(g @ np.linalg.solve(basis.T @ m @ basis, g))
        return readonly(out)

    def _basis(self, beta: ArrayLike, nu: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
        """``(T (n, p), c (n,))``: the motions the gears and linkages allow at steering angles `beta`, ``nu = T p``,
        and the linkages' velocity-product acceleration at velocities `nu` (``nu' = T p' + c``; 0 without `nu`)."""
        if self.pack[16].shape[1] == 0:
            return np.eye(self.n), np.zeros(self.n)
        columns = list(self.steer_columns)
        return reduced(self.pack[17], self.pack[16], lambda c: float(beta[columns.index(c)]), nu)

    def _beta(self, beta: ArrayLike | None) -> np.ndarray:
        if beta is None:
            return np.array(self.robot.beta, dtype=float)
        return _one(as_angles(beta, len(self.steer_columns), "beta"), len(self.steer_columns), "beta")


def _one(x: ArrayLike, size: int, name: str, columns: int | None = None) -> np.ndarray:
    """`x` as a writable float array (one compiled signature) of shape ``(size,)`` (or ``(size, columns)``) with
    finite entries, else :class:`ShapeError` naming `name` (the model's methods take one state at a time)."""
    a = np.array(x, dtype=float)
    shape = (size,) if columns is None else (size, columns)
    if a.shape != shape:
        raise ShapeError(f"{name}: expected shape {shape}, one state at a time, got {a.shape}")
    if not np.isfinite(a).all():
        raise ShapeError(f"{name}: expected finite numbers, got {a.tolist()}")
    return a


@functools.lru_cache(maxsize=64)
def _build(robot: Robot, tyre: Tyre | None, gravity: float) -> DynamicModel:
    body = robot.body
    if body is None:
        raise _located(robot, ("body",), "the robot has no mass properties: add a 'body: {mass, inertia, com, "
                       "com_height}' section to its description (docs/dynamics.md)")
    problem = body_problem(body)
    if problem:
        raise WmrkitError(f"robot '{robot.name}': {problem}")
    t = element_table(robot)
    names = list(robot.velocity_names)
    steer_cols = []
    for w in robot.wheels:
        if not w.kind.steers:
            continue
        if "steer" in w.kind.rates:
            steer_cols.append(names.index(f"{w.name}.steer"))
        else:
            names.append(f"{w.name}.steer")
            steer_cols.append(len(names) - 1)
    n, n_el = len(names), t.n_elements
    diag_i = np.zeros(n)
    for c, name in enumerate(names[3:], start=3):
        wheel, joint = name.split(".")
        w = robot.wheel(wheel)
        if joint.startswith("spin"):
            diag_i[c] = _need(w.spin_inertia, robot, wheel, "spin")
        elif joint == "roller":
            diag_i[c] = _need(w.roller_inertia, robot, wheel, "roller")
    steer_kind, steer_prm = [], []
    for w in robot.wheels:
        if w.kind.steers:
            castor = w.type in CASTOR_TYPES
            steer_kind.append(1 if castor else 0)
            i_s = _need(w.steer_inertia, robot, w.name, "steer")
            steer_prm.append((i_s, w.mass if castor else 0.0, w.l, w.alpha, w.d if castor else 0.0))
    tyres_e = tuple(tyre or robot.wheels[i].tyre or Tyre.of("pacejka") for i in t.element_wheel)
    el = np.column_stack([t.l, t.alpha, t.d, t.delta, t.gamma, t.r, t.r_r, t.element_beta_fixed,
                          [robot.wheels[i].spin_inertia for i in t.element_wheel],
                          [robot.wheels[i].roller_inertia for i in t.element_wheel]])
    el_steer = np.where(t.element_steers, t.element_steer_index, -1).astype(np.int64)
    carry = np.zeros(n)
    carry[:3] = 1.0
    carry[steer_cols] = 1.0
    moving = bool(np.any(t.element_steers & (np.abs(t.d) > 0)))
    geo = np.ones((3, n_el))
    geo[1] = t.l * np.cos(t.alpha) - t.d * np.sin(t.element_beta_fixed) - body.com[0]  # moving: recomputed
    geo[2] = t.l * np.sin(t.alpha) + t.d * np.cos(t.element_beta_fixed) - body.com[1]
    pack = (np.array(el, dtype=float, order="C"), el_steer, np.array(t.rate_map, dtype=float, order="C"),
            np.array([ty.kind.code for ty in tyres_e], dtype=np.int64), np.array([ty.vector() for ty in tyres_e]),
            np.array(steer_cols, dtype=np.int64), np.array(steer_kind, dtype=np.int64),
            np.array(steer_prm, dtype=float).reshape(-1, 5), diag_i, carry,
            np.array([body.mass, body.inertia, *body.com, body.com_height, gravity]),
            np.array(np.linalg.pinv(geo), order="C"), np.array([0 if moving else 1], dtype=np.int64),
            *_differentials(robot, names),
            np.zeros(n_el),  # 15: the contacts loaded at rest (lift-off: _integrate.assemble), set below
            *_coupling_pack(robot, tuple(names)))  # 16, 17: the motions the couplings allow, the linkages
    from ._kernels import normal_loads

    static = np.zeros(n_el)  # from the whole pack (the loads read none of 15-17): one compiled normal_loads
    normal_loads(np.array(robot.beta, dtype=float), np.zeros(n), np.zeros(n), pack, static)
    pack[15][:] = static > 0
    contacts = contact_names(robot)
    spread = np.linalg.svd(geo, compute_uv=False)
    if len(spread) < 3 or spread[2] <= 1e-9 * spread[0]:  # (7.64) has no solution: a pitch moment would be left
        raise _located(robot, ("wheels",), f"the contacts of its wheels ({', '.join(contacts)}) lie on one line, "
                       "so nothing holds the body up about that line and the normal loads (7.64) cannot balance it; "
                       "add a wheel (a castor) off that line")
    weight = (body.mass + sum(prm[1] for prm in steer_prm)) * gravity
    if gravity > 0 and static.sum() > weight * (1 + 1e-9):  # a load below 0 was clipped: no balance at rest
        unloaded = [c for c, f in zip(contacts, static, strict=True) if f == 0.0]
        raise _located(robot, ("body", "com"), f"the robot's centre of mass ({list(body.com)} m) is not supported by "
                       f"its wheels: at rest the normal loads (7.64) would pull {', '.join(unloaded)} down (negative), "
                       "so the robot tips over; move body.com inside the wheels' contacts")
    return DynamicModel(robot, tuple(names), tuple(contacts), tuple(steer_cols), tyres_e, gravity, pack)


def contact_names(robot: Robot) -> list[str]:
    """One name per contact point (``wheel``; ``wheel.1``, ``wheel.2`` for the contacts of a double wheel)."""
    names = []
    for w in robot.wheels:
        k = len(w.elements())
        names.extend([w.name] if k == 1 else [f"{w.name}.{j + 1}" for j in range(k)])
    return names


def gear_basis(robot: Robot, names: tuple[str, ...]) -> np.ndarray:
    """``T (n, p)``: the velocities the ``gear`` couplings allow are ``nu = T p``, a column per joint in no gear and
    one per gear (its ratios, ``q_j = ratio_j u``; :func:`wmrkit.couplings.gear_free`); ``(n, 0)`` without a gear.
    A gear is a holonomic constraint between joint angles; the dynamics hold it in these reduced coordinates,
    ``T' M T p' = T' rhs``: torques on any of its joints act on the whole chain, its inertias reflect through the
    ratios, and the constraint force does no work."""
    if not any(c.kind == "gear" for c in robot.couplings):
        return np.zeros((len(names), 0))
    return np.ascontiguousarray(gear_free(robot.couplings, names, ())[0], dtype=float)


def _coupling_pack(robot: Robot, names: tuple[str, ...]) -> tuple[np.ndarray, np.ndarray]:
    """``(basis (n, p), linkages (L, 10))``: :func:`gear_basis` less the linkages' followers, whose rows the
    integrators fill per state, and the linkage table (:mod:`.linkages`); ``(n, 0)`` without gear or linkage."""
    table = linkage_table(robot, names)
    return coupling_basis(gear_basis(robot, names), table, len(names)), table


def _differentials(robot: Robot, names: list[str]) -> tuple[np.ndarray, np.ndarray]:
    """Per velocity column, the differential coupling it belongs to (-1: none) and its ratio there: the wheel-rate
    servos of those columns act as one motor on the carrier ``sum(ratio_j q_j')``, its torque split by the ratios
    (an open differential: equal torques, the speed difference left to the tyres; ``wmrkit.couplings``)."""
    group, ratio = np.full(len(names), -1, dtype=np.int64), np.zeros(len(names))
    for k, c in enumerate(c for c in robot.couplings if c.kind == "differential"):
        for joint, r in zip(c.joints, c.ratios, strict=True):
            group[names.index(joint)], ratio[names.index(joint)] = k, r
    return group, ratio


def _need(value: float, robot: Robot, wheel: str, joint: str) -> float:
    """`value`, the inertia [kg m^2] of `wheel`'s `joint` (spin, steer or roller), which the dynamics needs > 0."""
    if value <= 0:
        raise _located(robot, ("wheels", robot.wheel_names.index(wheel), "inertia", joint),
                       f"wheel '{wheel}' needs 'inertia.{joint}' > 0 kg m^2 for the dynamics (docs/dynamics.md)",
                       wheel)
    return value


def _located(robot: Robot, loc: tuple[str | int, ...], message: str, wheel: str | None = None) -> DescriptionError:
    """What the dynamics lacks in `robot`'s description, at field `loc` of it: placed in the robot's file by the
    command line (``cli._common.dynamic_model``); ``robot 'NAME': FIELD: message`` in Python."""
    return DescriptionError(message, source=f"robot '{robot.name}'", loc=loc, wheel=wheel)
