"""Judging a learned run: the learned controller beside open-loop playback, same robots.

Seed 0 is the nominal robot; every other seed is perturbed (masses ±5 %, friction
0.7–1.0, servo stiffness ±10 %) and starts with a small random push of the base
(:func:`imitwalk.perturb.perturbed` with ``disturbance=True``). Learning never sees
these seeds. Both controllers start from the standing pose at the scale the run
reached and are judged by the same :func:`~imitwalk.metrics.walk_metrics`.
"""

from __future__ import annotations

from dataclasses import replace

from scipy.stats import binomtest

from imitwalk.gait import GaitModel
from imitwalk.learnconfig import LearnConfig
from imitwalk.metrics import summarise, walk_metrics
from imitwalk.models import build_policy, fit_models, unstack_episodes
from imitwalk.parallel import run_parallel
from imitwalk.perturb import FACTORS, perturbed
from imitwalk.retarget.cadence import with_cadence
from imitwalk.retarget.reference import Reference
from imitwalk.robots import Robot
from imitwalk.runs import RunDir
from imitwalk.sim import SimOptions, make_plant, playback, run
from imitwalk.stepconfig import StepConfig

__all__ = [
    "LearnedGait",
    "check_gain",
    "compare_falls",
    "evaluate_run",
    "judged_gain",
    "load_gait",
    "per_seed",
    "wilson",
]

KEYS = (
    "forward_distance_m",
    "forward_speed_mps",
    "progress_ratio",
    "lateral_drift_m",
    "yaw_drift_deg",
    "gyro_rms",
    "joint_rms_error_rad",
    "max_tilt_deg",
    "torque_saturation",
)


class LearnedGait:
    """Everything needed to replay a run's learned controller (rebuilt from its folder)."""

    def __init__(self, ref: Reference, config: LearnConfig, data: dict, metrics: dict):
        gain = metrics.get("channel_gain", config.step.gain)  # picked by the gain trials
        config = replace(config, step=replace(config.step, gain=float(gain)))
        for channel, value in (metrics.get("channel_offset") or {}).items():  # the trials'
            config = replace(config, offset_channel=channel).with_offset(value)
        self.ref, self.config, self.metrics = ref, config, metrics
        self.scale = float(metrics["scale_reached"]) or config.schedule.start
        self.cadence = float(metrics.get("cadence", 1.0))  # picked by the cadence trials
        # the learned controller plays the loop at its cadence; open loop, as retargeted
        played = with_cadence(ref, self.cadence)
        self.gait = GaitModel(played, config.schedule.scales(), config.gait)
        self.models = fit_models(data, config)

    def policy(self, robot: Robot, scale: float | None = None, gain: float | None = None):
        """A fresh controller (no exploration) at ``scale`` (default: the scale reached),
        with the channel gain ``gain`` (default: the one the run's trials kept)."""
        s = self.scale if scale is None else scale
        cfg = self.config
        if gain is not None:
            cfg = replace(cfg, step=replace(cfg.step, gain=float(gain)))
        return build_policy(self.gait, s, cfg, self.models, robot=robot)


def load_gait(run_dir) -> LearnedGait:
    """Rebuild the learned controller of a finished run folder."""
    from imitwalk.config import from_dict

    rd = RunDir(run_dir)
    metrics = rd.read_json("metrics.json")
    cfg = from_dict(LearnConfig, rd.read_json("config.json")["learn"])
    data = unstack_episodes(rd.read_arrays("data.npz")) if rd.exists("data.npz") else {}
    return LearnedGait(Reference.load(rd.file("reference.npz")), cfg, data, metrics)


_CACHE: dict = {}


def check_gain(gain: float | None) -> None:
    """A one-line :class:`~imitwalk.errors.ConfigError` unless ``gain`` is ``None`` or a
    valid ``StepConfig.gain``."""
    if gain is not None:
        StepConfig(gain=float(gain))  # its own check, its own message


def judged_gain(metrics: dict, gain: float | None) -> float | None:
    """The channel gain the learned controller is judged with: ``gain``, else the one the
    run's trials kept (``metrics`` of its ``metrics.json``)."""
    return metrics.get("channel_gain") if gain is None else float(gain)


def _one(job) -> dict:
    run_dir, robot, mode, seed, seconds, base, scale, factors, engine, gain = job
    # a worker keeps the last run it loaded, until that run's metrics.json changes
    key = (str(run_dir), RunDir(run_dir).file("metrics.json").stat().st_mtime_ns)
    if key not in _CACHE:
        _CACHE.clear()
        _CACHE[key] = load_gait(run_dir)
    lg = _CACHE[key]
    scale = lg.scale if scale is None else scale
    ref = lg.gait.ref if mode == "learned" else lg.ref  # at the cadence each one plays
    opts = perturbed(seed, ref.sim_options(base), disturbance=seed != 0, factors=factors)
    steps = round(seconds / ref.dt)
    q_ref = ref.trajectory(scale, seconds)
    if mode == "learned":
        ro = run(make_plant(robot, opts, engine), lg.policy(robot, scale, gain), steps)
    else:
        ro = playback(make_plant(robot, opts, engine), q_ref, q0=q_ref[0])
    m = walk_metrics(
        ro, ref.expected_distance(scale, ro.seconds), q_ref, ref.track(scale, ro.seconds)
    )
    out = m.to_dict()
    out["seed"] = seed
    out["cycle_period_s"] = ref.period
    return out


def per_seed(
    run_dir,
    robot: Robot,
    seconds: float,
    seeds,
    base: SimOptions | None = None,
    workers=None,
    modes=("learned", "open_loop"),
    scale=None,
    factors: tuple[str, ...] = FACTORS,
    engine: str = "mujoco",
    gain: float | None = None,
) -> dict[str, list[dict]]:
    """Per-seed metrics of each mode (``factors``: what the perturbed robots differ in,
    see :func:`imitwalk.perturb.perturbed`; ``engine``: one of
    :data:`imitwalk.sim.ENGINES`; ``gain``: the learned controller's channel gain instead
    of the one the run kept)."""
    check_gain(gain)
    jobs = [
        (str(run_dir), robot, mode, s, seconds, base, scale, tuple(factors), engine, gain)
        for mode in modes
        for s in seeds
    ]
    res = run_parallel(_one, jobs, workers)
    return {mode: [r for r, j in zip(res, jobs, strict=True) if j[2] == mode] for mode in modes}


def _summary(runs: list[dict], metrics: dict) -> dict:
    out = {"falls": int(sum(r["fell"] for r in runs)), "seeds": len(runs)}
    for k in KEYS:
        out[k] = summarise([r[k] for r in runs])
    out["cycle_period_s"] = runs[0]["cycle_period_s"] if runs else None
    out["scale_reached"] = metrics.get("scale_reached")
    for k in ("sim_seconds_used_for_learning", "wall_seconds_for_learning", "iterations"):
        out[k] = metrics.get(k)
    out["per_seed"] = [
        {
            k: r[k]
            for k in (
                "seed",
                "fell",
                "fall_time_s",
                "progress_ratio",
                "yaw_drift_deg",
                "lateral_drift_m",
                "forward_speed_mps",
                "torque_saturation",
                "saturated_joint",
                "commanded_turn_deg",
                "commanded_side_m",
            )
        }
        for r in runs
    ]
    return out


def wilson(k: int, n: int) -> tuple[float, float]:
    """95 % Wilson score interval of a rate ``k / n`` (``(0, 1)`` when ``n`` is 0)."""
    if n == 0:
        return 0.0, 1.0
    ci = binomtest(k, n).proportion_ci(confidence_level=0.95, method="wilson")
    return float(ci.low), float(ci.high)


def compare_falls(learned: list[bool], open_loop: list[bool]) -> dict:
    """Falls of the two controllers on the same robots, as a paired comparison.

    Returns the fall rates with their 95 % Wilson intervals, the discordant robots
    (``learned_only``: fell learned but not open loop; ``open_only``: the reverse) and
    the two-sided exact McNemar p-value (a binomial test on the discordant robots) of
    "learning changes the fall rate". Ten robots rarely decide it: a 0/10 against 2/10
    has p = 0.5.
    """
    if len(learned) != len(open_loop):
        raise ValueError("compare_falls: the two lists must cover the same robots")
    n = len(learned)
    lo = sum(1 for a, b in zip(learned, open_loop, strict=True) if a and not b)
    oo = sum(1 for a, b in zip(learned, open_loop, strict=True) if b and not a)
    p = float(binomtest(lo, lo + oo, 0.5).pvalue) if lo + oo else 1.0
    out = {"robots": n, "learned_only": lo, "open_only": oo, "mcnemar_p": p}
    for name, fell in (("learned", learned), ("open_loop", open_loop)):
        k = int(sum(fell))
        out[f"{name}_fall_rate"] = k / n if n else 0.0
        out[f"{name}_fall_rate_ci95"] = list(wilson(k, n))
    return out


def evaluate_run(
    run_dir,
    robot: Robot,
    seconds: float = 30.0,
    seeds: int = 10,
    workers=None,
    base: SimOptions | None = None,
    scale: float | None = None,
    engine: str = "mujoco",
    gain: float | None = None,
) -> dict:
    """``{"learned": ..., "open_loop": ...}`` with the same keys (per-seed figures as
    ``{"mean", "min", "max"}``); open loop is the reference at the same scale.
    ``"comparison"`` holds the paired fall comparison (:func:`compare_falls`).
    ``scale``: judge both at this scale instead of the one the run reached.
    ``engine``: the physics engine both are judged on (:data:`imitwalk.sim.ENGINES`),
    whichever the run learned on. ``gain``: the learned controller's channel gain
    (``StepConfig.gain``) instead of the one the run's trials kept."""
    metrics = RunDir(run_dir).read_json("metrics.json")
    res = per_seed(
        run_dir, robot, seconds, list(range(seeds)), base, workers, scale=scale, engine=engine,
        gain=gain,
    )  # fmt: skip
    out = {mode: _summary(runs, metrics) for mode, runs in res.items()}
    out["open_loop"]["sim_seconds_used_for_learning"] = 0.0
    out["open_loop"]["wall_seconds_for_learning"] = 0.0
    out["open_loop"]["iterations"] = 0
    out["comparison"] = compare_falls(
        [bool(r["fell"]) for r in res["learned"]], [bool(r["fell"]) for r in res["open_loop"]]
    )
    out["settings"] = {
        "seconds": seconds,
        "seeds": seeds,
        "scale": scale or metrics.get("scale_reached"),
        "engine": engine,
        "channel_gain": judged_gain(metrics, gain),
    }
    return out
