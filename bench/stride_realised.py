"""How much of its planned stride and swing-foot lift a reference realises, open loop.

Plays ``REF`` from its first posture on the nominal robot for ``--seconds`` at ``--scale``
(as ``imitwalk playback`` does) and compares, per foot, the sole's height over the
planned swing and its forward position at each planned touchdown with the task-space
plan. Prints JSON: fell, distance and the reference's expected distance [m], the planned
and realised swing height (max, mean over the planned swing) [mm], and the realised
forward advance per cycle against the planned stride [m].

Usage: ``python bench/stride_realised.py REF.npz [--scale 1.0] [--seconds 30] [--robot R]``
(``--robot``: a built-in name or a joint map; default: the robot the reference records).
"""

from __future__ import annotations

import argparse
import json

import mujoco
import numpy as np

from imitwalk.retarget.checks import sole_pose
from imitwalk.retarget.reference import Reference
from imitwalk.robots import load_robot
from imitwalk.sim.mujoco import make_plant, playback


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("reference")
    ap.add_argument("--scale", type=float, default=1.0)
    ap.add_argument("--seconds", type=float, default=30.0)
    ap.add_argument("--robot", default=None)
    a = ap.parse_args()
    ref = Reference.load(a.reference)
    robot = load_robot(a.robot or ref.provenance.robot or ref.robot)
    q = ref.trajectory(a.scale, a.seconds)
    plant = make_plant(robot, ref.sim_options())
    ro = playback(plant, q, q0=q[0])
    model, data = plant.model, mujoco.MjData(plant.model)
    soles = ("l_sole", "r_sole")  # the plan's keys, left then right
    x = np.zeros((len(ro.qpos), 2, 3))
    for k, qp in enumerate(ro.qpos):
        data.qpos[:] = qp
        mujoco.mj_kinematics(model, data)
        x[k] = [sole_pose(model, data, robot.soles[side])[0] for side in "lr"]
    plan, motion = ref.plan_at(a.scale), ref.motion_at(a.scale)
    p = np.array([[ref.plan_row(plan, motion, k)[s][:3] for s in soles] for k in range(len(ro.t))])
    stride = ref.at_scale(a.scale)[2]
    out = {
        "fell": bool(ro.fell),
        "fall_time_s": ro.fall_time,
        "distance_m": float(ro.torso_pos[-1, 0] - ro.torso_pos[0, 0]),
        "expected_m": ref.expected_distance(a.scale, ro.seconds),
        "stride_m": stride,
        "feet": {},
    }
    for j, name in enumerate(soles):
        swing = p[:, j, 2] > 1e-4
        down = ~swing
        td = np.flatnonzero(down[1:] & ~down[:-1]) + 1
        lift = x[:, j, 2] - x[0, j, 2]
        adv = np.diff(x[td, j, 0])
        out["feet"][name] = {
            "planned_lift_mm": [1e3 * p[swing, j, 2].max(), 1e3 * p[swing, j, 2].mean()],
            "realised_lift_mm": [1e3 * lift[swing].max(), 1e3 * lift[swing].mean()],
            "advance_per_cycle_m": float(np.median(adv[1:])) if len(adv) > 1 else None,
        }
    print(json.dumps(out, default=float))


if __name__ == "__main__":
    main()
