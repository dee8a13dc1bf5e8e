"""How a stepping run imitates its clip: cadence, stride and speed of the human, of the
style on the robot, and measured on the nominal robot from its sole forces.

Walks the run's ``learned`` controller on the nominal robot for ``--seconds`` from
standing and measures the steps after the start-up (:func:`imitwalk.sim.metrics.gait_timing`).

Usage: ``python bench/imitation.py RUN [RUN ...] [--seconds 30]``; prints JSON.
"""

from __future__ import annotations

import argparse
import json

from imitwalk.judge.replay import load_run
from imitwalk.robots import load_robot
from imitwalk.sim.metrics import gait_timing, walk_metrics
from imitwalk.sim.mujoco import make_plant, run


def measure(path: str, seconds: float) -> dict:
    lr = load_run(path)
    robot = load_robot(lr.ref.provenance.robot or "hoap2", lr.ref.provenance.joint_map)
    gait, st = lr.ref, lr.ref.style
    ro = run(
        make_plant(robot, gait.sim_options()),
        lr.policy("learned", robot, 1.0, seconds),
        round(seconds / gait.dt),
    )
    m = walk_metrics(ro, gait.expected_distance(1.0, ro.seconds))
    timing = gait_timing(
        ro,
        robot.total_mass * 9.81,
        after_s=gait.kick_time(0, 1) - gait.period,
        lifted_s=0.5 * st.single_support,
    )
    human = st.human
    # the soles' stride is a distance and a backward walk's style (learn --backward) is
    # negative: the robot's is signed the way it walked
    way = -1.0 if st.backward else 1.0
    stride = None if timing.stride_m is None else way * timing.stride_m
    speed = None if stride is None else stride / timing.cycle_s
    out = {
        "clip": gait.source,
        "fell": m.fell,
        "human": {
            "cadence_spm": 120.0 / human["period"],
            "stride_m": human["stride"],
            "speed_mps": human["speed"],
            "leg_m": human["leg"],
        },
        "style": {
            "cadence_spm": 60.0 / st.step_time,
            "stride_m": 2 * st.step_length,
            "speed_mps": st.speed,
            "leg_m": st.geometry.leg,
        },
        "robot": {
            "cadence_spm": timing.cadence_spm,
            "stride_m": stride,
            "speed_mps": speed,
            "steps": timing.steps,
            "scuffs": timing.scuffs,
        },
    }
    rob, sty = out["robot"], out["style"]
    out["ratios"] = {
        k: (None if rob[k] is None else rob[k] / sty[k])
        for k in ("cadence_spm", "stride_m", "speed_mps")
    }
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("runs", nargs="+")
    ap.add_argument("--seconds", type=float, default=30.0)
    args = ap.parse_args()
    print(json.dumps([measure(p, args.seconds) for p in args.runs], indent=2))


if __name__ == "__main__":
    main()
