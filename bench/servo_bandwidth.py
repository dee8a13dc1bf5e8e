"""Does the robot follow its reference's sway? Servo speed against the gait's, open loop.

Plays a reference open loop on the nominal robot with every servo's stiffness scaled by
each ``--kp-scale`` (``SimOptions.kp_scale``; damping as the robot has it) and reports,
per factor, how the measured centre of mass follows the planned one sideways over the
start-up's first cycle (both feet down): the ratio of their largest excursions and the
lag of the measured peak [s]; then the fall time [s] (``null``: up for ``--seconds``).
Beside it: the estimate √(kp / m l²) [rad/s] of the body's mode on its leg servos (leg
stiffness kp, mass m, leg l) against the gait's 2π / period. The centre of mass is
simulator ground truth: a measurement, not a controller input.

Usage: ``python bench/servo_bandwidth.py REF.npz [--robot ROBOT.json] [--kp-scale 1,2,4]
[--scale 1.0] [--seconds 10]``; prints JSON.
"""

from __future__ import annotations

import argparse
import json
import math
from dataclasses import replace

import numpy as np

from imitwalk.retarget import Reference
from imitwalk.retarget.ik import leg_geometry
from imitwalk.robots import load_robot
from imitwalk.sim.mujoco import MujocoPlant


def follow(ref: Reference, robot, scale: float, kp_scale: float, seconds: float) -> dict:
    """One open-loop walk at stride ``scale`` on the nominal robot, servos × ``kp_scale``."""
    q = ref.trajectory(scale, seconds)
    plan_y = ref.plan_at(scale)["com"][:, 1]
    first = round(ref.period / ref.dt)  # the start-up's first cycle: both feet down
    plant = MujocoPlant(robot, replace(ref.sim_options(), kp_scale=kp_scale))
    plant.reset(q[0])
    model = robot.compile()
    root = int(model.body_rootid[model.body(robot.torso).id])
    measured = []
    for k in range(len(q)):
        plant.command(q[k])
        plant.step()
        if k < first:
            measured.append(float(plant.data.subtree_com[root][1]))
        if plant.fell:
            break
    m = np.asarray(measured) - (measured[0] if measured else 0.0)
    p = plan_y[: len(m)] - plan_y[0]
    ratio = float(np.max(np.abs(m)) / np.max(np.abs(p))) if len(m) and np.any(p) else None
    lag = float((np.argmax(np.abs(m)) - np.argmax(np.abs(p))) * ref.dt) if len(m) else None
    return {
        "kp_scale": kp_scale,
        "sway_ratio": ratio,
        "sway_lag_s": lag,
        "fall_time_s": plant.fall_time,
    }


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("reference")
    ap.add_argument("--robot", default=None, help="robot (default: the reference's)")
    ap.add_argument("--kp-scale", default="1,2,4", help="servo stiffness factors")
    ap.add_argument("--scale", type=float, default=1.0, help="stride scale")
    ap.add_argument("--seconds", type=float, default=10.0)
    args = ap.parse_args()
    ref = Reference.load(args.reference)
    robot = load_robot(args.robot or ref.settings.get("robot") or "hoap2")
    leg = leg_geometry(robot).leg
    legs = [i for i, j in enumerate(robot.joint_names) if j[2:5] in ("hip", "kne", "ank")]
    kp_leg = float(np.median(robot.kp[legs]))
    out = {
        "robot": robot.name,
        "period_s": ref.period,
        "gait_rad_s": 2 * math.pi / ref.period,
        "servo_mode_rad_s": math.sqrt(kp_leg / (robot.total_mass * leg**2)),
        "leg_kp": kp_leg,
        "mass_kg": robot.total_mass,
        "leg_m": leg,
        "runs": [
            follow(ref, robot, args.scale, float(k), args.seconds) for k in args.kp_scale.split(",")
        ],
    }
    print(json.dumps(out, indent=2))


if __name__ == "__main__":
    main()
