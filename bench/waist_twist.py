"""Is the torso's yaw swing the reference's waist twist? A run's learned controller with
the waist-yaw targets scaled by 1, 0 and −1.

Walks the run's learned laws at scale 1.0 on a protocol's first robots (eval protocol's
draws; ``--engine bullet`` for the bullet protocol's) and prints, per waist factor, the
falls, their times and the median peak-to-peak torso yaw within 0.6 s windows over
2–6 s (simulator ground truth, for this diagnosis only).

Usage: ``python bench/waist_twist.py RUN [--engine bullet] [--robots 10]``; prints JSON lines.
"""

from __future__ import annotations

import argparse
import json

import numpy as np

from imitwalk.balance.feedback import TickPolicy
from imitwalk.judge.protocol import load_protocol
from imitwalk.judge.replay import load_run
from imitwalk.parallel import run_parallel
from imitwalk.robots import load_robot


def walk(job: tuple) -> tuple:
    """(fell, fall time [s], median yaw swing [deg]) of one robot."""
    from imitwalk.sim.mujoco import make_plant, run

    run_dir, engine, factor, seed, seconds = job
    r, robot = load_run(run_dir), load_robot("hoap2")
    pol = TickPolicy(r.ref, r.scale, tuple(r.laws["learned"]), robot.joint_names, seconds)
    pol.q_ref[:, robot.joint_names.index("waist_yaw")] *= factor
    opt = load_protocol("eval").draw(seed, robot, r.ref.sim_options(), seconds).options
    ro = run(make_plant(robot, r.ref.sim_options(opt), engine), pol, len(pol.q_ref))
    w, x, y, z = ro.torso_quat.T
    yaw = np.degrees(np.unwrap(np.arctan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z))))
    seg = yaw[200:600]
    swing = [np.ptp(seg[i : i + 60]) for i in range(0, len(seg) - 60, 60)]
    return ro.fell, ro.fall_time, float(np.median(swing)) if swing else float("nan")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("run_dir")
    ap.add_argument("--engine", default="mujoco", choices=("mujoco", "bullet"))
    ap.add_argument("--robots", type=int, default=10)
    ap.add_argument("--seconds", type=float, default=30.0)
    args = ap.parse_args()
    for factor in (1.0, 0.0, -1.0):
        jobs = [(args.run_dir, args.engine, factor, s, args.seconds) for s in range(args.robots)]
        res = run_parallel(walk, jobs)
        print(json.dumps({
            "engine": args.engine, "waist_factor": factor, "robots": args.robots,
            "falls": int(sum(r[0] for r in res)),
            "fall_times_s": sorted(round(float(r[1]), 1) for r in res if r[0]),
            "yaw_swing_deg_median": round(float(np.nanmedian([r[2] for r in res])), 1),
        }), flush=True)  # fmt: skip


if __name__ == "__main__":
    main()
