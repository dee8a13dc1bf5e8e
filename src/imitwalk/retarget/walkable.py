"""The walkable reference: the robot's own IK solution of a task-space gait plan.

For every scale of a grid the stride is scaled in task space and the IK re-solved
(rather than shrinking a joint pattern); lift and sway stay as they are. See
:mod:`imitwalk.retarget.plan` for the plan and :mod:`imitwalk.retarget.ik` for the IK.
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from imitwalk.retarget.checks import kinematic_checks
from imitwalk.retarget.command import GaitCommand
from imitwalk.retarget.ik import IKResult, WalkIK, leg_geometry
from imitwalk.retarget.plan import GaitParams, LegGeometry, TaskPlan, plan_walk
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


@dataclass
class _Solved:
    """What each solved scale adds to the reference, in scale order: the start-up and loop
    ``(M, n)``, ``(N, n)`` [rad], stride [m], start-up travel ``(M,)`` [m], loop motion
    ``(5,)``, plan arrays, residuals ``(M + N,)`` [mm] and the joints that sat on a limit."""

    starts: list[np.ndarray] = field(default_factory=list)
    loops: list[np.ndarray] = field(default_factory=list)
    strides: list[float] = field(default_factory=list)
    travel: list[np.ndarray] = field(default_factory=list)
    motion: list[np.ndarray] = field(default_factory=list)
    plans: dict[str, list] = field(default_factory=lambda: {k: [] for k in PLAN_KEYS})
    resid: list[np.ndarray] = field(default_factory=list)
    clipped: list[dict] = field(default_factory=list)

    def add(self, robot: Robot, scale: float, plan: TaskPlan, res: IKResult, m: int) -> None:
        """Record one scale's plan and solution (its first ``m`` ticks the start-up)."""
        assert plan.path is not None and plan.motion is not None  # plan_walk sets both
        self.starts.append(res.q[:m])
        self.loops.append(res.q[m:])
        self.strides.append(plan.stride)
        self.travel.append(plan.path[:m, 3] - plan.path[0, 3])
        self.motion.append(plan.motion)
        for key, val in plan_arrays(plan).items():
            self.plans[key].append(val)
        self.resid.append(res.residual_mm)
        self.clipped.extend(_clipped(robot, res, scale, len(plan.phase)))


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
    solved = _Solved()
    t0 = time.perf_counter()
    frames = 0
    check_i = int(np.argmin(np.abs(scales - check_scale)))
    checks: dict = {}
    for si, s in enumerate(scales):
        plan, res = _solve_scale(ik, template, geom, params, float(s), dt, command)
        frames += len(plan.phase)
        n_loop = round(plan.period / dt)
        m = len(plan.phase) - n_loop
        solved.add(robot, float(s), plan, res, m)
        if si == check_i:
            checks = _checks(robot, plan, res, float(s), n_loop, m)
            phase, stance = plan.phase[m:], plan.stance[m:]
    elapsed = time.perf_counter() - t0
    ref = Reference(
        robot=robot.name,
        joint_names=robot.joint_names,
        mapping="walkable",
        dt=dt,
        period=n_loop * dt,
        scales=scales,
        loops=np.stack(solved.loops),
        starts=np.stack(solved.starts),
        strides=np.array(solved.strides),
        start_travel=np.stack(solved.travel),
        phase=phase,
        stance=stance,
        residual_mm=np.stack(solved.resid),
        clipped=solved.clipped,
        checks=checks,
        params=params,
        plan={k: np.stack(v) for k, v in solved.plans.items()},
        command=command,
        motion=np.stack(solved.motion),
    )
    return WalkableBuild(ref, frames, elapsed)


def _solve_scale(
    ik: WalkIK,
    template: GaitTemplate,
    geom: LegGeometry,
    params: GaitParams,
    scale: float,
    dt: float,
    command: GaitCommand,
) -> tuple[TaskPlan, IKResult]:
    """The plan at stride ``scale`` and its IK solution (``dt`` [s] per tick)."""
    # two start-up cycles and two steady ones: by the last cycle every foot has
    # landed by the steady rule, so that cycle is the closed loop and the rest,
    # which ends exactly where the loop begins, is the start-up
    plan = plan_walk(template, geom, params, scale, dt, cycles=2, start=True, command=command)
    return plan, ik.solve(plan)


def _clipped(robot: Robot, res: IKResult, scale: float, ticks: int) -> list[dict]:
    """One entry per joint of ``robot`` that sat on a limit in ``res`` (of ``ticks``)."""
    clipped = []
    for j in np.flatnonzero(res.at_limit.any(axis=0)):
        clipped.append(
            {
                "scale": scale,
                "joint": robot.joint_names[j],
                "ticks": int(res.at_limit[:, j].sum()),
                "of": ticks,
            }
        )
    return clipped


def _checks(robot: Robot, plan: TaskPlan, res: IKResult, scale: float, n_loop: int, m: int) -> dict:
    """Kinematic checks of the stepping part of one scale's solution (``m`` start-up
    ticks, then a loop of ``n_loop``)."""
    steady = slice(n_loop, None)  # the stepping part: from the start-up's second cycle
    checks = kinematic_checks(
        robot, res.qpos[steady], plan.stance[steady], plan.swing[steady], res.q[m:]
    )
    checks["scale"] = scale
    checks["pelvis_drop_mm_max"] = float(res.pelvis_drop_mm.max())
    return checks
