"""Can a margin rank feedback laws where rare falls cannot? Kick margins on training robots.

The trials rank laws by falls on 14 training robots, which cannot see fall rates of a
few percent (docs/RESULTS.md, "How the trials choose"). This bench measures a continuous
figure instead: for each law of :data:`LAWS`, on ``--robots`` training robots (eval
protocol, seeds from 100 001), the largest kick [m/s] survived for ``--after`` s, found by
bisection between 0 and the push bench's top speed, kicked towards each of four
directions (world frame: forward, left, back, right) at ``--phases`` times half a cycle
apart, two cycles after the start-up. A robot that falls unkicked scores 0. The law's
margin is the mean over robots, directions and times. Compare it with the validation
table's falls (the same laws on 40 robots from seed 300 000, 30 s).

Usage: ``python bench/kick_margin.py REF.npz [--robots 4] [--phases 2] [--steps 4]``;
prints JSON lines, one per law.
"""

from __future__ import annotations

import argparse
import json
import math
from dataclasses import replace

import numpy as np

from imitwalk.balance.tickconfig import TickLearnConfig
from imitwalk.balance.tickrun import TickJob, run_tick_episode
from imitwalk.balance.tickstore import feedback_law
from imitwalk.judge.protocol import load_protocol
from imitwalk.judge.pushes import top_speed
from imitwalk.parallel import run_parallel
from imitwalk.retarget.reference import Reference
from imitwalk.robots import load_robot

#: (pitch, roll, heading) gains: the validation table's laws.
LAWS = ((0, 0, 0), (0.05, 0, 0), (0.1, 0, 0), (0.05, 0.05, 0), (0.1, 0.05, 0),
        (0.05, 0, -0.25), (0.05, 0, -0.5), (0.1, 0, -0.25), (0.1, 0.05, -0.25),
        (0.075, 0, -0.25))  # fmt: skip
#: Kick directions, the angle of Δv from +x [rad].
DIRECTIONS = (0.0, math.pi / 2, math.pi, -math.pi / 2)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("reference")
    ap.add_argument("--robots", type=int, default=4)
    ap.add_argument("--first", type=int, default=100_001)
    ap.add_argument("--phases", type=int, default=2)
    ap.add_argument("--steps", type=int, default=4)
    ap.add_argument("--after", type=float, default=3.0)
    args = ap.parse_args()
    ref, robot, cfg = Reference.load(args.reference), load_robot("hoap2"), TickLearnConfig()
    protocol = load_protocol("eval")
    t0 = ref.starts.shape[1] * ref.dt + 2 * ref.period
    times = [t0 + k * ref.period / 2 for k in range(args.phases)]
    seconds = times[-1] + args.after
    draws = [protocol.draw(args.first + j, robot, ref.sim_options(), seconds)
             for j in range(args.robots)]  # fmt: skip
    laws = [(feedback_law(cfg, {"pitch": p, "roll": r, "heading": h}),) for p, r, h in LAWS]
    top = top_speed(robot.height)

    def job(law, d, kick=None):
        opt = d.options
        if kick is not None:
            t, ang, v = kick
            opt = replace(opt, pushes=((t, v * math.cos(ang), v * math.sin(ang)),))
        return TickJob(args.reference, robot, 1.0, law, d.seed, opt, seconds, record=False)

    plain = run_parallel(run_tick_episode, [job(w, d) for w in laws for d in draws])
    up = np.array([not r.fell for r in plain]).reshape(len(laws), len(draws))
    keys = [(i, j, t, a) for i in range(len(laws)) for j in range(len(draws)) if up[i, j]
            for t in times for a in DIRECTIONS]  # fmt: skip
    lo, hi = dict.fromkeys(keys, 0.0), dict.fromkeys(keys, top)
    for _ in range(args.steps):
        mids = {k: (lo[k] + hi[k]) / 2 for k in keys}
        jobs = [job(laws[i], draws[j], (t, a, mids[(i, j, t, a)])) for i, j, t, a in keys]
        res = run_parallel(run_tick_episode, jobs)
        for k, r in zip(keys, res, strict=True):
            (hi if r.fell else lo)[k] = mids[k]
    for i, law in enumerate(LAWS):
        per_dir = {}
        for a, name in zip(DIRECTIONS, ("forward", "left", "back", "right"), strict=True):
            got = [lo.get((i, j, t, a), 0.0) for j in range(len(draws)) for t in times]
            per_dir[name] = round(float(np.mean(got)), 3)
        print(json.dumps({
            "pitch_roll_heading": list(law),
            "unkicked_falls": int((~up[i]).sum()),
            "margin_mps": round(float(np.mean(list(per_dir.values()))), 3),
            "by_direction": per_dir,
        }), flush=True)  # fmt: skip


if __name__ == "__main__":
    main()
