"""One walk of the stepping gait on one robot, and what it scored.

The learner (:mod:`imitwalk.step.learn`) and the judge walk many of these in parallel
(:func:`imitwalk.parallel.run_parallel`); only the simulator steps the physics.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass
from typing import TYPE_CHECKING

import numpy as np

from imitwalk.parallel import abandoned
from imitwalk.robots import Robot
from imitwalk.sim.metrics import WalkMetrics
from imitwalk.sim.types import Rollout, SimOptions
from imitwalk.step.gains import StepGains
from imitwalk.step.schedule import nominal_track
from imitwalk.step.style import GaitStyle

if TYPE_CHECKING:  # the controller poses the robot with MuJoCo: imported where it walks
    from imitwalk.step.controller import SteppingController

__all__ = ["FALL_COST", "StepJob", "StepScore", "score_walk", "walk_step"]

#: A fall costs at least this much, more the earlier it comes; a walk that stays up
#: costs less (its progress shortfall and heading drift), so no walk that falls ever
#: ranks above one that does not.
FALL_COST = 1.0
#: The heading drift [deg] that costs as much as standing still.
YAW_SCALE = 30.0


@dataclass(frozen=True)
class StepJob:
    """One walk.

    Attributes:
        robot: the robot; style: the walk; gains: the controller's gains; seed: the
        robot's seed in its protocol; options: its simulation; seconds: [s]; engine:
        the physics engine; dt: the control period [s].
    """

    robot: Robot
    style: GaitStyle
    gains: StepGains
    seed: int
    options: SimOptions
    seconds: float
    engine: str = "mujoco"
    dt: float = 0.01


@dataclass(frozen=True)
class StepScore:
    """A walk's outcome: ``seed``; ``fell`` and ``fall_time_s`` [s]; ``seconds`` walked
    [s]; ``progress`` (forward distance over the style's); ``yaw_deg``, the heading drift;
    ``cost``, the learner's (:func:`score_walk`)."""

    seed: int
    fell: bool
    fall_time_s: float | None
    seconds: float
    progress: float
    yaw_deg: float
    cost: float

    def to_dict(self) -> dict:
        """Plain-JSON dictionary."""
        return asdict(self)


def score_walk(m: WalkMetrics, seconds: float) -> float:
    """The learner's cost of a walk: ``FALL_COST`` plus the share of ``seconds`` [s] not
    walked if it fell; else the squared progress shortfall and heading drift, each
    capped so that the sum stays below ``FALL_COST``."""
    if m.fell:
        t = m.fall_time_s if m.fall_time_s is not None else 0.0
        return FALL_COST + max(0.0, 1.0 - t / seconds)
    short = min(max(0.0, 1.0 - m.progress_ratio), 1.0) ** 2
    drift = min(abs(m.yaw_drift_deg) / YAW_SCALE, 1.0) ** 2
    return 0.5 * FALL_COST * (0.9 * short + 0.9 * drift)


def walk_step(job: StepJob, log: bool = False) -> tuple[SteppingController, Rollout, WalkMetrics]:
    """Walk ``job``: its controller, rollout and :class:`~imitwalk.sim.metrics.WalkMetrics`
    (a walk its map no longer needs ends early, see :func:`~imitwalk.parallel.abandoned`)."""
    from imitwalk.sim.metrics import walk_metrics
    from imitwalk.sim.mujoco import make_plant, run
    from imitwalk.step.controller import SteppingController

    ctrl = SteppingController(job.robot, job.style, job.gains, job.dt, log=log)
    opts = job.options
    if abs(opts.control_hz * job.dt - 1.0) > 1e-9:
        from dataclasses import replace

        opts = replace(opts, control_hz=1.0 / job.dt)
    plant = make_plant(job.robot, opts, job.engine)
    ro = run(plant, ctrl, int(round(job.seconds / job.dt)), abandon=abandoned)
    st = job.style
    track = None
    if st.turn:  # a turning gait is judged along its turn
        track = nominal_track(st.step_length, st.step_time, st.turn / 2, job.dt, ro.seconds)
    m = walk_metrics(ro, st.speed * ro.seconds, track=track)
    return ctrl, ro, m


def run_step_job(job: StepJob) -> StepScore:
    """:func:`walk_step` reduced to its :class:`StepScore` (runs in a worker process)."""
    _, _, m = walk_step(job)
    return StepScore(
        seed=job.seed,
        fell=m.fell,
        fall_time_s=m.fall_time_s,
        seconds=m.seconds,
        progress=float(m.progress_ratio),
        yaw_deg=float(m.yaw_drift_deg),
        cost=float(score_walk(m, job.seconds)),
    )


def mean_cost(scores: list[StepScore]) -> float:
    """The mean cost of some walks (``inf`` for none)."""
    return float(np.mean([s.cost for s in scores])) if scores else float("inf")
