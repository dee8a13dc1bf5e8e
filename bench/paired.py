"""Runs side by side on the same robots: falls of every named controller, and each one's
paired comparison (McNemar) with the first.

Each ``RUN:CONTROLLER`` walks robots ``--first`` … ``--first + --seeds − 1`` of the
protocol for ``--seconds``: a stepping run's ``learned`` or ``default``, a per-tick run's
``learned``, ``fixed`` or ``open_loop``, ... Robot ``s`` is the same robot for every
controller, so the comparison is paired.

Usage: ``python bench/paired.py STEP_RUN:learned TICK_RUN:learned TICK_RUN:fixed
--protocol hard --seeds 40``; prints JSON.
"""

from __future__ import annotations

import argparse
import json

from imitwalk.judge.replay import load_run
from imitwalk.judge.verdict import judge_protocol
from imitwalk.paper.evaluate import compare_falls
from imitwalk.robots import load_robot
from imitwalk.sim.protocol import load_protocol


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("runs", nargs="+", metavar="RUN:CONTROLLER")
    ap.add_argument("--protocol", default="hard")
    ap.add_argument("--seeds", type=int, default=40)
    ap.add_argument("--seconds", type=float, default=30.0)
    ap.add_argument("--first", type=int, default=0)
    args = ap.parse_args()
    protocol = load_protocol(args.protocol)
    rows, falls = {}, {}
    for item in args.runs:
        path, _, controller = item.rpartition(":")
        lr = load_run(path)
        robot = load_robot(lr.ref.provenance.robot or "hoap2", lr.ref.provenance.joint_map)
        v = judge_protocol(
            path, robot, protocol, args.seeds, args.seconds, (controller,), first=args.first
        )
        side = v.controllers[controller]
        falls[item] = [r.fell for r in side.per_seed]
        rows[item] = {
            "learner": lr.learner,
            "falls": side.falls,
            "robots": side.robots,
            "distance_m": side.distance_m,
            "abs_yaw_deg": side.abs_yaw_deg,
            "progress_ratio_min": side.progress_ratio_min,
            "fall_seeds": [r.seed for r in side.per_seed if r.fell],
        }
    first = args.runs[0]
    for item in args.runs[1:]:
        rows[item]["vs_first"] = compare_falls(falls[first], falls[item])
    print(
        json.dumps(
            {
                "protocol": args.protocol,
                "seeds": args.seeds,
                "first": args.first,
                "seconds": args.seconds,
                "runs": rows,
            },
            indent=2,
        )
    )


if __name__ == "__main__":
    main()
