"""A robot: a name and its wheels; the composite equations (3.20)-(3.23), batched over configurations.

The velocity vector ``q_dot`` of the slip form (3.21)-(3.22) is ordered: the body twist ``(vx, vy, omega)``,
then each wheel's joint rates in wheel order (``Robot.velocity_names``, e.g. ``left.spin``, ``caster.steer``).
The steering configuration ``beta`` is ordered as ``Robot.steer_names``: one angle per wheel whose type steers.
"""

from __future__ import annotations

import functools
import math
import os
from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING, Any, Literal

import numpy as np
from numpy.typing import ArrayLike

from ._shapes import as_angles, as_vectors, check_kind, readonly
from .couplings import Coupling, check_couplings
from .dynamics.mass import Body
from .errors import ShapeError, UnknownNameError
from .wheels import Wheel, WheelError, generic_wheel_jacobian, rotate_rows_to_robot

if TYPE_CHECKING:
    from .slip.settings import OdometrySettings

TWIST_NAMES = ("vx", "vy", "omega")


@dataclass(frozen=True, slots=True)
class Robot:
    """A wheeled robot: a name and an ordered tuple of wheels. Never mutated; change it with ``replace``."""

    name: str
    wheels: tuple[Wheel, ...]
    notes: str = ""
    couplings: tuple[Coupling, ...] = ()  # mechanical couplings between joints (wmrkit.couplings)
    body: Body | None = None  # mass properties of the vehicle* (wmrkit.dynamics.mass), None when not described
    odometry: OdometrySettings | None = None  # slip weights, Kalman noise, method (wmrkit.slip.settings)
    _hash: int = field(default=0, init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        _check_wheels(self)
        check_couplings(self)
        # Hashed once: derived arrays are cached per robot (keyed by it) and looked up on every batched call.
        object.__setattr__(self, "_hash", hash((self.name, self.wheels, self.notes, self.couplings, self.body,
                                                   self.odometry)))

    def __hash__(self) -> int:
        return self._hash

    def __reduce__(self) -> tuple:
        # rebuilt: the hash is this process's
        return (Robot, (self.name, self.wheels, self.notes, self.couplings, self.body, self.odometry))

    # ---- names -------------------------------------------------------------------------------------------
    @property
    def wheel_names(self) -> tuple[str, ...]:
        """Wheel names, in order."""
        return tuple(w.name for w in self.wheels)

    def wheel(self, name: str) -> Wheel:
        """The wheel called `name`, or :class:`UnknownNameError` listing the wheels."""
        for w in self.wheels:
            if w.name == name:
                return w
        raise UnknownNameError(f"robot '{self.name}' has no wheel '{name}' (wheels: {', '.join(self.wheel_names)})")

    @property
    def velocity_names(self) -> tuple[str, ...]:
        """Names of the columns of the slip form (3.22): ``vx, vy, omega`` then every wheel's rates."""
        return _velocity_names(self)

    @property
    def rate_names(self) -> tuple[str, ...]:
        """Names of the wheel joint rates (the velocity vector without the twist)."""
        return self.velocity_names[3:]

    @property
    def free_steering(self) -> tuple[str, ...]:
        """The steering rates no twist determines: a double wheel's (``wheel.steer``), which turns by rolling its
        two sub-wheels apart (3.24), (3.29); inputs of the inverse model besides the twist (its degree of
        steerability)."""
        return tuple(f"{w.name}.steer" for w in self.wheels if w.type == "double")

    @property
    def steer_names(self) -> tuple[str, ...]:
        """Wheels whose steering angle is a configuration variable, in the order of ``beta``."""
        return tuple(w.name for w in self.wheels if w.kind.steers)

    @property
    def beta(self) -> np.ndarray:
        """The described steering configuration, ``(n_steer,)`` [rad]."""
        return readonly(np.array([w.beta for w in self.wheels if w.kind.steers], dtype=float))

    @property
    def heading(self) -> np.ndarray:
        """The described steering configuration as headings (rolling directions, 0 = forward) ``(n_steer,)``."""
        return self.heading_of_beta(self.beta)

    def heading_of_beta(self, beta: ArrayLike) -> np.ndarray:
        """Headings of the steering wheels from the thesis's β: ``(..., n_steer) -> (..., n_steer)`` [rad]."""
        from .wheels import heading_from_beta

        beta = as_angles(beta, len(self.steer_names), "beta")
        return heading_from_beta(beta, _steer_delta(self))

    def steering(self, beta: ArrayLike | None = None, heading: ArrayLike | None = None) -> np.ndarray | None:
        """The thesis's β from either keyword: `beta` as is, `heading` converted; None when neither is given.

        Every function that takes a steering configuration accepts ``heading=`` (the users' angle, 0 = rolling
        forward) as well as ``beta=`` (the thesis's angle); giving both is an error.
        """
        if heading is None:
            return beta if beta is None else as_angles(beta, len(self.steer_names), "beta")
        if beta is not None:
            raise ShapeError("give the steering configuration as beta (thesis) or heading (rolling direction), "
                             "not both")
        return self.beta_of_heading(heading)

    def beta_of_heading(self, heading: ArrayLike) -> np.ndarray:
        """The thesis's β of the steering wheels from headings: ``(..., n_steer) -> (..., n_steer)`` [rad]."""
        from .wheels import beta_from_heading, heading_limit

        heading, delta = as_angles(heading, len(self.steer_names), "heading"), _steer_delta(self)
        far = ~(np.abs(heading) <= heading_limit(delta))  # as Wheel.with_heading refuses one
        if far.any():
            index = np.argwhere(far)[0]
            raise ShapeError(f"heading: {self.steer_names[index[-1]]}: {heading[tuple(index)]!r} rad is beyond "
                             f"+-{heading_limit(delta[index[-1]]):.10g} rad, where the thesis's beta (heading - "
                             "delta + 90 deg) of one sign reaches the limit of every angle (no angle to steer by)")
        return beta_from_heading(heading, delta)

    @property
    def actuated(self) -> tuple[str, ...]:
        """Actuated joints, qualified ``wheel.joint``."""
        return tuple(f"{w.name}.{j}" for w in self.wheels for j in w.actuated)

    @property
    def sensed(self) -> tuple[str, ...]:
        """Sensed joints, qualified ``wheel.joint``."""
        return tuple(f"{w.name}.{j}" for w in self.wheels for j in w.sensed)

    @property
    def row_wheels(self) -> np.ndarray:
        """The wheel (index into ``wheels``) of every row of :meth:`constraint_matrix`, ``(2 * n_contacts,)``."""
        return readonly(np.repeat(element_table(self).element_wheel, 2))

    def velocity_index(self, name: str) -> int:
        """Column of `name` in the velocity vector, or :class:`UnknownNameError`."""
        names = self.velocity_names
        if name in names:
            return names.index(name)
        raise UnknownNameError(f"robot '{self.name}' has no velocity '{name}' (velocities: {', '.join(names)})")

    # ---- changes -----------------------------------------------------------------------------------------
    def with_beta(self, beta: ArrayLike) -> Robot:
        """The same robot at steering configuration `beta` ``(n_steer,)``."""
        beta = as_angles(beta, len(self.steer_names), "beta")
        if beta.ndim != 1:
            raise ShapeError(f"beta: with_beta takes one configuration (n_steer,), got {beta.shape}; "
                             "batched functions take beta directly")
        angles = iter(beta.tolist())
        return replace(self, wheels=tuple(w.with_beta(next(angles)) if w.kind.steers else w for w in self.wheels))

    def with_steering(self, headings: Mapping[str, float]) -> Robot:
        """The same robot with the named wheels steered to the given headings [rad] (0 = rolling forward, +x).

        The users' convention (WPILib, ROS 2); :meth:`with_beta_angles` takes the thesis's β instead.
        """
        self._check_steers(headings, "headings")
        return replace(self, wheels=tuple(w.with_heading(headings[w.name]) if w.name in headings else w
                                          for w in self.wheels))

    def with_beta_angles(self, angles: Mapping[str, float]) -> Robot:
        """The same robot with the named wheels at the thesis's steering angles β [rad]."""
        self._check_steers(angles, "angles")
        return replace(self, wheels=tuple(w.with_beta(angles[w.name]) if w.name in angles else w for w in self.wheels))

    def _check_steers(self, names: Mapping[str, float], argument: str) -> None:
        if not isinstance(names, Mapping):  # a wheel's name was read letter by letter: "no wheel 'f'"
            raise ShapeError(f"{argument}: expected a mapping {{wheel name: angle [rad]}} such as "
                             f"{{'{self.steer_names[0] if self.steer_names else 'wheel'}': 0.5}}, got "
                             f"{type(names).__name__} {names!r:.60}")
        for name, value in names.items():
            if self.wheel(name).kind.steers is False:
                raise UnknownNameError(f"wheel '{name}' of robot '{self.name}' does not steer")
            if isinstance(value, list | tuple) or (isinstance(value, np.ndarray) and value.ndim > 0):
                raise ShapeError(f"{argument}: {name}: expected one angle [rad], got {type(value).__name__} "
                                 f"{value!r:.60}")

    # ---- composite equations -----------------------------------------------------------------------------
    def constraint_matrix(
        self, beta: ArrayLike | None = None, *, heading: ArrayLike | None = None,
        frame: Literal["roller", "robot"] = "roller",
    ) -> np.ndarray:
        """The slip matrix ``A`` of eq. (3.22): ``v_slip = A @ q_dot``; no slip is ``A @ q_dot = 0`` (3.23).

        ``(..., n_steer) -> (..., 2 * n_contacts, 3 + n_rates)``; columns named by ``velocity_names``. The
        steering configuration is the thesis's `beta` or the users' `heading` (see :meth:`steering`); default the
        described one.
        ``frame="roller"`` gives each wheel's rows along its roller axes (3.6), ``"robot"`` in the robot frame
        (3.5); the two differ by a rotation per wheel, so ranks, null spaces and least squares agree.
        """
        from ._constraint_kernel import fill_constraint_rows

        if frame not in ("roller", "robot"):
            raise ShapeError(f"frame must be 'roller' or 'robot', got {frame!r}")
        t = element_table(self)
        beta_e = element_beta(self, self.steering(beta, heading))  # (..., E)
        flat = beta_e.reshape(-1, t.n_elements)
        a = np.empty((flat.shape[0], t.n_elements, 2, 3 + t.n_rates))
        fill_constraint_rows(flat, t.l, t.alpha, t.d, t.delta, t.gamma, t.r, t.r_r, t.rate_map, a)
        a = a.reshape(*beta_e.shape, 2, 3 + t.n_rates)
        if frame == "robot":
            a = rotate_rows_to_robot(a, beta_e + t.delta + t.gamma)
        return a.reshape(*a.shape[:-3], 2 * t.n_elements, 3 + t.n_rates)

    def slip_velocity(self, q_dot: ArrayLike, beta: ArrayLike | None = None, *,
                      heading: ArrayLike | None = None) -> np.ndarray:
        """Slip of every contact along its roller axes, ``A @ q_dot`` (3.22). ``(..., k) -> (..., 2 n_contacts)``;
        `q_dot` finite (the rates of a twist within the query limit, 1e6 m/s, may pass 1e6 rad/s), its batch shape
        broadcast with the steering's."""
        from .kinematics.models import bounded

        q_dot = bounded(as_vectors(q_dot, 3 + element_table(self).n_rates, "q_dot"), self.velocity_names, "q_dot",
                        limit=math.inf)
        steering = self.steering(beta, heading)
        shape = (len(self.steer_names),) if steering is None else steering.shape
        try:
            np.broadcast_shapes(q_dot.shape[:-1], shape[:-1])
        except ValueError:
            raise ShapeError(f"q_dot {q_dot.shape} and the steering {shape}: their batch shapes (all but the last "
                             "axis) do not broadcast") from None
        with np.errstate(over="ignore", invalid="ignore"):  # finite rates near the largest float: refused below
            slip = (self.constraint_matrix(steering) @ q_dot[..., None])[..., 0]
        if not np.isfinite(slip).all():
            raise ShapeError("q_dot: the slip overflows (rates near the largest float)")
        return slip

    def jacobian_form(self, beta: ArrayLike | None = None, *,
                      heading: ArrayLike | None = None) -> tuple[np.ndarray, np.ndarray]:
        """The composite Jacobian form (3.20): ``I_bar @ twist_robot = J @ q_dot_w``.

        Returns ``(I_bar, J)`` of shapes ``(3 E, 3)`` and ``(..., 3 E, n_rates + E)``; ``q_dot_w`` is the
        wheel rates (as in ``rate_names``) followed by one copy of ``omega`` per contact (3.17)-(3.19).
        For one-element wheels J is block diagonal with the blocks (3.19). The steering configuration is the
        thesis's `beta` or the users' `heading` (see :meth:`steering`); default the described one.
        """
        t = element_table(self)
        beta_e = element_beta(self, self.steering(beta, heading))
        jac = generic_wheel_jacobian(beta_e, t.l, t.alpha, t.d, t.delta, t.gamma, t.r, t.r_r)  # (..., E, 3, 4)
        j_rates = jac[..., :3] @ t.rate_map  # (..., E, 3, n_rates)
        j_omega = jac[..., 3:] * np.eye(t.n_elements)[:, None, :]  # (..., E, 3, E)
        j = np.concatenate([j_rates, j_omega], axis=-1)
        j = j.reshape(*j.shape[:-3], 3 * t.n_elements, t.n_rates + t.n_elements)
        return np.tile(np.eye(3), (t.n_elements, 1)), j

    # ---- conversions -------------------------------------------------------------------------------------
    @classmethod
    def from_dict(cls, data: Mapping[str, Any], *, source: str = "<dict>") -> Robot:
        """A robot from a description mapping (the file format of ``docs/description-format.md``)."""
        from .description import robot_from_dict

        return robot_from_dict(data, source=source)

    def to_dict(self, *, thesis: bool = False) -> dict[str, Any]:
        """The description mapping, wheels as users write them (``position``, ``heading``) where exact, or with
        `thesis` in the thesis's ``l``, ``alpha``, ``beta``; ``Robot.from_dict(r.to_dict()) == r``."""
        from .description import robot_to_dict

        return robot_to_dict(self, thesis=thesis)

    @classmethod
    def from_file(cls, path: str | os.PathLike[str]) -> Robot:
        """A robot from a YAML (``.yaml``/``.yml``) or JSON (``.json``) description file."""
        from .description import load_robot_file

        return load_robot_file(path)

    def to_file(self, path: str | os.PathLike[str]) -> None:
        """Write the description to a YAML or JSON file (by extension); loading it gives this robot back."""
        from .description import save_robot_file

        save_robot_file(self, path)


def _check_wheels(robot: Robot) -> None:
    """A robot built in Python has wheels as a description has them: a non-empty tuple of :class:`Wheel` with
    distinct names (two wheels named 'left' gave the velocity 'left.spin' twice); a text name and notes and a
    :class:`Body` or None (a dict raised TypeError 'unhashable type', a name 5 was taken)."""
    for key, expected, ok in (("name", "a text", isinstance(robot.name, str)),
                              ("notes", "a text", isinstance(robot.notes, str)),
                              ("body", "a wmrkit.dynamics.mass.Body or None",
                               robot.body is None or isinstance(robot.body, Body))):
        if not ok:
            got = type(getattr(robot, key)).__name__
            raise WheelError(f"robot {robot.name!r:.40}: {key}: expected {expected}, got {got}")
    wheels = robot.wheels
    if not isinstance(wheels, tuple) or not wheels:
        raise WheelError(f"robot '{robot.name}': wheels: expected a non-empty tuple of Wheel, got "
                         f"{'()' if wheels == () else type(wheels).__name__}")
    names: set[str] = set()
    for i, wheel in enumerate(wheels):
        if not isinstance(wheel, Wheel):
            raise WheelError(f"robot '{robot.name}': wheels[{i}]: expected a Wheel, got {type(wheel).__name__}")
        if wheel.name in names:
            raise WheelError(f"robot '{robot.name}': wheels[{i}]: duplicate wheel name '{wheel.name}'")
        names.add(wheel.name)


@functools.lru_cache(maxsize=256)
def _velocity_names(robot: Robot) -> tuple[str, ...]:
    return TWIST_NAMES + tuple(n for w in robot.wheels for n in w.rate_names)


@functools.lru_cache(maxsize=256)
def _steer_delta(robot: Robot) -> np.ndarray:
    return readonly(np.array([w.delta for w in robot.wheels if w.kind.steers], dtype=float))


@dataclass(frozen=True, eq=False)
class ElementTable:
    """Per-contact-element parameters of a robot, as arrays (derived once per robot, read-only)."""

    l: np.ndarray
    alpha: np.ndarray
    beta_offset: np.ndarray
    d: np.ndarray
    delta: np.ndarray
    gamma: np.ndarray
    r: np.ndarray
    r_r: np.ndarray
    rate_map: np.ndarray  # (E, 3, n_rates)
    element_wheel: np.ndarray  # (E,) wheel index of each element
    steer_wheels: np.ndarray  # (n_steer,) wheel indices of the steering wheels
    beta_described: np.ndarray  # (N,)
    n_rates: int
    element_beta_fixed: np.ndarray  # (E,) element angle, the steering wheels' described beta left out
    element_steers: np.ndarray  # (E,) bool: the element follows a steering angle
    element_steer_index: np.ndarray  # (E,) index into beta of that angle (0 where it follows none)

    @property
    def n_elements(self) -> int:
        return len(self.l)


@functools.lru_cache(maxsize=256)
def element_table(robot: Robot) -> ElementTable:
    """The per-contact-element arrays of `robot` (3.8) that every batched kernel reads (cached per robot)."""
    rows, maps, owner = [], [], []
    n_rates = sum(len(w.kind.rates) for w in robot.wheels)
    start = 0
    for i, w in enumerate(robot.wheels):
        n = len(w.kind.rates)
        for e in w.elements():
            rows.append(e[:8])
            m = np.zeros((3, n_rates))
            m[:, start:start + n] = e.rate_map
            maps.append(m)
            owner.append(i)
        start += n
    cols = np.array(rows, dtype=float).reshape(-1, 8).T
    arrays = [readonly(np.ascontiguousarray(c)) for c in cols]
    steer_wheels = [i for i, w in enumerate(robot.wheels) if w.kind.steers]
    steers = np.array([i in steer_wheels for i in owner], dtype=bool)
    steer_index = np.array([steer_wheels.index(i) if i in steer_wheels else 0 for i in owner], dtype=int)
    fixed = np.where(steers, 0.0, np.array([robot.wheels[i].beta for i in owner], dtype=float)) + cols[2]
    return ElementTable(
        *arrays,
        rate_map=readonly(np.array(maps).reshape(-1, 3, n_rates)),
        element_wheel=readonly(np.array(owner, dtype=int)),
        steer_wheels=readonly(np.array(steer_wheels, dtype=int)),
        beta_described=readonly(np.array([w.beta for w in robot.wheels], dtype=float)),
        n_rates=n_rates,
        element_beta_fixed=readonly(fixed),
        element_steers=readonly(steers),
        element_steer_index=readonly(steer_index),
    )


def element_beta(robot: Robot, beta: ArrayLike | None) -> np.ndarray:
    """Absolute angle of every contact element's steering frame, ``(..., E)``, at the steering angles `beta`
    ``(..., n_steer)`` (the described ones when None)."""
    t = element_table(robot)
    described = t.beta_described[t.element_wheel] + t.beta_offset
    if beta is None:
        return described
    beta = as_vectors(beta, len(t.steer_wheels), "beta")
    if len(t.steer_wheels) == 0:
        return np.broadcast_to(described, (*beta.shape[:-1], len(described)))
    return np.where(t.element_steers, beta[..., t.element_steer_index], 0.0) + t.element_beta_fixed


#: How to build a :class:`Robot`, said where something else was given.
ROBOT_ADVICE = "wmrkit.catalog.load(name), Robot.from_file(path)"


def check_robot(robot: object, error: type[Exception] = ShapeError) -> None:
    """Raise `error` naming the argument unless `robot` is a :class:`Robot`: a catalog name given instead raised
    "'str' object has no attribute 'steering'" deep inside."""
    check_kind(robot, Robot, "robot", ROBOT_ADVICE, error)
