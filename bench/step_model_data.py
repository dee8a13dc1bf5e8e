"""Does the step model want more data? Its held-out error against the share of a run's
recorded steps it is fitted on.

For a finished (or interrupted) run folder, holds out a third of the episodes recorded at
scales ≥ ``--min-scale`` (three random splits), fits the run's step model
(:func:`imitwalk.models.step_model`, its ensemble included) on a share of
the remaining episodes and reports the one-step prediction error on the held-out ones as
a fraction of "nothing changes" (``overall_ratio``, as ``imitwalk learn`` prints it).
A curve that stays flat as the share grows says the model is limited by what its state
holds, not by how much it has seen. Pure NumPy; prints JSON.

Usage: ``python bench/step_model_data.py RUN [--min-scale 0.75] [--centers 24 48]``
"""

from __future__ import annotations

import argparse
import json

import numpy as np

from imitwalk.config import from_dict
from imitwalk.learnconfig import LearnConfig
from imitwalk.models import step_model, unstack_episodes
from imitwalk.runs import RunDir
from imitwalk.stepconfig import STEP_STATE

SHARES = (0.25, 0.5, 0.75, 1.0)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("run")
    ap.add_argument("--min-scale", type=float, default=0.75, help="held-out episodes' scale")
    ap.add_argument("--centers", type=int, nargs="*", help="RBF centres (default: the run's)")
    ap.add_argument("--splits", type=int, default=3)
    args = ap.parse_args()
    rd = RunDir(args.run)
    cfg = from_dict(LearnConfig, rd.read_json("config.json")["learn"])
    eps = [e for e in unstack_episodes(rd.read_arrays("data.npz"))["step"] if len(e[0]) > 3]
    high = [i for i, e in enumerate(eps) if e[1][0, -1] >= args.min_scale - 1e-9]
    if len(high) < 3:
        raise SystemExit(f"bench: {args.run} has {len(high)} episodes at scale >= {args.min_scale}")
    rows = []
    for centers in args.centers or [cfg.step.n_centers]:
        for share in SHARES:
            ratios, dims = [], []
            for split in range(args.splits):
                rng = np.random.default_rng(split)
                test = set(rng.choice(high, len(high) // 3, replace=False).tolist())
                train = [e for i, e in enumerate(eps) if i not in test]
                keep = rng.permutation(len(train))[: max(1, int(round(share * len(train))))]
                model = step_model(cfg, centers).fit([train[i] for i in keep])
                rep = model.evaluate([eps[i] for i in sorted(test)])
                ratios.append(rep.overall_ratio)
                dims.append(rep.ratio)
            rows.append(
                {
                    "n_centers": centers,
                    "share": share,
                    "train_episodes": int(round(share * (len(eps) - len(high) // 3))),
                    "overall_ratio": round(float(np.mean(ratios)), 3),
                    "ratio": dict(
                        zip(STEP_STATE, np.round(np.mean(dims, axis=0), 2).tolist(), strict=True)
                    ),
                }
            )
    out = {
        "run": str(args.run),
        "episodes": len(eps),
        "held_out": len(high) // 3,
        "min_scale": args.min_scale,
        "rows": rows,
    }
    print(json.dumps(out))


if __name__ == "__main__":
    main()
