"""One protocol robot on both engines, side by side: where MuJoCo and Bullet part.

Walks a run's controller on one robot of a protocol (its draws, default ``bullet``'s)
on MuJoCo and on Bullet, and prints, every ``--every`` s, the torso's roll, pitch and yaw
[deg] (simulator ground truth, for diagnosis only), each sole's summed normal force [N]
and the torso's position [m], then each engine's fall time.

Usage: ``python bench/engine_trace.py RUN [--seed 9] [--controller learned]
[--protocol bullet] [--seconds 8] [--every 0.25] [--robot hoap2]``; prints JSON lines,
one per engine and sample.
"""

from __future__ import annotations

import argparse
import json

from scipy.spatial.transform import Rotation

from imitwalk.judge.protocol import load_protocol
from imitwalk.judge.replay import load_run
from imitwalk.robots import load_robot
from imitwalk.sim.mujoco import ENGINES, make_plant, run


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("run_dir", help="a per-tick run folder")
    ap.add_argument("--robot", default="hoap2", help="the run's robot (name or joint map)")
    ap.add_argument("--controller", default="learned", help="a controller the run builds")
    ap.add_argument("--protocol", default="bullet", help="whose draws make the robot")
    ap.add_argument("--seed", type=int, default=9, help="the protocol's robot")
    ap.add_argument("--seconds", type=float, default=8.0)
    ap.add_argument("--every", type=float, default=0.25, help="sampling period [s]")
    args = ap.parse_args()
    loaded, robot = load_run(args.run_dir), load_robot(args.robot)
    draw = load_protocol(args.protocol).draw(
        args.seed, robot, loaded.ref.sim_options(), args.seconds
    )
    stride = max(1, round(args.every * draw.options.control_hz))
    for engine in ENGINES:
        policy = loaded.policy(args.controller, robot, seconds=args.seconds)
        plant = make_plant(robot, draw.options, engine=engine)
        ro = run(plant, policy, round(args.seconds * draw.options.control_hz))
        euler = Rotation.from_quat(ro.torso_quat[:, [1, 2, 3, 0]]).as_euler("xyz", degrees=True)
        soles = ro.foot_force.sum(axis=2)
        for k in range(0, len(ro.t), stride):
            print(
                json.dumps(
                    {
                        "engine": engine,
                        "t_s": round(float(ro.t[k]), 2),
                        "roll_deg": round(float(euler[k, 0]), 1),
                        "pitch_deg": round(float(euler[k, 1]), 1),
                        "yaw_deg": round(float(euler[k, 2]), 1),
                        "sole_l_n": round(float(soles[k, 0]), 1),
                        "sole_r_n": round(float(soles[k, 1]), 1),
                        "x_m": round(float(ro.torso_pos[k, 0]), 3),
                        "y_m": round(float(ro.torso_pos[k, 1]), 3),
                    }
                )
            )
        print(json.dumps({"engine": engine, "fell": bool(ro.fell), "fall_time_s": ro.fall_time}))


if __name__ == "__main__":
    main()
