"""Does the start-up rock the robot off a sole? Open loop on the nominal robot, by friction.

Plays a reference open loop at ``--scale`` on the nominal robot, on floors of each
``--friction``, and prints per floor the fall time [s] (``null``: up for ``--seconds``)
and each sole's highest point [mm] during the start-up's first cycle, when the plan keeps
both feet on the floor: a sole that rises there was rocked off it by the sway. The sole
heights are simulator ground truth: a measurement, not a controller input.

Usage: ``python bench/start_up.py REF.npz [--robot ROBOT.json] [--friction 0.6,1.0,1.5]
[--scale 1.0] [--seconds 15]``; prints JSON.
"""

from __future__ import annotations

import argparse
import json
from dataclasses import replace

import mujoco
import numpy as np

from imitwalk.retarget import Reference
from imitwalk.robots import load_robot
from imitwalk.sim.mujoco import MujocoPlant, run


def sole_heights(model: mujoco.MjModel, qpos: np.ndarray, soles: dict) -> dict:
    """Each sole's highest point [mm] over ``qpos`` ``(T, nq)`` (a site, else a body)."""
    data = mujoco.MjData(model)
    sites = {model.site(i).name for i in range(model.nsite)}
    out = {}
    for side, name in soles.items():
        z = []
        for q in qpos:
            data.qpos[:] = q
            mujoco.mj_kinematics(model, data)
            z.append((data.site(name) if name in sites else data.body(name)).xpos[2])
        out[side] = round(1000.0 * (max(z) - z[0]), 1)
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("reference")
    ap.add_argument("--robot", default="hoap2")
    ap.add_argument("--friction", default="0.6,1.0,1.2,1.5")
    ap.add_argument("--scale", type=float, default=1.0)
    ap.add_argument("--seconds", type=float, default=15.0)
    args = ap.parse_args()
    ref, robot = Reference.load(args.reference), load_robot(args.robot)
    q = ref.trajectory(args.scale, args.seconds)
    first = round(ref.period / ref.dt)  # the start-up's first cycle: both feet down
    model, rows = robot.compile(), []
    for mu in (float(x) for x in args.friction.split(",")):
        plant = MujocoPlant(robot, replace(ref.sim_options(), friction=mu))
        r = run(plant, lambda k, _o: q[k], len(q), q0=q[0])
        rows.append({
            "friction": mu,
            "fall_s": float(r.fall_time) if r.fell and r.fall_time is not None else None,
            "sole_rise_first_cycle_mm": sole_heights(model, r.qpos[:first], robot.soles),
        })  # fmt: skip
    print(json.dumps({"reference": args.reference, "scale": args.scale, "rows": rows}, indent=1))


if __name__ == "__main__":
    main()
