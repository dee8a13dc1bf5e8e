"""The Gymnasium environment's speed: simulated seconds per wall second, on one and on
two cores, over bare ``mj_step`` measured in the same run (interleaved, best of
``--repeat``), so that the ratios hold on a noisy machine.

Sides, each on the nominal-rate hoap2 at 1 kHz physics and 100 Hz control:

- ``bare``: ``mj_step`` alone on the standing robot;
- ``loop``: imitwalk's own loop (:func:`imitwalk.sim.mujoco.run`) with the stepping gait;
- ``env_residual`` / ``env_joints``: ``imitwalk/Walk-v0`` stepped with zero actions
  (residual: the stepping gait runs inside every step);
- on two cores: ``bare`` in two processes, and a 2-process ``AsyncVectorEnv``.

Usage: ``python bench/env_speed.py [--seconds 10] [--repeat 3]``; prints JSON.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import time
from multiprocessing import get_context

os.environ.setdefault("MUJOCO_GL", "egl")

import gymnasium as gym
import mujoco
import numpy as np

import imitwalk.envs  # noqa: F401  (registers imitwalk/Walk-v0)
from imitwalk.robots import load_robot


def bare(seconds: float) -> float:
    """Simulated seconds per wall second of ``mj_step`` alone."""
    robot = load_robot("hoap2")
    m = robot.compile()
    m.opt.timestep = 1e-3
    d = mujoco.MjData(m)
    d.qpos[:] = robot.stand_qpos
    steps = round(seconds / m.opt.timestep)
    t = time.perf_counter()
    for _ in range(steps):
        mujoco.mj_step(m, d)
    return seconds / (time.perf_counter() - t)


def loop(seconds: float) -> float:
    """Simulated seconds per wall second of imitwalk's loop with the stepping gait."""
    from imitwalk.mocap import default_clip, load_motion
    from imitwalk.sim.mujoco import MujocoPlant, run
    from imitwalk.step.controller import SteppingController
    from imitwalk.step.gains import StepGains
    from imitwalk.step.pipeline import gait_from_motion

    robot = load_robot("hoap2")
    gait = gait_from_motion(load_motion(default_clip()), robot)
    plant = MujocoPlant(robot)
    ctrl = SteppingController(robot, gait.style, StepGains(), gait.dt)
    t = time.perf_counter()
    ro = run(plant, ctrl, round(seconds / gait.dt), stop_on_fall=False)
    return ro.seconds / (time.perf_counter() - t)


def env_rate(action: str, seconds: float) -> float:
    """Simulated seconds per wall second of one environment, zero actions."""
    env = gym.make("imitwalk/Walk-v0", action=action, protocol="eval", seconds=seconds)
    dt = env.unwrapped.setup.dt
    env.reset(options={"robot_seed": 0})
    zero = np.zeros(env.action_space.shape, np.float32)
    if action == "joints":
        zero = ((env.action_space.low + env.action_space.high) / 2).astype(np.float32)
    ticks = 0
    t = time.perf_counter()
    for _ in range(round(seconds / dt)):
        *_, term, trunc, _ = env.step(zero)
        ticks += 1
        if term or trunc:
            env.reset()
    return ticks * dt / (time.perf_counter() - t)


def vector_rate(action: str, seconds: float, n: int = 2) -> float:
    """Simulated seconds per wall second of ``n`` environments in ``n`` processes."""
    make = lambda: gym.make("imitwalk/Walk-v0", action=action, protocol="eval", seconds=seconds)  # noqa: E731
    envs = gym.vector.AsyncVectorEnv([make] * n)
    try:
        envs.reset(seed=list(range(n)))
        zero = np.zeros((n, *envs.single_action_space.shape), np.float32)
        steps = round(seconds / 0.01)
        t = time.perf_counter()
        for _ in range(steps):
            envs.step(zero)
        return n * steps * 0.01 / (time.perf_counter() - t)
    finally:
        envs.close()


def bare_two(seconds: float) -> float:
    """Two processes of :func:`bare` at once: the sum of their rates (each timed inside
    its process, after its start-up)."""
    with get_context("spawn").Pool(2) as pool:
        return float(sum(pool.map(bare, [seconds, seconds])))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seconds", type=float, default=10.0, help="simulated seconds per trial")
    ap.add_argument("--repeat", type=int, default=3, help="trials; the best is kept")
    args = ap.parse_args()
    s = args.seconds
    one = {
        "bare": bare,
        "loop": loop,
        "env_residual": lambda x: env_rate("residual", x),
        "env_joints": lambda x: env_rate("joints", x),
    }
    two = {
        "bare": bare_two,
        "env_residual": lambda x: vector_rate("residual", x),
        "env_joints": lambda x: vector_rate("joints", x),
    }
    best1 = dict.fromkeys(one, 0.0)
    best2 = dict.fromkeys(two, 0.0)
    for _ in range(args.repeat):  # interleaved: every side sees the same machine
        for k, f in one.items():
            best1[k] = max(best1[k], f(s))
        for k, f in two.items():
            best2[k] = max(best2[k], f(s))
    out = {
        "unit": "simulated seconds per wall second (1 kHz physics, 100 Hz control)",
        "one_core": {k: round(v, 2) for k, v in best1.items()},
        "one_core_over_bare": {k: round(v / best1["bare"], 3) for k, v in best1.items()},
        "two_cores": {k: round(v, 2) for k, v in best2.items()},
        "two_cores_over_bare": {k: round(v / best2["bare"], 3) for k, v in best2.items()},
        "env_steps_per_second": {
            "one_core_residual": round(best1["env_residual"] / 0.01),
            "two_cores_residual": round(best2["env_residual"] / 0.01),
        },
        "seconds": s,
        "repeat": args.repeat,
        "machine": {
            "cpus": os.cpu_count(),
            "python": platform.python_version(),
            "mujoco": mujoco.__version__,
        },
    }
    print(json.dumps(out, indent=1))


if __name__ == "__main__":
    main()
