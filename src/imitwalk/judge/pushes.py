"""Push recovery: the largest kick a controller survives, by direction and gait phase.

On the nominal robot at the scale the run reached, the walk is kicked once, two gait
cycles after the start-up, at one of :data:`PHASES` phases of the cycle and in one of
four horizontal directions (:data:`DIRECTIONS`, in the walking frame: forward, back,
left, right). A kick is a velocity change of the whole robot (as the protocols' pushes,
:mod:`imitwalk.sim.protocol`). For every (controller, direction, phase) the largest kick the
robot survives for :data:`AFTER_S` seconds is found by bisection between 0 and
:func:`top_speed` (the protocols' largest kick for this robot's height, twice over).
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass, replace
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from imitwalk.judge.records import PushSettings, PushSide, PushVerdict
from imitwalk.judge.replay import LoadedRun, load_run
from imitwalk.parallel import run_parallel
from imitwalk.robots import Robot
from imitwalk.sim.types import SimOptions

if TYPE_CHECKING:
    from imitwalk.retarget.reference import Reference
    from imitwalk.step.gait import StepGait

__all__ = ["AFTER_S", "DIRECTIONS", "PHASES", "PushJob", "push_recovery", "top_speed"]

#: Kick directions in the walking frame, by name: the angle of Δv from forward [rad].
DIRECTIONS = {"forward": 0.0, "left": math.pi / 2, "back": math.pi, "right": -math.pi / 2}
#: Phases of the gait cycle kicked at (0: the left heel strike).
PHASES = 8
#: How long after the kick the robot must stay up [s].
AFTER_S = 5.0
#: Bisection steps (the resolution is the top speed / 2**STEPS).
STEPS = 6


def top_speed(height: float) -> float:
    """The bisection's upper end [m/s]: twice the hard protocol's largest kick, 0.5 m/s
    for a 1.3 m robot Froude-scaled by sqrt(height / 1.3 m)."""
    return 2 * 0.5 * math.sqrt(height / 1.3)


@dataclass(frozen=True)
class PushJob:
    """One kick: ``controller`` of the run at ``run_dir`` on the nominal robot at
    ``scale``, kicked by ``speed`` [m/s] towards ``direction`` at ``phase`` (of
    :data:`PHASES`)."""

    run_dir: str
    robot: Robot
    controller: str
    scale: float
    direction: str
    phase: int
    speed: float


_CACHE: dict = {}


def _run(path: str) -> LoadedRun:
    if path not in _CACHE:
        _CACHE.clear()
        _CACHE[path] = load_run(path)
    return _CACHE[path]


def kick_time(ref: Reference | StepGait, phase: int) -> float:
    """When [s] the kick at ``phase`` comes: two cycles after the start-up, plus the phase
    (a stepping gait says when its own walk is steady:
    :meth:`~imitwalk.step.gait.StepGait.kick_time`)."""
    if hasattr(ref, "kick_time"):
        return float(ref.kick_time(phase, PHASES))
    n, m = ref.loops.shape[1], ref.starts.shape[1]
    return (m + 2 * n + round(phase * n / PHASES)) * ref.dt


def survives(job: PushJob) -> bool:
    """Whether the robot is still up :data:`AFTER_S` after the kick (a worker's job)."""
    from imitwalk.sim.mujoco import make_plant, run

    lr = _run(job.run_dir)
    ref = lr.ref
    t = kick_time(ref, job.phase)
    seconds = t + AFTER_S
    track = ref.track(job.scale, seconds)  # (T, 3): the commanded heading is column 2
    heading = float(track[min(int(round(t / ref.dt)), len(track) - 1), 2])
    angle = heading + DIRECTIONS[job.direction]
    dv = (t, job.speed * math.cos(angle), job.speed * math.sin(angle))
    opts = ref.sim_options(replace(SimOptions(), pushes=(dv,) if job.speed > 0 else ()))
    policy = lr.policy(job.controller, job.robot, job.scale, seconds)
    ro = run(make_plant(job.robot, opts, lr.engine), policy, round(seconds / ref.dt))
    return not ro.fell


def push_recovery(
    run_dir: str | Path,
    robot: Robot,
    controllers: Iterable[str] | None = None,
    scale: float | None = None,
    workers: int | None = None,
) -> PushVerdict:
    """The largest kick survived per controller, direction and phase (a table [m/s]).

    Returns:
        a :class:`~imitwalk.judge.records.PushVerdict`; in its tables a speed equal to
        ``top_mps`` means "survived the largest kick tried", 0 that even no kick is
        survived (the walk falls by itself).
    """
    lr = load_run(run_dir)
    names = lr.controllers() if controllers is None else tuple(controllers)
    for c in names:
        lr.policy(c, robot)  # a one-line error for a controller the run cannot build
    scale = lr.scale if scale is None else scale
    top = top_speed(robot.height)
    cells = [(c, d, p) for c in names for d in DIRECTIONS for p in range(PHASES)]
    lo = {cell: 0.0 for cell in cells}
    hi = {cell: top for cell in cells}
    jobs = [PushJob(str(run_dir), robot, c, scale, d, p, 0.0) for c, d, p in cells]
    jobs += [PushJob(str(run_dir), robot, c, scale, d, p, top) for c, d, p in cells]
    res = run_parallel(survives, jobs, workers)
    calm, strong = res[: len(cells)], res[len(cells) :]
    open_ = []
    for cell, ok0, ok1 in zip(cells, calm, strong, strict=True):
        if not ok0:
            hi[cell] = 0.0  # falls without a kick: nothing to bisect
        elif ok1:
            lo[cell] = top  # survives the largest kick tried
        else:
            open_.append(cell)
    for _ in range(STEPS):
        if not open_:
            break
        mids = {cell: 0.5 * (lo[cell] + hi[cell]) for cell in open_}
        jobs = [PushJob(str(run_dir), robot, c, scale, d, p, mids[(c, d, p)]) for c, d, p in open_]
        for cell, ok in zip(open_, run_parallel(survives, jobs, workers), strict=True):
            if ok:
                lo[cell] = mids[cell]
            else:
                hi[cell] = mids[cell]
    settings = PushSettings(
        scale=scale,
        phases=PHASES,
        directions=tuple(DIRECTIONS),
        after_s=AFTER_S,
        top_mps=top,
        resolution_mps=top / 2**STEPS,
        kick_times_s=tuple(kick_time(lr.ref, p) for p in range(PHASES)),
    )
    sides = {}
    for c in names:
        table = {d: [lo[(c, d, p)] for p in range(PHASES)] for d in DIRECTIONS}
        sides[c] = PushSide(
            table=table,
            min_by_direction={d: float(min(v)) for d, v in table.items()},
            mean=float(np.mean([v for row in table.values() for v in row])),
        )
    return PushVerdict(settings, sides)
