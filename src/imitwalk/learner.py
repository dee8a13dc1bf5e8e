"""The learning loop (paper §5 steps 3–7, §6): execute, record, retrain, re-optimise, scale up.

Each iteration runs the current controller on the training robots (the nominal one, and
for the extended variant training perturbations never used for evaluation — new ones at
every iteration with ``fresh_robots``), records the
sensory-motor data, refits the models on everything recorded so far and moves along the
scale schedule: a scale is passed when its last ``confirm`` iterations (no exploration)
walk without a fall on every training robot. With ``offsets``, a scale where the schedule
would stop first gets trials of a constant channel offset (:mod:`imitwalk.trust`); if
another offset measures better there, the schedule goes on with it (the scale reached
gets the trials too). When it stops, a few
consolidation iterations at the scale reached add on-policy data where the gait will be
used (their falls are logged; they do not change the scale reached). With ``gains``, the
channel-gain trials then decide how much of the learned correction to apply, and with
``cadences`` the cadence trials how fast to play the loop (:mod:`imitwalk.trust`); they
are checkpointed too. After every
iteration the run folder is checkpointed atomically, so ``resume`` continues an
interrupted run and ends where an uninterrupted one would (same seed, same result).
With ``back_off_to``, a run whose gain trials still fall at the top scale gives back
scale where the same trials measure fewer falls (:func:`imitwalk.tuning.back_off`), and
with ``back_off_when`` including ``"consolidation"`` one whose consolidation falls
consolidates one scale lower first (:func:`imitwalk.tuning.give_back_scale`); the
trials themselves run in :mod:`imitwalk.tuning`.
"""

from __future__ import annotations

import time
from dataclasses import asdict

import numpy as np

from imitwalk import tuning
from imitwalk.config import from_dict, to_dict
from imitwalk.episode import run_episode
from imitwalk.errors import RunError
from imitwalk.gait import GaitModel
from imitwalk.learnconfig import LearnConfig
from imitwalk.models import fit_models, stack_episodes, unstack_episodes
from imitwalk.parallel import run_parallel
from imitwalk.perturb import train_seeds
from imitwalk.retarget.reference import Reference
from imitwalk.robots import Robot
from imitwalk.runs import RunDir

__all__ = ["learn"]


def _iteration_log(scale, it, results, reports, t0) -> dict:
    ms = [r["metrics"] for r in results]
    pred = [r.get("tick_pred") for r in results if r.get("tick_pred") is not None]
    spred = [r.get("step_pred") for r in results if r.get("step_pred") is not None]
    return {
        "scale": scale,
        "iteration": it,
        "robots": len(results),
        "seeds": [r["seed"] for r in results],
        "falls": int(sum(m["fell"] for m in ms)),
        "fell": [m["fell"] for m in ms],
        "fall_time_s": [m["fall_time_s"] for m in ms],
        "cost_measured": float(
            np.mean([r["gyro_cost"] for r in results if r["gyro_cost"] is not None] or [np.nan])
        ),
        "cost_predicted": float(np.mean(pred)) if pred else None,
        "step_cost_predicted": float(np.mean(spred)) if spred else None,
        "prediction": reports,
        "forward_speed_mps": float(np.mean([m["forward_speed_mps"] for m in ms])),
        "progress_ratio": float(np.mean([m["progress_ratio"] for m in ms])),
        "yaw_drift_deg": float(np.mean([m["yaw_drift_deg"] for m in ms])),
        "sim_seconds": float(sum(m["seconds"] for m in ms)),
        "wall_seconds": time.perf_counter() - t0,
    }


def learn(
    ref: Reference, robot: Robot, config: LearnConfig, run_dir, resume: bool = False, progress=None
) -> dict:
    """Learn to walk ``ref`` on ``robot``; write everything to ``run_dir``.

    Args:
        ref: the retargeted reference; robot: the robot; config: settings.
        run_dir: output folder; resume: continue the run there.
        progress: optional ``callback(line)`` for one line per iteration.

    Returns:
        the learning summary (also written as ``metrics.json``).
    """
    rd = RunDir(run_dir)
    cfg_json = {"learn": to_dict(config), "reference": ref.summary(), "robot": robot.name}
    if resume:
        if not rd.exists("checkpoint.json"):
            raise RunError(f"nothing to resume in {rd.path}: no checkpoint.json")
        state = rd.read_json("checkpoint.json")
        saved = from_dict(LearnConfig, rd.read_json("config.json")["learn"])  # + new defaults
        if to_dict(saved) != cfg_json["learn"]:
            raise RunError(f"{rd.path} was started with other settings; resume with the same ones")
        log = rd.read_log()
        data = unstack_episodes(rd.read_arrays("data.npz")) if rd.exists("data.npz") else {}
    else:
        if rd.exists("checkpoint.json"):
            raise RunError(f"{rd.path} already holds a run; pass --resume or choose another --out")
        rd.path.mkdir(parents=True, exist_ok=True)
        rd.write_json("config.json", cfg_json)
        ref.save(rd.file("reference.npz"))
        state = {
            "scale_index": 0,
            "iteration": 0,
            "failures": 0,
            "passed": [],
            "done": False,
            "total_iterations": 0,
            "sim_seconds": 0.0,
            "wall_seconds": 0.0,
        }
        log, data = [], {"tick": [], "step": []}
    scales = config.schedule.scales()
    gait = GaitModel(ref, scales, config.gait)
    sch = config.schedule
    while not state["done"]:
        t0 = time.perf_counter()
        si, it = state["scale_index"], state["iteration"]
        scale = scales[si]
        models = fit_models(data, config)
        polishing = state.get("consolidate_left") is not None
        draw = state["total_iterations"] if config.fresh_robots else 0
        seeds = train_seeds(config.train_models, draw)
        run_cfg = config.with_offset(state.get("offset"))  # the offset kept so far
        explore = 0.0
        if sch.iterations > 1 and not polishing:
            explore = max(0.0, 1.0 - it / (sch.iterations - 1))
        jobs = [
            (
                robot,
                gait,
                scale,
                run_cfg,
                models,
                s,
                explore,
                [config.seed, state["total_iterations"], j],
                sch.seconds,
            )
            for j, s in enumerate(seeds)
        ]
        results = run_parallel(run_episode, jobs, config.workers)
        reports = models.held_out(results)
        for r in results:
            for kind in ("tick", "step"):
                if kind in r and len(r[kind][0]) > 2:
                    data[kind].append(r[kind])
        entry = _iteration_log(scale, it, results, reports, t0)
        entry["consolidation"] = polishing
        log.append(entry)
        fell = entry["falls"] > 0
        last = it >= sch.iterations - 1
        if polishing:
            state["consolidate_left"] -= 1
            state["done"] = state["consolidate_left"] <= 0
            lower = tuning.give_back_scale(config, state, log) if state["done"] else None
            if lower is not None:  # its consolidation fell: consolidate one scale down
                state["done"], state["consolidate_left"] = False, sch.consolidate
                state["scale_index"] = scales.index(lower)
                if progress:
                    progress(f"back-off: the consolidation fell at {scale:g}; on to {lower:g}")
        elif fell:
            state["failures"] += 1
            state["clean"] = 0
            if state["failures"] > sch.retries:
                state["done"] = not tuning.retry_with_offset(
                    gait, robot, config, data, scale, state, progress
                )
        elif last:
            state["clean"] = state.get("clean", 0) + 1
        passed = not polishing and last and not fell and state.get("clean", 0) >= sch.confirm
        if passed:
            state["passed"].append(scale)
            state["failures"] = state["clean"] = 0
        if not polishing and not state["done"]:
            if passed:
                state["scale_index"], state["iteration"] = si + 1, 0
                state["done"] = si + 1 >= len(scales)
            else:
                state["iteration"] = min(it + 1, sch.iterations - 1)
        if state["done"] and not polishing and state["passed"] and sch.consolidate > 0:
            # the schedule has stopped: a few more iterations at the scale reached
            state["done"], state["consolidate_left"] = False, sch.consolidate
            state["scale_index"] = scales.index(max(state["passed"]))
            state["iteration"] = sch.iterations - 1
        state["total_iterations"] += 1
        state["sim_seconds"] += entry["sim_seconds"]
        state["wall_seconds"] += entry["wall_seconds"]
        rd.write_arrays("data.npz", stack_episodes(data))
        rd.write_log(log)
        rd.write_json("checkpoint.json", state)
        if progress:
            progress(_progress_line(entry))
    reached = tuning.settled_scale(state)  # lower after a back-off in the trials
    if config.offsets and state["passed"]:  # and at the scale reached (once per scale)
        tuning.retry_with_offset(gait, robot, config, data, reached, state, progress)
        rd.write_json("checkpoint.json", state)
    run_cfg = config.with_offset(state.get("offset"))
    for key, values in (("gain", config.gains), ("cadence", config.cadences)):
        if values and config.steps and state["passed"] and key not in state:
            gain = state["gain"]["gain"] if "gain" in state else config.step.gain
            choice = tuning.tune(gait, robot, run_cfg, data, reached, key, values, gain, progress)
            state[key] = choice.to_dict()
            tuning.spend(state, choice)
            rd.write_json("checkpoint.json", state)
        if key == "gain" and config.back_off_to is not None and "gain" in state:
            reached = tuning.back_off(gait, robot, config, data, state, progress)
            rd.write_json("checkpoint.json", state)
    summary = {
        "variant": config.variant,
        "scale_reached": reached,
        "scales_passed": state["passed"],
        "iterations": state["total_iterations"],
        "sim_seconds_used_for_learning": state["sim_seconds"],
        "wall_seconds_for_learning": state["wall_seconds"],
        "channel_gain": state["gain"]["gain"] if "gain" in state else config.step.gain,
        "gain_trials": state.get("gain"),
        "back_off": state.get("back_off"),
        "cadence": state["cadence"]["cadence"] if "cadence" in state else 1.0,
        "cadence_trials": state.get("cadence"),
        "channel_offset": (
            {config.offset_channel: state["offset"]} if state.get("offset") is not None else None
        ),
        "offset_trials": state.get("offset_trials", []),
        "gait": gait.report(),
        "config": asdict(config),
    }
    rd.write_json("metrics.json", summary)
    return summary


def _progress_line(e: dict) -> str:
    pred = e["prediction"].get("tick") or e["prediction"].get("step")
    ratio = f"{pred['overall_ratio']:.2f}" if pred else "  - "
    cp = f"{e['cost_predicted']:.3f}" if e["cost_predicted"] is not None else "  -  "
    return (
        f"scale {e['scale']:.2f} it {e['iteration']} | fell {e['falls']}/{e['robots']} | "
        f"cost meas {e['cost_measured']:.3f} pred {cp} | pred err/baseline {ratio} | "
        f"{e['forward_speed_mps']:.3f} m/s, progress {e['progress_ratio']:.2f}, "
        f"yaw {e['yaw_drift_deg']:+.1f} deg | {e['wall_seconds']:.1f} s"
    )
