"""A lead, not a product option: hold the gait phase until the foot about to lift is unloaded.

Plays a reference at one stride scale on training robots (the nominal one first; never an
evaluation robot), open loop except for one rule on the phase (eq. 9's ε_φ, 0 or 1 per
tick): before a planned lift-off the reference does not advance while the lifting foot
still carries more than ``threshold`` of the weight the soles measure, for at most
``max_hold`` seconds per lift-off. Sole forces are what the robot measures (and the gyro,
with ``--pitch-gain``); nothing else is read. ``--kick`` adds a sideways kick at 8 s.
Prints, per (threshold, max_hold), each robot's fall time (``null``: up for
``--seconds``), the ticks held and how far into the reference it got [s].

Usage: ``python bench/phase_hold.py REF.npz [--robot ROBOT.json] [--scale 0.3]
[--robots 4] [--seconds 12] [--rules 1,0 0.3,0.5 0.3,1.0] [--kick 0.2] [--pitch-gain 0.05]``;
prints JSON.
"""

from __future__ import annotations

import argparse
import json
from dataclasses import replace

import numpy as np

from imitwalk.parallel import run_parallel
from imitwalk.retarget import Reference
from imitwalk.robots import load_robot
from imitwalk.sim.mujoco import MujocoPlant
from imitwalk.sim.perturb import perturbed, train_seeds


def _walk(job) -> dict:
    path, robot_name, scale, seconds, seed, threshold, max_hold, kick, pitch_gain = job
    ref, robot = Reference.load(path), load_robot(robot_name)
    q = ref.trajectory(scale, 2 * seconds)  # the reference may fall behind the clock
    plan = ref.plan_at(scale)
    lifted = np.stack([plan["l_sole"][:, 2], plan["r_sole"][:, 2]], axis=1) > 1e-4  # (P, 2)
    n0, nl = ref.starts.shape[1], ref.loops.shape[1]

    def up(k: int) -> np.ndarray:
        return lifted[min(k if k < n0 else n0 + (k - n0) % nl, len(lifted) - 1)]

    opt = perturbed(seed, ref.sim_options())
    if kick:  # a sideways kick at 8 s [m/s]
        opt = replace(opt, pushes=((8.0, 0.0, kick),))
    pitch = [robot.joint_names.index(j) for j in ("l_ankle_pitch", "r_ankle_pitch")]
    plant = MujocoPlant(robot, opt)
    obs = plant.reset(q[0])
    k = held = holds = 0
    for _ in range(round(seconds / ref.dt)):
        load = obs.foot_force.sum(axis=1)
        share = load / max(float(load.sum()), 1e-9)
        lifting = up(k + 1) & ~up(k)
        if np.any(lifting & (share > threshold)) and held < max_hold / ref.dt:
            held, holds = held + 1, holds + 1
        else:
            held, k = 0, k + 1
        target = q[min(k, len(q) - 1)].copy()
        target[pitch] += pitch_gain * obs.gyro[1]  # the fixed baseline's feedback, if given
        plant.command(target)
        obs = plant.step()
        if plant.fell:
            break
    return {
        "seed": seed,
        "fall_time_s": plant.fall_time,
        "held_ticks": holds,
        "reached_s": k * ref.dt,
    }


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("reference")
    ap.add_argument("--robot", default=None, help="robot (default: the reference's)")
    ap.add_argument("--scale", type=float, default=0.3)
    ap.add_argument("--robots", type=int, default=4)
    ap.add_argument("--seconds", type=float, default=12.0)
    ap.add_argument("--rules", nargs="+", default=["1,0", "0.3,0.5", "0.3,1.0"],
                    help="threshold,max_hold pairs (1,0: never hold)")  # fmt: skip
    ap.add_argument("--kick", type=float, default=0.0, help="a sideways kick at 8 s [m/s]")
    ap.add_argument("--pitch-gain", type=float, default=0.0,
                    help="gyro_y to both ankle pitches [rad per rad/s]")  # fmt: skip
    args = ap.parse_args()
    ref = Reference.load(args.reference)
    robot = args.robot or ref.settings.get("robot") or "hoap2"
    rules = [tuple(float(x) for x in r.split(",")) for r in args.rules]
    seeds = train_seeds(args.robots)
    extra = (args.kick, args.pitch_gain)
    jobs = [(args.reference, robot, args.scale, args.seconds, s, t, h, *extra)
            for t, h in rules for s in seeds]  # fmt: skip
    res = run_parallel(_walk, jobs)
    out = {
        "scale": args.scale,
        "seconds": args.seconds,
        "kick_mps": args.kick,
        "pitch_gain": args.pitch_gain,
        "rules": [
            {"threshold": t, "max_hold_s": h, "robots": res[i * len(seeds) : (i + 1) * len(seeds)]}
            for i, (t, h) in enumerate(rules)
        ],
    }
    print(json.dumps(out, indent=2))


if __name__ == "__main__":
    main()
