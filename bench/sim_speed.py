"""Bare simulation speed of the built-in robot, and the cost of the Plant layer around it.

Prints JSON. Both figures come from the same run, so their ratio is meaningful on a
noisy machine:

* ``mj_step_per_s``: ``mujoco.mj_step`` in a tight loop (robot holding its pose);
* ``plant_steps_per_s``: physics steps per second through ``MujocoPlant.step`` at the
  default 100 Hz control / 1 kHz physics (sensor reads and fall checks included).

Usage: ``python bench/sim_speed.py [--seconds 20] [--repeat 3]``
"""

from __future__ import annotations

import argparse
import json
import platform
import time

import mujoco
import numpy as np

from imitwalk.robots import load_robot
from imitwalk.sim.mujoco import MujocoPlant, SimOptions


def bare(robot, steps: int) -> float:
    m = robot.compile()
    d = mujoco.MjData(m)
    d.qpos[:] = robot.stand_qpos
    d.ctrl[:] = robot.stand * robot.signs  # hoap2's actuator order is its role order
    t = time.perf_counter()
    for _ in range(steps):
        mujoco.mj_step(m, d)
    return steps / (time.perf_counter() - t)


def plant(robot, steps: int) -> float:
    p = MujocoPlant(robot, SimOptions())
    p.reset()
    ticks = steps // p.options.substeps
    t = time.perf_counter()
    for _ in range(ticks):
        p.command(robot.stand)
        p.step()
    return ticks * p.options.substeps / (time.perf_counter() - t)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seconds", type=float, default=20.0, help="simulated seconds per trial")
    ap.add_argument("--repeat", type=int, default=3, help="trials; the best is kept")
    args = ap.parse_args()
    robot = load_robot("hoap2")
    steps = int(args.seconds * 1000)
    b = p = 0.0
    for _ in range(args.repeat):  # interleaved, so that both sides see the same machine
        b = max(b, bare(robot, steps))
        p = max(p, plant(robot, steps))
    print(
        json.dumps(
            {
                "robot": "hoap2",
                "dof": robot.dof,
                "timestep_s": 0.001,
                "mj_step_per_s": round(b),
                "us_per_mj_step": round(1e6 / b, 2),
                "plant_steps_per_s": round(p),
                "plant_over_bare": round(p / b, 3),
                "realtime_factor_bare": round(b * 0.001, 1),
                "mujoco": mujoco.__version__,
                "numpy": np.__version__,
                "cpu": platform.processor() or platform.machine(),
            },
            indent=2,
        )
    )


if __name__ == "__main__":
    main()
