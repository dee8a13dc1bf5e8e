"""Does the swing foot clear the floor? Open loop on evaluation robots, contacts counted.

Plays a reference open loop at one scale on evaluation robots 0..N-1 (as ``imitwalk
evaluate`` draws them) and, over the steady loop, counts each foot's mid-swing ticks
(where the plan lifts that sole above ``--above`` of its peak lift) in which it
touches the floor, where on the sole (the centre of its contacts within the outer or
the inner 40 % of the half-width, or between), and the swing knee's mean tracking lag
there. Ground truth from MuJoCo's contacts, for diagnosis only: the learner never sees
it. Prints JSON.

Usage: ``python bench/swing_drag.py REFERENCE.npz [--scale 1.0] [--robots 4]
[--seconds 30] [--above 0.6]``
"""

from __future__ import annotations

import argparse
import json

import numpy as np

from imitwalk.perturb import perturbed
from imitwalk.retarget import Reference
from imitwalk.robots import load_robot
from imitwalk.sim import MujocoPlant, run

SIDES = {"l": ("l_sole", "l_foot", "l_knee", 1.0), "r": ("r_sole", "r_foot", "r_knee", -1.0)}


def one_robot(ref: Reference, robot, scale: float, seed: int, seconds: float, above: float):
    """Counts for one evaluation robot (``seed``)."""
    plan = ref.plan_at(scale)
    m, n = ref.starts.shape[1], ref.loops.shape[1]
    q = ref.trajectory(scale, seconds)
    plant = MujocoPlant(robot, perturbed(seed, ref.sim_options(None), disturbance=seed != 0))
    model, data = plant.model, plant.data
    names = list(ref.joint_names)
    # per side: is each loop tick mid-swing; the knee's index; the sole's geom and body
    mid = {
        s: plan[v[0]][m : m + n, 2] >= above * plan[v[0]][m : m + n, 2].max()
        for s, v in SIDES.items()
    }
    knee = {s: names.index(v[2]) for s, v in SIDES.items()}
    ids = {s: (model.geom(v[1]).id, model.body(v[1]).id) for s, v in SIDES.items()}
    acc = {
        s: {"mid_swing_ticks": 0, "touching": 0, "outer": 0, "inner": 0, "lag": []} for s in SIDES
    }

    def policy(k: int, obs) -> np.ndarray:
        t = k - 1  # the tick whose step produced this observation
        if t >= m + n:  # the steady loop, after its first cycle
            ph = (t - m) % n
            for s, (*_, out_sign) in SIDES.items():
                if not mid[s][ph]:
                    continue
                a = acc[s]
                a["mid_swing_ticks"] += 1
                j = knee[s]
                a["lag"].append(q[t][j] - obs.joints[j])
                gid, bid = ids[s]
                hit = [c for c in data.contact[: data.ncon] if gid in (c.geom1, c.geom2)]
                if hit:
                    a["touching"] += 1
                    pos = np.mean([c.pos for c in hit], axis=0)  # the contacts' centre
                    loc = data.xmat[bid].reshape(3, 3).T @ (pos - data.xpos[bid])
                    half = model.geom_size[gid][1]
                    a["outer"] += bool(out_sign * loc[1] > 0.6 * half)
                    a["inner"] += bool(out_sign * loc[1] < -0.6 * half)
        return q[k]  # run() calls k = 0 .. len(q) - 1

    ro = run(plant, policy, len(q), q0=q[0])
    out = {"seed": seed, "fell": bool(ro.fell), "fall_time_s": ro.fall_time}
    for s, a in acc.items():
        mid = a["mid_swing_ticks"]
        out[s] = {
            "mid_swing_ticks": mid,
            "touching_share": a["touching"] / mid if mid else None,
            "outer_edge": a["outer"],
            "inner_edge": a["inner"],
            "knee_lag_deg": float(np.degrees(np.mean(a["lag"]))) if a["lag"] else None,
        }
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("reference")
    ap.add_argument("--scale", type=float, default=1.0)
    ap.add_argument("--robots", type=int, default=4, help="evaluation robots 0..N-1")
    ap.add_argument("--seconds", type=float, default=30.0)
    ap.add_argument(
        "--above", type=float, default=0.6, help="mid-swing: plan lift above this share of its peak"
    )
    args = ap.parse_args()
    ref = Reference.load(args.reference)
    robot = load_robot(ref.robot)
    rows = [
        one_robot(ref, robot, args.scale, s, args.seconds, args.above) for s in range(args.robots)
    ]
    print(json.dumps({"reference": args.reference, "scale": args.scale, "robots": rows}, indent=1))


if __name__ == "__main__":
    main()
