"""Prototype: the torso's pitch, measured, held to the nominal robot's through the hips.

A servo spread along a leg's pitch chain changes how its sag is shared: the hip pitch,
which carries the upper body, lets the torso lean more or less than on the nominal
robot. The nominal robot's torso pitch per tick (the start-up) and per loop tick (the
loop), from :class:`~imitwalk.balance.estimator.StateEstimator` (gyro and accelerometer
only), is recorded by walking the run's controller on the nominal model. On any robot
both hip-pitch targets get ``k × (pitch − pitch_nom)`` each tick (``--leak``: a leaky
integral of it instead, time constant [s]). A prototype to measure: the gain is an
argument, not learned.

Usage: ``python bench/torso_hip.py RUN --controller open_loop --gains 0,0.3,-0.3
[--protocol eval] [--robots 40] [--first 0] [--leak 0] [--joints hip_pitch]``; prints
JSON lines: the falls per gain.
"""

from __future__ import annotations

import argparse
import json

import numpy as np

from imitwalk.balance.estimator import StateEstimator
from imitwalk.judge.protocol import load_protocol
from imitwalk.judge.replay import load_run
from imitwalk.parallel import run_parallel
from imitwalk.robots import load_robot


class TorsoHip:
    """``base`` plus the torso pitch's departure from nominal on the chosen joints."""

    def __init__(self, base, ref, nom_tick, nom_loop, gain, leak, mask, dt):
        self.base, self.gain, self.mask, self.dt = base, gain, mask, dt
        self.start, self.n_loop = ref.starts.shape[1], ref.loops.shape[1]
        self.nom_tick, self.nom_loop = nom_tick, nom_loop
        self.est = StateEstimator(dt)
        self.leak, self.acc = leak, 0.0

    @property
    def q0(self):
        return self.base.q0

    def nominal(self, k):
        if k < self.start + self.n_loop:
            return self.nom_tick[min(k, len(self.nom_tick) - 1)]
        return self.nom_loop[(k - self.start) % self.n_loop]

    def __call__(self, k, obs):
        q = np.asarray(self.base(k, obs), dtype=float)
        e = self.est.update(obs.gyro, obs.accel, obs.foot_force).pitch - self.nominal(k)
        if self.leak > 0:
            self.acc += self.dt * (e - self.acc / self.leak)
            e = self.acc
        return q + self.gain * e * self.mask


def nominal_pitch(run_dir, controller, robot, seconds):
    from imitwalk.sim.mujoco import make_plant, run

    lr = load_run(run_dir)
    pol = lr.policy(controller, robot, seconds=seconds)
    est = StateEstimator(lr.ref.dt)
    pitch = []

    def rec(k, obs):
        pitch.append(est.update(obs.gyro, obs.accel, obs.foot_force).pitch)
        return pol(k, obs)

    rec.q0 = pol.q0
    run(make_plant(robot, lr.ref.sim_options()), rec, round(seconds / lr.ref.dt))
    p = np.asarray(pitch)
    start, n = lr.ref.starts.shape[1], lr.ref.loops.shape[1]
    loop = np.zeros(n)
    cnt = np.zeros(n)
    for k in range(start + n, len(p)):
        loop[(k - start) % n] += p[k]
        cnt[(k - start) % n] += 1
    return p, loop / np.maximum(cnt, 1)


def walk(job):
    from imitwalk.sim.mujoco import make_plant, run

    run_dir, controller, seed, proto, gain, leak, joints, nom_tick, nom_loop, seconds = job
    robot = load_robot("hoap2")
    lr = load_run(run_dir)
    protocol = load_protocol(proto)
    d = protocol.draw(seed, robot, seconds=seconds)
    pol = lr.policy(controller, robot, seconds=seconds)
    if gain:
        mask = np.array([any(j in n for j in joints.split(",")) for n in robot.joint_names])
        pol = TorsoHip(pol, lr.ref, nom_tick, nom_loop, gain, leak, mask.astype(float), lr.ref.dt)
    plant = make_plant(robot, lr.ref.sim_options(d.options), protocol.engine)
    ro = run(plant, pol, round(seconds / lr.ref.dt))
    return bool(ro.fell)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("run_dir")
    ap.add_argument("--controller", default="learned")
    ap.add_argument("--protocol", default="eval")
    ap.add_argument("--robots", type=int, default=40)
    ap.add_argument("--first", type=int, default=0)
    ap.add_argument("--gains", default="0,0.3,-0.3")
    ap.add_argument("--leak", type=float, default=0.0)
    ap.add_argument("--joints", default="hip_pitch")
    ap.add_argument("--seconds", type=float, default=30.0)
    a = ap.parse_args()
    robot = load_robot("hoap2")
    nom_tick, nom_loop = nominal_pitch(a.run_dir, a.controller, robot, a.seconds)
    for g in [float(x) for x in a.gains.split(",")]:
        jobs = [(a.run_dir, a.controller, a.first + s, a.protocol, g, a.leak, a.joints,
                 nom_tick, nom_loop, a.seconds) for s in range(a.robots)]  # fmt: skip
        res = run_parallel(walk, jobs, None)
        fallen = [a.first + s for s, f in enumerate(res) if f]
        row = {"gain": g, "leak_s": a.leak, "joints": a.joints, "controller": a.controller,
               "protocol": a.protocol, "falls": len(fallen), "of": a.robots,
               "fallen": fallen}  # fmt: skip
        print(json.dumps(row), flush=True)


if __name__ == "__main__":
    main()
