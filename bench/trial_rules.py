"""How would each trial rule choose? Candidate per-tick laws walked on one set of robots.

Walks each law of :data:`LAWS` (pitch, roll, heading gains of the trial-picked law) at
full scale on robots ``first … first + robots − 1`` of a protocol, and prints, per law,
its falls, their times, the mean eq.-6 cost Γ of the robots that stayed up and the mean
|yaw|. With the learner's own training robots (``--first 100001``, the default) it shows
what the trials see; with a set no run uses (``--first 300000 --robots 40 --seconds 30``)
it is the validation the trial rule was chosen on (docs/RESULTS.md, "How the trials
choose"). Never run it on the evaluation seeds (0 …) to pick a rule.

Usage: ``python bench/trial_rules.py REF.npz [--first N] [--robots N] [--seconds S]
[--protocol eval]``; prints JSON.
"""

from __future__ import annotations

import argparse
import json

import numpy as np

from imitwalk.balance.tickconfig import TickLearnConfig
from imitwalk.balance.tickrun import TickJob, run_tick_episode
from imitwalk.balance.tickstore import feedback_law
from imitwalk.parallel import run_parallel
from imitwalk.retarget.reference import Reference
from imitwalk.robots import load_robot
from imitwalk.sim.protocol import load_protocol

#: (pitch, roll, heading) gains: the coordinate search's path and its neighbours.
LAWS = (
    (0, 0, 0),
    (0.05, 0, 0),
    (0.1, 0, 0),
    (0.2, 0, 0),
    (0.05, 0.05, 0),
    (0.1, 0.05, 0),
    (0.05, 0, -0.25),
    (0.05, 0, -0.5),
    (0.1, 0, -0.25),
    (0.1, 0.05, -0.25),
    (0.075, 0, -0.25),
)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("reference")
    ap.add_argument("--first", type=int, default=100_001)
    ap.add_argument("--robots", type=int, default=14)
    ap.add_argument("--seconds", type=float, default=10.0)
    ap.add_argument("--protocol", default="eval")
    ap.add_argument("--robot", default="hoap2")
    args = ap.parse_args()
    ref, robot, cfg = Reference.load(args.reference), load_robot(args.robot), TickLearnConfig()
    protocol = load_protocol(args.protocol)
    draws = [
        protocol.draw(args.first + j, robot, ref.sim_options(), args.seconds)
        for j in range(args.robots)
    ]
    jobs = [
        TickJob(
            args.reference,
            robot,
            1.0,
            (feedback_law(cfg, {"pitch": p, "roll": r, "heading": h}),),
            d.seed,
            d.options,
            args.seconds,
            engine=protocol.engine,
            record=False,
        )
        for p, r, h in LAWS
        for d in draws
    ]
    res = run_parallel(run_tick_episode, jobs)
    out = []
    for k, law in enumerate(LAWS):
        rows = res[k * len(draws) : (k + 1) * len(draws)]
        up = [r.cost for r in rows if not r.fell]
        out.append(
            {
                "pitch_roll_heading": list(law),
                "falls": sum(r.fell for r in rows),
                "fall_times_s": [r.fall_time_s for r in rows if r.fell],
                "cost": float(np.mean(up)) if up else None,
                "abs_yaw_deg": float(np.mean([abs(r.yaw_drift_deg) for r in rows])),
            }
        )
    print(
        json.dumps(
            {
                "reference": args.reference,
                "first": args.first,
                "robots": args.robots,
                "seconds": args.seconds,
                "protocol": args.protocol,
                "laws": out,
            },
            indent=1,
        )
    )


if __name__ == "__main__":
    main()
