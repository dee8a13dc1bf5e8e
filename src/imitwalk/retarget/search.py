"""A small model-free search for the reference parameters, by trials in simulation.

In the spirit of the paper (no dynamics model), the few parameters of the walkable
reference (:class:`~imitwalk.retarget.plan.GaitParams`: sway, pelvis height, lift,
double support, lean, width) are chosen by the cross-entropy method over open-loop
rollouts: each candidate reference is solved by IK at a few stride scales and played
on the nominal robot and on training perturbations (never an evaluation robot). A
rollout scores ``alive fraction + ½·min(progress ratio, 1) − ½·min(|yaw drift| / 45°, 1)``.
A ``walker`` plays each candidate under a controller instead (a learned balance law:
:mod:`imitwalk.learning.refchoice`), with the same robots, scales and score.
"""

from __future__ import annotations

import json
import time
from collections.abc import Callable
from dataclasses import asdict, dataclass, fields, replace
from functools import partial
from typing import TYPE_CHECKING

import numpy as np

from imitwalk.errors import ConfigError, unknown_name
from imitwalk.parallel import run_parallel
from imitwalk.retarget.command import GaitCommand
from imitwalk.retarget.ik import WalkIK, leg_geometry
from imitwalk.retarget.params import leg_scaled
from imitwalk.retarget.plan import GaitParams
from imitwalk.retarget.searchreport import SearchReport
from imitwalk.retarget.template import GaitTemplate
from imitwalk.retarget.walkable import build_walkable
from imitwalk.robots import Robot
from imitwalk.sim.metrics import WalkMetrics, walk_metrics
from imitwalk.sim.mujoco import SimOptions, make_plant, playback
from imitwalk.sim.perturb import perturbed, train_seeds
from imitwalk.sim.types import ENGINES

if TYPE_CHECKING:
    from imitwalk.retarget.reference import Reference

__all__ = [
    "BOUNDS",
    "LENGTHS",
    "SearchConfig",
    "Walker",
    "bounds",
    "open_loop",
    "search_line",
    "search_params",
]

#: ``walker(reference, robot, scale, seed, options, seconds)`` walks a candidate
#: :class:`~imitwalk.retarget.reference.Reference` at ``scale`` on one robot for
#: ``seconds`` [s] and returns its :class:`~imitwalk.sim.metrics.WalkMetrics` (it runs in
#: the search's worker process). :func:`open_loop` plays it without feedback.
Walker = Callable[..., WalkMetrics]

#: Search range of each reference parameter; the ranges of the lengths (:data:`LENGTHS`)
#: are for a leg of :data:`~imitwalk.retarget.params.REFERENCE_LEG` (:func:`bounds`).
BOUNDS: dict[str, tuple[float, float]] = {
    "sway": (0.4, 1.1),
    "height": (0.80, 0.98),
    "lift": (0.015, 0.045),
    "ds": (0.05, 0.3),
    "lean": (-0.005, 0.02),
    "width": (0.0, 0.015),
}
#: The parameters that are lengths [m]: their ranges scale with the robot's leg.
LENGTHS = ("lift", "lean", "width")


def bounds(leg: float | None) -> dict[str, tuple[float, float]]:
    """:data:`BOUNDS` for a robot whose leg (hip to ankle) is ``leg`` [m] (``None``: as
    written, for :data:`~imitwalk.retarget.params.REFERENCE_LEG`)."""
    return {
        k: (leg_scaled(v[0], leg), leg_scaled(v[1], leg)) if k in LENGTHS else v
        for k, v in BOUNDS.items()
    }


@dataclass(frozen=True)
class SearchConfig:
    """Budget of the search.

    Attributes:
        generations, population, elites: cross-entropy method sizes.
        scales: stride scales every candidate is tried at.
        models: number of robots per trial (the nominal one + training perturbations).
            With 2, the default clip's reference kept its feet but turned more than 15°
            on 2 of 6 robots at scale 0.5; 4 doubles the search's cost and fixed that.
        seconds: simulated time per rollout [s]; seed: the search's random seed.
        workers: parallel processes (``None``: one per core).
        engine: the physics engine of the trials (:data:`imitwalk.sim.types.ENGINES`).
    """

    generations: int = 5
    population: int = 8
    elites: int = 3
    scales: tuple[float, ...] = (0.5, 1.0)
    models: int = 4
    seconds: float = 12.0
    seed: int = 0
    workers: int | None = None
    engine: str = "mujoco"

    def __post_init__(self) -> None:
        if self.engine not in ENGINES:
            raise unknown_name("engine", self.engine, ENGINES, ConfigError)
        for name in ("generations", "population", "models"):
            if getattr(self, name) < 1:
                raise ConfigError(f"search_config.{name}: {getattr(self, name)} is below 1")
        if not 1 <= self.elites <= self.population:
            raise ConfigError(
                f"search_config.elites: {self.elites} is not in 1..{self.population} (population)"
            )
        if not self.seconds > 0:
            raise ConfigError(f"search_config.seconds: {self.seconds} is not above 0 s")
        if not self.scales or not all(0.0 < x <= 1.0 for x in self.scales):
            raise ConfigError(f"search_config.scales: {self.scales} must be scales in (0, 1]")


_IK: dict = {}


def open_loop(
    ref: Reference,
    robot: Robot,
    scale: float,
    seed: int,
    options: SimOptions,
    seconds: float,
    engine: str = "mujoco",
) -> WalkMetrics:
    """The search's default :data:`Walker`: ``ref`` played open loop on ``engine``
    (``seed`` is drawn into ``options`` already)."""
    q = ref.trajectory(scale, seconds)
    ro = playback(make_plant(robot, options, engine), q, q0=q[0])
    return walk_metrics(
        ro, ref.expected_distance(scale, ro.seconds), track=ref.track(scale, ro.seconds)
    )


def _trial(
    job: tuple[
        GaitTemplate,
        Robot,
        GaitParams,
        SearchConfig,
        float,
        SimOptions | None,
        GaitCommand | None,
        Walker | None,
    ],
) -> dict:
    template, robot, params, cfg, dt, base, command, walker = job
    key = (robot.name, str(robot.mjcf))
    ik = _IK.setdefault(key, WalkIK(robot))
    build = build_walkable(template, robot, params, list(cfg.scales), dt, ik=ik, command=command)
    ref = build.reference
    base = ref.sim_options(base)
    walk = walker or partial(open_loop, engine=cfg.engine)
    runs, score = [], []
    for s in cfg.scales:
        for seed in train_seeds(cfg.models):
            m = walk(ref, robot, s, seed, perturbed(seed, base), cfg.seconds)
            val = (
                m.seconds / cfg.seconds
                + 0.5 * float(np.clip(m.progress_ratio, 0.0, 1.0))
                - 0.5 * min(abs(m.yaw_drift_deg) / 45.0, 1.0)
            )
            score.append(val)
            runs.append(
                {
                    "scale": s,
                    "seed": seed,
                    "fell": m.fell,
                    "seconds": m.seconds,
                    "progress_ratio": m.progress_ratio,
                    "yaw_drift_deg": m.yaw_drift_deg,
                }
            )
    return {"params": params.to_dict(), "score": float(np.mean(score)), "runs": runs}


def search_line(gen: int, total: int, score: float, params: dict) -> str:
    """The search's progress after generation ``gen`` of ``total``: the best score and
    its parameters, on one line (the ``progress`` callback of :func:`search_params`
    formats it)."""
    shown = ", ".join(f"{k}={v:.3g}" for k, v in params.items())
    return f"  search generation {gen}/{total}: best score {score:.3f} ({shown})"


def search_params(
    template: GaitTemplate,
    robot: Robot,
    config: SearchConfig | None = None,
    start: GaitParams | None = None,
    dt: float = 0.01,
    base: SimOptions | None = None,
    progress: Callable[[int, int, float, dict], None] | None = None,
    command: GaitCommand | None = None,
    walker: Walker | None = None,
) -> tuple[GaitParams, SearchReport]:
    """Find reference parameters for ``template`` on ``robot`` (walking as ``command``
    says: a turn or sidestep is judged against its own path, a slope on its slope).
    ``walker`` (:data:`Walker`; ``None``: :func:`open_loop` on ``config.engine``) walks
    each candidate.

    Returns:
        the best parameters found and the report of every trial.
    """
    cfg = config or SearchConfig()
    names = [f.name for f in fields(GaitParams)]
    leg = leg_geometry(robot).leg
    box = bounds(leg)  # the lengths' ranges scale with the leg
    lo = np.array([box[n][0] for n in names])
    hi = np.array([box[n][1] for n in names])
    x0 = np.array([getattr((start or GaitParams()).for_leg(leg), n) for n in names])
    mu = np.clip((x0 - lo) / (hi - lo), 0.0, 1.0)
    sd = np.full(len(names), 0.25)
    rng = np.random.default_rng(cfg.seed)
    history, best = [], None
    t0 = time.perf_counter()
    for gen in range(cfg.generations):
        u = np.clip(mu + sd * rng.standard_normal((cfg.population, len(names))), 0.0, 1.0)
        if gen == 0:
            u[0] = mu
        cands = [
            GaitParams(**dict(zip(names, (lo + ui * (hi - lo)).tolist(), strict=True))) for ui in u
        ]
        jobs = [(template, robot, c, cfg, dt, base, command, walker) for c in cands]
        results = run_parallel(_trial, jobs, cfg.workers)
        scores = np.array([r["score"] for r in results])
        order = np.argsort(-scores, kind="stable")
        elite = u[order[: cfg.elites]]
        mu, sd = elite.mean(axis=0), np.maximum(elite.std(axis=0), 0.05)
        for i, r in enumerate(results):
            history.append({"generation": gen, "candidate": i, **r})
        top = results[order[0]]
        if best is None or top["score"] > best["score"]:
            best = top
        if progress:
            progress(gen + 1, cfg.generations, best["score"], best["params"])
    assert best is not None  # at least one generation ran
    per = len(cfg.scales) * cfg.models * cfg.seconds
    report = SearchReport(
        method="cross-entropy method over "
        + ("open-loop rollouts" if walker is None else "rollouts under a learned law"),
        config=json.loads(json.dumps(asdict(replace(cfg, workers=None)))),  # as a file holds it
        bounds={k: list(v) for k, v in box.items()},
        score="alive fraction + 0.5*min(progress,1) - 0.5*min(|yaw|/45deg,1), mean over runs",
        evaluations=len(history),
        sim_seconds=len(history) * per,
        wall_seconds=time.perf_counter() - t0,
        best=best,
        history=tuple(history),
    )
    return GaitParams(**best["params"]), report
