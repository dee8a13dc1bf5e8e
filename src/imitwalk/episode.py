"""One learning episode: the learner's controller on one robot, recorded.

The learning loop (:mod:`imitwalk.learner`) and its measured trials run many of these in
parallel (:func:`imitwalk.parallel.run_parallel`); the simulator steps the physics.
"""

from __future__ import annotations

import numpy as np

from imitwalk.controller import stability_cost
from imitwalk.models import build_policy

__all__ = ["run_episode"]


def run_episode(job) -> dict:
    """One episode of the learner's controller on one robot (runs in a worker process).

    ``job``: ``(robot, gait, scale, config, models, seed, explore, rng_seed, seconds)``:
    the training robot ``seed`` (:func:`imitwalk.perturb.perturbed`, with the training
    friction range) walks ``gait`` at ``scale`` for ``seconds`` [s] under
    :func:`imitwalk.models.build_policy`'s controller. Returns its walk metrics, its
    recorded tick and step data (states, actions) and its measured gyro cost (eq. 6).
    """
    from imitwalk.metrics import walk_metrics
    from imitwalk.perturb import perturbed
    from imitwalk.sim import make_plant, run

    robot, gait, scale, cfg, models, seed, explore, rng_seed, seconds = job
    policy = build_policy(gait, scale, cfg, models, explore=explore, rng_seed=rng_seed, robot=robot)
    ref = gait.ref
    steps = round(seconds / ref.dt)
    opts = perturbed(
        seed, ref.sim_options(), disturbance=seed != 0, friction_range=tuple(cfg.train_friction)
    )
    ro = run(make_plant(robot, opts, cfg.engine), policy, steps)
    m = walk_metrics(
        ro,
        ref.expected_distance(scale, ro.seconds),
        ref.trajectory(scale, ro.seconds),
        ref.track(scale, ro.seconds),
    )
    out = {"seed": seed, "metrics": m.to_dict(), "ticks": len(ro.t)}
    if policy.tick_states:
        out["tick"] = (np.asarray(policy.tick_states), np.asarray(policy.tick_actions))
        out["tick_pred"] = float(np.mean(policy.tick_predicted)) if policy.tick_predicted else None
    if policy.steps is not None:
        out["step"] = policy.steps.episode()
        out["step_pred"] = (
            float(np.mean(policy.steps.predicted)) if policy.steps.predicted else None
        )
    g = ro.gyro[len(policy.start) - gait.n_ticks :]
    out["gyro_cost"] = float(stability_cost(g, np.ones(3)).mean()) if len(g) else None
    return out
