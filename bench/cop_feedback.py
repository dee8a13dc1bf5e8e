"""Sole-force (centre-of-pressure) feedback on each stance ankle, beside a run's laws.

A prototype for issue 30's hard robots, measured and not kept (docs/RESULTS.md, "The
other factors, tried one at a time"). Each foot's centre of pressure is read from its
four sole sensors (front-left, front-right, rear-left, rear-right), as a fraction of the
sensor span (−1 … 1, x forward, y left). Its nominal per loop tick is the mean over
training robots (eval protocol, seeds from 100 001) walking the run's own laws. On top of
those laws, each loaded foot's ankle pitch and roll get ``u``, a leaky integral of the
load-weighted error: ``du/dt = k · w · (cop − nominal) − u / T`` (``T = --leak``), ``w``
the foot's share of the sole forces. ``k`` is a candidate (a trial's choice); the bench
walks each on validation robots (seeds from 300 000) of the protocol's factors, one at a
time, then all but the kicks, the whole protocol and eval. ``--tilt`` feeds back the
torso's estimated pitch and roll (both feet alike, weight 1) instead of the feet's CoP.

Usage: ``python bench/cop_feedback.py RUN --gains "0,0;-0.5,0;-1,-1" [--factors slope,friction]
[--robots 20]``; prints JSON lines, one per (gains, protocol variant).
"""

from __future__ import annotations

import argparse
import json
from dataclasses import dataclass

import numpy as np

from imitwalk.balance.feedback import TickPolicy
from imitwalk.judge.protocol import load_protocol
from imitwalk.judge.replay import load_run
from imitwalk.parallel import run_parallel
from imitwalk.robots import load_robot


def foot_cop(f: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(2, 2)`` each foot's centre of pressure (x, y; −1 … 1) and ``(2,)`` its load share."""
    tot = f.sum(axis=1)
    safe = np.maximum(tot, 1e-6)
    cx = (f[:, 0] + f[:, 1] - f[:, 2] - f[:, 3]) / safe
    cy = (f[:, 0] + f[:, 2] - f[:, 1] - f[:, 3]) / safe
    share = tot / max(tot.sum(), 1e-6)
    return np.stack([cx, cy], axis=1), share


class CopPolicy(TickPolicy):
    """The run's laws plus leaky-integral CoP feedback on each loaded ankle."""

    def __init__(self, ref, scale, laws, names, seconds, nominal, gains, leak, tilt=False):
        super().__init__(ref, scale, laws, names, seconds)
        self.tilt = tilt
        self.nominal, self.gains, self.leak = nominal, np.asarray(gains, float), leak
        self.ix = [[names.index(f"{s}_ankle_pitch"), names.index(f"{s}_ankle_roll")] for s in "lr"]
        self.u = np.zeros((2, 2))
        self.log: list[tuple[int, np.ndarray, np.ndarray]] = []

    def __call__(self, k, obs):
        q = super().__call__(k, obs)
        i = self.phase_of(min(k, len(self.q_ref) - 1))
        if self.tilt:  # the torso's tilt, the same for both feet
            tilt = np.array([self.estimator.pitch, self.estimator.roll])
            signal, weight = np.stack([tilt, tilt]), np.array([1.0, 1.0])
        else:
            signal, weight = foot_cop(np.asarray(obs.foot_force, float))
        self.log.append((i, signal, weight))
        if self.nominal is not None:
            err = (signal - self.nominal[i]) * weight[:, None]  # (2 feet, 2 axes)
            self.u += self.estimator.dt * (self.gains * err - self.u / self.leak)
            for leg in range(2):
                q[self.ix[leg]] += self.u[leg]
        return q


@dataclass(frozen=True)
class Job:
    run_dir: str
    robot: object
    options: object
    seconds: float
    nominal: np.ndarray | None
    gains: tuple
    leak: float
    tilt: bool = False


def walk(job: Job):
    from imitwalk.sim.metrics import walk_metrics
    from imitwalk.sim.mujoco import make_plant, run

    r = load_run(job.run_dir)
    pol = CopPolicy(r.ref, r.scale, tuple(r.laws["learned"]), job.robot.joint_names,
                    job.seconds, job.nominal, job.gains, job.leak, job.tilt)  # fmt: skip
    plant = make_plant(job.robot, r.ref.sim_options(job.options), "mujoco")
    ro = run(plant, pol, len(pol.q_ref))
    m = walk_metrics(ro, r.ref.expected_distance(r.scale, ro.seconds), pol.q_ref,
                     r.ref.track(r.scale, ro.seconds))  # fmt: skip
    return m.fell, m.fall_time_s, m.forward_distance_m, pol.log


def nominal_cop(run_dir, robot, n_loop, robots=8, seconds=12.0, tilt=False):
    """``(n_loop, 2, 2)`` share-weighted mean CoP per loop tick on training robots."""
    r = load_run(run_dir)
    proto = load_protocol("eval")
    draws = [proto.draw(100_001 + s, robot, r.ref.sim_options(), seconds) for s in range(robots)]
    jobs = [Job(run_dir, robot, d.options, seconds, None, (0, 0), 1.0, tilt) for d in draws]
    num, den = np.zeros((n_loop, 2, 2)), np.zeros((n_loop, 2, 1))
    for _fell, _, _, log in run_parallel(walk, jobs):
        for i, cop, share in log[200:]:  # past the start-up
            num[i] += cop * share[:, None]
            den[i] += share[:, None]
    return num / np.maximum(den, 1e-6)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("run_dir")
    ap.add_argument("--robot", default="hoap2")
    ap.add_argument(
        "--gains", default="0,0;-0.5,0", help="pitch,roll [rad/s per unit]; candidates split by ;"
    )
    ap.add_argument("--leak", type=float, default=0.5, help="the integral's leak T [s]")
    ap.add_argument("--protocol", default="hard")
    ap.add_argument(
        "--tilt",
        action="store_true",
        help="feed back the estimated torso tilt (pitch, roll) instead of each foot's CoP",
    )
    ap.add_argument("--factors", default="slope,friction,torso_com,servo")
    ap.add_argument("--robots", type=int, default=20)
    ap.add_argument("--first", type=int, default=300_000)
    ap.add_argument("--seconds", type=float, default=30.0)
    args = ap.parse_args()
    r, robot = load_run(args.run_dir), load_robot(args.robot)
    nom = nominal_cop(args.run_dir, robot, r.ref.loops.shape[1], tilt=args.tilt)
    proto = load_protocol(args.protocol)
    variants = [proto.only((f,)) for f in args.factors.split(",") if f]
    if "pushes" in proto.factors:
        variants.append(proto.only(tuple(f for f in proto.factors if f != "pushes")))
    variants.append(proto)
    variants.append(load_protocol("eval"))
    for g in args.gains.split(";"):
        gains = tuple(float(v) for v in g.split(","))
        for p in variants:
            draws = [p.draw(args.first + s, robot, r.ref.sim_options(), args.seconds)
                     for s in range(args.robots)]  # fmt: skip
            jobs = [Job(args.run_dir, robot, d.options, args.seconds, nom, gains, args.leak,
                        args.tilt) for d in draws]  # fmt: skip
            res = run_parallel(walk, jobs)
            falls = [round(float(t or 0), 1) for f, t, _, _ in res if f]
            print(json.dumps({"gains": gains, "leak": args.leak, "protocol": p.name,
                              "falls": len(falls), "fall_times_s": sorted(falls),
                              "distance_m": round(float(np.mean([d for _, _, d, _ in res])), 2)}),
                  flush=True)  # fmt: skip


if __name__ == "__main__":
    main()
