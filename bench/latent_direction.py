"""Direction by the latent space, the paper's proposal (its conclusion, §7: "translation in
the x-y plane in the reduced 3D latent space can be used for changing direction"),
measured on a joint-trajectory run.

The run's reference loop is fitted with the paper's 3-D PCA posture subspace (§3.1,
``x = C (q − μ)``, :class:`~imitwalk.paper.subspace.PostureSubspace`, on every scale's
loop as :class:`~imitwalk.paper.gait.GaitModel` does). A translation ``d = α R (cos β,
sin β, 0)`` in the plane of its first two components, ``R`` the loop's mean radius there,
moves every posture by ``C⁺ d`` (the start-up ramps it in). The run's per-tick laws walk
the translated reference with their heading feedback taken out (it would steer the walk
back). Each robot's turn per cycle is the torso's true heading change from the loop's
first tick to the end, over the cycles walked.

Usage: ``python bench/latent_direction.py RUN [--seeds 10] [--seconds 20] [--controller
learned] [--offsets 0.1,0 0.1,180 ...]`` (each offset ``α,β[deg]``); RUN a per-tick run
(``imitwalk learn --variant extended``). Prints JSON, a line per offset, then all.
"""

from __future__ import annotations

import argparse
import json
from dataclasses import replace

import numpy as np

from imitwalk.balance.feedback import TickPolicy
from imitwalk.judge.replay import load_run
from imitwalk.paper.subspace import PostureSubspace
from imitwalk.parallel import run_parallel
from imitwalk.retarget.feedforward import walk_offsets
from imitwalk.robots import load_robot
from imitwalk.sim.metrics import yaw_rad
from imitwalk.sim.mujoco import make_plant, run
from imitwalk.sim.protocol import load_protocol


def without_heading(laws: tuple) -> tuple:
    """The laws with their gains on the heading feature (and its memory) zeroed."""
    out = []
    for law in laws:
        if "heading" not in law.features:
            out.append(law)
            continue
        d, j = len(law.features), list(law.features).index("heading")
        gains = np.array(law.gains, copy=True)
        gains[..., [j, j + d] if law.memory else [j]] = 0.0
        out.append(replace(law, gains=gains))
    return tuple(out)


def translated(ref, components: np.ndarray, d: np.ndarray):
    """The reference with every posture moved by ``C⁺ d`` ``(n,)`` [rad], ramped in over
    the start-up; and that offset."""
    dq = components.T @ d
    ramp = np.linspace(0.0, 1.0, ref.starts.shape[1])[:, None]
    return replace(ref, loops=ref.loops + dq, starts=ref.starts + ramp * dq), dq


def walk(job: tuple) -> dict:
    run_dir, ref, robot, controller, seed, options, seconds = job
    lr = load_run(run_dir)
    s = lr.settings_of(controller)
    offsets = walk_offsets(ref, robot, lr.scale, seconds, s["feedforward"])
    laws = without_heading(lr.laws[controller])
    policy = TickPolicy(
        ref, lr.scale, laws, robot.joint_names, seconds, offsets=offsets, wait=s["wait"]
    )
    ro = run(make_plant(robot, options), policy, int(round(seconds / ref.dt)))
    yaw = np.unwrap(yaw_rad(ro.torso_quat))
    k0 = min(ref.starts.shape[1], len(yaw) - 1)
    cycles = max((len(yaw) - k0) * ref.dt / ref.period, 1e-6)
    return {
        "seed": seed,
        "fell": bool(ro.fell),
        "fall_time_s": ro.fall_time,
        "deg_per_cycle": float(np.degrees(yaw[-1] - yaw[k0]) / cycles),
    }


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("run")
    ap.add_argument("--seeds", type=int, default=10)
    ap.add_argument("--seconds", type=float, default=20.0)
    ap.add_argument("--controller", default="learned")
    ap.add_argument("--offsets", nargs="+", default=["0,0", "0.1,0", "0.1,90", "0.1,180"])
    a = ap.parse_args()
    lr = load_run(a.run)
    ref = lr.reference
    robot = load_robot(ref.provenance.robot or ref.robot, ref.provenance.joint_map)
    sub = PostureSubspace(3).fit([ref.at_scale(s)[1] for s in ref.scales])
    X = sub.transform(ref.at_scale(lr.scale)[1])  # (N, 3)
    radius = float(np.mean(np.linalg.norm(X[:, :2] - X[:, :2].mean(axis=0), axis=1)))
    protocol = load_protocol("eval")
    out: dict = {
        "run": a.run,
        "radius": radius,
        "explained_variance_ratio": sub.explained_variance_ratio_.tolist(),
    }
    for spec in a.offsets:
        alpha, beta = (float(v) for v in spec.split(","))
        d = alpha * radius * np.array([np.cos(np.radians(beta)), np.sin(np.radians(beta)), 0.0])
        moved, dq = translated(ref, sub.components_, d)
        jobs = [
            (
                a.run,
                moved,
                robot,
                a.controller,
                seed,
                protocol.draw(seed, robot, moved.sim_options(), a.seconds).options,
                a.seconds,
            )
            for seed in range(a.seeds)
        ]
        res = run_parallel(walk, jobs)
        up = [r["deg_per_cycle"] for r in res if not r["fell"]]
        row = {
            "largest_joint_offset_deg": float(np.degrees(np.abs(dq).max())),
            "falls": len(res) - len(up),
            "fall_times_s": [r["fall_time_s"] for r in res if r["fell"]],
            "deg_per_cycle": (
                {"mean": float(np.mean(up)), "min": float(np.min(up)), "max": float(np.max(up))}
                if up
                else None
            ),
        }
        out[spec] = row
        print(json.dumps({spec: row}), flush=True)
    print(json.dumps(out))


if __name__ == "__main__":
    main()
