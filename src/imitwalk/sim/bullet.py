"""A second physics engine: the same robot, servos and sensors on PyBullet.

:class:`BulletPlant` implements :class:`imitwalk.sim.mujoco.Plant` on Bullet (the ``pybullet``
wheel, already a dependency for the default clip): a reference or a controller learned on
MuJoCo plays unchanged on another contact model and integrator (``imitwalk evaluate RUN
--protocol bullet``), and the whole method runs on it (``--set engine=bullet``).

The robot is the MuJoCo model written out as URDF (:func:`imitwalk.robots.urdf.to_urdf`):
the same masses, inertias, joint axes, ranges and collision shapes. The servos are the
MJCF's position actuators (``kp``, ``kv``, joint damping, torque limit), applied as torques
at 5 kHz and integrated implicitly joint by joint (:class:`imitwalk.sim.servo.StablePD`:
Bullet has no rotor inertia, and an explicit PD diverges on light links); joint friction
loss is left out. The gyro is read at its site; the accelerometer there from the site's
velocity change over the control period (a 10 ms mean, where MuJoCo's is instantaneous);
each touch sensor as the normal force of the contacts inside its box, as MuJoCo's. The
perturbations of :class:`~imitwalk.sim.types.SimOptions` use the same random draws as
:class:`~imitwalk.sim.mujoco.MujocoPlant`, so seed ``s`` is the same robot.
"""

from __future__ import annotations

import contextlib
from collections.abc import Sequence

import mujoco
import numpy as np
import pybullet as pb

from imitwalk.robots import Robot
from imitwalk.robots.servos import actuator_kind, torque_limit
from imitwalk.robots.urdf import UrdfRobot, urdf_file
from imitwalk.sim.servo import StablePD
from imitwalk.sim.types import (
    Observation,
    ServoQueue,
    SimOptions,
    checked_targets,
    gravity,
    jitter_draws,
    kicks_due,
)

__all__ = ["BulletPlant"]


def _rot(quat_xyzw: Sequence[float]) -> np.ndarray:
    return np.array(pb.getMatrixFromQuaternion(quat_xyzw)).reshape(3, 3)


class BulletPlant:
    """:class:`~imitwalk.sim.mujoco.Plant` on PyBullet, built from ``robot`` and ``options``.

    ``physics_hz`` replaces ``options.physics_hz`` (see the module's note on stability).
    """

    def __init__(self, robot: Robot, options: SimOptions | None = None, physics_hz: float = 5000.0):
        self.robot = robot
        self.options = opt = options or SimOptions()
        self.joint_names = robot.joint_names
        self.substeps = max(1, round(physics_hz / opt.control_hz))
        self.dt = 1.0 / (self.substeps * opt.control_hz)
        self.control_dt = 1.0 / opt.control_hz
        path, u = urdf_file(robot, tuple(opt.com_shift))
        m = robot.compile()
        self.nq = m.nq
        self.client = c = pb.connect(pb.DIRECT)
        self.gravity = gravity(opt)
        self.floor = self._make_floor()
        self.body = pb.loadURDF(str(path), flags=pb.URDF_USE_INERTIA_FROM_FILE, physicsClientId=c)
        joint = self._index_joints(u, m)
        scale, kps = jitter_draws(opt, m.nbody, robot.joint_names)  # as MujocoPlant's
        self._set_dynamics(m, u, scale)
        self._make_servos(m, joint, kps)
        self._imu = self._site(m, robot.gyro)
        self._touch = [[self._site(m, n) for n in robot.foot_force[s]] for s in ("l", "r")]
        self._soles = [self._site(m, robot.soles[s], sensor=False) for s in ("l", "r")]
        self._torso = self._link_of_body[m.body(robot.torso).id]
        self._all_dofs = list(range(pb.getNumJoints(self.body, physicsClientId=c)))
        self._noise = np.random.default_rng(opt.seed + 7919)
        self._cmd = robot.stand.copy()
        self._queue = ServoQueue(self._cmd.copy(), opt.delay_steps(1.0 / self.dt))
        self._steps = self._kicks = 0
        self._accel = np.zeros(3)
        self._imu_now: tuple[np.ndarray, ...] = (np.zeros(3), np.zeros(3), np.eye(3))  # (v, ω, R)
        self.time = 0.0
        self.fell = False
        self.fall_time: float | None = None

    # -- building ---------------------------------------------------------------
    def _make_floor(self) -> int:
        """Set gravity and the time step, and add the floor: its body id."""
        c = self.client
        pb.setGravity(*self.gravity, physicsClientId=c)
        pb.setTimeStep(self.dt, physicsClientId=c)
        plane = pb.createCollisionShape(pb.GEOM_PLANE, physicsClientId=c)
        floor = pb.createMultiBody(0, plane, physicsClientId=c)
        pb.changeDynamics(floor, -1, lateralFriction=1.0, physicsClientId=c)
        return floor

    def _index_joints(self, u: UrdfRobot, m: mujoco.MjModel) -> dict[str, int]:
        """The loaded robot's joint index by MJCF joint name; sets ``_link_of_body`` (MuJoCo
        body -> link) and releases the joints' default velocity motors."""
        c = self.client
        link = {u.base: -1}
        joint = {}
        for i in range(pb.getNumJoints(self.body, physicsClientId=c)):
            info = pb.getJointInfo(self.body, i, physicsClientId=c)
            link[info[12].decode()] = i
            joint[info[1].decode()] = i
            pb.setJointMotorControl2(self.body, i, pb.VELOCITY_CONTROL, force=0, physicsClientId=c)
        self._link_of_body = [link.get(u.links[b]) for b in range(m.nbody)]
        return joint

    def _set_dynamics(self, m: mujoco.MjModel, u: UrdfRobot, scale: np.ndarray) -> None:
        """Each link's mass and inertia (times ``scale`` ``(nbody,)``) and friction, and no
        velocity damping."""
        c, opt = self.client, self.options
        for b in range(1, m.nbody):
            mu = opt.friction if opt.friction is not None else u.friction[b]
            mass, inertia = m.body_mass[b] * scale[b], m.body_inertia[b] * scale[b]
            pb.changeDynamics(
                self.body,
                self._link_of_body[b],
                mass=max(float(mass), 1e-6),  # as the URDF's
                localInertiaDiagonal=inertia.tolist(),
                lateralFriction=float(mu * opt.friction_scale),
                physicsClientId=c,
            )
        # Bullet damps every multibody's velocities by default; MuJoCo does not. (Passed
        # with a link index, pybullet applies these to the base and drops the mass.)
        pb.changeDynamics(self.body, -1, linearDamping=0.0, angularDamping=0.0, physicsClientId=c)

    def _make_servos(self, m: mujoco.MjModel, joint: dict[str, int], kps: np.ndarray) -> None:
        """The role joints' servos (stiffness times ``kps`` ``(n,)``), and servos holding the
        standing posture on other hinges with a position servo."""
        robot = self.robot
        jid = [m.joint(j).id for j in robot.mj_joints]
        self._qadr = m.jnt_qposadr[jid]
        self._dof = [joint[j] for j in robot.mj_joints]
        act_for = {int(m.actuator_trnid[a, 0]): a for a in range(m.nu)}
        # hinges without a role that have a position servo hold the standing posture
        held = [j for j in act_for if j not in jid and m.joint(j).name in joint]
        held = [j for j in held if actuator_kind(m, act_for[j]) == "position"]
        self._held = [joint[m.joint(j).name] for j in held]
        self._held_target = robot.stand_qpos[m.jnt_qposadr[held]] if held else np.zeros(0)
        every = [*jid, *held]
        act = np.array([act_for[j] for j in every])
        kd = -m.actuator_biasprm[act, 2] + m.dof_damping[m.jnt_dofadr[every]]
        self.limit = robot.torque_limit
        limit = np.r_[self.limit, [torque_limit(m, act_for[j], j) for j in held]]
        kp = np.r_[robot.kp * kps, m.actuator_gainprm[[act_for[j] for j in held], 0]]
        self.servo = StablePD(kp, kd, limit, self.dt)
        self._sign = robot.signs
        self._stand_qpos = robot.stand_qpos.copy()

    def _site(
        self, m: mujoco.MjModel, name: str, sensor: bool = True
    ) -> tuple[int, np.ndarray, np.ndarray]:
        """(link, position in it, half-size) of a sensor's site, or of a sole (a site,
        else a body's origin)."""
        if not sensor and name not in [m.site(i).name for i in range(m.nsite)]:
            return self._link_of_body[m.body(name).id], np.zeros(3), np.zeros(3)
        sid = m.sensor(name).objid[0] if sensor else m.site(name).id
        link = self._link_of_body[m.site_bodyid[sid]]
        return link, m.site_pos[sid].copy(), m.site_size[sid].copy()

    def __del__(self) -> None:
        with contextlib.suppress(Exception):  # already gone at interpreter exit
            pb.disconnect(self.client)

    # -- geometry --------------------------------------------------------------
    def _frame(self, link: int) -> tuple[np.ndarray, np.ndarray, tuple]:
        """World position ``(3,)``, rotation ``(3, 3)`` and (x, y, z, w) quaternion of a
        link's URDF frame (``-1``: the base)."""
        c = self.client
        if link == -1:
            pos, orn = pb.getBasePositionAndOrientation(self.body, physicsClientId=c)
            ipos, iorn = pb.getDynamicsInfo(self.body, -1, physicsClientId=c)[3:5]
            inv = pb.invertTransform(ipos, iorn)
            pos, orn = pb.multiplyTransforms(pos, orn, *inv)
        else:
            st = pb.getLinkState(self.body, link, computeForwardKinematics=1, physicsClientId=c)
            pos, orn = st[4], st[5]
        return np.array(pos), _rot(orn), orn

    def _place_base(self, pos: Sequence[float], orn: Sequence[float]) -> None:
        """Put the base link's URDF frame (not its centre of mass) at ``pos``, ``orn``."""
        ipos, iorn = pb.getDynamicsInfo(self.body, -1, physicsClientId=self.client)[3:5]
        pos, orn = pb.multiplyTransforms(pos, orn, ipos, iorn)
        pb.resetBasePositionAndOrientation(self.body, pos, orn, physicsClientId=self.client)

    def _site_velocity(self, link: int, offset: np.ndarray) -> tuple[np.ndarray, ...]:
        """A site's world velocity ``(3,)``, its link's angular velocity and rotation."""
        c = self.client
        pos, rot, _ = self._frame(link)
        if link == -1:
            v, w = pb.getBaseVelocity(self.body, physicsClientId=c)
            com = pb.getBasePositionAndOrientation(self.body, physicsClientId=c)[0]
        else:
            st = pb.getLinkState(self.body, link, computeLinkVelocity=1, physicsClientId=c)
            v, w, com = st[6], st[7], st[0]
        w = np.array(w)
        return np.array(v) + np.cross(w, pos + rot @ offset - np.array(com)), w, rot

    # -- Plant interface ------------------------------------------------------
    def reset(self, q: np.ndarray | None = None) -> Observation:
        """Stand the robot in posture ``q``: ``(n,)`` finite joint angles [rad] in the
        order of :attr:`joint_names` (``None``: standing), and hold it.

        Raises:
            ConfigError: ``q`` of another length (e.g. another robot's), or not finite.
        """
        c, r, opt = self.client, self.robot, self.options
        qpos = self._stand_qpos.copy()
        q = r.stand if q is None else checked_targets(q, self.joint_names, r.name, "posture")
        qpos[self._qadr] = q * self._sign
        orn = [*qpos[4:7], qpos[3]]  # (x, y, z, w)
        self._place_base([0.0, 0.0, 0.0], orn)
        angles = np.r_[qpos[self._qadr], self._held_target]
        for i, angle in zip(self._dof + self._held, angles, strict=True):
            pb.resetJointState(self.body, i, float(angle), 0.0, physicsClientId=c)
        low = np.inf
        for link, off, _ in self._soles:
            pos, rot, _ = self._frame(link)
            low = min(low, (pos + rot @ off)[2])
        self._place_base([*qpos[:2], -low + 1e-4], orn)
        tw = np.asarray(opt.init_twist, dtype=float)  # angular part in the base's frame
        lin, ang = tw[:3].tolist(), (_rot(orn) @ tw[3:]).tolist()
        pb.resetBaseVelocity(self.body, lin, ang, physicsClientId=c)
        self._cmd = q.copy()
        self._queue = ServoQueue(self._cmd.copy(), opt.delay_steps(1.0 / self.dt))
        self._steps = self._kicks = 0
        self._imu_now = self._site_velocity(*self._imu[:2])  # (v, ω, R) of the IMU site
        self._accel = np.zeros(3)
        self.servo.reset()
        self.time = 0.0
        self.fell, self.fall_time = False, None
        return self.observe()

    def command(self, targets: np.ndarray) -> None:
        """Set ``(n,)`` joint targets [rad] for the next control period, clipped to the
        joint ranges.

        Raises:
            ConfigError: targets of another length, or not finite.
        """
        self._cmd = self.robot.clip(checked_targets(targets, self.joint_names, self.robot.name))

    def step(self) -> Observation:
        c, opt = self.client, self.options
        cid = {"physicsClientId": c}
        self._queue.issue(self._steps, self._cmd)
        states = pb.getJointStates(self.body, self._all_dofs, physicsClientId=c)
        mass = np.diag(pb.calculateMassMatrix(self.body, [s[0] for s in states], physicsClientId=c))
        dofs = self._dof + self._held  # the held hinges' servos keep the standing posture
        mjj = mass[6 + np.array(dofs)]  # each joint's own inertia [kg m²]
        for _ in range(self.substeps):
            states = pb.getJointStates(self.body, dofs, physicsClientId=c)
            q, qd = np.array([s[:2] for s in states]).T  # angles, velocities
            target = np.r_[self._queue.applied(self._steps) * self._sign, self._held_target]
            tau = self.servo.torque(target, q, qd, mjj).tolist()
            pb.setJointMotorControlArray(self.body, dofs, pb.TORQUE_CONTROL, forces=tau, **cid)
            if self._kicks < len(opt.pushes):
                self._kicks, dv = kicks_due(opt.pushes, self.time, self._kicks)
                if dv.any():  # the whole robot's horizontal velocity, as MuJoCo's kick
                    v, w = pb.getBaseVelocity(self.body, **cid)
                    v = [v[0] + dv[0], v[1] + dv[1], v[2]]
                    pb.resetBaseVelocity(self.body, v, w, **cid)
            pb.stepSimulation(physicsClientId=c)
            self.time += self.dt
            self._steps += 1
        v_before, self._imu_now = self._imu_now[0], self._site_velocity(*self._imu[:2])
        self._accel = (self._imu_now[0] - v_before) / self.control_dt
        self._check_fall()
        return self.observe()

    # -- extras (as MujocoPlant's) -------------------------------------------
    def observe(self) -> Observation:
        """Sensor readings now, with the configured noise."""
        opt = self.options
        _, w, rot = self._imu_now
        gyro = rot.T @ w
        accel = rot.T @ (self._accel - self.gravity)
        if opt.gyro_noise:
            gyro = gyro + self._noise.normal(0.0, opt.gyro_noise, 3)
        if opt.accel_noise:
            accel = accel + self._noise.normal(0.0, opt.accel_noise, 3)
        return Observation(self.time, gyro, accel, self._foot_forces(), self.joints())

    @property
    def commanded(self) -> np.ndarray:
        """``(n,)`` the joint targets [rad] last commanded (clipped, before any delay)."""
        return self._cmd

    def joints(self) -> np.ndarray:
        """``(n,)`` joint angles [rad], canonical signs."""
        states = pb.getJointStates(self.body, self._dof, physicsClientId=self.client)
        return np.array([s[0] for s in states]) * self._sign

    def _foot_forces(self) -> np.ndarray:
        out = np.zeros((2, max(len(s) for s in self._touch)))
        for k, sensors in enumerate(self._touch):
            link = sensors[0][0]
            pos, rot, _ = self._frame(link)
            for cp in pb.getContactPoints(self.body, self.floor, link, physicsClientId=self.client):
                local = rot.T @ (np.array(cp[5]) - pos)
                for i, (_, centre, half) in enumerate(sensors):
                    if np.all(np.abs(local - centre) <= half + 1e-3):
                        out[k, i] += cp[9]
                        break
        return out

    def qpos(self) -> np.ndarray:
        """The MuJoCo ``qpos`` of this state (for rendering a Bullet run with MuJoCo)."""
        pos, _, orn = self._frame(-1)
        out = self._stand_qpos.copy()
        out[:7] = [*pos, orn[3], orn[0], orn[1], orn[2]]
        out[self._qadr] = self.joints() * self._sign
        return out

    def torques(self) -> np.ndarray:
        """``(n,)`` each servo's output torque over the last physics step [Nm]."""
        return self.servo.tau[: len(self._dof)] * self._sign

    def torque_limits(self) -> np.ndarray:
        """``(n,)`` each servo's torque limit [Nm]."""
        return self.limit.copy()

    def torso_pose(self) -> tuple[np.ndarray, np.ndarray]:
        """Ground truth torso position ``(3,)`` [m] and quaternion ``(4,)`` (w, x, y, z)."""
        pos, _, orn = self._frame(self._torso)
        return pos, np.array([orn[3], orn[0], orn[1], orn[2]])

    def _check_fall(self) -> None:
        if self.fell:
            return
        pos, rot, _ = self._frame(self._torso)
        low = pos[2] < self.options.fall_height * self.robot.torso_height
        tilt = np.degrees(np.arccos(np.clip(rot[2, 2], -1.0, 1.0)))
        if low or tilt > self.options.fall_tilt_deg:
            self.fell, self.fall_time = True, float(self.time)
