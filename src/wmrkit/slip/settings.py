"""Slip weights and Kalman noise in robot descriptions: the optional ``odometry`` block and per-wheel ``slip``.

A description may say how ``wmrkit odometry`` estimates the robot's motion (``docs/description-format.md``)::

    odometry:
      method: wls                 # exact | rk2 | euler | paper002 (no-slip model) | wls | fk1 | fk2
      scheme: exact               # integration of the estimated twists (wls, fk1, fk2)
      slip: {lateral: 1, longitudinal: 1}                  # friction coefficients (7.59) of the wheels below
      noise: {process: 1, lateral: 1, longitudinal: 1, period: 10 ms}   # FK1/FK2 noise (7.77): k13 per nominal
                                  # sample period T (default: the log's) and row std-devs [m/s]
    wheels:
      - name: right_drive
        ...
        slip: {lateral: 1, longitudinal: 0.0032, noise: {lateral: 0.396, longitudinal: 3.57}}

Everything is optional. The friction coefficients weight the no-slip rows in WLS (only their ratios matter); the
noise sets the Kalman filters' ``Q`` and ``R``. Command-line options override the description. Validated when the
description is loaded (:mod:`wmrkit.description` calls :func:`settings_from_dict` with its located-error checker)
and kept as ``Robot.odometry``; :func:`settings_to_dict` writes the block (``Robot.to_dict``, ``wmrkit calibrate``).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from ..errors import WmrkitError, field_path

#: The values of ``odometry.method``: the no-slip model's integration schemes, then the slip-aware estimators.
METHODS = ("exact", "rk2", "euler", "paper002", "wls", "fk1", "fk2")
SCHEMES = ("exact", "rk2", "euler", "paper002")
BLOCK_FIELDS = ("method", "scheme", "slip", "noise")


@dataclass(frozen=True, slots=True)
class OdometrySettings:
    """What a description says about its odometry; every field None (or empty) when not said.

    ``slip``: default ``(mu_lateral, mu_longitudinal)``; ``wheel_slip``: ``((wheel, lateral, longitudinal), ...)``;
    ``noise``: default ``(process, lateral, longitudinal)``; ``wheel_noise``: ``((wheel, lateral, longitudinal), ...)``;
    ``period``: the nominal sample period T [s] of the process noise.
    """

    method: str | None = None
    scheme: str | None = None
    slip: tuple[float, float] | None = None
    wheel_slip: tuple[tuple[str, float, float], ...] = ()
    noise: tuple[float, float, float] | None = None
    wheel_noise: tuple[tuple[str, float, float], ...] = ()
    period: float | None = None

    def weights(self):
        """The WLS friction coefficients as :class:`~wmrkit.slip.weights.SlipWeights` (unit when not said)."""
        from .weights import SlipWeights

        return SlipWeights.of({n: (a, b) for n, a, b in self.wheel_slip}, self.slip or (1.0, 1.0))

    def kalman_noise(self):
        """The FK1/FK2 noise as :class:`~wmrkit.slip.kalman.KalmanNoise` (unit when not said)."""
        from .kalman import KalmanNoise

        return KalmanNoise(*(self.noise or (1.0, 1.0, 1.0)), self.wheel_noise, self.period)


def settings_from_dict(data: Mapping[str, Any], check: Any) -> OdometrySettings:
    """The odometry settings of a description mapping; errors located by `check` (a ``FieldReader``)."""
    block = data.get("odometry", {})
    loc: tuple[str | int, ...] = ("odometry",)
    if not isinstance(block, Mapping):
        check.fail("must be a mapping {method, scheme, slip: {lateral, longitudinal}, noise: {process, lateral, "
                   "longitudinal, period}}", loc)
    check.reject_unknown(block, BLOCK_FIELDS, loc)
    method = _choice(block, "method", METHODS, check, loc)
    scheme = _choice(block, "scheme", SCHEMES, check, loc)
    slip = _pair(block["slip"], check, (*loc, "slip"), ("noise",)) if "slip" in block else None
    noise = period = None
    if "noise" in block:
        item = block["noise"]
        if not isinstance(item, Mapping):
            check.fail("must be a mapping {process, lateral, longitudinal} of standard deviations [m/s] and the "
                       "nominal sample period of process [s]", (*loc, "noise"))
        check.reject_unknown(item, ("process", "lateral", "longitudinal", "period"), (*loc, "noise"))
        noise = tuple(_positive(item.get(k, 1.0), check, (*loc, "noise", k))
                      for k in ("process", "lateral", "longitudinal"))
        if "period" in item:
            period = _period(item["period"], check, (*loc, "noise", "period"))
    wheel_slip, wheel_noise = [], []
    noise_at = [(*loc, "noise")] if noise is not None else []
    for i, item in enumerate(data.get("wheels", [])):
        if not isinstance(item, Mapping) or "slip" not in item:
            continue
        where = ("wheels", i, "slip")
        name = str(item.get("name"))
        if _has_coefficients(item):  # else {noise: ...} alone: the wheel's Kalman noise, the default coefficients
            wheel_slip.append((name, *_pair(item["slip"], check, where, ("noise",))))
        if "noise" in item["slip"]:
            wheel_noise.append((name, *_pair(item["slip"]["noise"], check, (*where, "noise"), ())))
            noise_at.append((*where, "noise"))
    settings = OdometrySettings(method, scheme, slip, tuple(wheel_slip), noise, tuple(wheel_noise),  # type: ignore[arg-type]
                                period)
    _check_slip_spread(data, settings, check)
    if noise_at:
        try:
            settings.kalman_noise()  # the spread of the noises (KalmanNoise), refused where the file gives them
        except WmrkitError as err:
            check.fail(str(err), noise_at[0])
    return settings


def _check_slip_spread(data: Mapping[str, Any], settings: OdometrySettings, check: Any) -> None:
    """Refuse, at the place that gives it, a friction coefficient more than ``MAX_RATIO`` from another that applies
    to the same robot (``SlipWeights.row_mu`` refused it only when odometry ran, without the file)."""
    from .weights import MAX_RATIO

    wheels = list(data.get("wheels", []))
    used: list[tuple[float, tuple]] = []
    if settings.slip is not None and not all(_has_coefficients(w) for w in wheels):
        used += [(v, ("odometry", "slip", k)) for v, k in zip(settings.slip, ("lateral", "longitudinal"), strict=True)]
    elif settings.slip is None and len(settings.wheel_slip) < len(wheels):
        used += [(1.0, ())]  # the wheels without slip get the unit default
    at = [i for i, w in enumerate(wheels) if _has_coefficients(w)]
    for i, (_, lat, lon) in zip(at, settings.wheel_slip, strict=True):
        used += [(lat, ("wheels", i, "slip", "lateral")), (lon, ("wheels", i, "slip", "longitudinal"))]
    if not used:
        return
    lo, hi = min(used, key=lambda u: u[0]), max(used, key=lambda u: u[0])
    if hi[0] > MAX_RATIO * lo[0]:
        here, other = (lo, hi) if lo[1] else (hi, lo)
        where = field_path(other[1]) if other[1] else "the default of the wheels without slip"
        check.fail(f"{here[0]:g} and {other[0]:g} ({where}) differ by more than a factor {MAX_RATIO:g}: the weighted "
                   "least squares would lose the smaller rows to round-off (only ratios matter)", here[1])


def _has_coefficients(wheel: Any) -> bool:
    """Whether a wheel's description gives its own friction coefficients: a ``slip`` other than ``{noise: ...}``
    alone (a wheel's Kalman noise with the default coefficients)."""
    if not isinstance(wheel, Mapping) or "slip" not in wheel:
        return False
    return not (isinstance(wheel["slip"], Mapping) and set(wheel["slip"]) == {"noise"})


def settings_to_dict(settings: OdometrySettings) -> dict[str, Any]:
    """The description entries of `settings`: ``{"odometry": {...}}`` and, per wheel with its own values,
    ``{"wheels": {name: {"slip": {...}}}}`` (to merge into the wheels of that name). Empty parts left out."""
    block: dict[str, Any] = {}
    if settings.method is not None:
        block["method"] = settings.method
    if settings.scheme is not None:
        block["scheme"] = settings.scheme
    if settings.slip is not None:
        block["slip"] = {"lateral": settings.slip[0], "longitudinal": settings.slip[1]}
    if settings.noise is not None:
        block["noise"] = dict(zip(("process", "lateral", "longitudinal"), settings.noise, strict=True))
        if settings.period is not None:
            block["noise"]["period"] = settings.period
    wheels: dict[str, Any] = {n: {"slip": {"lateral": a, "longitudinal": b}} for n, a, b in settings.wheel_slip}
    for n, a, b in settings.wheel_noise:
        wheels.setdefault(n, {"slip": {}})["slip"]["noise"] = {"lateral": a, "longitudinal": b}
    return ({"odometry": block} if block else {}) | ({"wheels": wheels} if wheels else {})


def odometry_settings(spec: str) -> OdometrySettings:
    """The settings of the robot named by a ROBOT argument (a description file, else a catalog name), as
    ``catalog.resolve`` finds it (``Robot.odometry``; empty settings when the description says none)."""
    from .. import catalog

    return catalog.resolve(spec).odometry or OdometrySettings()


def _choice(block: Mapping[str, Any], key: str, choices: tuple[str, ...], check: Any, loc: tuple) -> str | None:
    if key not in block:
        return None
    value = block[key]
    if value not in choices:
        check.fail(f"must be one of {', '.join(choices)}, got {value!r}", (*loc, key))
    return str(value)


def _pair(item: Any, check: Any, loc: tuple, extra: tuple[str, ...]) -> tuple[float, float]:
    """``{lateral, longitudinal}``: two finite numbers > 0 (both required)."""
    if not isinstance(item, Mapping):
        check.fail("must be a mapping {lateral: NUMBER, longitudinal: NUMBER}", loc)
    check.reject_unknown(item, ("lateral", "longitudinal", *extra), loc)
    return (_positive(check.require(item, "lateral", loc), check, (*loc, "lateral")),
            _positive(check.require(item, "longitudinal", loc), check, (*loc, "longitudinal")))


def _period(value: Any, check: Any, loc: tuple) -> float:
    """``noise.period``: a time [s, or with a unit: '10 ms'] in the filters' range (:func:`.kalman.check_period`)."""
    from .kalman import check_period

    seconds = check.quantity(value, "time", loc)
    try:
        return check_period(seconds, "period")
    except WmrkitError as err:
        check.fail(str(err).removeprefix("period: "), loc)
        raise AssertionError from None  # unreachable: fail raises


def _positive(value: Any, check: Any, loc: tuple) -> float:
    number = check.quantity(value, "number", loc)
    if not (math.isfinite(number) and number > 0):
        check.fail(f"must be a number > 0, got {number}", loc)
    return number
