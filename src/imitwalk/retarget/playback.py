"""Open-loop playback of a reference on the nominal and on perturbed robots.

A model *walks* when it does not fall, its ``progress_ratio`` is at least 0.5 and
its yaw drift stays under 15°. Robots are simulated in parallel worker processes
(one per core by default); the results do not depend on the number of workers.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from imitwalk.parallel import run_parallel
from imitwalk.retarget.reference import Reference
from imitwalk.robots import Robot
from imitwalk.sim.metrics import WalkMetrics, walk_metrics
from imitwalk.sim.mujoco import SimOptions, make_plant, playback
from imitwalk.sim.perturb import perturbed

__all__ = ["ModelRun", "play_reference", "summary", "walked"]


def walked(m: WalkMetrics, min_progress: float = 0.5, max_yaw_deg: float = 15.0) -> bool:
    """True if a run walked: no fall, progress ratio ≥ 0.5, |yaw drift| < 15°."""
    return (not m.fell) and m.progress_ratio >= min_progress and abs(m.yaw_drift_deg) < max_yaw_deg


@dataclass(frozen=True)
class ModelRun:
    """One robot's open-loop run: its seed, the metrics, and whether it walked."""

    seed: int
    metrics: WalkMetrics
    walked: bool

    def to_dict(self) -> dict:
        """Plain-JSON dictionary."""
        return {"seed": self.seed, "walked": self.walked, **self.metrics.to_dict()}


def _one(
    args: tuple[Robot, np.ndarray, np.ndarray, SimOptions, _Expected, int, str],
) -> ModelRun:
    robot, q, q0, options, expected_fn, seed, engine = args
    plant = make_plant(robot, options, engine)
    ro = playback(plant, q, q0=q0)
    m = walk_metrics(ro, expected_fn(ro.seconds), q_ref=q, track=expected_fn.track(ro.seconds))
    return ModelRun(seed, m, walked(m))


class _Expected:
    def __init__(self, ref: Reference, scale: float):
        self.ref, self.scale = ref, scale

    def __call__(self, seconds: float) -> float:
        return self.ref.expected_distance(self.scale, seconds)

    def track(self, seconds: float) -> np.ndarray:
        return self.ref.track(self.scale, seconds)


def play_reference(
    ref: Reference,
    robot: Robot,
    scale: float,
    seconds: float,
    seeds: tuple[int, ...] | list[int] = (0,),
    base: SimOptions | None = None,
    workers: int | None = None,
    engine: str = "mujoco",
    disturbance: bool = False,
    stop: Callable[[list[ModelRun]], bool] | None = None,
) -> list[ModelRun]:
    """Play ``ref`` at ``scale`` open loop for ``seconds`` on the robots ``seeds``.

    Args:
        ref: the reference; robot: the robot it was built for.
        scale: stride scale; seconds: simulated time per robot [s].
        seeds: 0 is the nominal robot, others perturbed (see :mod:`imitwalk.sim.perturb`).
        base: options every run starts from (rates, noise, slope ...).
        workers: parallel processes (default: one per core; 1 runs in this process).
        engine: physics engine, one of :data:`imitwalk.sim.types.ENGINES`.
        disturbance: give the perturbed robots the evaluation's small initial push too.
        stop: ``stop(runs) -> bool``, asked after each robot in ``seeds`` order: once it
            holds, the robots not yet run are skipped (:func:`imitwalk.parallel.run_parallel`).
    """
    q = ref.trajectory(scale, seconds)
    base = ref.sim_options(base)  # on the ground the gait was built for
    expected = _Expected(ref, scale)
    opts = [perturbed(s, base, disturbance=disturbance and s != 0) for s in seeds]
    jobs = [(robot, q, q[0], o, expected, s, engine) for s, o in zip(seeds, opts, strict=True)]
    return run_parallel(_one, jobs, workers, stop)


def summary(runs: list[ModelRun]) -> dict:
    """Per-model results and the count that walked."""
    return {
        "walked": int(sum(r.walked for r in runs)),
        "models": len(runs),
        "runs": [r.to_dict() for r in runs],
        "mean_forward_speed_mps": float(np.mean([r.metrics.forward_speed_mps for r in runs])),
    }
