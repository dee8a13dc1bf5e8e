"""The reference refinement with and without early stop, side by side.

Runs the refinement (:func:`imitwalk.retarget.refine.refine_params`, or
``refine_per_scale`` with ``--per-scale``) twice in one process, from the searched
parameters of ``REF.npz`` (its ``search["best"]``) on its clip: first with every robot of
every trial played (``refine_early_stop=False``), then with early stop, the default. It
prints one JSON object: each one's wall and simulated seconds, its trials and how many
stopped early, the falls it ended at, and whether the two kept the same parameters. They
must: a trial stops only once it has fallen more often than the set it must beat.

Usage: ``python bench/refine_early_stop.py REF.npz [--rounds 2] [--per-scale]
[--models 24] [--seconds 30]``
"""

from __future__ import annotations

import argparse
import json
import time
from dataclasses import replace

from imitwalk.mocap import load_motion
from imitwalk.retarget import GaitParams, extract_template
from imitwalk.retarget.reference import Reference
from imitwalk.retarget.refine import refine_params, refine_per_scale
from imitwalk.retarget.search import SearchConfig
from imitwalk.robots import load_robot


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("reference", help="a searched reference (.npz), for its clip and start")
    ap.add_argument("--rounds", type=int, default=2, help="refinement rounds (2)")
    ap.add_argument("--per-scale", action="store_true", help="one set per scale")
    ap.add_argument("--models", type=int, default=24, help="robots per trial (24)")
    ap.add_argument("--seconds", type=float, default=30.0, help="simulated time per run (30)")
    args = ap.parse_args()
    ref = Reference.load(args.reference)
    if "best" not in ref.search:
        raise SystemExit(f"error: {args.reference} was not searched (no search record)")
    robot = load_robot(ref.settings.get("robot", ref.robot))
    template = extract_template(load_motion(ref.source))
    start = GaitParams(**ref.search["best"]["params"])
    config = SearchConfig(
        refine_rounds=args.rounds,
        refine_models=args.models,
        refine_seconds=args.seconds,
        refine_per_scale=args.per_scale,
    )
    how = refine_per_scale if args.per_scale else refine_params
    out, kept = {"reference": args.reference, "per_scale": args.per_scale}, []
    for early in (False, True):
        t0 = time.perf_counter()
        params, rep = how(
            template,
            robot,
            start,
            replace(config, refine_early_stop=early),
            dt=ref.dt,
            command=ref.gait_command(),
        )
        kept.append(params)
        out["early_stop" if early else "every_robot"] = {
            "wall_s": round(time.perf_counter() - t0, 1),
            "sim_s": rep["sim_seconds"],
            "trials": len(rep["trials"]),
            "stopped_early": rep["stopped_early"],
            "falls": rep["falls"],
        }
    out["same_parameters"] = kept[0] == kept[1]
    out["wall_ratio"] = round(out["every_robot"]["wall_s"] / out["early_stop"]["wall_s"], 2)
    out["sim_ratio"] = round(out["every_robot"]["sim_s"] / out["early_stop"]["sim_s"], 2)
    print(json.dumps(out, indent=1))


if __name__ == "__main__":
    main()
