"""Which servos' stiffness goes with a fall: open loop on many evaluation robots.

Plays a reference open loop at one scale on evaluation robots 0..N-1 (as ``imitwalk
evaluate`` draws them: masses, friction, servo stiffness, initial push) and relates each
robot's draws to whether it fell: the correlation of each joint's servo-stiffness factor
(and of the friction) with falling, and the 5-fold cross-validated ROC AUC of a logistic
model of falling on the servo factors and the friction (0.5: they do not tell; 1: they
decide). Prints JSON.

Usage: ``python bench/servo_falls.py REFERENCE.npz [--robots 160] [--scale 1.0]
[--seconds 30]``
"""

from __future__ import annotations

import argparse
import json
import time

import numpy as np
from sklearn.linear_model import LogisticRegression
from sklearn.model_selection import cross_val_score

from imitwalk.retarget import Reference
from imitwalk.robots import load_robot
from imitwalk.sim.perturb import perturbed
from imitwalk.sim.playback import play_reference
from imitwalk.sim.types import jitter_draws


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("reference")
    ap.add_argument("--robots", type=int, default=160, help="evaluation robots 0..N-1")
    ap.add_argument("--scale", type=float, default=1.0)
    ap.add_argument("--seconds", type=float, default=30.0)
    args = ap.parse_args()
    t0 = time.perf_counter()
    ref, robot = Reference.load(args.reference), load_robot("hoap2")
    seeds = range(args.robots)
    runs = play_reference(ref, robot, args.scale, args.seconds, seeds, disturbance=True)
    fell = np.array([r.metrics.fell for r in runs], dtype=float)
    # each robot's draws, as play_reference drew them
    opts = [perturbed(s, ref.sim_options(None), disturbance=s != 0) for s in seeds]
    friction = np.array([o.friction or 1.0 for o in opts])
    nbody, names = robot.compile().nbody, robot.joint_names
    kp = np.array([jitter_draws(o, nbody, names)[1] for o in opts])

    def corr(x: np.ndarray) -> float:
        return float(np.corrcoef(x, fell)[0, 1]) if x.std() > 0 and fell.std() > 0 else 0.0

    per_joint = {n: corr(kp[:, j]) for j, n in enumerate(names)}
    auc = None
    if 5 <= fell.sum() <= len(fell) - 5:
        model = LogisticRegression(C=1.0, max_iter=2000)
        x = np.c_[kp, friction]
        auc = float(cross_val_score(model, x, fell, cv=5, scoring="roc_auc").mean())
    top = sorted(per_joint.items(), key=lambda kv: -abs(kv[1]))
    out = {
        "reference": args.reference,
        "scale": args.scale,
        "seconds": args.seconds,
        "robots": args.robots,
        "falls": int(fell.sum()),
        "corr_fall_friction": corr(friction),
        "corr_fall_servo_stiffness": dict(top),
        "logistic_auc_5fold": auc,
        "wall_seconds": time.perf_counter() - t0,
    }
    print(json.dumps(out, indent=2))


if __name__ == "__main__":
    main()
