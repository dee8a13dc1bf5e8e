"""Prototype: the reference-parameter search with a run's trial-picked law in the loop.

The product's search (:func:`imitwalk.retarget.search.search_params`) plays its candidates
open loop, while ``learn`` walks the reference it keeps under per-tick feedback. This
bench repeats the search (the same cross-entropy method, robots, scales and score), but
walks every candidate with the law and reference settings a first run's trials kept
(``RUN/checkpoint.json``): a second pass, search → trials → search. It prints the
parameters found as ``--set`` arguments for ``imitwalk retarget --no-search``.

Usage: ``python bench/closed_search.py CLIP RUN [--generations 5] [--population 8]``

"""

from __future__ import annotations

import argparse
import json
import tempfile
from dataclasses import fields
from pathlib import Path

import numpy as np

from imitwalk.balance.tickconfig import TickLearnConfig
from imitwalk.balance.tickrun import TickJob, run_tick_episode
from imitwalk.balance.tickstore import feedback_law
from imitwalk.mocap import load_motion
from imitwalk.parallel import run_parallel
from imitwalk.retarget.params import GaitParams
from imitwalk.retarget.pipeline import RetargetConfig, extract_template
from imitwalk.retarget.search import SearchConfig, bounds
from imitwalk.retarget.walkable import build_walkable, leg_geometry
from imitwalk.robots import load_robot
from imitwalk.sim.perturb import perturbed, train_seeds

TMP = Path(tempfile.mkdtemp(prefix="closed_search_"))


def trial(job) -> dict:
    template, robot, params, cfg, law, settings, command, tag = job
    ref = build_walkable(template, robot, params, list(cfg.scales), 0.01, command=command).reference
    path = str(TMP / f"{tag}.npz")
    ref.save(path)
    score, runs = [], []
    for s in cfg.scales:
        for seed in train_seeds(cfg.models):
            r = run_tick_episode(
                TickJob(
                    path,
                    robot,
                    s,
                    (law,),
                    seed,
                    perturbed(seed, ref.sim_options()),
                    cfg.seconds,
                    record=False,
                    **settings,
                )
            )
            prog = r.distance_m / max(ref.expected_distance(s, r.seconds), 1e-6)
            score.append(
                r.seconds / cfg.seconds
                + 0.5 * float(np.clip(prog, 0, 1))
                - 0.5 * min(abs(r.yaw_drift_deg) / 45.0, 1.0)
            )
            runs.append((s, seed, r.fell, round(r.seconds, 1), round(prog, 2)))
    return {"params": params.to_dict(), "score": float(np.mean(score)), "runs": runs}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("clip")
    ap.add_argument("run")
    ap.add_argument("--generations", type=int, default=5)
    ap.add_argument("--population", type=int, default=8)
    a = ap.parse_args()
    ck = json.loads((Path(a.run) / "checkpoint.json").read_text())
    lcfg = TickLearnConfig()
    law = feedback_law(lcfg, ck["gains"], {k: np.array(v) for k, v in ck["profiles"].items()})
    settings = {k: float(v) for k, v in ck["settings"].items()}
    rcfg = RetargetConfig()
    motion = load_motion(a.clip)
    template = extract_template(motion, allow_turn=False)
    robot = load_robot("hoap2")
    leg = leg_geometry(robot).leg
    cfg = SearchConfig(generations=a.generations, population=a.population)
    names = [f.name for f in fields(GaitParams)]
    box = bounds(leg)
    lo, hi = np.array([box[n][0] for n in names]), np.array([box[n][1] for n in names])
    x0 = np.array([getattr(rcfg.params.for_leg(leg), n) for n in names])
    mu, sd = np.clip((x0 - lo) / (hi - lo), 0, 1), np.full(len(names), 0.25)
    rng = np.random.default_rng(cfg.seed)
    best = None
    for gen in range(cfg.generations):
        u = np.clip(mu + sd * rng.standard_normal((cfg.population, len(names))), 0, 1)
        if gen == 0:
            u[0] = mu
        cands = [
            GaitParams(**dict(zip(names, (lo + x * (hi - lo)).tolist(), strict=True))) for x in u
        ]
        jobs = [
            (template, robot, c, cfg, law, settings, rcfg.command, f"g{gen}c{i}")
            for i, c in enumerate(cands)
        ]
        res = run_parallel(trial, jobs, None)
        sc = np.array([r["score"] for r in res])
        order = np.argsort(-sc, kind="stable")
        mu, sd = u[order[: cfg.elites]].mean(0), np.maximum(u[order[: cfg.elites]].std(0), 0.05)
        if best is None or res[order[0]]["score"] > best["score"]:
            best = res[order[0]]
        print(
            json.dumps(
                {
                    "generation": gen + 1,
                    "best_score": round(best["score"], 3),
                    "best": {k: round(v, 4) for k, v in best["params"].items()},
                    "runs": best["runs"],
                }
            ),
            flush=True,
        )
    print(" ".join(f"--set params.{k}={v:.5g}" for k, v in best["params"].items()))


if __name__ == "__main__":
    main()
