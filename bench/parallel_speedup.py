"""Batch evaluation on 2 cores: ``mujoco.rollout`` with 1 and 2 threads, and imitwalk's
process pool with 1 and 2 workers, on the same open-loop playbacks (same run; the
settings are interleaved and the best of ``--repeat`` kept for each).

Usage: ``python bench/parallel_speedup.py [--models 8] [--seconds 10] [--repeat 2]``
"""

from __future__ import annotations

import argparse
import json
import time

import mujoco
import numpy as np
from mujoco import rollout

from imitwalk.mocap import default_clip, load_motion
from imitwalk.retarget import GaitParams, RetargetConfig, retarget
from imitwalk.retarget.playback import play_reference
from imitwalk.robots import load_robot
from imitwalk.sim.mujoco import MujocoPlant
from imitwalk.sim.perturb import perturbed


def _models(robot, n: int):
    """Perturbed MjModels (built by the Plant) and each one's per-physics-step controls."""
    models = []
    for s in range(n):
        p = MujocoPlant(robot, perturbed(s))
        p.reset()
        models.append(p)
    return models


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--models", type=int, default=8)
    ap.add_argument("--seconds", type=float, default=10.0)
    ap.add_argument("--repeat", type=int, default=2, help="trials; the best is kept")
    args = ap.parse_args()
    robot = load_robot("hoap2")
    cfg = RetargetConfig(search=False, scales=(0.5,), params=GaitParams())
    ref = retarget(load_motion(default_clip()), robot, cfg).reference
    q = ref.trajectory(0.5, args.seconds)
    plants = _models(robot, args.models)
    sub = plants[0].options.substeps
    nstep = len(q) * sub
    ctrl = np.zeros((args.models, nstep, plants[0].model.nu))
    states = []
    for i, p in enumerate(plants):
        act = p._act
        ctrl[i][:, act] = np.repeat(q * robot.signs, sub, axis=0)
        full = mujoco.mjtState.mjSTATE_FULLPHYSICS
        st = np.empty(mujoco.mj_stateSize(p.model, full))
        mujoco.mj_getState(p.model, p.data, st, full)
        states.append(st)
    models = [p.model for p in plants]
    out = {"models": args.models, "sim_seconds_each": args.seconds}
    for threads in (1, 2) * args.repeat:  # interleaved, best of --repeat each
        datas = [mujoco.MjData(models[0]) for _ in range(threads)]
        t = time.perf_counter()
        rollout.rollout(models, datas, np.array(states), ctrl, persistent_pool=False)
        dt = round(time.perf_counter() - t, 3)
        key = f"rollout_{threads}_threads_s"
        out[key] = min(out.get(key, dt), dt)
    out["rollout_speedup"] = round(out["rollout_1_threads_s"] / out["rollout_2_threads_s"], 2)
    for workers in (1, 2) * args.repeat:
        t = time.perf_counter()
        play_reference(ref, robot, 0.5, args.seconds, list(range(args.models)), workers=workers)
        dt = round(time.perf_counter() - t, 3)
        key = f"pool_{workers}_workers_s"
        out[key] = min(out.get(key, dt), dt)
    out["pool_speedup"] = round(out["pool_1_workers_s"] / out["pool_2_workers_s"], 2)
    print(json.dumps(out, indent=2))


if __name__ == "__main__":
    main()
