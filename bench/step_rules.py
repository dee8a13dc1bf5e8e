"""What sets the floor of the learned walk's falls: the channels, the model, or the timing?

For a finished run, plays on the same robots (from the training seed range, never an
evaluation robot; 30 s, with the initial disturbance, at the run's scale):

* ``open``: the reference open loop; ``open@R``: its loop played R times as fast
  (:func:`imitwalk.retarget.cadence.with_cadence`);
* ``model``: the learned controller as the run kept it; ``model@R``: the same at cadence R;
* a hand-set linear step rule on the learned controller's channels instead of its
  search, e.g. ``lean:pitch:-0.05;yaw:heading:-0.3`` (channel = gain × (state − the
  controller's target state), summed, clipped to the channel box; names from
  :data:`imitwalk.balance.STEP_CHANNELS` and :data:`imitwalk.balance.STEP_STATE`);
* a constant offset on the channels and nothing else, e.g. ``dx=-0.005;lean=0.003``
  [m] (``step.offset`` with no step model: the reference with every swing foot landing
  5 mm short and the centre of mass 3 mm further forward); ``dx=-0.005@R``: the same
  at cadence R.

The rules are a diagnostic, not a controller the product uses. Prints JSON, one row per
entry: falls, the robots that fell, mean |yaw|.

Usage: ``python bench/step_rules.py RUN_DIR [--robots 40] [--scale S] [--entries open,model,...]``
(``--scale``: another scale than the run's).
"""

from __future__ import annotations

import argparse
import json
from dataclasses import replace

import numpy as np

from imitwalk.balance import STEP_CHANNELS, STEP_STATE
from imitwalk.evaluate import load_gait
from imitwalk.gait import GaitModel
from imitwalk.metrics import walk_metrics
from imitwalk.models import Models, build_policy
from imitwalk.parallel import run_parallel
from imitwalk.perturb import TRAIN_SEED_BASE, perturbed
from imitwalk.retarget.cadence import with_cadence
from imitwalk.robots import load_robot
from imitwalk.sim import MujocoPlant, playback, run

#: Robots of this diagnostic: training-range seeds that learning's draws do not reach
#: in a run of ordinary length (6 robots × ~50 iterations).
FIRST_SEED = TRAIN_SEED_BASE + 4000
SECONDS = 30.0
_CACHE: dict = {}


def _rule(terms):
    def search(self, s, s_prev, c_prev):
        c = np.zeros(len(STEP_CHANNELS))
        d = s - self.target
        for ch, st, k in terms:
            c[STEP_CHANNELS.index(ch)] += k * d[STEP_STATE.index(st)]
        return np.clip(c, self.c_min, self.c_max), 0.0

    return search


def _offset(entry: str, config):
    off = np.zeros(len(STEP_CHANNELS))
    for term in entry.split(";"):
        ch, _, value = term.partition("=")
        off[STEP_CHANNELS.index(ch)] = float(value)
    step = replace(config.step, offset=tuple(off.tolist()), gain=0.0)
    return replace(config, step=step)


def _one(job) -> dict:
    run_dir, entry, seed, scale = job
    if run_dir not in _CACHE:
        _CACHE.clear()
        _CACHE[run_dir] = load_gait(run_dir)
    lg = _CACHE[run_dir]
    robot = load_robot(lg.ref.robot)
    name, _, rate = entry.partition("@")
    base = lg.ref if name == "open" else lg.gait.ref  # the learned walk at its own cadence
    ref = with_cadence(base, float(rate)) if rate else base
    plant = MujocoPlant(robot, perturbed(seed, disturbance=True))
    scale = lg.scale if scale is None else scale
    q = ref.trajectory(scale, SECONDS)
    gait = lg.gait
    if rate and name != "open":
        gait = GaitModel(ref, lg.gait.scales, lg.config.gait)
    if name == "open":
        ro = playback(plant, q, q0=q[0])
    elif "=" in name:  # a constant offset, no model
        policy = build_policy(gait, scale, _offset(name, lg.config), Models(), robot=robot)
        ro = run(plant, policy, len(q))
    else:
        policy = build_policy(gait, scale, lg.config, lg.models, robot=robot)
        if name != "model":
            terms = [(c, s, float(k)) for c, s, k in (t.split(":") for t in name.split(";"))]
            policy.steps.config = replace(lg.config.step, gain=1.0)
            policy.steps._search = _rule(terms).__get__(policy.steps)
        ro = run(plant, policy, len(q))
    m = walk_metrics(ro, ref.expected_distance(scale, ro.seconds), q)
    return {
        "entry": entry,
        "seed": seed,
        "fell": bool(ro.fell),
        "yaw": abs(m.yaw_drift_deg),
        "speed": m.forward_speed_mps,
    }


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("run_dir")
    ap.add_argument("--robots", type=int, default=40)
    ap.add_argument("--entries", default="open,open@1.12,model,lean:pitch:-0.05")
    ap.add_argument("--scale", type=float, default=None, help="default: the run's")
    ap.add_argument("--workers", type=int, default=None)
    args = ap.parse_args()
    entries = args.entries.split(",")
    seeds = range(FIRST_SEED, FIRST_SEED + args.robots)
    jobs = [(args.run_dir, e, s, args.scale) for e in entries for s in seeds]
    res = run_parallel(_one, jobs, args.workers)
    for e in entries:
        rows = [r for r in res if r["entry"] == e]
        out = {
            "entry": e,
            "falls": sum(r["fell"] for r in rows),
            "robots": len(rows),
            "fell": [r["seed"] for r in rows if r["fell"]],
            "mean_abs_yaw_deg": float(np.mean([r["yaw"] for r in rows])),
            "mean_speed_mps": float(np.mean([r["speed"] for r in rows])),
        }
        print(json.dumps(out), flush=True)


if __name__ == "__main__":
    main()
