"""The simulator layer's records: settings, one tick's observation, a whole run.

Plain data (NumPy only), so code that judges or plots runs needs no MuJoCo.
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass, field

import numpy as np

from imitwalk.errors import ConfigError

__all__ = [
    "ENGINES",
    "Observation",
    "Rollout",
    "ServoQueue",
    "SimOptions",
    "checked_targets",
    "gravity",
    "jitter_draws",
    "kicks_due",
]

#: Physics engines a plant can run on: MuJoCo (the default everywhere) and Bullet
#: (:class:`imitwalk.sim.bullet.BulletPlant`, to judge transfer or to learn on another engine).
ENGINES = ("mujoco", "bullet")


@dataclass(frozen=True)
class SimOptions:
    """Simulation settings. Every perturbation defaults to off.

    Attributes:
        physics_hz: physics rate [Hz] (HOAP-2's servo loop runs at 1 kHz).
        control_hz: rate at which joint targets are commanded [Hz].
        gyro_noise: gyro noise standard deviation [rad/s].
        accel_noise: accelerometer noise standard deviation [m/s²].
        servo_delay: commands reach the servos this late [s] (rounded to physics steps).
        friction: if set, the sliding friction coefficient of every contact.
        friction_scale: multiplies every sliding friction coefficient.
        mass_scale: multiplies every body mass and inertia.
        mass_jitter: each body's mass also scaled by U(1 - j, 1 + j) (drawn from ``seed``).
        kp_scale: multiplies every servo stiffness; kp_jitter: per servo U(1 - j, 1 + j).
        slope_deg: ground slope [deg]; positive is uphill along +x (gravity tilted about y).
        cross_slope_deg: the ground's slope across the walk [deg]: positive rises along +y,
            to the robot's left at the start (gravity tilted about x as well).
        com_shift: ``(3,)`` the torso's centre of mass moved by this much in its own frame [m].
        pushes: velocity kicks ``(t [s], Δv_x, Δv_y [m/s])``, in time order: at the first
            physics step at or after ``t`` the whole robot's horizontal velocity changes by
            ``Δv`` (world frame), an impulse of mass × Δv, so a kick means the same on a
            light and a heavy robot (:mod:`imitwalk.sim.protocol` draws them).
        init_twist: ``(6,)`` initial base velocity, linear [m/s] then angular [rad/s].
        seed: seeds sensor noise and jitter.
        fall_height: a fall is the torso under this fraction of its standing height ...
        fall_tilt_deg: ... or the torso tilted more than this [deg].
    """

    physics_hz: float = 1000.0
    control_hz: float = 100.0
    gyro_noise: float = 0.0
    accel_noise: float = 0.0
    servo_delay: float = 0.0
    friction: float | None = None
    friction_scale: float = 1.0
    mass_scale: float = 1.0
    mass_jitter: float = 0.0
    kp_scale: float = 1.0
    kp_jitter: float = 0.0
    slope_deg: float = 0.0
    cross_slope_deg: float = 0.0
    com_shift: tuple[float, float, float] = (0.0, 0.0, 0.0)
    pushes: tuple[tuple[float, float, float], ...] = ()
    init_twist: tuple[float, ...] = (0.0,) * 6
    seed: int = 0
    fall_height: float = 0.5
    fall_tilt_deg: float = 45.0

    @property
    def substeps(self) -> int:
        """Physics steps per control period."""
        return max(1, round(self.physics_hz / self.control_hz))

    def delay_steps(self, physics_hz: float | None = None) -> int:
        """``servo_delay`` in physics steps (of ``physics_hz``, default this rate)."""
        return max(0, round(self.servo_delay * (physics_hz or self.physics_hz)))


class ServoQueue:
    """Joint commands on their way to the servos, ``delay`` physics steps late.

    :meth:`issue` a command at a physics step; :meth:`applied` says which command the
    servos hold at a physics step (the last one issued at least ``delay`` steps before).
    """

    def __init__(self, first: np.ndarray, delay: int):
        self.delay, self._now = delay, first
        self._pending: deque[tuple[int, np.ndarray]] = deque()

    def issue(self, step: int, command: np.ndarray) -> None:
        """Send ``command`` at physics step ``step``."""
        self._pending.append((step + self.delay, command))

    def applied(self, step: int) -> np.ndarray:
        """The command the servos hold at physics step ``step``."""
        while self._pending and self._pending[0][0] <= step:
            self._now = self._pending.popleft()[1]
        return self._now


def kicks_due(
    pushes: tuple[tuple[float, float, float], ...], t: float, done: int
) -> tuple[int, np.ndarray]:
    """The velocity kicks of ``pushes`` due by time ``t`` [s] that were not applied yet
    (``done`` of them were): how many are done now, and their summed ``(2,)`` Δv [m/s]."""
    dv = np.zeros(2)
    while done < len(pushes) and pushes[done][0] <= t + 1e-9:
        dv += np.asarray(pushes[done][1:3], dtype=float)
        done += 1
    return done, dv


def gravity(opt: SimOptions) -> np.ndarray:
    """``(3,)`` gravity [m/s²] in the world frame for ``opt``'s floor: tilted by
    ``slope_deg`` about y and ``cross_slope_deg`` about x (the floor's normal is
    ``(tan slope, tan cross, 1)`` normalised, and gravity points against it)."""
    th = np.deg2rad(opt.slope_deg)
    if opt.cross_slope_deg == 0.0:  # along the walk only, as before the cross slope existed
        return 9.81 * np.array([-np.sin(th), 0.0, -np.cos(th)])
    normal = np.array([np.tan(th), np.tan(np.deg2rad(opt.cross_slope_deg)), 1.0])
    return -9.81 * normal / np.linalg.norm(normal)


def checked_targets(
    targets: object, joint_names: tuple[str, ...], robot: str, what: str = "joint targets"
) -> np.ndarray:
    """``targets`` as ``(n,)`` finite joint angles [rad], one per name of ``joint_names``
    (of the robot named ``robot``; ``what``: what they are, for the message): the one
    check of every target the simulator or the environment is handed. Ints and floats
    pass (the same array if already float64); bools, text and objects do not.

    Raises:
        ConfigError: not numbers, another shape (e.g. another robot's, nothing is
            broadcast), or not finite (MuJoCo would silently zero a NaN control, driving
            its joint to 0 rad).
    """
    n = len(joint_names)
    try:
        a = np.asarray(targets)
    except ValueError:  # a ragged list
        a = np.asarray(None, dtype=object)
    numbers = a.dtype.kind in "iuf"
    if numbers and a.shape == (n,):
        a = a.astype(float, copy=False)
        if np.isfinite(a).all():  # every tick: one pass
            return a
    want = f"expected {n} finite numbers [rad], a ({n},) array, one per joint of {robot!r}"
    if not numbers:
        raise ConfigError(f"{what}: not numbers (a {type(targets).__name__}); {want}")
    if a.shape != (n,):
        raise ConfigError(f"{what} of shape {a.shape}: {want}")
    bad = np.flatnonzero(~np.isfinite(a))
    i = int(bad[0])
    raise ConfigError(
        f"{what}[{i}] = {a[i]}: {joint_names[i]} is {a[i]} ({bad.size} of {n} not finite); {want}"
    )


def jitter_draws(
    options: SimOptions, nbody: int, joint_names: tuple[str, ...]
) -> tuple[np.ndarray, np.ndarray]:
    """The per-body mass and per-servo stiffness factors of a perturbed robot.

    Every engine draws them here, in this order, from ``options.seed``, so a seed is the
    same robot on MuJoCo and on Bullet.

    Returns:
        ``(nbody,)`` mass (and inertia) factors, the world's (body 0) 1; ``(n,)`` servo
        stiffness factors, in the order of ``joint_names``.
    """
    opt = options
    rng = np.random.default_rng(opt.seed)
    mass = opt.mass_scale * rng.uniform(1 - opt.mass_jitter, 1 + opt.mass_jitter, nbody)
    mass[0] = 1.0
    kp = rng.uniform(1 - opt.kp_jitter, 1 + opt.kp_jitter, len(joint_names))
    return mass, opt.kp_scale * kp


@dataclass(frozen=True)
class Observation:
    """What the robot measures at one control tick.

    Attributes:
        t: time [s]; gyro: ``(3,)`` torso angular velocity [rad/s], torso frame;
        accel: ``(3,)`` torso specific force [m/s²]; foot_force: ``(2, k)`` normal
        force per sole sensor [N], left row then right; joints: ``(n,)`` angles [rad].
    """

    t: float
    gyro: np.ndarray
    accel: np.ndarray
    foot_force: np.ndarray
    joints: np.ndarray


@dataclass
class Rollout:
    """Everything recorded at each control tick of a run (``N`` ticks).

    ``t`` (N,) [s]; ``q_cmd``/``q`` (N, n) commanded/measured joints [rad];
    ``gyro``/``accel`` (N, 3); ``foot_force`` (N, 2, k) [N]; ``torso_pos`` (N, 3) [m]
    and ``torso_quat`` (N, 4) (w, x, y, z) are simulator ground truth, for metrics
    only; ``qpos`` (N, nq) for rendering. ``fell``/``fall_time`` [s] say whether and
    when the torso fell; ``control_dt`` [s]; ``info`` holds per-run extras.
    ``torque`` (N, n) is each servo's output torque [Nm] and ``torque_limit`` (n,) its
    limit [Nm] (simulator ground truth, for metrics only; ``None`` if not recorded).
    """

    t: np.ndarray
    q_cmd: np.ndarray
    q: np.ndarray
    gyro: np.ndarray
    accel: np.ndarray
    foot_force: np.ndarray
    torso_pos: np.ndarray
    torso_quat: np.ndarray
    qpos: np.ndarray
    fell: bool
    fall_time: float | None
    control_dt: float
    joint_names: tuple[str, ...] = ()
    info: dict = field(default_factory=dict)
    torque: np.ndarray | None = None
    torque_limit: np.ndarray | None = None

    @property
    def seconds(self) -> float:
        """Simulated time covered [s]."""
        return len(self.t) * self.control_dt
