"""The walkable reference: the robot's own IK solution of a task-space gait plan.

For every scale of a grid the stride is scaled in task space and the IK re-solved
(rather than shrinking a joint pattern); lift and sway stay as they are. See
:mod:`imitwalk.retarget.plan` for the plan and :mod:`imitwalk.retarget.ik` for the IK.
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from imitwalk.retarget.checks import kinematic_checks
from imitwalk.retarget.command import GaitCommand
from imitwalk.retarget.ik import WalkIK, leg_geometry
from imitwalk.retarget.plan import GaitParams, plan_walk
from imitwalk.retarget.reference import PLAN_KEYS, Reference, plan_arrays
from imitwalk.retarget.template import GaitTemplate
from imitwalk.robots import Robot

__all__ = ["WalkableBuild", "build_walkable"]


@dataclass
class WalkableBuild:
    """A built reference and what it cost: ``frames`` solved in ``seconds`` of wall time."""

    reference: Reference
    frames: int
    seconds: float


def build_walkable(
    template: GaitTemplate,
    robot: Robot,
    params: GaitParams,
    scales: Sequence[float] | np.ndarray,
    dt: float,
    ik: WalkIK | None = None,
    check_scale: float = 1.0,
    command: GaitCommand | None = None,
) -> WalkableBuild:
    """Solve the walkable reference at every scale.

    Args:
        template: the human gait; robot: the robot; params: reference parameters.
        scales: stride scales to solve (sorted ascending).
        dt: control period [s].
        ik: a solver to reuse (built if ``None``).
        check_scale: the scale whose kinematics are checked (nearest in the grid).
        command: turn, sidestep, stride fraction and slope (default: straight, level).
    """
    ik = ik or WalkIK(robot)
    geom = leg_geometry(robot)
    scales = np.asarray(sorted(scales), dtype=float)
    command = command or GaitCommand()
    starts, loops, strides, resid, clipped, travel, motion = [], [], [], [], [], [], []
    plans: dict[str, list] = {k: [] for k in PLAN_KEYS}
    t0 = time.perf_counter()
    frames = 0
    check_i = int(np.argmin(np.abs(scales - check_scale)))
    checks: dict = {}
    for si, s in enumerate(scales):
        # two start-up cycles and two steady ones: by the last cycle every foot has
        # landed by the steady rule, so that cycle is the closed loop and the rest,
        # which ends exactly where the loop begins, is the start-up
        plan = plan_walk(
            template, geom, params, float(s), dt, cycles=2, start=True, command=command
        )
        res = ik.solve(plan)
        assert plan.path is not None and plan.motion is not None  # plan_walk sets both
        frames += len(plan.phase)
        n_loop = round(plan.period / dt)
        m = len(plan.phase) - n_loop
        starts.append(res.q[:m])
        loops.append(res.q[m:])
        strides.append(plan.stride)
        travel.append(plan.path[:m, 3] - plan.path[0, 3])
        motion.append(plan.motion)
        for key, val in plan_arrays(plan).items():
            plans[key].append(val)
        resid.append(res.residual_mm)
        for j in np.flatnonzero(res.at_limit.any(axis=0)):
            clipped.append(
                {
                    "scale": float(s),
                    "joint": robot.joint_names[j],
                    "ticks": int(res.at_limit[:, j].sum()),
                    "of": len(plan.phase),
                }
            )
        if si == check_i:
            steady = slice(n_loop, None)  # the stepping part: from the start-up's second cycle
            checks = kinematic_checks(
                robot, res.qpos[steady], plan.stance[steady], plan.swing[steady], res.q[m:]
            )
            checks["scale"] = float(s)
            checks["pelvis_drop_mm_max"] = float(res.pelvis_drop_mm.max())
            phase, stance = plan.phase[m:], plan.stance[m:]
    elapsed = time.perf_counter() - t0
    ref = Reference(
        robot=robot.name,
        joint_names=robot.joint_names,
        mapping="walkable",
        dt=dt,
        period=n_loop * dt,
        scales=scales,
        loops=np.stack(loops),
        starts=np.stack(starts),
        strides=np.array(strides),
        start_travel=np.stack(travel),
        phase=phase,
        stance=stance,
        residual_mm=np.stack(resid),
        clipped=clipped,
        checks=checks,
        params=params,
        plan={k: np.stack(v) for k, v in plans.items()},
        command=command,
        motion=np.stack(motion),
    )
    return WalkableBuild(ref, frames, elapsed)
