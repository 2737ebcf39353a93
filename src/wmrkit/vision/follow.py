"""Closed-loop line following by vision, thesis §9.2.2-9.2.3: camera image -> (psi, h) -> control -> wheels.

Each control period T (the image processing time) the synthetic camera renders what the robot sees
(:func:`.render.render`), the line is extracted and the robot positioned from the image (:func:`locate_image`),
optionally with bounded uniform noise on (h, psi) (example 2). The command reaches the wheels one period
later (the image is being processed meanwhile: the one-sample delay that makes example 3 oscillate, digest §2.6).

Control (9.25)-(9.26) in wmrkit's line frame L (x along the line, y left; the thesis's G has X to the right):
pose ``(y, theta) = (h, -psi)``; world velocity of P ``(v_follow, -a h)`` (erratum: the printed
``-a_x h`` is in the thesis's X-right frame and has the wrong sign there; the lateral error must decay), turned
into the robot frame with the measured heading. The law is :mod:`wmrkit.control`'s P law (8.2) with the poles
of (9.26) (:func:`line_following_law`), the twist the one the robot's fixed wheels admit
(:func:`wmrkit.control.points.twist_for_velocity`), the wheel commands come from
:func:`wmrkit.kinematics.wheel_ik.wheel_commands` (8.48)-(8.51), the motion from those wheel commands by
:func:`wmrkit.kinematics.wheel_ik.forward_kinematics` and :func:`wmrkit.odometry.integrators.integrate_exact`.
"""

from __future__ import annotations

import math
import numbers
from collections.abc import Sequence
from dataclasses import dataclass, replace
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from .._shapes import as_real, as_vectors, readonly
from ..control.laws import PositionLaw, law_velocity
from ..control.points import ControlError, control_point, twist_for_velocity
from ..errors import WmrkitError
from ..kinematics.wheel_ik import forward_kinematics, wheel_commands
from ..limits import MAX_COORDINATE, MAX_SIZE, MAX_SPEED, check_seed
from ..odometry.integrators import integrate_exact
from ..robot import Robot
from ..wheels import wrap_angle
from .camera import Camera, CameraError, check_type, extrinsics
from .lines import extract_lines
from .positioning import Positioning, check_placement, locate_points
from .render import MAX_BLUR, MAX_CLUTTER, MAX_NOISE, Scene, render

__all__ = ["LineFollowing", "follow_line", "line_following_law", "line_following_twist", "locate_image",
           "thesis_initial_commands", "view_width"]


def locate_image(camera: Camera, image: ArrayLike, *, spacing: float = 0.0, ns: tuple[int, ...] | None = None,
                 z_p: float = 0.0, mode: str = "threshold", rows_a: float | None = None) -> Positioning:
    """Position (psi, h) from an image (§9.2.1.C then (9.10)-(9.11)): extraction, two points per line, mean.

    `ns`: the index n (9.8) of each line expected, left to right in the image; default ``(0,)`` without
    `spacing`, ``(-1, 0, 1)`` with it (crop rows); ``(-1, 1)`` is a road's two lines. Of the lines found (up to
    four more than expected: the chufa camera sees five crop rows), the neighbouring ones centred on the image's
    near row are used; with a `spacing`, those that put P nearest the followed line (identical rows: the robot
    follows the nearest). The points are taken on rows ``+-rows_a`` [px] (default a quarter of the image height;
    the far one halfway to the horizon when ``-rows_a`` is above it).
    Raises :class:`WmrkitError` when fewer lines than expected are found, or the image is not the camera's size.
    """
    check_type(camera, Camera, "camera", "Camera.from_file(path) or Camera(focal_px, tilt, height)")
    check_placement(spacing, z_p)  # before spacing > 0: '1' raised a bare TypeError
    if ns is not None and (isinstance(ns, str) or not isinstance(ns, Sequence)):
        raise CameraError(f"ns: expected a sequence of line indices n such as (-1, 0, 1), got {ns!r:.60}")  # TypeError
    ns = ns if ns is not None else ((-1, 0, 1) if spacing > 0 else (0,))
    shape = np.shape(image)[:2]
    if shape != (camera.rows, camera.width):  # the camera model's centre and rows: another image was misread
        raise CameraError(f"image: {' x '.join(map(str, shape[::-1]))} px, the camera's is {camera.width} x "
                          f"{camera.rows}")
    found = extract_lines(image, n_lines=len(ns) + 4, mode=mode, k1=camera.k1, focal_px=camera.focal_px)
    if len(found) < len(ns):
        raise WmrkitError(f"image: found {len(found)} line(s), expected {len(ns)}")
    a = as_real(rows_a, "rows_a") if rows_a is not None else camera.rows / 4  # '1': a bare TypeError
    horizon = camera.focal_px / math.tan(camera.tilt)  # rows above -horizon see no ground: the far point is taken
    far = a if a < horizon else horizon / 2  # below it (any two points of a line give the same position)
    undistorted = replace(camera, k1=0.0)  # the extracted lines are already undistorted

    def located(start: int) -> Positioning:
        return locate_points(undistorted, [(n, np.array([[ln.x_at(-far), -far], [ln.x_at(a), a]]))
                                           for n, ln in zip(ns, found[start:start + len(ns)], strict=True)],
                             spacing=spacing, z_p=z_p)

    # the len(ns) neighbouring lines around the image's centre on the near row +A (more rows may be in view)
    starts = sorted(range(len(found) - len(ns) + 1), key=lambda i: abs(sum(ln.x_at(a) for ln in found[i:i + len(ns)])))
    if spacing == 0 or len(starts) == 1:
        return located(starts[0])
    # identical rows: the group P is nearest the followed one of (|h| <= spacing / 2). The image's centre was one row
    # over for a robot turned 5 deg at 0.2 m from its row (h = -0.4 m: it steered to the next row)
    fixes = []
    for start in starts:
        try:
            fixes.append(located(start))
        except WmrkitError:  # a group with a stray line (not spaced as given): not the followed one
            continue
    return min(fixes, key=lambda f: abs(f.h)) if fixes else located(starts[0])


def line_following_law(gain: float) -> PositionLaw:
    """(9.26) as a P law (8.2) of :mod:`wmrkit.control`: pole `gain` [1/s] across the line, none along it (the
    longitudinal position is unobservable: pure velocity control) and none on the heading."""
    return PositionLaw("p", (0.0, gain, 0.0), (0.0, 0.0, 0.0), None)


def line_following_twist(robot: Robot, psi: float, h: float, gain: float, speed: float) -> np.ndarray:
    """Body twist ``(v_x, v_y, omega)`` commanded from a positioning (psi, h), eqs. (9.25)-(9.26) corrected.

    ``-> (3,)``. The pose in the line frame L is ``(?, h, -psi)`` (9.25); the law's world velocity of P is
    ``(speed, -gain h)`` (lateral error ``exp(-gain t)``; the printed ``-a_x h`` is in the thesis's X-right frame
    and has the wrong sign there); :func:`wmrkit.control.points.twist_for_velocity` turns it into the twist the
    robot's fixed wheels admit, with P the robot origin. `psi` [rad] and `h` [m] must be finite, `gain` [1/s] and
    `speed` [m/s] finite and > 0 (at most ``limits.MAX_SPEED``, as ``gain * |h|``), else :class:`WmrkitError` names
    the argument.
    """
    check_type(robot, Robot, "line_following_twist: robot", "wmrkit.catalog.load(name) or Robot.from_file(path)")
    for name, value, low in (("psi", psi, -math.inf), ("h", h, -math.inf), ("gain", gain, 0.0),
                             ("speed", speed, 0.0)):
        if isinstance(value, bool | str) or not isinstance(value, numbers.Real | np.ndarray) or np.ndim(value) \
                or not low < float(value) < math.inf:
            need = "a finite number" if low < 0 else "a finite number > 0"
            raise WmrkitError(f"line_following_twist: {name}: expected {need}, got {value!r}")
    if speed > MAX_SPEED:
        raise WmrkitError(f"line_following_twist: speed: {speed:g} m/s is faster than {MAX_SPEED:g} m/s")
    if gain * abs(h) > MAX_SPEED:  # the twist's or the wheel rates' bound refused it, naming neither
        raise WmrkitError(f"line_following_twist: gain * h: {gain:g} 1/s x {h:g} m commands {gain * abs(h):g} m/s "
                          f"across the line, faster than {MAX_SPEED:g} m/s")
    pose = np.array([0.0, h, -psi])
    v_world = law_velocity(line_following_law(gain), np.zeros(3), np.array([speed, 0.0, 0.0]), pose, np.zeros(3))
    return twist_for_velocity(control_point(robot, (0.0, 0.0)), pose, v_world)


@dataclass(frozen=True, eq=False)
class LineFollowing:
    """A simulated line-following run (§9.2.3). Frozen, arrays read-only; K control periods.

    - ``time`` ``(K + 1,)`` [s]; ``pose`` ``(K + 1, 3)`` of P in the line frame L (x along, y left [m], theta);
    - ``measured`` ``(K, 2)``: (psi [rad], h [m]) used by the command of each period (one period old);
    - ``twist`` ``(K, 3)``: the twist the wheels produced; ``rates`` ``(K, n_rates)`` [rad/s] the wheel commands
      (``rate_names``); ``steer`` ``(K, n_steer)`` [rad] steering headings of ``steer_names`` (0 = ahead);
    - ``lost`` ``(K,)`` bool: no line found in that image (the previous positioning was kept);
    - ``images``: when asked for, the camera image seen at each pose ``(K + 1)``: ``images[k]`` at ``pose[k]``.
    """

    robot_name: str
    rate_names: tuple[str, ...]
    steer_names: tuple[str, ...]
    gain: float
    speed: float
    period: float
    time: np.ndarray
    pose: np.ndarray
    measured: np.ndarray
    twist: np.ndarray
    rates: np.ndarray
    steer: np.ndarray
    lost: np.ndarray
    images: tuple[np.ndarray, ...] | None = None

    @property
    def lateral(self) -> np.ndarray:
        """Signed distance h [m] of P to the line at each sample ``(K + 1,)``."""
        return self.pose[:, 1]

    def settling_time(self, fraction: float = 0.95) -> float | None:
        """First time [s] after which |h| stays within ``(1 - fraction)`` of its initial value; None when the last
        sample is still outside (not settled within the run: the end of the run is no settling time) or when the
        run starts on the line (h = 0: no band to settle in, see :meth:`started_on_line`)."""
        h = np.abs(self.lateral)
        if self.started_on_line:
            return None
        outside = np.flatnonzero(h > (1 - fraction) * h[0])
        if outside.size and outside[-1] == len(h) - 1:
            return None
        return float(self.time[outside[-1] + 1]) if outside.size else 0.0

    @property
    def started_on_line(self) -> bool:
        """Whether the run starts with P on the line (h = 0), where a settling time relative to the start's
        distance is not defined."""
        return bool(self.lateral[0] == 0.0)

    def failure(self) -> str | None:
        """Why the run is not a line following, or None: the line was lost in some images (the command then used
        the last positioning found, so the robot drove blind; ``lost``)."""
        n_lost = int(np.count_nonzero(self.lost))
        if not n_lost:
            return None
        first = float(self.time[int(np.flatnonzero(self.lost)[0])])
        return (f"follow-line: the line was lost in {n_lost} of {len(self.lost)} images (first at t = {first:g} s; "
                f"the last positioning found was used meanwhile): the line was not followed (h went from "
                f"{self.lateral[0]:.4g} m to {self.lateral[-1]:.4g} m, at most {np.max(np.abs(self.lateral)):.4g} m "
                "from the line)")

    def to_dict(self) -> dict[str, Any]:
        """Summary and ``trace``, one ``{t, x, h, psi}`` a period (the ``wmrkit follow-line --json`` output;
        ``samples`` is a count in every other answer); psi [rad] wrapped to (-pi, pi]; the wheel
        commands of each period: ``wheel_rates`` [rad/s] and ``steering`` headings [rad] of the steered wheels."""
        h = self.lateral
        return {
            "robot": self.robot_name, "gain": self.gain, "speed": self.speed, "period": self.period,
            "final_h": float(h[-1]), "final_psi": float(wrap_angle(-self.pose[-1, 2])),
            "overshoot": float(max(0.0, -np.min(h * np.sign(h[0])))) if h[0] != 0 else 0.0,
            "settling_time_95": self.settling_time(), "lost_images": int(np.count_nonzero(self.lost)),
            "trace": [{"t": float(t), "x": float(p[0]), "h": float(p[1]), "psi": float(wrap_angle(-p[2]))}
                        for t, p in zip(self.time, self.pose, strict=True)],
            "wheel_rates": {n: self.rates[:, i].tolist() for i, n in enumerate(self.rate_names)},
            "steering": {n: self.steer[:, i].tolist() for i, n in enumerate(self.steer_names)},
        }


def view_width(camera: Camera, rows_a: float | None = None) -> float:
    """Width [m] of the ground seen across the image on row ``+rows_a`` [px] (default a quarter of the image
    height, the near row :func:`locate_image` measures on), camera looking along the line (psi = 0)."""
    from .camera import ground_from_image

    a = rows_a if rows_a is not None else camera.rows / 4
    half = (camera.width - 1) / 2
    psi, t = extrinsics((0.0, 0.0, 0.0), camera)
    ends = ground_from_image(np.array([[-half, a], [half, a]]), psi, camera.tilt, t, camera.focal_px)
    return float(abs(ends[1, 0] - ends[0, 0]))


#: Most control periods of a run: each renders and processes one image (about 10 ms).
MAX_PERIODS = 10**4
#: Most pixels rendered over a run (periods x image pixels): MAX_PERIODS images of the docs' follower camera
#: (320 x 240 px). Rendering costs about 0.5 us a pixel: a 4096 x 4096 camera took 10 s and 1.9 GB an image, so
#: 10^4 periods of it ran for a day (and ``keep_images`` held 170 GB).
MAX_RUN_PIXELS = MAX_PERIODS * 320 * 240


def follow_line(robot: Robot, camera: Camera, *, gain: float = 0.3, speed: float = 0.1, period: float = 0.5,
                duration: float = 20.0, start: ArrayLike = (0.0, 0.3, 0.0), z_p: float = 0.0,
                scene: Scene | None = None, noise: tuple[float, float] = (0.0, 0.0), image_noise: float = 0.0,
                blur: float = 0.0, clutter: int = 0, seed: int = 0, keep_images: bool = False,
                from_image: bool = True) -> LineFollowing:
    """Simulate the vision line follower of §9.2.3 (module docstring).

    `gain` a_x [1/s]; `speed` v_follow [m/s]; `period` T [s]; `duration` [s]: the whole periods within it (at
    least one); `start`: pose of P ``(x, y, theta)`` in the line
    frame L (the thesis's p(0) = (-0.3 m, 0, 0) with its X to the right is ``y = +0.3``); `scene`: default one
    painted line 2 cm wide; `noise`: bounds (h [m], psi [rad, below pi/2]) of uniform noise added to each
    positioning;
    `z_p` [m]: from the lens to P along the optical axis, within ``limits.MAX_SIZE``;
    `image_noise`, `blur`, `clutter`: options of the synthetic camera. ``from_image=False`` skips the camera and
    measures the exact (psi, h) of the pose (what the thesis's simulation did), for comparison.
    """
    check_type(robot, Robot, "follow-line: robot", "wmrkit.catalog.load(name) or Robot.from_file(path)")
    check_type(camera, Camera, "follow-line: camera", "Camera.from_file(path) or Camera(focal_px, tilt, height)")
    # the Python API reads no units: text raised a bare TypeError, blur=True reached OpenCV
    z_p, image_noise, blur = (as_real(v, f"follow-line: {name}") for name, v in (
        ("z_p", z_p), ("image_noise", image_noise), ("blur", blur)))
    for name, value, unit in (("gain", gain, "1/s"), ("period", period, "s"), ("duration", duration, "s"),
                              ("speed", speed, "m/s")):
        number = isinstance(value, numbers.Real) and not isinstance(value, bool)  # "0.3" raised a bare TypeError
        if not (number and 0 < value < math.inf):  # NaN included
            got = f"{value:g}" if number else repr(value)
            raise WmrkitError(f"follow-line: {name} (--{name}): expected a finite number > 0 [{unit}], got {got}")
    if speed > MAX_SPEED:
        raise WmrkitError(f"follow-line: speed (--speed) {speed:g} m/s is faster than {MAX_SPEED:g} m/s")
    if not duration / period <= MAX_PERIODS:
        raise WmrkitError(f"follow-line: duration (--duration) {duration:g} s at a period of {period:g} s is more "
                          f"than {MAX_PERIODS} periods (one image each)")
    n_steps = math.floor(duration / period + 1e-9)  # whole periods within the duration (rounding ran past it)
    if n_steps < 1:  # no period: the start was printed as the result
        raise WmrkitError(f"follow-line: duration (--duration) {duration:g} s is shorter than one period (--period, "
                          f"{period:g} s)")
    if from_image and n_steps * camera.width * camera.rows > MAX_RUN_PIXELS:
        raise WmrkitError(f"follow-line: {n_steps} periods of {camera.width} x {camera.rows} px "
                          f"images are more than the {MAX_RUN_PIXELS:.3g} pixels a run renders (docs/limits.md): "
                          "shorten the duration, lengthen the period or use a smaller camera image")
    noise = tuple(as_vectors(noise, 2, "noise"))  # (0.1,) raised IndexError
    if not (all(np.isfinite(noise)) and 0 <= noise[0] <= MAX_COORDINATE and 0 <= noise[1] < np.pi / 2):
        # psi positioned from an image lies within +-90 deg (9.10): '--noise 0.02 3' (3 rad, meant as 3 deg) ran
        # with the heading's noise beyond it, and printed a run that never settled, exit 0
        raise WmrkitError(f"follow-line: noise (--noise H PSI): noise bounds must be h in [0, {MAX_COORDINATE:g}] m "
                          f"and psi in [0, 90) deg (a heading positioned from an image lies within +-90 deg; a bare "
                          f"PSI is in radians, write e.g. '3deg'), got {noise[0]:g} m, {noise[1]:g} rad "
                          f"({math.degrees(noise[1]):.4g} deg)")
    if not abs(z_p) <= MAX_SIZE:  # NaN included; it was refused in the first image: 'the camera does not see the line'
        raise WmrkitError(f"follow-line: z_p (--z-p): expected a length in [-{MAX_SIZE:g}, {MAX_SIZE:g}] m, "
                          f"got {z_p:g}")
    if not 0 <= image_noise <= MAX_NOISE:  # NaN included; the synthetic camera's options, named as options (render
        # refused them in the first image, naming no option)
        raise WmrkitError(f"follow-line: image_noise (--image-noise): image noise must be in [0, {MAX_NOISE:g}] grey "
                          f"levels (a standard deviation), got {image_noise:g}")
    if not 0 <= blur <= MAX_BLUR:
        raise WmrkitError(f"follow-line: blur (--blur): expected a blur in [0, {MAX_BLUR:g}] px (a Gaussian sigma), "
                          f"got {blur:g}")
    if isinstance(clutter, bool) or not isinstance(clutter, int | np.integer) or not 0 <= clutter <= MAX_CLUTTER:
        raise WmrkitError(f"follow-line: clutter (--clutter): clutter must be an integer in [0, {MAX_CLUTTER}] blobs, "
                          f"got {clutter!r}")
    noise = (abs(float(noise[0])), abs(float(noise[1])))  # -0.0 is a bound of 0 (numpy's uniform refuses it)
    check_seed(seed, WmrkitError, "follow-line: seed")
    if gain * period >= 1:
        raise WmrkitError(f"follow-line: gain (--gain) * period (--period) = {gain * period:g} >= 1: the delayed "
                          "loop is unstable (digest §2.6: a_x T < 1)")
    scene = scene or Scene(ns=(0,), width=0.02)
    view = view_width(camera)
    if scene.width >= view:  # the line fills the positioning row: no edge, nothing to locate
        raise WmrkitError(f"follow-line: line width (--line-width) {scene.width:g} m is not narrower than what the "
                          f"camera sees across its image on the row where the line is measured ({view:.4g} m at "
                          f"row +{camera.rows / 4:g} px, looking straight along the line): the line's edges "
                          "are out of view")
    try:  # P, the point positioned (9.25) and steered (9.26), is the robot's origin
        control_point(robot, (0.0, 0.0))
    except ControlError as err:  # its advice, "choose a point ahead of the axle", has no option here
        if "fixed axle" not in str(err):
            raise
        raise WmrkitError(f"follow-line: robot '{robot.name}': its origin, the point P the camera positions and the "
                          "command steers (9.25)-(9.26), lies on its fixed axle, where its velocity across the line "
                          "cannot be commanded; describe the robot with its origin ahead of the axle (the "
                          "line-follower's is 0.39 m ahead)") from None
    actuated = [n for n in robot.rate_names if n.endswith(".spin") and n in robot.actuated] or \
        [n for n in robot.rate_names if n.endswith(".spin")]
    rng = np.random.default_rng(seed)
    pose = np.empty((n_steps + 1, 3))
    pose[0] = as_vectors(start, 3, "start")
    if not np.all(np.isfinite(pose[0])):  # render refused it, naming 'pose and z_p'
        raise WmrkitError(f"follow-line: start (--start): expected a finite pose (x, y, theta), got "
                          f"({', '.join(f'{v:g}' for v in pose[0])})")
    if not np.all(np.abs(pose[0, :2]) <= MAX_COORDINATE):
        raise WmrkitError(f"follow-line: start position (--start) ({pose[0, 0]:g}, {pose[0, 1]:g}) m is beyond "
                          f"{MAX_COORDINATE:g} m")
    if gain * (abs(pose[0, 1]) + noise[0]) > MAX_SPEED:  # the first command: |h| up to the start's plus the noise
        raise WmrkitError(f"follow-line: gain {gain:g} 1/s times the start's distance to the line and the noise bound "
                          f"on h ({abs(pose[0, 1]):g} + {noise[0]:g} m) commands up to "
                          f"{gain * (abs(pose[0, 1]) + noise[0]):g} m/s across the line, faster than {MAX_SPEED:g} m/s")
    measured = np.empty((n_steps, 2))
    twists, rates, steers = np.empty((n_steps, 3)), np.empty((n_steps, len(robot.rate_names))), []
    lost = np.zeros(n_steps, dtype=bool)
    images: list[np.ndarray] = []
    beta = robot.beta
    why: list[str] = []  # why the last image gave no positioning

    def view(p: np.ndarray) -> np.ndarray:
        return render(camera, p, scene, z_p=z_p, noise=image_noise, blur=blur, clutter=clutter,
                      seed=int(rng.integers(1 << 31)))

    def position(p: np.ndarray, keep: bool) -> tuple[float, float] | None:
        if not from_image:
            return (-p[2] + rng.uniform(-noise[1], noise[1]), p[1] + rng.uniform(-noise[0], noise[0]))
        img = view(p)
        if keep_images and keep:  # one image per pose, the one seen there
            images.append(img)
        try:
            fix = locate_image(camera, img, spacing=scene.spacing, ns=scene.ns, z_p=z_p)
        except WmrkitError as err:
            why[:] = [str(err)]
            return None
        return (fix.psi + rng.uniform(-noise[1], noise[1]), fix.h + rng.uniform(-noise[0], noise[0]))

    last = position(pose[0], True)  # the image taken before starting
    if last is None:
        raise WmrkitError(f"follow-line: the camera does not see the line at the start pose (--start): {why[0]}")
    for k in range(n_steps):
        psi, h = last
        measured[k] = psi, h
        cmd = wheel_commands(robot, line_following_twist(robot, psi, h, gain, speed), beta)
        beta = cmd.beta
        names = list(cmd.rate_names)
        twist, _ = forward_kinematics(robot, {n: cmd.rates[names.index(n)] for n in actuated}, beta)
        twists[k], rates[k] = twist, cmd.rates
        steers.append(robot.heading_of_beta(beta))
        new = position(pose[k], k > 0)  # processed during this period, used in the next one (pose[0]'s is kept)
        lost[k] = new is None
        last = new if new is not None else last
        pose[k + 1] = integrate_exact(pose[k], twist, period)
    if keep_images and from_image:  # what the camera sees at the end (the animation's last frame)
        images.append(view(pose[-1]))
    time = np.arange(n_steps + 1) * period
    steer = np.array(steers).reshape(n_steps, len(robot.steer_names))
    return LineFollowing(robot.name, tuple(robot.rate_names), tuple(robot.steer_names), gain, speed, period,
                         readonly(time), readonly(pose), readonly(measured), readonly(twists), readonly(rates),
                         readonly(steer), readonly(lost), tuple(images) if keep_images else None)


def thesis_initial_commands(robot: Robot, h: float = 0.3, gain: float = 0.3, speed: float = 0.1) -> dict[str, float]:
    """The twist and wheel rates [rad/s] of the first command of §9.2.3 example 1 (psi = 0), named."""
    twist = line_following_twist(robot, 0.0, h, gain, speed)
    cmd = wheel_commands(robot, twist)
    return {"vx": float(twist[0]), "vy": float(twist[1]), "omega": float(twist[2]),
            **dict(zip(cmd.rate_names, cmd.rates.tolist(), strict=True))}
