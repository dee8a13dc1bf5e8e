"""Which factors of a protocol fell a run's robots: each factor alone, then all of them,
then all but the kicks, on the same validation robots.

Each variant is the protocol reduced to some factors
(:meth:`imitwalk.judge.protocol.Protocol.only`): a robot draws each factor alike alone
and with the others, so robot ``s`` is the same robot in every variant. Robots from
``--first`` (300 000: neither learning's training robots nor the judges' robots). Works
for a run of any learner.

Usage: ``python bench/factors.py RUN [--controller learned] [--protocol hard]
[--seeds 40] [--first 300000] [--seconds 30]``; prints JSON.
"""

from __future__ import annotations

import argparse
import json

from imitwalk.judge.protocol import load_protocol
from imitwalk.judge.replay import load_run
from imitwalk.judge.verdict import judge_protocol
from imitwalk.robots import load_robot


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("run")
    ap.add_argument("--controller", default="learned")
    ap.add_argument("--protocol", default="hard")
    ap.add_argument("--seeds", type=int, default=40)
    ap.add_argument("--first", type=int, default=300_000)
    ap.add_argument("--seconds", type=float, default=30.0)
    args = ap.parse_args()
    lr = load_run(args.run)
    robot = load_robot(lr.ref.settings.get("robot") or "hoap2", lr.ref.settings.get("joint_map"))
    whole = load_protocol(args.protocol)
    variants = {f: (f,) for f in whole.factors}
    variants["all"] = tuple(whole.factors)
    if "pushes" in whole.factors:
        variants["all but pushes"] = tuple(f for f in whole.factors if f != "pushes")
    out = {
        "run": args.run,
        "learner": lr.learner,
        "controller": args.controller,
        "protocol": args.protocol,
        "seeds": args.seeds,
        "first": args.first,
        "falls": {},
    }
    for name, factors in variants.items():
        v = judge_protocol(
            args.run,
            robot,
            whole.only(factors),
            args.seeds,
            args.seconds,
            (args.controller,),
            first=args.first,
        )
        side = v.controllers[args.controller]
        out["falls"][name] = side.falls
        print(json.dumps({"variant": name, "falls": side.falls, "robots": side.robots}), flush=True)
    print(json.dumps(out, indent=2))


if __name__ == "__main__":
    main()
