"""One episode of the paper's learner: its controller on one robot, recorded.

The learning loop (:mod:`imitwalk.paper.learner`) runs many of these in parallel
(:func:`imitwalk.parallel.run_parallel`); the simulator steps the physics.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from imitwalk.paper.controller import stability_cost
from imitwalk.paper.gait import GaitModel
from imitwalk.paper.learnconfig import LearnConfig
from imitwalk.paper.models import build_policy
from imitwalk.paper.predictor import SensoryMotorModel
from imitwalk.robots import Robot

__all__ = ["EpisodeJob", "run_episode"]


@dataclass(frozen=True)
class EpisodeJob:
    """One episode: training robot ``seed`` (:func:`imitwalk.sim.perturb.perturbed`) walks
    ``gait`` at ``scale`` for ``seconds`` [s] under the paper's controller with ``model``
    (``None``: the nominal actions), ``explore`` a fraction of the box, ``rng`` seeding it."""

    robot: Robot
    gait: GaitModel
    scale: float
    config: LearnConfig
    model: SensoryMotorModel | None
    seed: int
    explore: float
    rng: tuple[int, ...]
    seconds: float


def run_episode(job: EpisodeJob) -> dict:
    """One episode (runs in a worker process): its walk metrics, its recorded tick data
    (states, actions) and its measured gyro cost (eq. 6)."""
    from imitwalk.sim.metrics import walk_metrics
    from imitwalk.sim.mujoco import make_plant, run
    from imitwalk.sim.perturb import perturbed

    gait, scale = job.gait, job.scale
    policy = build_policy(gait, scale, job.config, job.model, job.explore, job.rng)
    ref = gait.ref
    steps = round(job.seconds / ref.dt)
    opts = perturbed(job.seed, ref.sim_options(), disturbance=job.seed != 0)
    ro = run(make_plant(job.robot, opts, job.config.engine), policy, steps)
    m = walk_metrics(
        ro,
        ref.expected_distance(scale, ro.seconds),
        ref.trajectory(scale, ro.seconds),
        ref.track(scale, ro.seconds),
    )
    out = {"seed": job.seed, "metrics": m.to_dict(), "ticks": len(ro.t)}
    if policy.tick_states:
        out["tick"] = (np.asarray(policy.tick_states), np.asarray(policy.tick_actions))
        out["tick_pred"] = float(np.mean(policy.tick_predicted)) if policy.tick_predicted else None
    g = ro.gyro[len(policy.start) - gait.n_ticks :]
    out["gyro_cost"] = float(stability_cost(g, np.ones(3)).mean()) if len(g) else None
    return out
