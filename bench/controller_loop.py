"""The controller in the loop: physics steps per second with each controller, over bare
``mj_step`` measured in the same run (so the ratio holds on a noisy machine).

Controllers: open-loop playback; the paper's per-tick predictive search (faithful
variant, a gyro model fitted on a short recorded walk); the extended variant's
step-level balance channels (with their online IK). Decision latency of the per-tick
search is reported too.

Usage: ``python bench/controller_loop.py [--seconds 10]``
"""

from __future__ import annotations

import argparse
import json
import os
import time

os.environ.setdefault("IMITWALK_WORKERS", "1")

import mujoco
import numpy as np

from imitwalk.gait import GaitModel
from imitwalk.learnconfig import preset
from imitwalk.mocap import default_clip, load_motion
from imitwalk.models import Models, build_policy, fit_models
from imitwalk.retarget import GaitParams, RetargetConfig, retarget
from imitwalk.robots import load_robot
from imitwalk.sim import MujocoPlant, playback, run


def bare(robot, steps: int) -> float:
    m = robot.compile()
    d = mujoco.MjData(m)
    d.qpos[:] = robot.stand_qpos
    t = time.perf_counter()
    for _ in range(steps):
        mujoco.mj_step(m, d)
    return steps / (time.perf_counter() - t)


def loop(robot, policy, ticks: int) -> float:
    plant = MujocoPlant(robot)
    t = time.perf_counter()
    ro = run(plant, policy, ticks, stop_on_fall=False)
    return len(ro.t) * plant.options.substeps / (time.perf_counter() - t)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seconds", type=float, default=10.0, help="simulated seconds per run")
    args = ap.parse_args()
    robot = load_robot("hoap2")
    cfg = RetargetConfig(search=False, scales=(0.5,), params=GaitParams())
    ref = retarget(load_motion(default_clip()), robot, cfg).reference
    ticks = round(args.seconds / ref.dt)
    out = {"seconds": args.seconds, "control_hz": 1 / ref.dt}
    out["bare_mj_step_per_s"] = round(bare(robot, ticks * 10))
    q = ref.trajectory(0.5, args.seconds)
    t = time.perf_counter()
    playback(MujocoPlant(robot), q, q0=q[0], stop_on_fall=False)
    out["open_loop_steps_per_s"] = round(ticks * 10 / (time.perf_counter() - t))
    faithful = preset("faithful")
    gait = GaitModel(ref, (0.5,), faithful.gait)
    warm = build_policy(gait, 0.5, faithful, Models(), explore=1.0, rng_seed=0)
    run(MujocoPlant(robot), warm, ticks, stop_on_fall=False)  # record data for the model
    data = {"tick": [(np.asarray(warm.tick_states), np.asarray(warm.tick_actions))], "step": []}
    models = fit_models(data, faithful)
    pol = build_policy(gait, 0.5, faithful, models)
    out["faithful_mpc_steps_per_s"] = round(loop(robot, pol, ticks))
    sel = pol.selector
    lat = []
    s = np.zeros(3)
    a = gait.nominal_action(0.5, 0)
    for _ in range(300):
        t = time.perf_counter()
        sel.select(s, s, a)
        lat.append(time.perf_counter() - t)
    out["mpc_decision_ms_median"] = round(1e3 * float(np.median(lat)), 3)
    out["mpc_candidates"] = int(np.prod(faithful.tick.grid))
    ext = preset("extended")
    egait = GaitModel(ref, (0.5,), ext.gait)
    out["extended_channels_steps_per_s"] = round(
        loop(robot, build_policy(egait, 0.5, ext, Models(), robot=robot), ticks)
    )
    for k in ("open_loop", "faithful_mpc", "extended_channels"):
        out[f"{k}_over_bare"] = round(out[f"{k}_steps_per_s"] / out["bare_mj_step_per_s"], 3)
    print(json.dumps(out, indent=2))


if __name__ == "__main__":
    main()
