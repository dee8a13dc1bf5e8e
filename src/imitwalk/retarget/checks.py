"""Kinematic checks of a retargeted gait, by forward kinematics only."""

from __future__ import annotations

import itertools

import mujoco
import numpy as np

from imitwalk.robots import Robot

__all__ = ["kinematic_checks", "sole_pose"]


def sole_pose(
    model: mujoco.MjModel, data: mujoco.MjData, name: str
) -> tuple[np.ndarray, np.ndarray]:
    """Position ``(3,)`` [m] and rotation ``(3, 3)`` of the sole ``name`` (a site, else a
    body; :attr:`~imitwalk.robots.Robot.soles`) in ``data``, after kinematics."""
    if mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, name) >= 0:
        i = model.site(name).id
        return data.site_xpos[i].copy(), data.site_xmat[i].reshape(3, 3).copy()
    i = model.body(name).id
    return data.xpos[i].copy(), data.xmat[i].reshape(3, 3).copy()


def _closure(q: np.ndarray) -> float:
    """How much bigger the wrap-around step q[-1] → q[0] is than any step inside the loop.

    Per joint, ``max(0, |q[0] - q[-1]| - max_t |q[t+1] - q[t]|)``, the worst joint [rad]:
    zero for a closed loop, the size of the jump for one that is not.
    """
    if len(q) < 3:
        return 0.0
    inner = np.abs(np.diff(q, axis=0)).max(axis=0)
    return float(np.clip(np.abs(q[0] - q[-1]) - inner, 0.0, None).max())


def _mid_swing_ticks(stance: np.ndarray, phase_sigma: np.ndarray) -> list[tuple[int, int]]:
    """``(tick, foot)`` of the tick nearest σ = 0.5 in every swing (a run of ~stance ticks)."""
    out = []
    for j in range(stance.shape[1]):
        swing = (~stance[:, j]).astype(int)
        starts = np.flatnonzero(np.diff(np.r_[0, swing]) == 1)
        ends = np.flatnonzero(np.diff(np.r_[swing, 0]) == -1) + 1
        for a, b in zip(starts, ends, strict=True):
            dist = np.abs(np.nan_to_num(phase_sigma[a:b, j], nan=np.inf) - 0.5)
            if np.isfinite(dist).any():
                out.append((int(a) + int(np.argmin(dist)), j))
    return out


def kinematic_checks(
    robot: Robot, qpos: np.ndarray, stance: np.ndarray, phase_sigma: np.ndarray, q: np.ndarray
) -> dict:
    """Replay whole-body states kinematically and measure the gait.

    Args:
        robot: the robot; qpos: ``(N, nq)`` states of one or more cycles (time order).
        stance: ``(N, 2)`` bool, left/right foot planned on the floor.
        phase_sigma: ``(N, 2)`` swing progress σ ∈ [0, 1] of each foot (NaN in stance).
        q: ``(N, n)`` joint angles of exactly one closed loop (for the wrap check).

    Returns:
        ``stance_tilt_deg_max``, ``swing_clearance_mm_min`` (at mid-swing),
        ``foot_skate_mm_per_step``, ``loop_closure_rad_max`` (see :func:`_closure`),
        ``feet_alternate``,
        ``steps_forward``, ``knee_min_deg``.
    """
    m = robot.compile()
    d = mujoco.MjData(m)
    n = len(qpos)
    pos = np.zeros((n, 2, 3))
    tilt = np.zeros((n, 2))
    for i in range(n):
        d.qpos[:] = qpos[i]
        mujoco.mj_kinematics(m, d)
        for j, s in enumerate("lr"):
            p, rmat = sole_pose(m, d, robot.soles[s])
            pos[i, j] = p
            tilt[i, j] = np.degrees(np.arccos(np.clip(rmat[2, 2], -1.0, 1.0)))
    stance_tilt = float(tilt[stance].max()) if stance.any() else 0.0
    mids = _mid_swing_ticks(stance, phase_sigma)
    clearance = float(min(pos[i, j, 2] for i, j in mids) * 1000) if mids else float("nan")
    skate, landings = [], []
    for j in range(2):
        c = stance[:, j].astype(int)
        starts = np.flatnonzero(np.diff(c) == 1) + 1
        ends = np.flatnonzero(np.diff(c) == -1) + 1
        for a in starts:
            later = ends[ends > a]
            b = int(later[0]) if len(later) else n
            xy = pos[a:b, j, :2]
            skate.append(float(np.linalg.norm(xy.max(0) - xy.min(0)) * 1000))
            landings.append((a, j, float(pos[a, j, 0])))
    landings.sort()
    order = [j for _, j, _ in landings]
    alternate = all(a != b for a, b in itertools.pairwise(order))
    forward = all(
        x2 > x1 + 1e-4 for (_, j1, x1), (_, j2, x2) in itertools.pairwise(landings) if j1 != j2
    )
    wrap = _closure(q)
    knees = [robot.index(k) for k in ("l_knee", "r_knee") if k in robot.joint_names]
    return {
        "stance_tilt_deg_max": stance_tilt,
        "swing_clearance_mm_min": clearance,
        "foot_skate_mm_per_step": float(np.mean(skate)) if skate else 0.0,
        "loop_closure_rad_max": float(wrap),
        "feet_alternate": bool(alternate and len(order) >= 2),
        "steps_forward": bool(forward),
        "knee_min_deg": float(np.degrees(q[:, knees].min())) if knees else float("nan"),
    }
