"""Ablation: the extended learner with each extension switched off in turn (and the
optional time and lift channels switched on).

For one clip's reference, learns with each variant and evaluates it on the 10
evaluation robots (30 s, with the initial disturbance): at the scale it reached, and at
one fixed scale for a like-for-like comparison. Prints JSON, one row per variant.

Usage: ``python bench/ablation.py REFERENCE.npz [--scale 0.9] [--only NAME ...]``
"""

from __future__ import annotations

import argparse
import json
import tempfile
import time

import numpy as np

from imitwalk.config import apply_overrides
from imitwalk.evaluate import per_seed
from imitwalk.learnconfig import preset
from imitwalk.learner import learn
from imitwalk.retarget import Reference
from imitwalk.robots import load_robot

VARIANTS = {
    "extended (all)": ("extended", []),
    "no balance channels": ("extended", ["steps=false"]),
    "no training perturbations": ("extended", ["train_models=1"]),
    "no lean channel": ("extended", ["step.channels=dx,dy,yaw,sway"]),
    "no foot placement (dx, dy, yaw)": ("extended", ["step.channels=sway,lean"]),
    "no turn channel": ("extended", ["step.channels=dx,dy,sway,lean"]),
    "one-step horizon": ("extended", ["step.horizon=1"]),
    "one step model (no ensemble)": ("extended", ["step.ensemble=1"]),
    "no gain trials (gain 1)": ("extended", ["gains="]),
    "k = 3 components": ("extended", ["gait.n_components=3"]),
    "with the time channel (an addition)": ("extended", ["step.channels=dx,dy,yaw,sway,lean,time"]),
    "with the lift channel (an addition)": ("extended", ["step.channels=dx,dy,yaw,sway,lean,lift"]),
    "faithful (the paper)": ("faithful", []),
}


def _row(runs: list[dict]) -> dict:
    return {
        "falls": int(sum(r["fell"] for r in runs)),
        "progress_ratio_min": float(min(r["progress_ratio"] for r in runs)),
        "yaw_drift_deg_mean": float(np.mean([r["yaw_drift_deg"] for r in runs])),
        "abs_yaw_drift_deg_mean": float(np.mean([abs(r["yaw_drift_deg"]) for r in runs])),
        "forward_speed_mps": float(np.mean([r["forward_speed_mps"] for r in runs])),
    }


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("reference")
    ap.add_argument("--scale", type=float, default=0.9, help="the fixed comparison scale")
    ap.add_argument("--seeds", type=int, default=10)
    ap.add_argument("--only", nargs="*", help="variant names to run")
    args = ap.parse_args()
    ref = Reference.load(args.reference)
    robot = load_robot("hoap2")
    rows = {}
    for name, (base, sets) in VARIANTS.items():
        if args.only and name not in args.only:
            continue
        cfg = apply_overrides(preset(base), sets)
        with tempfile.TemporaryDirectory() as tmp:
            t = time.perf_counter()
            summary = learn(ref, robot, cfg, tmp)
            wall = time.perf_counter() - t
            seeds = list(range(args.seeds))
            reached = per_seed(tmp, robot, 30.0, seeds, modes=("learned",))["learned"]
            fixed = per_seed(tmp, robot, 30.0, seeds, modes=("learned",), scale=args.scale)
        rows[name] = {
            "settings": sets,
            "scale_reached": summary["scale_reached"],
            "channel_gain": summary.get("channel_gain"),
            "learn_wall_seconds": round(wall, 1),
            "at_scale_reached": _row(reached),
            f"at_{args.scale:g}": _row(fixed["learned"]),
        }
        print(json.dumps({name: rows[name]}), flush=True)
    print(json.dumps(rows, indent=2))


if __name__ == "__main__":
    main()
