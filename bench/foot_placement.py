"""Does per-tick swing-foot placement help against kicks? A measurement, not a product option.

On top of a per-tick run's learned controller, a law moves the swing leg every tick:
its hip roll by ``k_roll × gyro_x`` (the ankle roll by the opposite, to keep the foot
flat) and its hip pitch by ``k_pitch × gyro_y`` (ankle pitch opposite), on the leg
the reference has in swing at that tick. Each gain is tried on the same robots of a
protocol reduced to one factor (``--factor pushes`` by default) and on the full one.
The gains are swept on validation robots (seeds from ``--first``, 300 000: neither the
learner's training robots nor the evaluation's); the sweep's best (fewest falls on the
full protocol, then on the one factor, then the smaller gain) is then judged beside the
learned controller alone on the evaluation robots of ``--judge`` (seeds from 0: 40 of
``eval``, 10 of ``bullet``, 40 of ``hard``). None is kept by imitwalk (docs/RESULTS.md,
"Baselines").

Usage: ``python bench/foot_placement.py RUN [--seeds 20] [--factor pushes] [--first N]
[--judge eval:40,bullet:10,hard:40]``; prints JSON.
"""

from __future__ import annotations

import argparse
import json
import sys

import numpy as np

from imitwalk.balance.feedback import FeedbackLaw
from imitwalk.balance.tickrun import TickJob, run_tick_episode
from imitwalk.judge.protocol import load_protocol
from imitwalk.judge.replay import load_run
from imitwalk.parallel import run_parallel
from imitwalk.robots import load_robot

GAINS = (-0.3, -0.15, 0.15, 0.3)
CHANNELS = (
    "l_hip_roll",
    "r_hip_roll",
    "l_ankle_roll",
    "r_ankle_roll",
    "l_hip_pitch",
    "r_hip_pitch",
    "l_ankle_pitch",
    "r_ankle_pitch",
)


def swing_law(stance: np.ndarray, k_roll: float, k_pitch: float) -> FeedbackLaw:
    """The swing-leg law of the module doc, per loop tick of ``stance`` ``(N, 2)``."""
    swing = (~np.asarray(stance, dtype=bool)).astype(float)  # (N, 2) left, right
    g = np.zeros((len(swing), len(CHANNELS), 2))
    for leg in range(2):
        g[:, leg, 0], g[:, 2 + leg, 0] = k_roll * swing[:, leg], -k_roll * swing[:, leg]
        g[:, 4 + leg, 1], g[:, 6 + leg, 1] = k_pitch * swing[:, leg], -k_pitch * swing[:, leg]
    return FeedbackLaw(CHANNELS, ("gyro_x", "gyro_y"), g, np.zeros((1, 2)), np.full(8, 0.3))


def falls(run, robot, laws, protocol, seeds: int, first: int = 0) -> dict:
    ref = run.ref
    draws = [protocol.draw(first + s, robot, ref.sim_options(), 30.0) for s in range(seeds)]
    jobs = [
        TickJob(
            run.path + "/reference.npz",
            robot,
            run.scale,
            tuple(laws),
            d.seed,
            d.options,
            30.0,
            engine=protocol.engine,
            record=False,
            **run.settings_of("learned"),  # the run's reference settings, under both laws
        )
        for d in draws
    ]
    res = run_parallel(run_tick_episode, jobs)
    return {
        "falls": int(sum(r.fell for r in res)),
        "robots": len(res),
        "distance_m": float(np.mean([r.distance_m for r in res])),
    }


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("run_dir", help="a per-tick run folder")
    ap.add_argument("--seeds", type=int, default=20, help="robots per protocol")
    ap.add_argument("--factor", default="pushes", help="the one factor of the reduced protocol")
    ap.add_argument("--first", type=int, default=300_000, help="first validation seed")
    ap.add_argument("--judge", default="eval:40,bullet:10,hard:40", help="PROTOCOL:ROBOTS,...")
    args = ap.parse_args()
    robot = load_robot("hoap2")
    run = load_run(args.run_dir)
    hard = load_protocol("hard")
    protocols = {args.factor: hard.only((args.factor,)), "hard": hard}
    base = run.laws["learned"]
    out = {"run": args.run_dir, "seeds": args.seeds, "results": []}
    variants = [("learned", 0.0, 0.0)]
    variants += [("swing roll", k, 0.0) for k in GAINS] + [("swing pitch", 0.0, k) for k in GAINS]
    for name, kr, kp in variants:
        laws = base if name == "learned" else (*base, swing_law(run.ref.stance, kr, kp))
        row = {"law": name, "k_roll": kr, "k_pitch": kp}
        for p, proto in protocols.items():
            row[p] = falls(run, robot, laws, proto, args.seeds, args.first)
        out["results"].append(row)
        print(json.dumps(row), file=sys.stderr, flush=True)  # progress
    swept = [r for r in out["results"] if r["law"] != "learned"]
    best = min(
        swept,
        key=lambda r: (
            r["hard"]["falls"],
            r[args.factor]["falls"],
            abs(r["k_roll"]) + abs(r["k_pitch"]),
        ),
    )
    out["picked"] = {"k_roll": best["k_roll"], "k_pitch": best["k_pitch"]}
    placed = (*base, swing_law(run.ref.stance, best["k_roll"], best["k_pitch"]))
    out["judged"] = {}
    for item in filter(None, args.judge.split(",")):
        name, n = item.split(":")
        proto = load_protocol(name)
        out["judged"][name] = {
            "learned": falls(run, robot, base, proto, int(n)),
            "learned + placement": falls(run, robot, placed, proto, int(n)),
        }
        print(json.dumps({name: out["judged"][name]}), file=sys.stderr, flush=True)
    print(json.dumps(out, indent=2))


if __name__ == "__main__":
    main()
