"""Refine the searched reference parameters at full stride, by falls counted on many robots.

The cross-entropy search (:mod:`imitwalk.retarget.search`) scores short rollouts (12 s)
on a few robots (4) at a few scales. That is enough to find a walk, but at full stride
the walk it finds sits on a knife edge, and the search cannot see it: on CMU 07_06 the
searched reference fell open loop on 15 of 40 training-range robots in 30 s at scale
1.0; 5 mm more swing-foot lift made it 19, the sway 2 % of a cycle earlier 40, and
1.5 mm more lean 9. Short trials on four robots cannot tell these apart. The edge also moves
with the stride: parameters nudged until 1.0 fell on 3 of those robots fell on 7 at 0.8,
where the searched ones fell on 1. One parameter set serves every scale, so it is judged
at several.

:func:`refine_params` is a coordinate search on those falls: a few rounds over the
parameters, each nudged by :data:`STEPS` up, then down; the first nudge whose reference
falls on fewer robots, summed over ``refine_scales`` (played open loop, ``refine_seconds``
each, with the evaluation's initial push), is kept if it walks about as far
(:data:`PROGRESS_SLACK`), and the round goes on to the next parameter. Falls are not the
whole story: on the default clip the kept nudges took the mean |heading drift| of the
trials from 11.5° to 26.7° (guarding the heading kept one nudge within noise: measured in
docs/history-0.1.md, "Refining the reference at several strides"). It stops
after ``refine_rounds`` rounds, earlier when a whole round keeps nothing or when nothing
falls. Like the search it uses training robots only (:func:`imitwalk.sim.perturb.train_seeds`),
never an evaluation robot, and no dynamics model: it measures.

A nudge is kept only if it falls less often than the set it must beat, so once its falls
pass that set's it cannot be kept, whatever its remaining robots do. With
``refine_early_stop`` (on by default) its trial stops there: the longest stride, where
most falls are, is played first, and the robots not yet run are skipped. The nudges kept,
and so the reference, are the same as with every robot played; only the rejected
trials' counts become lower bounds (``complete`` false), and the refinement costs less.

:func:`refine_per_scale` (``refine_per_scale``) runs the same search once per scale of
``refine_scales``, each judged at its own scale only and starting from the searched
set, so that the reference can be solved with each scale's own set there
(:func:`~imitwalk.retarget.walkable.build_walkable`'s ``scale_params``) instead of one
compromise for every stride.
"""

from __future__ import annotations

import time
from dataclasses import asdict, dataclass, fields, replace

import numpy as np

from imitwalk.retarget.command import GaitCommand
from imitwalk.retarget.ik import WalkIK, leg_geometry
from imitwalk.retarget.params import GaitParams, leg_scaled
from imitwalk.retarget.search import LENGTHS, bounds
from imitwalk.retarget.template import GaitTemplate
from imitwalk.retarget.walkable import build_walkable
from imitwalk.robots import Robot
from imitwalk.sim.perturb import train_seeds
from imitwalk.sim.types import SimOptions

__all__ = ["PROGRESS_SLACK", "STEPS", "RefineTrial", "refine_params", "refine_per_scale"]

#: How far one nudge moves each parameter (its units: see :class:`GaitParams`); the lengths'
#: nudges are for a leg of :data:`~imitwalk.retarget.params.REFERENCE_LEG` and scale with
#: the robot's (as :func:`~imitwalk.retarget.search.bounds` does).
STEPS: dict[str, float] = {
    "sway": 0.025,
    "height": 0.01,
    "lift": 0.002,
    "ds": 0.02,
    "lean": 0.0015,
    "width": 0.002,
}

#: However few robots it fells, a nudge may not cost more mean progress ratio than this.
PROGRESS_SLACK = 0.05


@dataclass(frozen=True)
class RefineTrial:
    """One parameter set played open loop on the refinement robots.

    Attributes:
        params: the reference parameters; changed: ``"name+"``/``"name-"`` (``""``: the
            search's own); falls, robots: how many runs fell, of how many (robots × scales).
        mean_seconds: mean time up [s]; mean_progress: mean progress ratio;
        mean_abs_yaw_deg: mean |heading drift| [deg]; kept: whether it was kept;
        repeat: the set was played before (a later round came back to it), and its
        measurement was reused (the runs are deterministic); at: the one scale it was
        judged at (per-scale refinement; ``None``: every one of ``refine_scales``);
        complete: every robot was played (false: the trial stopped once it fell more
        often than the set it had to beat, so ``falls`` is a lower bound and ``robots``
        the runs played).
    """

    params: dict
    changed: str
    falls: int
    robots: int
    mean_seconds: float
    mean_progress: float
    mean_abs_yaw_deg: float
    kept: bool = False
    repeat: bool = False
    at: float | None = None
    complete: bool = True

    def beats(self, other: RefineTrial) -> bool:
        """Fewer falls than ``other`` (or as many, and longer up), at no great cost in
        progress."""
        better = (self.falls, -self.mean_seconds) < (other.falls, -other.mean_seconds - 1e-9)
        return better and self.mean_progress >= other.mean_progress - PROGRESS_SLACK


def _falls(runs) -> int:
    """How many of ``runs`` (:class:`~imitwalk.sim.playback.ModelRun`) fell."""
    return sum(r.metrics.fell for r in runs)


def refine_params(
    template: GaitTemplate,
    robot: Robot,
    params: GaitParams,
    config,
    dt: float = 0.01,
    base: SimOptions | None = None,
    command: GaitCommand | None = None,
    progress=None,
    at: float | None = None,
) -> tuple[GaitParams, dict]:
    """Nudge ``params`` (the search's best) while the reference falls on fewer robots.

    Args:
        template: the human gait; robot: the robot; params: where to start.
        config: the :class:`~imitwalk.retarget.search.SearchConfig` (``refine_scales``,
            ``refine_rounds``, ``refine_models``, ``refine_seconds``, ``workers``,
            ``engine``).
        dt: control period [s]; base: simulation options every run starts from;
        command: the commanded gait; progress: optional ``callback(done, total, trial)``
            after each trial (``trial.kept``: whether it was kept).
        at: judge at this one scale instead of every one of ``refine_scales``.

    Returns:
        the kept parameters and a JSON-able report of every trial.
    """
    from imitwalk.sim.playback import play_reference  # it imports this package

    scales = [at] if at is not None else sorted(config.refine_scales)
    seeds = train_seeds(config.refine_models)
    leg = leg_geometry(robot).leg if robot is not None else None
    box = bounds(leg)
    steps = {k: leg_scaled(v, leg) if k in LENGTHS else v for k, v in STEPS.items()}
    ik = WalkIK(robot)
    names = [f.name for f in fields(GaitParams)]
    total = 1 + config.refine_rounds * 2 * len(names)
    t0 = time.perf_counter()
    trials: list[RefineTrial] = []
    played: dict[tuple, RefineTrial] = {}

    def trial(p: GaitParams, changed: str, bound: int | None = None) -> RefineTrial:
        """Play ``p``; with ``bound``, stop once it has fallen more often than that."""
        key = tuple(p.to_dict().values())
        if key in played:  # a partial count stays above any later set to beat: falls only drop
            out = replace(played[key], changed=changed, repeat=True)
            trials.append(out)
            return out
        ref = build_walkable(template, robot, p, scales, dt, ik=ik, command=command).reference
        runs: dict[float, list] = {}
        fell = 0
        for s in sorted(scales, reverse=True):  # the longest stride falls most: first
            stop = None if bound is None else (lambda rs, f=fell: f + _falls(rs) > bound)
            runs[s] = play_reference(
                ref,
                robot,
                s,
                config.refine_seconds,
                seeds,
                base,
                config.workers,
                config.engine,
                disturbance=True,
                stop=stop,
            )
            fell += _falls(runs[s])
            if bound is not None and fell > bound:
                break
        ms = [r.metrics for s in scales for r in runs.get(s, [])]  # in scale order, as counted
        out = RefineTrial(
            params=p.to_dict(),
            changed=changed,
            falls=int(sum(m.fell for m in ms)),
            robots=len(ms),
            mean_seconds=float(np.mean([m.seconds for m in ms])),
            mean_progress=float(np.mean([m.progress_ratio for m in ms])),
            mean_abs_yaw_deg=float(np.mean([abs(m.yaw_drift_deg) for m in ms])),
            at=at,
            complete=len(ms) == len(scales) * len(seeds),
        )
        trials.append(out)
        played[key] = out
        return out

    def report(t: RefineTrial, keep: bool) -> None:
        if progress:
            progress(len(trials), total, replace(t, kept=keep))

    best, current = trial(params, ""), params
    report(best, True)
    kept = [0]
    for _ in range(config.refine_rounds):
        moved = False
        for name in names:
            if best.falls == 0:
                break  # nothing can beat a set that never falls (it is up the whole time)
            lo, hi = box[name]
            value = getattr(current.for_leg(leg), name)  # an unset lift: the robot's default
            for sign, tag in ((1.0, "+"), (-1.0, "-")):
                x = float(np.clip(value + sign * steps[name], lo, hi))
                if abs(x - value) < 1e-12:
                    continue  # at its bound
                cand = replace(current, **{name: x})
                t = trial(cand, name + tag, best.falls if config.refine_early_stop else None)
                keep = t.beats(best)
                report(t, keep)
                if keep:
                    best, current, moved = t, cand, True
                    kept.append(len(trials) - 1)
                    break
        if not moved or best.falls == 0:
            break
    rows = [replace(t, kept=i in kept) for i, t in enumerate(trials)]
    out = {
        "method": "coordinate search on open-loop falls, summed over scales"
        if at is None
        else "coordinate search on open-loop falls at one scale",
        "scales": scales,
        "seconds": config.refine_seconds,
        "seeds": list(seeds),
        "steps": steps,
        "progress_slack": PROGRESS_SLACK,
        "early_stop": config.refine_early_stop,
        "trials": [asdict(r) for r in rows],
        "stopped_early": sum(not (r.complete or r.repeat) for r in rows),
        "start_falls": rows[0].falls,
        "falls": best.falls,
        "params": current.to_dict(),
        "sim_seconds": sum(r.robots for r in rows if not r.repeat) * config.refine_seconds,
        "wall_seconds": time.perf_counter() - t0,
    }
    return current, out


def refine_per_scale(
    template: GaitTemplate, robot: Robot, params: GaitParams, config, progress=None, **kw
) -> tuple[dict[float, GaitParams], dict]:
    """:func:`refine_params` once per scale of ``config.refine_scales``, each judged at
    that scale alone and starting from ``params``; ``kw`` (``dt``, ``base``,
    ``command``) and ``progress`` (counted over every scale) as there.

    Returns:
        ``{scale: kept parameters}`` and a JSON-able report: the summed falls, cost and
        trials (each with its scale ``at``), and each scale's own report in ``per_scale``.
    """
    scales = sorted(config.refine_scales)
    kept, reports, done = {}, [], [0]
    total = len(scales) * (1 + config.refine_rounds * 2 * len(fields(GaitParams)))

    def relay(_done: int, _total: int, trial: RefineTrial) -> None:
        done[0] += 1
        if progress:
            progress(done[0], total, trial)

    for s in scales:
        kept[s], rep = refine_params(template, robot, params, config, progress=relay, at=s, **kw)
        reports.append(rep)
    out = {
        "method": "coordinate search on open-loop falls, one per scale",
        "scales": scales,
        "start_falls": sum(r["start_falls"] for r in reports),
        "falls": sum(r["falls"] for r in reports),
        "trials": [t for r in reports for t in r["trials"]],
        "stopped_early": sum(r["stopped_early"] for r in reports),
        "sim_seconds": sum(r["sim_seconds"] for r in reports),
        "wall_seconds": sum(r["wall_seconds"] for r in reports),
        "per_scale": {f"{s:g}": r for s, r in zip(scales, reports, strict=True)},
    }
    return kept, out
