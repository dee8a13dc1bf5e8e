"""A turning gait's turn, measured: the heading change per gait cycle each robot of a
protocol walks, beside the clip's and the style's.

Each robot walks the run's learned gains for ``--seconds``; its turning rate is the
torso's true heading change from the first lift-off to the end, over the gait cycles
its controller stepped in that time (two steps a cycle). Falls and the fall times are
reported beside.

Usage: ``python bench/turning.py RUN [--protocol eval] [--seeds 40] [--seconds 30]``;
prints JSON.
"""

from __future__ import annotations

import argparse
import json

import numpy as np

from imitwalk.judge.replay import load_run
from imitwalk.parallel import run_parallel
from imitwalk.robots import load_robot
from imitwalk.sim.metrics import yaw_rad
from imitwalk.sim.protocol import load_protocol
from imitwalk.step.episode import StepJob, walk_step


def turn_of(job: StepJob) -> dict:
    ctrl, ro, _ = walk_step(job)
    yaw = np.unwrap(yaw_rad(ro.torso_quat))
    k0 = int(round(1.6 * job.style.step_time / job.dt))  # the first lift-off
    cycles = max(ctrl.steps - 1, 1) / 2
    return {
        "seed": job.seed,
        "fell": bool(ro.fell),
        "fall_time_s": ro.fall_time,
        "deg_per_cycle": float(np.degrees(yaw[-1] - yaw[min(k0, len(yaw) - 1)]) / cycles),
    }


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("run")
    ap.add_argument("--protocol", default="eval")
    ap.add_argument("--seeds", type=int, default=40)
    ap.add_argument("--seconds", type=float, default=30.0)
    a = ap.parse_args()
    lr = load_run(a.run)
    gait = lr.step_gait
    robot = load_robot(gait.provenance.robot or gait.robot, gait.provenance.joint_map)
    style, gains = gait.at_scale(lr.scale), lr.step_gains["learned"]
    protocol = load_protocol(a.protocol)
    jobs = [
        StepJob(
            robot,
            style,
            gains,
            seed,
            protocol.draw(seed, robot, gait.sim_options(), a.seconds).options,
            a.seconds,
            protocol.engine,
            gait.dt,
        )
        for seed in range(a.seeds)
    ]
    rows = run_parallel(turn_of, jobs)
    up = [r["deg_per_cycle"] for r in rows if not r["fell"]]
    clip = float(style.human.get("turn_deg", 0.0))
    print(
        json.dumps(
            {
                "run": a.run,
                "protocol": protocol.name,
                "robots": len(rows),
                "falls": sum(r["fell"] for r in rows),
                "clip_deg_per_cycle": clip,
                "style_deg_per_cycle": float(np.degrees(style.turn)),
                "walked_deg_per_cycle": {
                    "mean": float(np.mean(up)),
                    "min": float(np.min(up)),
                    "max": float(np.max(up)),
                }
                if up
                else None,
                "within_20pct_of_clip": bool(up)
                and all(abs(x - clip) <= 0.2 * abs(clip) for x in up),
                "robots_detail": rows,
            },
            indent=1,
        )
    )


if __name__ == "__main__":
    main()
