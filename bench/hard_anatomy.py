"""Where the hard robots fall: each factor of a protocol alone, then all of them.

Walks a run's controller on validation robots (seeds from ``--first``, 300 000: neither the
learner's training robots nor the evaluation's) of a protocol reduced to one factor at a
time (:meth:`imitwalk.judge.protocol.Protocol.only`), then of the whole protocol and of the
protocol without its kicks. For each it prints the falls, their times, and for the
whole protocol how many robots fell before their first kick. Each robot's draws are
the protocol's own (a factor draws alike alone and with the others), so a robot that
falls under one factor alone is the same robot in the whole protocol.

Usage: ``python bench/hard_anatomy.py RUN [--controller learned] [--protocol hard]
[--robots 40] [--first 300000] [--seconds 30] [--robot hoap2]``; prints JSON lines, one per protocol
variant, then a summary. Where the protocol kicks, each fall's last kick before it is
given (how long before, its size and direction), and the largest kick walked on from.
"""

from __future__ import annotations

import argparse
import json

import numpy as np

from imitwalk.balance.tickrun import TickJob, run_tick_episode
from imitwalk.judge.protocol import load_protocol
from imitwalk.judge.replay import OPEN_LOOP, load_run
from imitwalk.parallel import run_parallel
from imitwalk.robots import load_robot


def walks(run, robot, controller: str, protocol, robots: int, first: int, seconds: float) -> dict:
    """The falls of the run's ``controller`` (its laws, and the reference played as the run
    plays it for that controller) on ``robots`` robots of ``protocol``."""
    laws = () if controller == OPEN_LOOP else tuple(run.laws[controller])
    draws = [protocol.draw(first + s, robot, run.ref.sim_options(), seconds) for s in range(robots)]
    jobs = [
        TickJob(
            run.path + "/reference.npz",
            robot,
            run.scale,
            laws,
            d.seed,
            d.options,
            seconds,
            record=False,
            **run.settings_of(controller),
        )
        for d in draws
    ]
    res = run_parallel(run_tick_episode, jobs)
    fell = [(d, r) for d, r in zip(draws, res, strict=True) if r.fell]
    before = [
        d.seed
        for d, r in fell
        if not d.options.pushes or d.options.pushes[0][0] > (r.fall_time_s or 0.0)
    ]
    return {
        "protocol": protocol.name,
        "robots": robots,
        "falls": len(fell),
        "fall_times_s": sorted(round(float(r.fall_time_s or 0.0), 2) for _, r in fell),
        "fell_before_first_kick": len(before),
        "distance_m": round(float(np.mean([r.distance_m for r in res])), 2),
        **_kicks(draws, res),
    }


def _kicks(draws, res) -> dict:
    """The kick before each fall (seconds before it, |Δv| [m/s], direction [deg from
    forward, + to the left]), by size, and the largest kick a robot walked on from."""
    fatal, survived = [], []
    for d, r in zip(draws, res, strict=True):
        due = [k for k in d.options.pushes if not r.fell or k[0] <= (r.fall_time_s or 0.0)]
        last = due.pop() if r.fell and due else None
        survived += [float(np.hypot(k[1], k[2])) for k in due]
        if last is not None:
            t, vx, vy = last
            fatal.append(
                [
                    round(float(r.fall_time_s - t), 2),
                    round(float(np.hypot(vx, vy)), 2),
                    round(float(np.degrees(np.arctan2(vy, vx)))),
                ]
            )
    if not fatal and not survived:
        return {}
    return {
        "fatal_kicks": sorted(fatal, key=lambda k: k[1]),
        "largest_kick_survived_mps": round(max(survived, default=0.0), 2),
    }


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("run_dir", help="a per-tick run folder")
    ap.add_argument("--robot", default="hoap2", help="the run's robot (name or joint map)")
    ap.add_argument("--controller", default="learned", help="a controller the run builds")
    ap.add_argument("--protocol", default="hard")
    ap.add_argument("--robots", type=int, default=40)
    ap.add_argument("--first", type=int, default=300_000, help="first validation seed")
    ap.add_argument("--seconds", type=float, default=30.0)
    args = ap.parse_args()
    run, robot = load_run(args.run_dir), load_robot(args.robot)
    proto = load_protocol(args.protocol)
    variants = [proto.only((f,)) for f in proto.factors]
    if "pushes" in proto.factors:
        variants.append(proto.only(tuple(f for f in proto.factors if f != "pushes")))
    variants.append(proto)
    rows = []
    for p in variants:
        row = walks(run, robot, args.controller, p, args.robots, args.first, args.seconds)
        rows.append(row)
        print(json.dumps(row), flush=True)
    print(
        json.dumps(
            {
                "run": args.run_dir,
                "controller": args.controller,
                "falls": {r["protocol"]: r["falls"] for r in rows},
            }
        )
    )


if __name__ == "__main__":
    main()
