"""The servos' sag taken out of the reference: a computed-torque feedforward.

A position servo holds its joint only where its torque ``kp·(q_target − q) − kv·q̇`` is
what the motion needs, so a robot played its reference sags and lags behind it: in single
support G1's stance hip roll carries about m·g·(half the stance width) ≈ 39 Nm, 4.5° at
kp 500. :func:`reference_offsets` gives, for every joint target, the offset
``(τ + kv·q̇_ref)/kp`` (Craig's computed-torque feedforward, through a position servo),
where ``τ`` is the joint torque the reference needs on the robot's *nominal* model. It
reads no sensor and no state of a simulation: it is part of the reference, as the paper's
joint angles are, and the learner picks how much of it to add
(:class:`~imitwalk.balance.tickconfig.TrialConfig`'s ``feedforward``).

- The floating base is placed every tick so that the planned stance sole stays flat and
  still (its velocity from the sole's Jacobian, its acceleration by finite differences,
  smoothed over :data:`SMOOTH` ticks).
- ``mj_inverse`` gives the generalised forces of that motion, contacts off.
- The soles' wrenches are what the base's six rows need (one sole down: solved; both:
  least norm weighted by each sole's share of the plan's load), and ``τ`` is the rest.
"""

from __future__ import annotations

import hashlib
from typing import TYPE_CHECKING

import mujoco
import numpy as np
from scipy.ndimage import gaussian_filter1d

from imitwalk.errors import ConfigError
from imitwalk.retarget.reference import Reference

if TYPE_CHECKING:
    from imitwalk.robots import Robot

__all__ = ["CLIP", "SMOOTH", "reference_offsets", "servo_offsets", "walk_offsets"]

#: Accelerations are smoothed over this many ticks (σ); offsets are clipped to ±CLIP [rad].
SMOOTH, CLIP = 2.0, 0.2

_CACHE: dict[tuple, tuple[np.ndarray, np.ndarray, dict]] = {}


def _servo_gains(m: mujoco.MjModel, jid: list[int]) -> tuple[np.ndarray, np.ndarray]:
    """``(n,)`` kp [Nm/rad] and kv [Nm·s/rad] of each joint's position servo (0: none)."""
    kp, kv = np.zeros(len(jid)), np.zeros(len(jid))
    for a in range(m.nu):
        if m.actuator_trntype[a] == mujoco.mjtTrn.mjTRN_JOINT and m.actuator_trnid[a, 0] in jid:
            i = jid.index(m.actuator_trnid[a, 0])
            kp[i], kv[i] = m.actuator_gainprm[a, 0], -m.actuator_biasprm[a, 2]
    return kp, kv


def servo_offsets(
    robot: Robot, q_ref: np.ndarray, stance: np.ndarray, share: np.ndarray, dt: float
) -> np.ndarray:
    """``(T, n)`` target offsets [rad] so that the nominal servos give the reference's torques.

    Args:
        robot: the robot (:class:`~imitwalk.robots.Robot`); q_ref: ``(T, n)`` canonical
            joint targets [rad]; stance: ``(T, 2)`` planned feet down (left, right);
            share: ``(T,)`` the left sole's share of the load; dt: the control period [s].
    """
    m = robot.compile()
    m.opt.disableflags |= mujoco.mjtDisableBit.mjDSBL_CONTACT
    d = mujoco.MjData(m)
    jid = [m.joint(j).id for j in robot.mj_joints]
    qadr, dadr = m.jnt_qposadr[jid], m.jnt_dofadr[jid]
    kp, kv = _servo_gains(m, jid)
    soles = [m.site(robot.soles[s]).id for s in ("l", "r")]
    T, nv = len(q_ref), m.nv
    qdot = np.gradient(q_ref * robot.signs, dt, axis=0)  # (T, n) MJCF joint rates [rad/s]
    qpos, qvel = np.zeros((T, m.nq)), np.zeros((T, nv))
    jacs = np.zeros((T, 2, 6, nv))  # each sole's Jacobian: position rows, then rotation
    quat = np.zeros(4)
    for t in range(T):
        st = soles[0] if share[t] >= 0.5 else soles[1]
        d.qpos[:] = robot.stand_qpos
        d.qpos[:3], d.qpos[3:7] = (0.0, 0.0, 5.0), (1, 0, 0, 0)
        d.qpos[qadr] = q_ref[t] * robot.signs
        mujoco.mj_kinematics(m, d)
        # the base turned so that the stance sole is level (and faces +x)
        mujoco.mju_mat2Quat(quat, d.site_xmat[st].reshape(3, 3).T.copy().ravel())
        d.qpos[3:7] = quat
        mujoco.mj_kinematics(m, d)
        mujoco.mj_comPos(m, d)
        for j, s in enumerate(soles):
            mujoco.mj_jacSite(m, d, jacs[t, j, :3], jacs[t, j, 3:], s)
        # the soles planned down stay still (least squares with both down)
        J = np.vstack([jacs[t, j] for j, s in enumerate(soles) if stance[t, j] or s == st])
        qvel[t, dadr] = qdot[t]
        qvel[t, :6] = np.linalg.lstsq(J[:, :6], -J[:, dadr] @ qdot[t], rcond=None)[0]
        qpos[t] = d.qpos
    qacc = gaussian_filter1d(np.gradient(qvel, dt, axis=0), SMOOTH, axis=0, mode="nearest")
    out = np.zeros_like(q_ref)
    for t in range(T):
        d.qpos[:], d.qvel[:], d.qacc[:] = qpos[t], qvel[t], qacc[t]
        mujoco.mj_inverse(m, d)
        b, J = d.qfrc_inverse.copy(), jacs[t].reshape(12, nv)
        w = np.repeat(np.array([share[t], 1.0 - share[t]]) * stance[t] + 1e-6, 6)
        A = J[:, :6].T  # (6, 12): the base's rows of Jᵀ
        f = w * (A.T @ np.linalg.solve((A * w) @ A.T, b[:6]))  # weighted least norm
        tau = b[dadr] - (J.T @ f)[dadr]
        out[t] = (tau + kv * qvel[t, dadr]) / np.where(kp > 0, kp, np.inf) * robot.signs
    return np.clip(out, -CLIP, CLIP)


def _cycles(ref: Reference, robot: Robot, scale: float) -> tuple[np.ndarray, np.ndarray, dict]:
    """:func:`servo_offsets` of the start-up and first loop ``(M + N, n)``, and of one
    loop in the steady walk ``(N, n)`` (the second of three, clear of both ends' finite
    differences): every later cycle repeats it. Computed once per reference, scale and
    robot in a process (the last few kept), with the walks built from them by length."""
    m, n = ref.starts.shape[1], ref.loops.shape[1]
    q = ref.trajectory(scale, (m + 3 * n) * ref.dt)
    key = (hashlib.sha1(q.tobytes()).hexdigest(), str(robot.mjcf), robot.name, robot.kp.tobytes())
    if key not in _CACHE:
        if len(_CACHE) >= 4:
            _CACHE.pop(next(iter(_CACHE)))
        down, share = ref.planned_load(scale, len(q))
        out = servo_offsets(robot, q, down, share, ref.dt)
        _CACHE[key] = (out[: m + n], out[m + n : m + 2 * n], {})
    return _CACHE[key]


def reference_offsets(ref: Reference, robot: Robot, scale: float, seconds: float) -> np.ndarray:
    """``(T, n)`` :func:`servo_offsets` of ``ref`` at ``scale`` for ``seconds`` (``T`` the
    ticks of :meth:`Reference.trajectory`), on ``robot``'s nominal model: the start-up and
    first loop as computed, then the steady loop repeated (:meth:`Reference.loop_index`),
    so that a walk of any length costs one computation of four cycles.

    Raises:
        ConfigError: the reference has no task-space plan (the paper's mapping).
    """
    if not ref.plan:
        raise ConfigError(
            "the feedforward needs the reference's task-space plan; the paper's mapping "
            "has none: use trials.feedforward=0 or the walkable mapping"
        )
    first, loop, walks = _cycles(ref, robot, scale)
    T = len(ref.trajectory(scale, seconds))
    if T not in walks:
        i, c = ref.loop_index(np.arange(T))
        m = ref.starts.shape[1]
        walks[T] = np.where((c == 0)[:, None], first[i], loop[(i - m) % len(loop)])
    return walks[T]


def walk_offsets(
    ref: Reference, robot: Robot, scale: float, seconds: float, fraction: float
) -> np.ndarray | None:
    """``fraction`` × :func:`reference_offsets` for a walk of ``seconds`` whose clock may
    wait (``(T', n)``, ``T'`` the ticks of twice as long), or ``None`` at a fraction of 0."""
    if not fraction:
        return None
    return fraction * reference_offsets(ref, robot, scale, 2.0 * seconds)
