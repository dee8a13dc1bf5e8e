"""The measured trials the learning loop runs once its scale schedule has ended or stalled.

:mod:`imitwalk.trust` picks a value from trial counts; this module runs those trials
inside :func:`imitwalk.learner.learn`: the channel-gain, cadence and channel-offset trials
(:func:`tune`, :func:`retry_with_offset`) and the back-off (:func:`back_off`), which gives
back scale when the trials at the scale reached still fall. Every trial is a full
episode on trial robots the learner never learned on and the evaluation never uses
(:func:`imitwalk.perturb.trial_seeds`). Each function also adds the simulated and wall
time it used to the learner's ``state`` (its checkpoint) where it keeps a result there.
"""

from __future__ import annotations

import time
from dataclasses import replace

from imitwalk.episode import run_episode
from imitwalk.gait import GaitModel
from imitwalk.learnconfig import LearnConfig
from imitwalk.models import fit_models
from imitwalk.parallel import run_parallel
from imitwalk.perturb import trial_seeds
from imitwalk.retarget.cadence import with_cadence
from imitwalk.stepconfig import STEP_CHANNELS
from imitwalk.trust import LABELS, GainChoice, tune_gain

__all__ = [
    "back_off",
    "give_back_scale",
    "kept_falls",
    "retry_with_offset",
    "settled_scale",
    "spend",
    "tune",
]


def tune(gait, robot, config: LearnConfig, data, scale, key, values, gain, progress) -> GainChoice:
    """Trials at ``scale`` (:func:`imitwalk.trust.tune_gain`) of ``values`` of the channel
    gain (``key="gain"``), of the cadence with the channel gain ``gain`` (``"cadence"``),
    or of the channel offset with that gain (``"offset"``)."""
    t0 = time.perf_counter()
    models = fit_models(data, config)

    def episodes(value: float, seeds) -> list[dict]:
        g = value if key == "gain" else gain
        rate = value if key == "cadence" else 1.0
        cfg = config.with_offset(value) if key == "offset" else config
        cfg = replace(cfg, step=replace(cfg.step, gain=g))
        walk = gait  # the gait the schedule learned, at the candidate cadence
        if rate != 1.0:
            walk = GaitModel(with_cadence(gait.ref, rate), gait.scales, config.gait)
        jobs = [
            (robot, walk, scale, cfg, models, s, 0.0, [config.seed, 10**6, j], config.gain_seconds)
            for j, s in enumerate(seeds)
        ]
        return [r["metrics"] for r in run_parallel(run_episode, jobs, config.workers)]

    seeds = trial_seeds(config.gain_robots, config.stratify_trials, tuple(config.train_friction))
    choice = tune_gain(episodes, values, seeds, progress, key)
    if progress:
        progress(f"{LABELS[key]} kept: {choice.gain:g}")
    return replace(choice, wall_seconds=time.perf_counter() - t0)


def spend(state: dict, choice: GainChoice) -> None:
    """Add a round of trials' simulated and wall time [s] to the learner's ``state``."""
    state["sim_seconds"] += choice.sim_seconds
    state["wall_seconds"] += choice.wall_seconds


def retry_with_offset(gait, robot, config: LearnConfig, data, scale, state, progress) -> bool:
    """The schedule would stop at ``scale``: try ``config.offsets`` there (once per scale).
    True if another offset measured better; it is kept and the schedule goes on."""
    if not (config.offsets and config.steps) or scale in state.get("offset_tried", []):
        return False
    state.setdefault("offset_tried", []).append(scale)
    run_cfg = config.with_offset(state.get("offset"))
    now = float(run_cfg.step.offset_vector[STEP_CHANNELS.index(config.offset_channel)])
    values = sorted(set(config.offsets) | {now}, key=lambda v: (abs(v - now), v))  # ties: now
    gain = run_cfg.step.gain
    choice = tune(gait, robot, run_cfg, data, scale, "offset", values, gain, progress)
    state.setdefault("offset_trials", []).append({"scale": scale, **choice.to_dict()})
    spend(state, choice)
    if choice.gain == now:
        return False
    state["offset"], state["failures"] = choice.gain, 0
    return True


def kept_falls(trials: dict, key: str = "gain") -> int:
    """Trial robots that fell with the value the trials kept (``GainChoice.to_dict()``)."""
    return next(r["falls"] for r in trials["table"] if r[key] == trials[key])


def settled_scale(state: dict) -> float:
    """The scale reached before the gain trials: the top scale the schedule passed, or the
    one its consolidation settled at (:func:`give_back_scale`); 0 if none passed."""
    return state.get("settled", max(state["passed"])) if state["passed"] else 0.0


def _passed_below(config: LearnConfig, state: dict, scale: float) -> list[float]:
    """The passed scales below ``scale`` and not below ``back_off_to``, highest first."""
    floor = config.back_off_to - 1e-9
    return sorted((s for s in state["passed"] if floor <= s < scale - 1e-9), reverse=True)


def give_back_scale(config: LearnConfig, state: dict, log: list[dict]) -> float | None:
    """The consolidation iterations at a scale have ended: the scale to consolidate at
    next, or ``None`` to settle at this one.

    The consolidation runs the learned controller without exploration on training robots
    (fresh ones with ``fresh_robots``) at the scale reached: a further confirmation of
    that scale. With ``back_off_to`` set and ``"consolidation"`` in ``back_off_when``, a
    fall in it on any robot gives the scale back: the consolidation runs again at the next
    passed scale down, not below ``back_off_to``. Every consolidation is recorded in
    ``state["consolidated"]`` (``scale``, ``falls``, ``robots``), and the scale it ended
    at in ``state["settled"]``.
    """
    done = log[-config.schedule.consolidate :]
    scale = done[-1]["scale"]
    falls = sum(e["falls"] for e in done)
    state.setdefault("consolidated", []).append(
        {"scale": scale, "falls": falls, "robots": sum(e["robots"] for e in done)}
    )
    state["settled"] = scale
    if config.back_off_to is None or "consolidation" not in config.back_off_when or not falls:
        return None
    below = _passed_below(config, state, scale)
    return below[0] if below else None


def back_off(gait, robot, config: LearnConfig, data, state, progress) -> float:
    """Give back scale while the gain trials at the scale reached still fall (``back_off_to``).

    ``state["gain"]`` holds the gain trials at the scale reached: the top scale the
    schedule passed, or the one its consolidation settled at (:func:`give_back_scale`).
    With ``"trials"`` in ``back_off_when``, while the gain kept there still falls on some
    trial robot, the same gain trials run one passed scale lower (not below
    ``config.back_off_to``); if the best gain there falls on fewer trial robots, the walk
    settles at that scale with that gain and the search goes on one scale lower.
    ``state["back_off"]`` records the top passed (``from``), the scale settled at, every
    round of trials and every consolidation; ``state["gain"]`` becomes the settled
    scale's trials.

    Returns:
        the scale the walk settles at (the scale reached if nothing measured better
        below it).
    """
    if "back_off" in state:
        return state["back_off"]["scale"]
    top = settled_scale(state)
    below = _passed_below(config, state, top) if "trials" in config.back_off_when else []
    scale, best, rounds = top, state["gain"], []
    run_cfg = config.with_offset(state.get("offset"))
    for lower in below:
        if kept_falls(best) == 0:
            break
        if progress:
            progress(f"back-off: the kept gain fell at scale {scale:g}; trials at {lower:g}")
        choice = tune(gait, robot, run_cfg, data, lower, "gain", config.gains, None, progress)
        spend(state, choice)
        trials = {"scale": lower, **choice.to_dict()}
        rounds.append(trials)
        if kept_falls(trials) >= kept_falls(best):
            break
        scale, best = lower, trials
    start = max(state["passed"])
    state["back_off"] = {
        "from": start,
        "scale": scale,
        "trials": rounds,
        "consolidation": state.get("consolidated", []),
    }
    state["gain"] = best
    if progress and scale != start:
        progress(f"back-off: settled at scale {scale:g} (from {start:g}), gain {best['gain']:g}")
    return scale
