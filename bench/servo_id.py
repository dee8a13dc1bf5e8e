"""Prototype: each servo's stiffness identified from the encoders, its sag made nominal.

A position servo of stiffness r·kp lags its target by (τ + kv·q̇)/(r·kp): the same
torque, 1/r times the nominal lag. The nominal robot's lag e_nom(ψ) per loop tick is
recorded by walking the run's controller on the nominal model (the product's own model,
no sensor of the judged robot). On any robot, each tick, 1/r per joint is the
exponentially weighted least-squares ratio of the measured lag (the last target less the
encoder) to e_nom, and the target gets (1/r − 1)·e_nom(ψ): the lag the nominal robot
would have. Encoders only; ``--tau`` is the forgetting time [s].

Usage: ``python bench/servo_id.py RUN --controller learned --protocol eval --robots 40
[--tau 2] [--only servo]``; prints JSON: falls with and without the identification.
"""

from __future__ import annotations

import argparse
import json

import numpy as np

from imitwalk.judge.protocol import load_protocol
from imitwalk.judge.replay import load_run
from imitwalk.parallel import run_parallel
from imitwalk.robots import load_robot


class ServoId:
    """``base`` plus the nominal lag on every joint (see the module doc)."""

    def __init__(self, base, ref, e_nom: np.ndarray, tau_s: float, dt: float):
        self.base, self.e_nom = base, e_nom
        self.start, self.n_loop = ref.starts.shape[1], ref.loops.shape[1]
        self.a = float(np.exp(-dt / tau_s))
        n = e_nom.shape[1]
        self.sxy, self.sxx = np.zeros(n), np.zeros(n)
        self.prev, self.prev_i = None, 0
        self.inv_r = np.ones(n)
        # joints whose nominal lag is under 1° RMS carry too little signal to identify
        self.mask = np.sqrt(np.mean(e_nom**2, axis=0)) > np.radians(1.0)

    @property
    def q0(self):
        return self.base.q0

    def __call__(self, k, obs):
        q = np.asarray(self.base(k, obs), dtype=float)
        i = (k - self.start) % self.n_loop if k >= self.start else None
        if self.prev is not None and self.prev_i is not None:
            e = self.prev - obs.joints
            en = self.e_nom[self.prev_i]
            self.sxy = self.a * self.sxy + e * en
            self.sxx = self.a * self.sxx + en * en
            ok = self.sxx > 1e-6
            self.inv_r = np.where(
                ok, np.clip(self.sxy / np.maximum(self.sxx, 1e-12), 0.7, 1.4), 1.0
            )
        if i is not None:
            q = q + self.mask * (self.inv_r - 1.0) * self.e_nom[i]
        self.prev, self.prev_i = q, i
        return q


def nominal_lag(run_dir, controller, robot, seconds=20.0):
    from imitwalk.sim.mujoco import make_plant, run

    lr = load_run(run_dir)
    pol = lr.policy(controller, robot, seconds=seconds)
    cmds = []

    def rec(k, obs):
        q = pol(k, obs)
        cmds.append(np.array(q))
        return q

    rec.q0 = pol.q0
    ro = run(make_plant(robot, lr.ref.sim_options()), rec, round(seconds / lr.ref.dt))
    e = ro.q_cmd - ro.q  # row k: tick k's target less the encoders after it
    n_loop, start = lr.ref.loops.shape[1], lr.ref.starts.shape[1]
    out = np.zeros((n_loop, e.shape[1]))
    cnt = np.zeros(n_loop)
    for k in range(start + n_loop, len(e)):
        i = (k - start) % n_loop
        out[i] += e[k]
        cnt[i] += 1
    return out / np.maximum(cnt, 1)[:, None], ro.fell


def walk(job):
    from imitwalk.sim.mujoco import make_plant, run

    run_dir, controller, seed, proto, only, tau, e_nom, seconds = job
    robot = load_robot("hoap2")
    lr = load_run(run_dir)
    p = load_protocol(proto)
    if only:
        p = p.only(only.split(","))
    d = p.draw(seed, robot, seconds=seconds)
    pol = lr.policy(controller, robot, seconds=seconds)
    if tau > 0:
        pol = ServoId(pol, lr.ref, e_nom, tau, lr.ref.dt)
    ro = run(make_plant(robot, lr.ref.sim_options(d.options)), pol, round(seconds / lr.ref.dt))
    return bool(ro.fell), ro.fall_time


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("run_dir")
    ap.add_argument("--controller", default="learned")
    ap.add_argument("--protocol", default="eval")
    ap.add_argument("--only", default="")
    ap.add_argument("--robots", type=int, default=40)
    ap.add_argument("--first", type=int, default=0)
    ap.add_argument("--taus", default="0,2")
    ap.add_argument("--seconds", type=float, default=30.0)
    a = ap.parse_args()
    robot = load_robot("hoap2")
    e_nom, _ = nominal_lag(a.run_dir, a.controller, robot)
    for tau in [float(t) for t in a.taus.split(",")]:
        jobs = [
            (a.run_dir, a.controller, a.first + s, a.protocol, a.only, tau, e_nom, a.seconds)
            for s in range(a.robots)
        ]
        res = run_parallel(walk, jobs, None)
        falls = [a.first + s for s, (f, _) in enumerate(res) if f]
        print(
            json.dumps(
                {
                    "tau_s": tau,
                    "protocol": a.protocol,
                    "only": a.only,
                    "controller": a.controller,
                    "falls": len(falls),
                    "of": a.robots,
                    "fallen": falls,
                }
            ),
            flush=True,
        )


if __name__ == "__main__":
    main()
