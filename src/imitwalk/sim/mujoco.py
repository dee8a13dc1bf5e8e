"""The MuJoCo plant (with `imitwalk.sim.bullet`, the only code that steps physics).

:class:`Plant` is the interface a real robot driver could also implement: reset to
a posture, command joint targets, step one control period, read an
:class:`Observation` (what the robot's own sensors measure). :class:`MujocoPlant`
implements it on MuJoCo with position servos commanded at ``control_hz`` while the
physics runs at ``physics_hz``. :func:`run` closes a loop around any policy and
returns a typed :class:`Rollout`; :func:`playback` plays a joint trajectory.

Robustness options (all default off) live in :class:`SimOptions`: gyro and
accelerometer noise (added in NumPy, MuJoCo does not simulate sensor noise), servo
delay, friction / mass / servo-stiffness scaling and per-part jitter, a shifted torso
centre of mass, a ground slope (gravity tilted about y), velocity kicks (pushes) and
an initial twist.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING, Protocol, runtime_checkable

import mujoco
import numpy as np

from imitwalk.errors import ConfigError, unknown_name
from imitwalk.robots import Robot
from imitwalk.sim.types import (
    ENGINES,
    Observation,
    Rollout,
    ServoQueue,
    SimOptions,
    checked_targets,
    gravity,
    jitter_draws,
    kicks_due,
)

if TYPE_CHECKING:
    from imitwalk.sim.bullet import BulletPlant

__all__ = [
    "ENGINES",
    "MujocoPlant",
    "Observation",
    "Plant",
    "Rollout",
    "SimOptions",
    "make_plant",
    "playback",
    "run",
]


@runtime_checkable
class Plant(Protocol):
    """A robot that takes joint targets at a fixed control period and reports sensors."""

    joint_names: tuple[str, ...]
    control_dt: float

    def reset(self, q: np.ndarray | None = None) -> Observation:
        """Put the robot in posture ``q`` (``(n,)`` rad; ``None``: standing) and hold it."""
        ...

    def command(self, targets: np.ndarray) -> None:
        """Set ``(n,)`` finite joint targets [rad] for the next control period."""
        ...

    def step(self) -> Observation:
        """Advance one control period and return the new observation."""
        ...


class MujocoPlant:
    """:class:`Plant` on MuJoCo. Builds its own (perturbed) model from ``robot``."""

    def __init__(self, robot: Robot, options: SimOptions | None = None):
        self.robot = robot
        self.options = opt = options or SimOptions()
        self.joint_names = robot.joint_names
        self.control_dt = opt.substeps / opt.physics_hz
        self.model = m = robot.compile()
        scale, kps = jitter_draws(opt, m.nbody, robot.joint_names)
        m.opt.timestep = 1.0 / opt.physics_hz
        m.opt.gravity[:] = gravity(opt)
        if opt.friction is not None:
            m.geom_friction[:, 0] = opt.friction
        m.geom_friction[:, 0] *= opt.friction_scale
        # Masses are perturbed after compiling: the model's derived constants (its
        # ``body_subtreemass``, so ``subtree_com`` and ``subtree_linvel``) stay the
        # nominal robot's. Read the perturbed robot's mass and centre of mass from
        # :attr:`mass` and :meth:`com`, never from those.
        m.body_mass[:] *= scale
        m.body_inertia[:] *= scale[:, None]
        m.body_ipos[m.body(robot.torso).id] += np.asarray(opt.com_shift, dtype=float)
        #: the perturbed robot's whole mass [kg]
        self.mass = float(m.body_mass.sum())
        self._jid = np.array([m.joint(j).id for j in robot.mj_joints])
        self._qadr = m.jnt_qposadr[self._jid]
        act_for = {int(m.actuator_trnid[a, 0]): a for a in range(m.nu)}
        self._act = np.array([act_for[j] for j in self._jid])
        m.actuator_gainprm[self._act, 0] *= kps
        m.actuator_biasprm[self._act, 1] *= kps
        self._sign = robot.signs

        def sadr(name: str) -> slice:
            sid = m.sensor(name).id
            return slice(m.sensor_adr[sid], m.sensor_adr[sid] + m.sensor_dim[sid])

        self._gyro = sadr(robot.gyro)
        self._accel = sadr(robot.accelerometer) if robot.accelerometer else None
        self._ff = [[sadr(n) for n in robot.foot_force[s]] for s in ("l", "r")]
        self._torso = m.body(robot.torso).id
        free = [j for j in range(m.njnt) if m.jnt_type[j] == mujoco.mjtJoint.mjJNT_FREE]
        self._base_dof = int(m.jnt_dofadr[free[0]]) if free else None
        self._noise = np.random.default_rng(opt.seed + 7919)
        self.data = mujoco.MjData(m)
        self._delay = opt.delay_steps()
        self._queue = ServoQueue(robot.stand.copy(), self._delay)
        self._steps = self._kicks = 0
        self._cmd = robot.stand.copy()
        self.fell = False
        self.fall_time: float | None = None

    # -- Plant interface ------------------------------------------------------
    def reset(self, q: np.ndarray | None = None) -> Observation:
        """Stand the robot in posture ``q``: ``(n,)`` finite joint angles [rad] in the
        order of :attr:`joint_names` (``None``: standing), and hold it.

        Raises:
            ConfigError: ``q`` of another length (e.g. another robot's), or not finite.
        """
        if q is not None:
            q = checked_targets(q, self.joint_names, self.robot.name, "posture")
        m, d, r = self.model, self.data, self.robot
        mujoco.mj_resetData(m, d)
        if r.stand_ctrl is not None:  # servos of joints without a role hold the posture
            d.ctrl[:] = r.stand_ctrl
        d.qpos[:] = r.stand_qpos
        if q is not None:
            d.qpos[self._qadr] = q * self._sign
            mujoco.mj_kinematics(m, d)
            low = min(self._sole_z(s) for s in ("l", "r"))
            d.qpos[2] -= low - 1e-4
        d.qvel[:6] = self.options.init_twist
        self._cmd = (r.stand if q is None else q).copy()
        self._queue = ServoQueue(self._cmd.copy(), self._delay)
        self._steps = self._kicks = 0
        d.ctrl[self._act] = self._cmd * self._sign
        mujoco.mj_forward(m, d)
        self.fell, self.fall_time = False, None
        return self.observe()

    def command(self, targets: np.ndarray) -> None:
        """Set ``(n,)`` joint targets [rad] for the next control period, clipped to the
        joint ranges.

        Raises:
            ConfigError: targets of another length, or not finite (MuJoCo would zero a
                NaN control silently, driving its joint to 0 rad).
        """
        self._cmd = self.robot.clip(checked_targets(targets, self.joint_names, self.robot.name))

    def step(self) -> Observation:
        m, d, opt = self.model, self.data, self.options
        self._queue.issue(self._steps, self._cmd)
        for _ in range(opt.substeps):
            d.ctrl[self._act] = self._queue.applied(self._steps) * self._sign
            if self._kicks < len(opt.pushes) and self._base_dof is not None:
                self._kicks, dv = kicks_due(opt.pushes, d.time, self._kicks)
                b = self._base_dof  # the free base's linear velocity, world frame
                d.qvel[b : b + 2] += dv
            mujoco.mj_step(m, d)
            self._steps += 1
        self._check_fall()
        return self.observe()

    # -- extras (not part of Plant; BulletPlant has them too) -----------------
    @property
    def nq(self) -> int:
        """Length of the MuJoCo ``qpos``."""
        return self.model.nq

    @property
    def commanded(self) -> np.ndarray:
        """``(n,)`` the joint targets [rad] last commanded (clipped, before any delay)."""
        return self._cmd

    def qpos(self) -> np.ndarray:
        """A copy of the MuJoCo ``qpos`` now (free base, then joints)."""
        return self.data.qpos.copy()

    def observe(self) -> Observation:
        """Sensor readings now, with the configured noise."""
        d, opt = self.data, self.options
        gyro = d.sensordata[self._gyro].copy()
        accel = d.sensordata[self._accel].copy() if self._accel else np.zeros(3)
        if opt.gyro_noise:
            gyro += self._noise.normal(0.0, opt.gyro_noise, 3)
        if opt.accel_noise:
            accel += self._noise.normal(0.0, opt.accel_noise, 3)
        ff = np.array([[d.sensordata[s][0] for s in side] for side in self._ff])
        return Observation(d.time, gyro, accel, ff, d.qpos[self._qadr] * self._sign)

    def torques(self) -> np.ndarray:
        """``(n,)`` each servo's output torque now [Nm], in the robot's joint signs."""
        return self.data.actuator_force[self._act] * self._sign

    def torque_limits(self) -> np.ndarray:
        """``(n,)`` each servo's torque limit [Nm] (:attr:`Robot.torque_limit`: its force
        range and its joint's, ``inf`` if none)."""
        return self.robot.torque_limit.copy()

    def com(self) -> np.ndarray:
        """``(3,)`` the perturbed robot's centre of mass now, in the world frame [m]: its
        bodies' centres weighted by their perturbed masses (``subtree_com`` divides by
        the nominal robot's mass, see ``__init__``)."""
        m, d = self.model, self.data
        return np.asarray(m.body_mass @ d.xipos / self.mass)

    def torso_pose(self) -> tuple[np.ndarray, np.ndarray]:
        """Ground truth torso position ``(3,)`` [m] and quaternion ``(4,)`` (w, x, y, z)."""
        return self.data.xpos[self._torso].copy(), self.data.xquat[self._torso].copy()

    def _sole_z(self, side: str) -> float:
        name = self.robot.soles[side]
        if mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_SITE, name) >= 0:
            return float(self.data.site_xpos[self.model.site(name).id][2])
        return float(self.data.xpos[self.model.body(name).id][2])

    def _check_fall(self) -> None:
        if self.fell:
            return
        d, opt = self.data, self.options
        low = d.xpos[self._torso][2] < opt.fall_height * self.robot.torso_height
        tilt = np.degrees(np.arccos(np.clip(d.xmat[self._torso][8], -1.0, 1.0)))
        if low or tilt > opt.fall_tilt_deg:
            self.fell, self.fall_time = True, float(d.time)


def make_plant(
    robot: Robot, options: SimOptions | None = None, engine: str = "mujoco"
) -> MujocoPlant | BulletPlant:
    """A plant of ``robot`` on ``engine`` (one of :data:`ENGINES`).

    Raises:
        ConfigError: an unknown engine (the message lists the valid ones).
    """
    if engine == "mujoco":
        return MujocoPlant(robot, options)
    if engine == "bullet":
        from imitwalk.sim.bullet import BulletPlant

        return BulletPlant(robot, options)
    raise unknown_name("engine", engine, ENGINES, ConfigError)


Policy = Callable[[int, Observation], np.ndarray]


def run(
    plant: MujocoPlant | BulletPlant,
    policy: Policy,
    steps: int,
    q0: np.ndarray | None = None,
    stop_on_fall: bool = True,
    abandon: Callable[[], bool] | None = None,
) -> Rollout:
    """Run ``policy(tick, obs) -> (n,) targets`` for ``steps`` control periods.

    Args:
        plant: the simulated robot (reset here to ``q0``): a :class:`MujocoPlant` or an
            :class:`imitwalk.sim.bullet.BulletPlant` (``run`` also reads their ground-truth
            extras: ``nq``, ``commanded``, ``qpos()``, ``torques()``, ``torso_pose()``).
        policy: called once per tick with the tick index and the latest observation.
        steps: number of control periods to run.
        q0: ``(n,)`` starting posture [rad]; ``None``: the policy's own ``q0`` if it
            declares one (a controller starts where its trajectory starts, as open-loop
            playback of that trajectory does), else standing.
        stop_on_fall: end the run at the first fall; abandon: end it once this, asked
            after every tick, holds (:func:`imitwalk.parallel.abandoned`).
    """
    if q0 is None:
        q0 = getattr(policy, "q0", None)
    obs = plant.reset(q0)
    n, nq = len(plant.joint_names), plant.nq
    keys = ("t", "q_cmd", "q", "gyro", "accel", "ff", "pos", "quat", "qpos", "torque")
    rec: dict[str, list[object]] = {k: [] for k in keys}
    for k in range(steps):
        target = np.asarray(policy(k, obs), dtype=float)
        plant.command(target)
        obs = plant.step()
        pos, quat = plant.torso_pose()
        row = (obs.t, plant.commanded, obs.joints, obs.gyro, obs.accel, obs.foot_force, pos, quat)
        for key, val in zip(rec, (*row, plant.qpos(), plant.torques()), strict=True):
            rec[key].append(val)
        if (plant.fell and stop_on_fall) or (abandon is not None and abandon()):
            break
    arr = {k: np.asarray(v) for k, v in rec.items()}
    empty = len(arr["t"]) == 0
    return Rollout(
        t=arr["t"],
        q_cmd=arr["q_cmd"].reshape(-1, n),
        q=arr["q"].reshape(-1, n),
        gyro=arr["gyro"].reshape(-1, 3),
        accel=arr["accel"].reshape(-1, 3),
        foot_force=arr["ff"] if not empty else np.zeros((0, 2, 0)),
        torso_pos=arr["pos"].reshape(-1, 3),
        torso_quat=arr["quat"].reshape(-1, 4),
        qpos=arr["qpos"].reshape(-1, nq),
        fell=plant.fell,
        fall_time=plant.fall_time,
        control_dt=plant.control_dt,
        joint_names=plant.joint_names,
        torque=arr["torque"].reshape(-1, n),
        torque_limit=plant.torque_limits(),
    )


def playback(
    plant: MujocoPlant | BulletPlant,
    targets: np.ndarray,
    q0: np.ndarray | None = None,
    stop_on_fall: bool = True,
) -> Rollout:
    """Play ``(N, n)`` joint targets, one row per control period, open loop."""
    targets = np.asarray(targets, dtype=float)
    return run(plant, lambda k, _obs: targets[k], len(targets), q0=q0, stop_on_fall=stop_on_fall)
