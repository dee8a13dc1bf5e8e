"""The paper's learning loop as written (§5 steps 3–7, §6; the ``faithful`` variant).

Each iteration runs the current controller (:class:`~imitwalk.paper.policy.WalkPolicy`) on
the training robots, records the gyro states and actions (φ, r, h), refits the gyro
model of eqs. 3–4 on everything recorded so far and moves along the scale schedule: a
scale is passed when its last iteration (without exploration) walks without a fall on
every training robot; after ``retries`` more falling attempts at a scale, learning
stops there. After every iteration the run folder is checkpointed atomically, so
``resume`` continues an interrupted run and ends where an uninterrupted one would.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np

from imitwalk.config import from_dict, to_dict
from imitwalk.paper.episode import EpisodeJob, run_episode
from imitwalk.paper.gait import GaitModel
from imitwalk.paper.learnconfig import LearnConfig, ScheduleConfig
from imitwalk.paper.models import fit_model, stack_episodes, unstack_episodes
from imitwalk.paper.predictor import SensoryMotorModel
from imitwalk.parallel import run_parallel
from imitwalk.retarget.reference import Reference
from imitwalk.robots import Robot
from imitwalk.runs import FaithfulOutcome, LearnSummary, RunDir
from imitwalk.sim.perturb import train_seeds

__all__ = ["FaithfulProgress", "learn"]


@dataclass
class FaithfulProgress:
    """Where a faithful run is (``checkpoint.json``).

    Attributes:
        scale_index, iteration: where the schedule is; failures: falling iterations at
        this scale; passed: scales passed; done: the schedule has ended;
        total_iterations; sim_seconds, wall_seconds: what learning has cost [s].
    """

    scale_index: int = 0
    iteration: int = 0
    failures: int = 0
    passed: list = field(default_factory=list)
    done: bool = False
    total_iterations: int = 0
    sim_seconds: float = 0.0
    wall_seconds: float = 0.0


def _iteration_log(
    scale: float, it: int, results: list[dict], report: dict | None, t0: float
) -> dict:
    ms = [r["metrics"] for r in results]
    pred = [r.get("tick_pred") for r in results if r.get("tick_pred") is not None]
    costs = [r["gyro_cost"] for r in results if r["gyro_cost"] is not None]
    return {
        "scale": scale,
        "iteration": it,
        "robots": len(results),
        "seeds": [r["seed"] for r in results],
        "falls": int(sum(m["fell"] for m in ms)),
        "fall_time_s": [m["fall_time_s"] for m in ms],
        "cost_measured": float(np.mean(costs)) if costs else None,
        # `pred` holds no None (filtered above); mypy cannot narrow the `r.get(...)` it holds
        "cost_predicted": float(np.mean(pred)) if pred else None,  # type: ignore[arg-type]
        "prediction": report,
        "forward_speed_mps": float(np.mean([m["forward_speed_mps"] for m in ms])),
        "progress_ratio": float(np.mean([m["progress_ratio"] for m in ms])),
        "yaw_drift_deg": float(np.mean([m["yaw_drift_deg"] for m in ms])),
        "sim_seconds": float(sum(m["seconds"] for m in ms)),
        "wall_seconds": time.perf_counter() - t0,
    }


def learn(
    ref: Reference,
    robot: Robot,
    config: LearnConfig,
    run_dir: str | Path,
    resume: bool = False,
    progress: Callable[[str], None] | None = None,
) -> LearnSummary:
    """Learn to walk ``ref`` on ``robot`` as the paper does; write everything to ``run_dir``.

    Args:
        ref: the retargeted reference; robot: the robot; config: settings.
        run_dir: output folder; resume: continue the run there.
        progress: optional ``callback(line)`` for one line per iteration.

    Returns:
        the learning summary (also written as ``metrics.json``).
    """
    rd = RunDir(run_dir)
    saved, log = _open_run(rd, ref, robot, config, resume)
    state = FaithfulProgress(**saved) if saved else FaithfulProgress()
    data = unstack_episodes(rd.read_arrays("data.npz")) if saved and rd.exists("data.npz") else []
    sch = config.schedule
    scales = sch.scales()
    gait = GaitModel(ref, scales, config.gait)
    while not state.done:
        t0 = time.perf_counter()
        scale, it = scales[state.scale_index], state.iteration
        model = fit_model(data, config)
        jobs = _episode_jobs(robot, gait, scale, config, model, it, state.total_iterations)
        results = run_parallel(run_episode, jobs, config.workers)
        report = _prediction_report(model, results)
        data.extend(r["tick"] for r in results if "tick" in r and len(r["tick"][0]) > 2)
        entry = _iteration_log(scale, it, results, report, t0)
        log.append(entry)
        _advance(state, entry, scale, it, sch, len(scales))
        rd.write_arrays("data.npz", stack_episodes(data))
        rd.write_log(log)
        rd.write_json("checkpoint.json", asdict(state))
        if progress:
            progress(_progress_line(entry))
    summary = LearnSummary(
        learner="faithful",
        scale_reached=max(state.passed) if state.passed else 0.0,
        scales_passed=state.passed,
        iterations=state.total_iterations,
        sim_seconds_used_for_learning=state.sim_seconds,
        wall_seconds_for_learning=state.wall_seconds,
        config=asdict(config),
        outcome=FaithfulOutcome(gait=gait.report()),
    )
    rd.write_json("metrics.json", summary.to_dict())
    return summary


def _open_run(
    rd: RunDir, ref: Reference, robot: Robot, config: LearnConfig, resume: bool
) -> tuple[dict | None, list[dict]]:
    """Start the run folder ``rd`` (or, with ``resume``, reopen it): the saved progress
    (``None``: a fresh run) and the log so far."""
    cfg_json = {
        "learn": to_dict(config),
        "reference": ref.summary(),
        "robot": robot.name,
        "learner": "faithful",
    }
    canonical = lambda learn: to_dict(from_dict(LearnConfig, learn))  # noqa: E731
    return rd.start(cfg_json, ref, resume, canonical)


def _episode_jobs(
    robot: Robot,
    gait: GaitModel,
    scale: float,
    config: LearnConfig,
    model: SensoryMotorModel | None,
    it: int,
    total_iterations: int,
) -> list[EpisodeJob]:
    """One episode per training robot at ``scale``, exploring less as iteration ``it`` of
    the scale nears the last."""
    sch = config.schedule
    explore = max(0.0, 1.0 - it / (sch.iterations - 1)) if sch.iterations > 1 else 0.0
    return [
        EpisodeJob(
            robot,
            gait,
            scale,
            config,
            model,
            s,
            explore,
            (config.seed, total_iterations, j),
            sch.seconds,
        )
        for j, s in enumerate(train_seeds(config.train_models))
    ]


def _prediction_report(model: SensoryMotorModel | None, results: list[dict]) -> dict | None:
    """How well ``model`` predicted the new episodes of more than three ticks (``None``:
    no model, no such episode, or it could not be evaluated)."""
    new = [r["tick"] for r in results if "tick" in r and len(r["tick"][0]) > 3]
    report = None
    if model is not None and new:
        try:
            report = model.evaluate(new).to_dict()
        except ValueError:
            report = None
    return report


def _advance(
    state: FaithfulProgress,
    entry: dict,
    scale: float,
    it: int,
    sch: ScheduleConfig,
    n_scales: int,
) -> None:
    """Move ``state`` on after iteration ``it`` at ``scale`` (logged as ``entry``): pass the
    scale, retry it, or stop."""
    fell, last = entry["falls"] > 0, it >= sch.iterations - 1
    if fell:
        state.failures += 1
        state.done = state.failures > sch.retries
    if last and not fell:
        state.passed.append(scale)
        state.failures = 0
        state.scale_index, state.iteration = state.scale_index + 1, 0
        state.done = state.scale_index >= n_scales
    elif not state.done:
        state.iteration = min(it + 1, sch.iterations - 1)
    state.total_iterations += 1
    state.sim_seconds += entry["sim_seconds"]
    state.wall_seconds += entry["wall_seconds"]


def _progress_line(e: dict) -> str:
    pred = e["prediction"]
    ratio = f"{pred['overall_ratio']:.2f}" if pred else "  - "
    cm = f"{e['cost_measured']:.3f}" if e["cost_measured"] is not None else "  -  "
    cp = f"{e['cost_predicted']:.3f}" if e["cost_predicted"] is not None else "  -  "
    return (
        f"scale {e['scale']:.2f} it {e['iteration']} | fell {e['falls']}/{e['robots']} | "
        f"cost meas {cm} pred {cp} | pred err/baseline {ratio} | "
        f"{e['forward_speed_mps']:.3f} m/s, progress {e['progress_ratio']:.2f}, "
        f"yaw {e['yaw_drift_deg']:+.1f} deg | {e['wall_seconds']:.1f} s"
    )
