"""Judging a run on a robustness protocol: every controller on the same robots.

:func:`judge_protocol` draws ``seeds`` robots from a :class:`~imitwalk.judge.protocol.Protocol`
and walks each controller the run can build on every one of them, for ``seconds``
from standing. Per controller it reports survival with its 95 % Wilson interval,
distance, speed and mean |yaw| drift, and the falls broken down by the factor each
robot drew furthest from nominal; every controller is compared with open loop on the
same robots by the paired McNemar test. Robot ``s`` is the same robot whatever the
controller, so the comparison is paired.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from imitwalk.errors import ConfigError, unknown_name
from imitwalk.judge.protocol import Protocol
from imitwalk.judge.replay import OPEN_LOOP, LoadedRun, load_run
from imitwalk.paper.evaluate import compare_falls, wilson
from imitwalk.parallel import run_parallel
from imitwalk.robots import Robot
from imitwalk.runs import RunDir
from imitwalk.sim.metrics import walk_metrics
from imitwalk.sim.types import SimOptions

__all__ = ["JudgeJob", "judge_protocol", "run_controller"]


@dataclass(frozen=True)
class JudgeJob:
    """One controller on one robot of a protocol (runs in a worker process).

    Attributes:
        run_dir: the run folder; robot: the robot; controller: its name (``open_loop``,
        ``learned``); seed: the protocol's robot; options: that robot's simulation;
        furthest: the factor it drew furthest from nominal; seconds: simulated time
        [s]; scale: the stride scale (``None``: the run's); engine: the physics engine.
    """

    run_dir: str
    robot: Robot
    controller: str
    seed: int
    options: SimOptions
    furthest: str | None
    seconds: float
    scale: float | None
    engine: str


_CACHE: dict = {}


def _loaded(run_dir: str) -> LoadedRun:
    key = (run_dir, RunDir(run_dir).file("metrics.json").stat().st_mtime_ns)
    if key not in _CACHE:
        _CACHE.clear()
        _CACHE[key] = load_run(run_dir)
    return _CACHE[key]


def run_controller(job: JudgeJob) -> dict:
    """Walk ``job``'s controller on its robot; its walk metrics, seed and furthest factor."""
    from imitwalk.sim.mujoco import make_plant, run

    lr = _loaded(job.run_dir)
    scale = lr.scale if job.scale is None else job.scale
    ref = lr.ref
    policy = lr.policy(job.controller, job.robot, scale, job.seconds)
    plant = make_plant(job.robot, ref.sim_options(job.options), job.engine)
    ro = run(plant, policy, round(job.seconds / ref.dt))
    m = walk_metrics(
        ro,
        ref.expected_distance(scale, ro.seconds),
        ref.trajectory(scale, job.seconds),
        ref.track(scale, ro.seconds),
    )
    return {**m.to_dict(), "seed": job.seed, "furthest": job.furthest}


def _side(runs: list[dict], factors) -> dict:
    n = len(runs)
    falls = int(sum(r["fell"] for r in runs))
    by = {f: 0 for f in factors}
    for r in runs:
        if r["fell"] and r["furthest"] is not None:
            by[r["furthest"]] = by.get(r["furthest"], 0) + 1
    mean = lambda k: float(np.mean([r[k] for r in runs])) if runs else None  # noqa: E731
    return {
        "robots": n,
        "survived": n - falls,
        "falls": falls,
        "survival": (n - falls) / n if n else 0.0,
        "survival_ci95": list(wilson(n - falls, n)),
        "distance_m": mean("forward_distance_m"),
        "speed_mps": mean("forward_speed_mps"),
        "abs_yaw_deg": float(np.mean([abs(r["yaw_drift_deg"]) for r in runs])) if runs else None,
        "progress_ratio_min": float(min(r["progress_ratio"] for r in runs)) if runs else None,
        "falls_by_furthest_factor": by,
        "per_seed": [
            {k: r[k] for k in ("seed", "fell", "fall_time_s", "forward_distance_m", "furthest")}
            | {"yaw_drift_deg": r["yaw_drift_deg"]}
            for r in runs
        ],
    }


def judge_protocol(
    run_dir,
    robot: Robot,
    protocol: Protocol,
    seeds: int = 40,
    seconds: float = 30.0,
    controllers: tuple[str, ...] | None = None,
    scale: float | None = None,
    workers: int | None = None,
) -> dict:
    """Every controller in ``controllers`` (``None``: every one the run can build) on
    robots ``0 … seeds − 1`` of ``protocol``.

    Returns:
        ``{"protocol": …, "settings": …, "controllers": {name: side}, "comparison":
        {name: McNemar vs open loop}}``; a side holds ``survived``, ``survival`` and its
        ``survival_ci95``, ``distance_m``, ``speed_mps``, ``abs_yaw_deg``,
        ``progress_ratio_min``, ``falls_by_furthest_factor`` and ``per_seed``.
    """
    metrics = RunDir(run_dir).read_json("metrics.json")
    loaded = _loaded(str(run_dir))
    valid = loaded.controllers()
    controllers = valid if controllers is None else tuple(controllers)
    for c in controllers:
        if c not in valid:
            raise unknown_name("controller", c, valid, ConfigError)
    draws = [protocol.draw(s, robot, seconds=seconds) for s in range(seeds)]
    twin = {c: loaded.twin(c) for c in controllers}
    jobs = [
        JudgeJob(
            str(run_dir),
            robot,
            c,
            d.seed,
            d.options,
            d.furthest,
            seconds,
            scale,
            protocol.engine,
        )
        for c in dict.fromkeys(twin.values())  # exact copies walk once
        for d in draws
    ]
    res = run_parallel(run_controller, jobs, workers)
    by = {
        c: [r for r, j in zip(res, jobs, strict=True) if j.controller == twin[c]]
        for c in controllers
    }
    out = {
        "protocol": {"name": protocol.name, "version": protocol.version, "path": protocol.path},
        "settings": {
            "seeds": seeds,
            "seconds": seconds,
            "engine": protocol.engine,
            "scale": scale if scale is not None else metrics.get("scale_reached"),
            "controllers": list(controllers),
        },
        "controllers": {c: _side(runs, protocol.factors) for c, runs in by.items()},
        "comparison": {},
    }
    if OPEN_LOOP in by:
        base = [bool(r["fell"]) for r in by[OPEN_LOOP]]
        for c in controllers:
            if c != OPEN_LOOP:
                out["comparison"][c] = compare_falls([bool(r["fell"]) for r in by[c]], base)
    return out
