"""Judging a run on a robustness protocol: every controller on the same robots.

:func:`judge_protocol` draws ``seeds`` robots from a :class:`~imitwalk.protocol.Protocol`
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
from imitwalk.evaluate import compare_falls, judged_gain, load_gait, wilson
from imitwalk.metrics import walk_metrics
from imitwalk.parallel import run_parallel
from imitwalk.protocol import Protocol
from imitwalk.robots import Robot
from imitwalk.runs import RunDir
from imitwalk.simtypes import SimOptions

__all__ = ["OPEN_LOOP", "JudgeJob", "TickRun", "judge_protocol", "load_run", "run_controller"]

#: The controller every run can build: its reference played as it is.
OPEN_LOOP = "open_loop"


@dataclass(frozen=True)
class JudgeJob:
    """One controller on one robot of a protocol (runs in a worker process).

    Attributes:
        run_dir: the run folder; robot: the robot; controller: its name (``open_loop``,
        ``learned``); seed: the protocol's robot; options: that robot's simulation;
        furthest: the factor it drew furthest from nominal; seconds: simulated time
        [s]; scale: the stride scale (``None``: the run's); engine: the physics engine;
        gain: the learned controller's channel gain (``None``: the run's).
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
    gain: float | None = None


_CACHE: dict = {}


@dataclass(frozen=True)
class TickRun:
    """A finished per-tick run (:mod:`imitwalk.ticklearn`): its reference, the scale it
    reached and the feedback laws of each controller it can build."""

    ref: object
    scale: float
    laws: dict

    def controllers(self) -> tuple[str, ...]:
        return (*self.laws, OPEN_LOOP)


def load_run(run_dir):
    """A finished run folder: a :class:`TickRun`, or the step-level learner's gait."""
    rd = RunDir(run_dir)
    if rd.read_json("config.json").get("learner") == "tick":
        from imitwalk.retarget.reference import Reference
        from imitwalk.ticklearn import load_laws

        metrics = rd.read_json("metrics.json")
        ref = Reference.load(rd.file("reference.npz"))
        return TickRun(ref, float(metrics["scale_reached"]), load_laws(run_dir))
    return load_gait(run_dir)


def _loaded(run_dir: str):
    key = (run_dir, RunDir(run_dir).file("metrics.json").stat().st_mtime_ns)
    if key not in _CACHE:
        _CACHE.clear()
        _CACHE[key] = load_run(run_dir)
    return _CACHE[key]


def run_controller(job: JudgeJob) -> dict:
    """Walk ``job``'s controller on its robot; its walk metrics, seed and furthest factor."""
    from imitwalk.sim import make_plant, playback, run

    lg = _loaded(job.run_dir)
    scale = lg.scale if job.scale is None else job.scale
    tick = isinstance(lg, TickRun)
    ref = lg.ref if job.controller == OPEN_LOOP or tick else lg.gait.ref
    steps = round(job.seconds / ref.dt)
    q_ref = ref.trajectory(scale, job.seconds)
    plant = make_plant(job.robot, ref.sim_options(job.options), job.engine)
    if job.controller == OPEN_LOOP:
        ro = playback(plant, q_ref, q0=q_ref[0])
    elif tick:
        from imitwalk.feedback import TickPolicy

        if job.controller not in lg.laws:
            raise unknown_name("controller", job.controller, lg.controllers(), ConfigError)
        laws = lg.laws[job.controller]
        ro = run(plant, TickPolicy(ref, scale, laws, job.robot.joint_names, job.seconds), steps)
    else:
        ro = run(plant, lg.policy(job.robot, scale, job.gain), steps)
    m = walk_metrics(
        ro, ref.expected_distance(scale, ro.seconds), q_ref, ref.track(scale, ro.seconds)
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
    controllers: tuple[str, ...] = ("learned", OPEN_LOOP),
    scale: float | None = None,
    workers: int | None = None,
    gain: float | None = None,
) -> dict:
    """Every controller in ``controllers`` on robots ``0 … seeds − 1`` of ``protocol``.

    Returns:
        ``{"protocol": …, "settings": …, "controllers": {name: side}, "comparison":
        {name: McNemar vs open loop}}``; a side holds ``survived``, ``survival`` and its
        ``survival_ci95``, ``distance_m``, ``speed_mps``, ``abs_yaw_deg``,
        ``progress_ratio_min``, ``falls_by_furthest_factor`` and ``per_seed``.
    """
    metrics = RunDir(run_dir).read_json("metrics.json")
    draws = [protocol.draw(s, robot, seconds=seconds) for s in range(seeds)]
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
            gain,
        )
        for c in controllers
        for d in draws
    ]
    res = run_parallel(run_controller, jobs, workers)
    by = {c: [r for r, j in zip(res, jobs, strict=True) if j.controller == c] for c in controllers}
    out = {
        "protocol": {"name": protocol.name, "version": protocol.version, "path": protocol.path},
        "settings": {
            "seeds": seeds,
            "seconds": seconds,
            "engine": protocol.engine,
            "scale": scale if scale is not None else metrics.get("scale_reached"),
            "channel_gain": judged_gain(metrics, gain),
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
