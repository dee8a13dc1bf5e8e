"""Is joint tracking why a reference falls? Iterative learning control from the encoders.

Plays a reference open loop on the nominal robot, then corrects the commanded joint
targets from the encoders and plays again, ``--iters`` times (P-type iterative learning
control: each tick's target moves by ``--gain`` × the joint error measured ``--lead``
ticks later, smoothed over 5 ticks; the last 0.5 s before a fall is left alone). Per
iteration it prints the fall time [s] and the joints' RMS and largest tracking error
[deg]. Then it plays the last commands and the plain reference on ``--test`` training
robots (eval protocol, seeds from 100 001) and prints both fall times. If the joints
follow their targets closely and the robot falls all the same, the reference itself is
what the body cannot carry, not the servos. Encoders only: no ground truth is used.

Usage: ``python bench/tracking_ilc.py REF.npz [--robot ROBOT.json] [--scale 0.3]
[--seconds 10] [--iters 8] [--test 4]``; prints JSON lines.
"""

from __future__ import annotations

import argparse
import json

import numpy as np
from scipy.ndimage import uniform_filter1d

from imitwalk.judge.protocol import load_protocol
from imitwalk.retarget import Reference
from imitwalk.robots import load_robot
from imitwalk.sim.mujoco import MujocoPlant, run


def fall_s(r) -> float | None:
    """A rollout's fall time [s], ``None`` if it stayed up."""
    return float(r.fall_time) if r.fell and r.fall_time is not None else None


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("reference")
    ap.add_argument("--robot", default="hoap2")
    ap.add_argument("--scale", type=float, default=0.3)
    ap.add_argument("--seconds", type=float, default=10.0)
    ap.add_argument("--iters", type=int, default=8)
    ap.add_argument("--gain", type=float, default=0.7)
    ap.add_argument("--lead", type=int, default=3, help="ticks")
    ap.add_argument("--test", type=int, default=4, help="training robots")
    args = ap.parse_args()
    ref, robot = Reference.load(args.reference), load_robot(args.robot)
    q_ref = ref.trajectory(args.scale, args.seconds)  # (T, n)
    q_cmd, opt, keep = q_ref.copy(), ref.sim_options(), round(0.5 / ref.dt)
    for it in range(args.iters):
        r = run(MujocoPlant(robot, opt), lambda k, _o, q=q_cmd: q[k], len(q_ref), q0=q_ref[0])
        err = q_ref[: len(r.q)] - r.q  # (T', n) encoders only
        print(
            json.dumps(
                {
                    "iter": it,
                    "fall_s": fall_s(r),
                    "rms_err_deg": round(float(np.degrees(np.sqrt(np.mean(err**2)))), 2),
                    "max_err_deg": round(float(np.degrees(np.abs(err).max())), 1),
                }
            ),
            flush=True,
        )
        upto = len(err) - (keep if r.fell else 0)
        shifted = np.zeros_like(q_ref)
        if upto > args.lead:
            shifted[: upto - args.lead] = err[args.lead : upto]
        q_cmd = q_cmd + args.gain * uniform_filter1d(shifted, 5, axis=0)
    protocol = load_protocol("eval")
    for j in range(args.test):
        d = protocol.draw(100_001 + j, robot, opt, args.seconds)
        times = {}
        for name, q in (("reference", q_ref), ("learned commands", q_cmd)):
            r = run(MujocoPlant(robot, d.options), lambda k, _o, q=q: q[k], len(q), q0=q_ref[0])
            times[name] = fall_s(r)
        print(json.dumps({"robot": d.seed, "fall_s": times}), flush=True)


if __name__ == "__main__":
    main()
