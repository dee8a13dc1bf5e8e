"""Which perturbation makes a robot fall: each factor left out in turn, then alone.

A perturbed evaluation robot differs from the nominal one in its masses, its floor
friction, its servo stiffnesses and an initial push (:data:`imitwalk.perturb.FACTORS`).
This runs a learned run's controller and open loop on the same evaluation robots with
each factor left out in turn (the others keep their draws), with each factor alone, and
with the servo spread on one joint group only. Prints JSON: falls per variant and mode,
and the seeds that fell.

Usage: ``python bench/fall_causes.py RUN_DIR [--seeds 20] [--seconds 30] [--scale 1.0]
[--only NAME ...]``
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from dataclasses import replace

from imitwalk.evaluate import per_seed
from imitwalk.perturb import FACTORS
from imitwalk.robots import load_robot
from imitwalk.sim import SimOptions

#: servo-spread groups: both sides of each joint of the legs' pitch and roll chains
GROUPS = {
    "hip_pitch": ("l_hip_pitch", "r_hip_pitch"),
    "knee": ("l_knee", "r_knee"),
    "ankle_pitch": ("l_ankle_pitch", "r_ankle_pitch"),
    "hip_roll": ("l_hip_roll", "r_hip_roll"),
    "ankle_roll": ("l_ankle_roll", "r_ankle_roll"),
}


def variants() -> dict[str, tuple[tuple[str, ...], SimOptions]]:
    """Name → (factors, base options) of every variant."""
    base = SimOptions()
    out = {"all factors (the evaluation's robots)": (FACTORS, base)}
    for f in FACTORS:
        out[f"without {f}"] = (tuple(x for x in FACTORS if x != f), base)
    for f in FACTORS:
        out[f"{f} only"] = ((f,), base)
    for g, joints in GROUPS.items():
        out[f"servo spread on {g} only"] = (("servo",), replace(base, kp_jitter_joints=joints))
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("run")
    ap.add_argument("--seeds", type=int, default=20, help="evaluation robots 0..N-1")
    ap.add_argument("--seconds", type=float, default=30.0)
    ap.add_argument("--scale", type=float, default=None, help="default: the run's scale")
    ap.add_argument("--only", nargs="*", help="variant names to run")
    args = ap.parse_args()
    robot = load_robot("hoap2")
    rows = {}
    for name, (factors, base) in variants().items():
        if args.only and name not in args.only:
            continue
        t0 = time.perf_counter()
        res = per_seed(
            args.run, robot, args.seconds, list(range(args.seeds)), base,
            scale=args.scale, factors=factors,
        )  # fmt: skip
        rows[name] = {
            mode: {
                "falls": int(sum(r["fell"] for r in runs)),
                "fell": [r["seed"] for r in runs if r["fell"]],
            }
            for mode, runs in res.items()
        }
        rows[name]["wall_s"] = round(time.perf_counter() - t0, 1)
        print(f"{name}: {json.dumps(rows[name])}", file=sys.stderr, flush=True)
    out = {"run": args.run, "seeds": args.seeds, "seconds": args.seconds, "scale": args.scale}
    print(json.dumps({**out, "variants": rows}, indent=1))


if __name__ == "__main__":
    main()
