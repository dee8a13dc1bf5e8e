"""The controller in the loop: physics steps per second with each controller of a run,
over bare ``mj_step`` measured in the same run (so the ratios hold on a noisy machine),
and each controller's per-tick decision time.

Controllers: every one the run can build (a per-tick run: ``learned``, ``feedback``,
``fixed``, ``open_loop``; a faithful run: ``learned``, the paper's predictive search,
``open_loop``). Each walks the nominal robot for ``--seconds`` from standing at the
scale the run reached; the trials are interleaved and the best of ``--repeat`` kept.

Usage: ``python bench/controller_loop.py RUN [--seconds 10] [--repeat 3]``; prints JSON.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import time

os.environ.setdefault("IMITWALK_WORKERS", "1")

import mujoco
import numpy as np

from imitwalk.judge.replay import load_run
from imitwalk.robots import load_robot
from imitwalk.sim.mujoco import MujocoPlant, run


def bare(robot, steps: int) -> float:
    m = robot.compile()
    d = mujoco.MjData(m)
    d.qpos[:] = robot.stand_qpos
    t = time.perf_counter()
    for _ in range(steps):
        mujoco.mj_step(m, d)
    return steps / (time.perf_counter() - t)


class Timed:
    """A policy whose every decision is timed."""

    def __init__(self, policy):
        self.policy, self.q0, self.ms = policy, policy.q0, []

    def __call__(self, k, obs):
        t = time.perf_counter()
        out = self.policy(k, obs)
        self.ms.append(1e3 * (time.perf_counter() - t))
        return out


def loop(robot, lr, name: str, seconds: float) -> tuple[float, float]:
    """(physics steps per second with the controller in the loop, median decision [ms])."""
    plant = MujocoPlant(robot, lr.ref.sim_options())
    pol = Timed(lr.policy(name, robot, lr.scale, seconds))
    ticks = round(seconds / lr.ref.dt)
    t = time.perf_counter()
    ro = run(plant, pol, ticks, stop_on_fall=False)
    rate = len(ro.t) * plant.options.substeps / (time.perf_counter() - t)
    return rate, float(np.median(pol.ms))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("run_dir", help="a finished run folder")
    ap.add_argument("--seconds", type=float, default=10.0, help="simulated seconds per trial")
    ap.add_argument("--repeat", type=int, default=3, help="trials; the best is kept")
    args = ap.parse_args()
    robot = load_robot("hoap2")
    lr = load_run(args.run_dir)
    names = lr.controllers()
    steps = round(args.seconds * 1000)
    best = {"bare": 0.0, **{n: (0.0, np.inf) for n in names}}
    for _ in range(args.repeat):  # interleaved, so that every side sees the same machine
        best["bare"] = max(best["bare"], bare(robot, steps))
        for n in names:
            rate, ms = loop(robot, lr, n, args.seconds)
            best[n] = (max(best[n][0], rate), min(best[n][1], ms))
    out = {
        "run": args.run_dir,
        "learner": lr.learner,
        "seconds": args.seconds,
        "machine": platform.processor() or platform.machine(),
        "bare_mj_step_per_s": round(best["bare"]),
        "controllers": {
            n: {
                "steps_per_s": round(best[n][0]),
                "ratio_to_bare": round(best[n][0] / best["bare"], 3),
                "decision_ms_median": round(best[n][1], 4),
            }
            for n in names
        },
    }
    print(json.dumps(out, indent=2))


if __name__ == "__main__":
    main()
