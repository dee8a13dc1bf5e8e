"""MuJoCo and Bullet side by side: wall time per simulated second of open-loop playback
of the same reference on the same robot (settings interleaved, the best of ``--repeat``
kept), and how closely the two engines agree on it.

Usage: ``python bench/engine_speed.py [--seconds 10] [--scale 0.3] [--repeat 3]``
"""

from __future__ import annotations

import argparse
import json
import time

import numpy as np

from imitwalk.mocap import default_clip, load_motion
from imitwalk.retarget import GaitParams, RetargetConfig, retarget
from imitwalk.robots import load_robot
from imitwalk.sim.mujoco import make_plant, playback


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seconds", type=float, default=10.0)
    ap.add_argument("--scale", type=float, default=0.3)
    ap.add_argument("--repeat", type=int, default=3, help="trials; the best is kept")
    args = ap.parse_args()
    robot = load_robot("hoap2")
    cfg = RetargetConfig(search=False, scales=(args.scale,), params=GaitParams(sway=0.9, ds=0.1))
    ref = retarget(load_motion(default_clip()), robot, cfg).reference
    q = ref.trajectory(args.scale, args.seconds)
    best = {"mujoco": np.inf, "bullet": np.inf}
    runs = {}
    for engine in ("mujoco", "bullet") * args.repeat:
        plant = make_plant(robot, None, engine)
        t0 = time.perf_counter()
        ro = playback(plant, q, q0=q[0], stop_on_fall=False)
        best[engine] = min(best[engine], time.perf_counter() - t0)
        runs[engine] = ro
    mj, bt = runs["mujoco"], runs["bullet"]
    out = {
        "sim_seconds": args.seconds,
        "scale": args.scale,
        "wall_s_per_sim_s": {k: v / args.seconds for k, v in best.items()},
        "bullet_over_mujoco": best["bullet"] / best["mujoco"],
        "fell": {"mujoco": mj.fell, "bullet": bt.fell},
        "forward_m": {
            "mujoco": float(mj.torso_pos[-1, 0] - mj.torso_pos[0, 0]),
            "bullet": float(bt.torso_pos[-1, 0] - bt.torso_pos[0, 0]),
        },
        "joint_rms_diff_rad": float(np.sqrt(np.mean((mj.q - bt.q) ** 2))),
        "sole_force_mean_N": {
            "mujoco": float(mj.foot_force.sum(axis=(1, 2)).mean()),
            "bullet": float(bt.foot_force.sum(axis=(1, 2)).mean()),
        },
    }
    print(json.dumps(out, indent=2))


if __name__ == "__main__":
    main()
