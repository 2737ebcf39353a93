"""Mechanical couplings between joints: differentials, gear trains and chains, steering linkages.

Real robots couple joints mechanically: a car drives its rear wheels through a differential, a synchro drive turns
every wheel with one chain, an Ackermann linkage steers both front wheels with one actuator. A description says so
with ``couplings:`` (``docs/description-format.md``); the actuation analysis (thesis §4.4) then counts one actuator
per coupling instead of one per joint, and no longer reports such a robot as fighting itself. Sensors read their
joints one by one; a gear's unsensed joints turn with its sensed ones (:func:`gear_fill`: fk, odometry, sensing),
and a gear none of whose joints is read still turns as one (:func:`gear_free`).

- ``differential``: one actuator drives the weighted sum ``sum(ratio_j * q_j)`` of the joints' rates (a mechanical
  differential: the mean of the two wheel rates with ratios 1/2, 1/2); the other combinations stay free.
- ``gear``: the joints turn together, rigidly, ``q_j = ratio_j * u`` (a chain, a gear train, a synchro drive).
- ``linkage``: steering joints moved by one mechanism (an Ackermann linkage); the angles are a configuration, so
  the coupling says that actuating one of them sets them all. Sensing stays per angle (its ratios are not used), as
  it does per joint under the other kinds; the dynamics hold its ideal ``law`` (:data:`LINKAGE_LAWS`,
  :func:`linkage_law`, :mod:`wmrkit.kinematics.linkage_law`), and ``ik`` and ``fk`` check angles against it
  (:mod:`wmrkit.kinematics.linkage_check`).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from ._shapes import as_names, finite_number
from .errors import UnknownNameError, WmrkitError, name_list
from .limits import MAX_COUPLING_RATIO, MIN_COUPLING_RATIO, MIN_RATIO, below, shown

if TYPE_CHECKING:
    from .robot import Robot
    from .wheels import Wheel

COUPLING_KINDS = ("differential", "gear", "linkage")
#: The laws a ``linkage`` may state: ``ackermann``, the linked wheels' axles meet on the fixed wheels' axle line;
#: ``parallel``, the linked wheels turn together (a synchro drive's chain, a crab-steering pair).
LINKAGE_LAWS = ("ackermann", "parallel")


class CouplingError(WmrkitError, ValueError):
    """A coupling built in Python that no description would give (``docs/description-format.md``, Couplings)."""


@dataclass(frozen=True, slots=True)
class Coupling:
    """Joints ``wheel.joint`` moved by one mechanism of `kind`, with one ratio per joint (see module docstring); a
    linkage's `law` (:data:`LINKAGE_LAWS`), None when the description does not state it (:func:`linkage_law`)."""

    kind: str
    joints: tuple[str, ...]
    ratios: tuple[float, ...]
    law: str | None = None

    def __post_init__(self) -> None:
        joints = as_names(self.joints, f"coupling {self.kind}: joints", "'wheel.joint' names", CouplingError)
        object.__setattr__(self, "joints", joints)  # lists, as a description has them, kept as tuples (hashed)
        if isinstance(self.ratios, list | np.ndarray):
            object.__setattr__(self, "ratios", tuple(self.ratios))
        name = f"coupling {self.kind}({', '.join(joints)})"
        if self.kind not in COUPLING_KINDS:
            raise CouplingError(f"{name}: unknown kind (kinds: {', '.join(COUPLING_KINDS)})")
        if len(self.joints) < 2 or len(set(self.joints)) != len(self.joints) or len(self.ratios) != len(self.joints):
            raise CouplingError(f"{name}: expected two or more distinct joints and one ratio per joint")
        problem = ratios_problem(self.ratios)
        if problem is not None:
            index, reason = problem
            raise CouplingError(f"{name}: ratios{'' if index is None else f'[{index}]'}: {reason}")
        if self.law is not None and (self.kind != "linkage" or self.law not in LINKAGE_LAWS):
            raise CouplingError(f"{name}: law {self.law!r}: {law_problem(self.kind, self.law)}")

    @property
    def rates(self) -> bool:
        """The coupling acts on joint rates (columns of the Jacobian form), not on steering angles."""
        return self.kind != "linkage"

    @property
    def channel_name(self) -> str:
        """The name of the one actuator or sensor it makes of its joints: ``differential(a.spin, b.spin)``."""
        return f"{self.kind}({', '.join(self.joints)})"

    def words(self, *, short: bool = False) -> str:
        """The coupling in the description's terms, for text (JSON keeps :attr:`channel_name`): ``the steering
        linkage of wheels 'fl' and 'fr'``, ``the differential of wheels 'rl' and 'rr'`` (each wheel's one joint of the
        kind: its spin or its steering), else by joints (``the gear of joints 'd.spin1' and 'd.spin2'``). `short`:
        the compact form for a list of identifiers, ``linkage of fl and fr``, ``gear of d.spin1 and d.spin2``."""
        names, by_wheel, steer = self._names()
        if short:
            return f"{self.kind} of {name_list(names[:-1])} and {names[-1]}"
        kind = f"steering {self.kind}" if steer and by_wheel else self.kind
        return f"the {kind} of {'wheels' if by_wheel else 'joints'} {_quoted(names)}"

    def joints_words(self) -> str:
        """Its joints in text, for a sentence about them (``... do not turn together``, ``turn ... out of its
        ratios``): ``the joints of the gear of wheels 'left' and 'right'``, and named by joint (:meth:`words`) ``the
        gear's joints 'd.spin1' and 'd.spin2'``, not ``the joints of the gear of joints ...``."""
        names, by_wheel, _ = self._names()
        return f"the joints of {self.words()}" if by_wheel else f"the {self.kind}'s joints {_quoted(names)}"

    def _names(self) -> tuple[list[str], bool, bool]:
        """The names text gives its joints, whether they are its wheels' (each wheel's one joint of the kind: its
        spin or its steering), and whether they are steering joints."""
        wheel, _, joint = zip(*(j.partition(".") for j in self.joints), strict=True)
        by_wheel = len(set(joint)) == 1 and joint[0] in ("spin", "steer") and len(set(wheel)) == len(wheel)
        return (list(wheel) if by_wheel else list(self.joints)), by_wheel, joint[0] == "steer"


def _quoted(names: list[str]) -> str:
    """``'a', 'b' and 'c'`` (past :data:`~wmrkit.errors.MAX_LISTED` names, the first ones and a count)."""
    quoted = [f"'{n}'" for n in names]
    return f"{name_list(quoted[:-1])} and {quoted[-1]}"


def ratios_problem(ratios: tuple[float, ...]) -> tuple[int | None, str] | None:
    """Why `ratios` are no coupling's, or None: the index of the ratio at fault (None: the set, too spread) and the
    reason. The one rule of :class:`Coupling` and the description's located check: each non-zero, of magnitude
    ``MIN_COUPLING_RATIO`` to ``MAX_COUPLING_RATIO``, the largest at most ``1 / MIN_RATIO`` times the smallest."""
    for j, k in enumerate(ratios):
        if k == 0:
            return j, "must be non-zero (a joint with ratio 0 is not coupled)"
        if not (finite_number(k) and MIN_COUPLING_RATIO <= abs(k) <= MAX_COUPLING_RATIO):
            edge = MAX_COUPLING_RATIO if finite_number(k) and abs(k) > 1 else MIN_COUPLING_RATIO
            value = shown(k, edge) if finite_number(k) else repr(k)
            return j, (f"{value}: outside the ratios wmrkit handles ({MIN_COUPLING_RATIO:g} to {MAX_COUPLING_RATIO:g}"
                       " in magnitude, docs/limits.md)")
    sizes = [abs(k) for k in ratios]
    if below(min(sizes), MIN_RATIO * max(sizes)):
        return None, (f"the largest ratio is more than {1 / MIN_RATIO:g} times the smallest: rank decisions would "
                      "lose the smaller to round-off (docs/limits.md)")
    return None


def joint_problem(kind: str, joint: str, wheels: Mapping[str, Wheel],
                  did_you_mean: Callable[[], str] = lambda: "") -> str | None:
    """Why `joint` (``wheel.joint``) cannot be in a coupling of `kind` on a robot whose `wheels` are given by name,
    or None: the robot has the joint, a steering angle in a linkage and a joint rate in the other kinds."""
    wheel, _, part = joint.partition(".")
    w = wheels.get(wheel)
    if w is None or part not in w.kind.joints:
        return f"no joint '{joint}' on this robot{did_you_mean()}"
    steer_angle = part == "steer" and "steer" not in w.kind.rates
    if steer_angle != (kind == "linkage"):
        return (f"'{joint}' is {'a steering angle' if steer_angle else 'a joint rate'}: a {kind} couples "
                f"{'steering angles (kind: linkage)' if kind == 'linkage' else 'rates'}")
    return None


def law_problem(kind: str, law: object) -> str:
    """Why `law` is no law of a coupling of `kind` (a linkage's is one of :data:`LINKAGE_LAWS`)."""
    if kind != "linkage":
        return f"only a linkage has a law (a {kind} turns its joints in its ratios)"
    return f"a linkage's law is one of {', '.join(LINKAGE_LAWS)}"


def fixed_axle(wheels: tuple[Wheel, ...] | list[Wheel]) -> tuple[np.ndarray, float, str | None] | None:
    """``(point, heading, odd)`` of the fixed wheels' common axle line: a point on it, their rolling direction
    [rad], and None, or the name of the first fixed wheel whose axle is off the first one's line; None without a
    fixed wheel."""
    fixed = [w for w in wheels if w.type == "fixed"]
    if not fixed:
        return None
    p0, h0 = np.array(fixed[0].position), fixed[0].heading
    n0 = np.array([np.cos(h0), np.sin(h0)])
    scale = max(1.0, *(float(np.abs(w.position).max()) for w in fixed))
    odd = next((w.name for w in fixed[1:] if abs(np.sin(w.heading - h0)) > 1e-9
                or abs(n0 @ (np.array(w.position) - p0)) > 1e-9 * scale), None)
    return p0, h0, odd


def axle_problem(wheels: tuple[Wheel, ...] | list[Wheel]) -> str | None:
    """Why the wheels give no axle line for ``law: ackermann`` (the linked wheels' axles meet on it), or None."""
    axle = fixed_axle(wheels)
    if axle is None:
        return ("its wheels' axles would meet on the fixed wheels' axle line, and the robot has no fixed "
                "wheel (state law: parallel if the linked wheels turn together)")
    if axle[2] is not None:
        first = next(w.name for w in wheels if w.type == "fixed")
        return (f"the fixed wheels' axles ({first}, {axle[2]}) are not one line, so no ICR is common to them and "
                "the linked wheels")
    return None


def linkage_law(c: Coupling, wheels: tuple[Wheel, ...] | list[Wheel]) -> str | None:
    """The law the dynamics hold on linkage `c` of a robot with `wheels`: the one it states; else ``ackermann``
    with fixed wheels, ``parallel`` when it links every wheel with a steering angle (a synchro drive); else None,
    not held: wmrkit does not guess (a four-wheel-steer car's front pair may be an Ackermann linkage)."""
    if c.law is not None:
        return c.law
    if any(w.type == "fixed" for w in wheels):
        return "ackermann"
    steered = {w.name for w in wheels if "steer" in w.kind.joints and "steer" not in w.kind.rates}
    return "parallel" if steered == {j.partition(".")[0] for j in c.joints} else None


def check_couplings(robot: Robot) -> None:
    """A robot built in Python couples joints as a description does (``description._couplings_from_dict``): a
    tuple of :class:`Coupling` whose joints the robot has, each in one coupling at most; else :class:`CouplingError`
    naming it (a linkage of a joint the robot lacks was ignored without a word)."""
    couplings = robot.couplings
    if not isinstance(couplings, tuple) or not all(isinstance(c, Coupling) for c in couplings):
        raise CouplingError(f"robot '{robot.name}': couplings: expected a tuple of Coupling, got {couplings!r:.80}")
    wheels = {w.name: w for w in robot.wheels}
    used: set[str] = set()
    for i, c in enumerate(couplings):
        for joint in c.joints:
            problem = joint_problem(c.kind, joint, wheels) or (f"joint '{joint}' is in two couplings"
                                                                if joint in used else None)
            if problem is not None:
                raise CouplingError(f"robot '{robot.name}': couplings[{i}] {c.channel_name}: {problem}")
            used.add(joint)
        problem = axle_problem(robot.wheels) if c.law == "ackermann" else None
        if problem is not None:
            raise CouplingError(f"robot '{robot.name}': couplings[{i}] {c.channel_name}: law ackermann: {problem}")


def channel_names(couplings: tuple[Coupling, ...], joints: tuple[str, ...]) -> tuple[str, ...]:
    """`joints` with those of each rate coupling replaced, once, by its channel (in the order of `joints`)."""
    out: list[str] = []
    for j in joints:
        c = next((c for c in couplings if c.rates and j in c.joints), None)
        name = j if c is None else c.channel_name
        if name not in out:
            out.append(name)
    return tuple(out)


def coupled_columns(
    couplings: tuple[Coupling, ...], names: tuple[str, ...], selected: tuple[int, ...]
) -> tuple[np.ndarray, tuple[str, ...], np.ndarray, np.ndarray]:
    """Change of joint-rate variables for the actuation/sensing trees (4.28)/(4.34) under rate couplings.

    `names`: the Jacobian-form columns; `selected`: the columns actuated (or sensed), in order. Returns
    ``(T_sel, channel_names, T_rest, T_drop)``: matrices ``(n_w, k)`` whose columns span, in rate space, the
    independent selected channels (one per coupling holding a selected joint, in the order of `selected`; the
    identity column of every other selected joint), the free rest, and the directions a gear coupling forbids.
    ``J @ T_sel`` and ``J @ T_rest`` replace ``J_sel`` and ``J_rest``; ``T_drop`` directions are held at zero.
    """
    n = len(names)
    eye = np.eye(n)
    owner: dict[int, Coupling] = {}
    for c in couplings:
        if c.rates:
            missing = [j for j in c.joints if j not in names]
            if missing:
                rates = ", ".join(n for n in names if not n.startswith("omega@"))
                raise UnknownNameError(f"{c.channel_name}: no joint rate {missing[0]} (rates: {rates})")
            owner.update({names.index(j): c for j in c.joints})
    channel: dict[Coupling, np.ndarray] = {}
    across: dict[Coupling, list[np.ndarray]] = {}
    for c in dict.fromkeys(owner.values()):
        idx = [names.index(j) for j in c.joints]
        k = np.array(c.ratios, dtype=float)
        t = np.zeros(n)
        t[idx] = k if c.kind == "gear" else k / (k @ k)  # gear: q = k u; differential: u = k . q
        channel[c] = t
        across[c] = []
        for b in np.linalg.svd(k[None, :])[2][1:]:  # the directions across the ratios
            v = np.zeros(n)
            v[idx] = b
            across[c].append(v)
    sel, sel_names, emitted = [], [], set()
    for i in selected:
        c = owner.get(i)
        if c is None:
            sel.append(eye[i])
            sel_names.append(names[i])
        elif c not in emitted:
            emitted.add(c)
            sel.append(channel[c])
            sel_names.append(c.channel_name)
    rest = [eye[i] for i in range(n) if i not in owner and i not in selected]
    rest += [channel[c] for c in channel if c not in emitted]
    rest += [v for c in channel if c.kind == "differential" for v in across[c]]
    drop = [v for c in channel if c.kind == "gear" for v in across[c]]

    def stack(cols: list[np.ndarray]) -> np.ndarray:
        return np.array(cols, dtype=float).reshape(len(cols), n).T

    return stack(sel), tuple(sel_names), stack(rest), stack(drop)


def linked_steering(couplings: tuple[Coupling, ...], steering: tuple[str, ...]) -> tuple[str, ...]:
    """The wheels whose steering is set through a linkage by one of the `steering` wheels (with them)."""
    out = list(steering)
    for c in couplings:
        wheels = [j.partition(".")[0] for j in c.joints]
        if c.kind == "linkage" and any(w in steering for w in wheels):
            out += [w for w in wheels if w not in out]
    return tuple(out)


def gear_fill(couplings: tuple[Coupling, ...], names: tuple[str, ...],
              given: tuple[int, ...]) -> tuple[tuple[int, ...], np.ndarray]:
    """The joint rates a ``gear`` fixes from given ones: ``q_j = ratio_j * u``, ``u = k_g . q_g / k_g . k_g`` the
    least-squares turn of the gear's given joints ``g`` (each given joint stays as given: sensors read per joint).

    `names`: the columns (velocity or Jacobian-form names); `given`: the positions of the given rates, in order.
    Returns ``(columns, F)``: `given` followed by the positions of the joints filled (those of `names` in a gear with
    a given joint), and ``F`` ``(len(columns), len(given))`` with ``q[columns] = F @ q[given]``.
    """
    columns, rows = list(given), [np.eye(len(given))[i] for i in range(len(given))]
    for c in couplings:
        if c.kind != "gear":
            continue
        idx = [names.index(j) if j in names else -1 for j in c.joints]
        k = np.array(c.ratios, dtype=float)
        known = [i for i, col in enumerate(idx) if col in given]
        if not known:
            continue
        u = np.zeros(len(given))  # u = F_u @ q_given
        u[[given.index(idx[i]) for i in known]] = k[known] / (k[known] @ k[known])
        for i, col in enumerate(idx):
            if col >= 0 and col not in columns:
                columns.append(col)
                rows.append(k[i] * u)
    return tuple(columns), np.array(rows, dtype=float).reshape(len(columns), len(given))


def gear_free(couplings: tuple[Coupling, ...], names: tuple[str, ...],
              given: tuple[int, ...]) -> tuple[np.ndarray, tuple[str, ...]]:
    """The unknown directions of the velocities `names` once the rates at positions `given` are known: one column
    per unknown (``q_unknown = T @ p``), a joint in no gear its own, a ``gear`` with none of its joints given one
    (its ratios ``q_j = ratio_j * u``: its constraint held though no joint of it is read), none for the joints a
    gear fills from given ones (:func:`gear_fill`). Returns ``(T (len(names), p), the names of p)``, in the order
    of `names` (a gear's column at its first joint, named by its channel)."""
    n = len(names)
    owner: dict[int, Coupling] = {}
    for c in couplings:
        if c.kind == "gear":
            owner.update({names.index(j): c for j in c.joints if j in names})
    cols, out_names, done = [], [], set()
    for i in range(n):
        c = owner.get(i)
        if c is None:
            if i not in given:
                cols.append(np.eye(n)[i])
                out_names.append(names[i])
            continue
        if c in done or any(owner.get(g) is c for g in given):
            continue
        done.add(c)
        t = np.zeros(n)
        for j, k in zip(c.joints, c.ratios, strict=True):
            if j in names:
                t[names.index(j)] = k
        cols.append(t)
        out_names.append(c.channel_name)
    return np.array(cols, dtype=float).reshape(len(cols), n).T, tuple(out_names)


def gear_unknowns(couplings: tuple[Coupling, ...], names: tuple[str, ...],
                  given: tuple[int, ...]) -> tuple[np.ndarray, np.ndarray]:
    """``(free (len(names), p), known (len(names), len(given)))``: the velocities `names` are ``free @ p + known @
    q_given`` with the rates at positions `given` known and every ``gear`` held (:func:`gear_fill`,
    :func:`gear_free`); `p` the unknowns."""
    filled, fill = gear_fill(couplings, names, given)
    known = np.zeros((len(names), len(given)))
    known[list(filled)] = fill
    return gear_free(couplings, names, given)[0], known


def steering_mechanisms(couplings: tuple[Coupling, ...], steered: list[str] | tuple[str, ...]) -> int:
    """How many independent steering commands the `steered` wheels take: one per wheel, a ``linkage`` of several
    of them (a synchro drive's chain, an Ackermann linkage) one for all."""
    groups = {w: w for w in steered}
    for c in (c for c in couplings if c.kind == "linkage"):
        linked = [groups[w] for w in (j.partition(".")[0] for j in c.joints) if w in groups]
        groups = {w: (linked[0] if g in linked else g) for w, g in groups.items()}
    return len(set(groups.values()))


#: A gear's joints (``q_j = ratio_j * u``) contradict it when their ``u_j = q_j / ratio_j`` differ, summed over the
#: rows, by more than a fraction of the largest ``|u_j|`` summed. Measured joints (a log's first intervals, judged by
#: ``odometry``): this fraction, backlash and encoder noise well within it.
GEAR_BREACH_RTOL = 0.1
#: The fraction for exact rates, given by a person or a program (``fk``'s given rates, the extended solutions'
#: assigned ones): round-off of a typed or unit-converted rate, ~1e-16 of it, with room to spare; rates typed
#: 0.1 % out of ratio are out of it.
GEAR_EXACT_RTOL = 1e-9


class GearWarning(UserWarning):
    """Given rates of a ``gear`` coupling's joints break its ratios (:func:`gear_breaches` at
    :data:`GEAR_EXACT_RTOL`): each is used as given, so the slip does not show it."""


@dataclass(frozen=True, slots=True)
class GearBreach:
    """A gear whose given joints (positions `given` in the names checked) turn `spread` apart (see
    :data:`GEAR_BREACH_RTOL`)."""

    coupling: Coupling
    given: tuple[int, ...]
    spread: float

    @property
    def head(self) -> str:
        """The start of a warning naming the coupling and its ratios."""
        ratios = ", ".join(f"{k:g}" for k in self.coupling.ratios)
        return f"{self.coupling.joints_words()} (ratios {ratios}) do not turn together"

    def warning(self, names: tuple[str, ...], values: np.ndarray) -> str:
        """The warning of ``fk`` (and the extended solutions) on given `values` of the joints `names` (one row)."""
        given = ", ".join(f"{names[i]} {values[i]:.4g}" for i in self.given)
        apart = f"{self.spread:.0%}" if self.spread >= 0.005 else f"{100 * self.spread:.1g}%"  # never "0%"
        return (f"{self.head} ({given} rad/s; {apart} apart): the rates contradict the description's gear "
                "(each is used as given); check the rates or the gear")


def gear_breaches(couplings: tuple[Coupling, ...], names: tuple[str, ...], q: np.ndarray, rtol: float,
                  least: float = 0.0) -> list[GearBreach]:
    """The ``gear`` couplings with two or more of `names` whose rates or increments `q` ``(N, len(names))`` (or one
    row) break their ratios beyond `rtol` (:data:`GEAR_BREACH_RTOL` for measured joints, :data:`GEAR_EXACT_RTOL`
    for given ones); a gear whose summed ``|u|`` is below `least` is not judged (too little turning to tell)."""
    q = np.atleast_2d(np.asarray(q, dtype=float))
    out = []
    for gear in (c for c in couplings if c.kind == "gear"):
        read = [(names.index(j), k) for j, k in zip(gear.joints, gear.ratios, strict=True) if j in names]
        if len(read) < 2:
            continue
        u = np.column_stack([q[:, i] / k for i, k in read])  # (N, joints): the gear's input by each joint
        scale = float(np.abs(u).max(axis=1).sum())
        off = float((u.max(axis=1) - u.min(axis=1)).sum())
        if scale >= least and off > rtol * scale:
            out.append(GearBreach(gear, tuple(i for i, _ in read), off / scale))
    return out


def coupling_words(couplings: tuple[Coupling, ...], channel: str, *, short: bool = False) -> str:
    """A coupling of `couplings` by its channel name (``linkage(fl.steer, fr.steer)``: the library's, kept in JSON) in
    the description's terms (:meth:`Coupling.words`); a `channel` no coupling has (a joint's name) as is."""
    c = next((c for c in couplings if c.channel_name == channel), None)
    return channel if c is None else c.words(short=short)
