"""Friction coefficients of the linear law (7.59) as weights of the no-slip rows, and the WLS odometry model.

Each contact's slip ``v_slip,i`` (3.22) has a lateral component (row 0 of the wheel's rows, along the axle or
roller axis E_x) and a longitudinal one (row 1, the rolling direction E_y). The linear friction law (7.59)
``F_i = -diag(mu_x,i, mu_y,i) v_slip,i`` gives every row a coefficient; the weighted least squares (7.50)-(7.52)
scales each row by ``sqrt(mu)``. Only ratios matter (the WLS solution is invariant to scaling every ``mu``,
(7.67)); the default ``mu = 1`` on every row is the unweighted least squares of today's odometry (4.11).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace

import numpy as np

from .._shapes import as_reals, real_number
from ..errors import ShapeError, WmrkitError
from ..odometry.model import OdometryModel, frozen, odometry_model, solution_maps
from ..robot import Robot

#: Largest ratio of two friction coefficients of one robot: beyond ~1e20 the weighted rows (scaled by sqrt(mu))
#: swamp the others in double precision and the solution collapses; 1e12 keeps six digits of margin.
MAX_RATIO = 1e12


class SlipWeightError(WmrkitError, ValueError):
    """A friction coefficient that is not a finite number > 0, or names a wheel the robot lacks; ``wheels``: the
    two wheels of coefficients too far apart (:meth:`SlipWeights.row_mu`), else empty."""

    wheels: tuple[str, ...] = ()


@dataclass(frozen=True, slots=True)
class SlipWeights:
    """Linear friction coefficients (7.59) per wheel: ``wheel name -> (mu_lateral, mu_longitudinal)``.

    Units are any consistent force per slip speed [N s/m]; only ratios matter. Wheels not named get
    ``default``. Build with :meth:`uniform` or :meth:`of`; ``mu`` is a tuple of pairs so the value is hashable.
    """

    mu: tuple[tuple[str, float, float], ...] = ()
    default: tuple[float, float] = (1.0, 1.0)

    def __post_init__(self) -> None:
        """Every coefficient a finite number > 0 (zero or NaN weights gave a zero or NaN twist)."""
        for name, lat, lon in (*self.mu, ("default", *self.default)):
            for what, v in (("lateral", lat), ("longitudinal", lon)):
                if not (real_number(v) and v > 0):
                    raise SlipWeightError(f"friction coefficient of wheel '{name}' ({what}) must be a finite "
                                          f"number > 0, got {v!r}")

    @classmethod
    def of(cls, mu: Mapping[str, tuple[float, float]], default: tuple[float, float] = (1.0, 1.0)) -> SlipWeights:
        """From a mapping ``{wheel: (mu_lateral, mu_longitudinal)}``; :class:`SlipWeightError` naming the argument for
        anything else (``SlipWeights.of('1')`` raised a bare AttributeError) and for coefficients that are not real
        numbers (text, booleans: the Python API reads no units)."""
        if not isinstance(mu, Mapping) or not all(isinstance(k, str) for k in mu):
            raise SlipWeightError(f"mu: expected a mapping {{wheel name: (mu_lateral, mu_longitudinal)}}, such as "
                                  f"{{'left': (1.0, 0.5)}}, got {type(mu).__name__} {mu!r:.60}")
        return cls(tuple((k, *_pair(f"mu['{k}']", v)) for k, v in mu.items()), _pair("default", default))

    @classmethod
    def uniform(cls, lateral: float = 1.0, longitudinal: float = 1.0) -> SlipWeights:
        """The same coefficients on every wheel."""
        return cls.of({}, (lateral, longitudinal))

    @classmethod
    def checked(cls, weights: object, argument: str = "weights") -> SlipWeights:
        """`weights`, or the default weights for None; :class:`SlipWeightError` naming `argument` for anything else
        (a mapping raised "'dict' object has no attribute 'row_mu'")."""
        if weights is None:
            return cls()
        if not isinstance(weights, SlipWeights):
            raise SlipWeightError(f"{argument}: expected SlipWeights or None (SlipWeights.of({{wheel: (mu_lateral, "
                                  f"mu_longitudinal)}}) builds one), got {type(weights).__name__} {weights!r:.60}")
        return weights

    def of_wheel(self, name: str) -> tuple[float, float]:
        """``(mu_lateral, mu_longitudinal)`` of wheel `name`."""
        for n, lat, lon in self.mu:
            if n == name:
                return lat, lon
        return self.default

    def to_dict(self) -> dict:
        """JSON-ready: ``{"default": [lat, lon], "wheels": {name: [lat, lon]}}``."""
        return {"default": list(self.default), "wheels": {n: [lat, lon] for n, lat, lon in self.mu}}

    def row_mu(self, robot: Robot) -> np.ndarray:
        """The coefficient of every row of ``robot.constraint_matrix()`` ``(2 n_contacts,)`` (lateral, longitudinal
        alternate per contact element)."""
        names = set(robot.wheel_names)
        for n, _, _ in self.mu:
            if n not in names:
                raise SlipWeightError(f"friction coefficients given for wheel '{n}', which robot '{robot.name}' "
                                      f"lacks (wheels: {', '.join(robot.wheel_names)})")
        out, rows, wheels = [], [], []
        for w in robot.wheels:
            out += list(self.of_wheel(w.name)) * len(w.elements())
            rows += [f"{w.name} (lateral)", f"{w.name} (longitudinal)"] * len(w.elements())
            wheels += [w.name] * (2 * len(w.elements()))
        mu = np.array(out, dtype=float)
        if mu.size and float(mu.max()) > MAX_RATIO * float(mu.min()):  # Python floats: inf, not a numpy warning
            lo, hi = int(np.argmin(mu)), int(np.argmax(mu))
            err = SlipWeightError(f"friction coefficients of wheel {rows[lo]} ({mu[lo]:g}) and {rows[hi]} "
                                  f"({mu[hi]:g}) differ by more than a factor {MAX_RATIO:g}: the weighted least "
                                  "squares would lose the smaller rows to round-off (only ratios matter)")
            err.wheels = (wheels[lo], wheels[hi])
            raise err
        return mu


def _pair(argument: str, value: object) -> tuple[float, float]:
    """``(lateral, longitudinal)`` given as `argument`; a string, a sequence of another length and values that are
    not real numbers are refused (``"12"`` read as (1, 2), a third value dropped, ``("1", "2")`` and ``(True, 1)``
    read as numbers)."""
    if not isinstance(value, str | bytes) and isinstance(value, Sequence | np.ndarray) and len(value) == 2:
        try:
            pair = as_reals(value, argument)
        except ShapeError as err:
            raise SlipWeightError(str(err)) from None
        if pair.shape == (2,) and not any(isinstance(v, bool | np.bool_) for v in value):  # (True, 1) read as ints
            return float(pair[0]), float(pair[1])
    raise SlipWeightError(f"{argument}: expected a pair of friction coefficients (lateral, longitudinal), got "
                          f"{value!r:.60}")


def wls_model(robot: Robot, weights: SlipWeights | None = None, sensed=None) -> OdometryModel:
    """The sensed direct model solved by weighted least squares (7.50)-(7.52): WLS odometry for any robot.

    The same :class:`~wmrkit.odometry.model.OdometryModel` as :func:`~wmrkit.odometry.model.odometry_model`
    (so the same compiled pipeline, streaming and integration schemes run it), with every kept row scaled by
    ``sqrt(mu)`` of its wheel and direction. Without slip the sensors satisfy ``A dq = 0`` exactly and every
    weighting gives the same (exact) odometry.
    """
    weights = SlipWeights.checked(weights)
    base = odometry_model(robot, sensed)
    w = np.sqrt(weights.row_mu(robot)[base.rows])
    if not base.constant:
        return replace(base, row_weights=frozen(w))
    s, rm = solution_maps(robot, robot.beta, base.rows, base.cols, base.sensed, w)
    return replace(base, row_weights=frozen(w), solution=frozen(s),
                   residual_map=None if base.residual_map is None else frozen(rm))
