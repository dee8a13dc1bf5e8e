"""Prototype: each servo's stiffness identified from the encoders, its sag made nominal.

A position servo of stiffness r·kp lags its target by (τ + kv·q̇)/(r·kp): the same
torque, 1/r times the nominal lag. The nominal robot's lag e_nom(ψ) per loop tick is
recorded by walking the run's controller on the nominal model (the product's own model,
no sensor of the judged robot). On any robot, each tick, 1/r per joint is the
exponentially weighted least-squares ratio of the measured lag (the last target less the
encoder) to e_nom, and the target gets (1/r − 1)·e_nom(ψ): the lag the nominal robot
would have. Encoders only; ``--tau`` is the forgetting time [s].

``--exact`` scales the lag measured at this tick, (1/r − 1)·(target − encoder), instead of
e_nom(ψ): at the control ticks a servo of stiffness r·kp then pulls as the nominal one
would. ``--by-tick`` records e_nom per tick of the walk instead of per loop tick.
``--track G`` identifies nothing: it adds G × (the lag now − e_nom(ψ)) to each target,
pulling every robot's joints toward the nominal robot's. ``--oracle`` (a diagnosis, not a controller) skips the identification and holds each
servo's true factor, read from the simulator (``--oracle-joints ankle,knee``: only on the
joints whose names hold one of these). ``--pattern P`` instead keeps only some
servos' drawn stiffness (the others nominal) and walks the run's controller plainly:
``all``, ``uniform`` (every servo at the robot's mean factor), ``sym`` (each right servo
as its left twin), ``legs``, ``upper``, ``pitch`` (hip pitch, knee, ankle pitch), ``roll``
(hip and ankle roll).

Usage: ``python bench/servo_id.py RUN --controller learned --protocol eval --robots 40
[--taus 0,2] [--only servo] [--first 0] [--exact] [--by-tick] [--track G] [--oracle] [--pattern P]``;
prints JSON lines: the falls per setting.
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

    def __init__(self, base, ref, e_nom: np.ndarray, tau_s: float, dt: float, exact=False):
        self.exact = exact
        self.track = 0.0  # > 0: no identification; that gain on the lag's departure from e_nom
        self.by_tick = len(e_nom) != ref.loops.shape[1]
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
        if self.by_tick:
            i = k if k < len(self.e_nom) else None
        else:
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
        if i is not None and self.track:
            q = q + self.mask * self.track * ((q - obs.joints) - self.e_nom[i])
        elif i is not None:
            lag = (q - obs.joints) if self.exact else self.e_nom[i]
            q = q + self.mask * (self.inv_r - 1.0) * lag
        self.prev, self.prev_i = q, i
        return q


def nominal_lag(run_dir, controller, robot, seconds=20.0, by_tick=False):
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
    if by_tick:
        return e, ro.fell
    n_loop, start = lr.ref.loops.shape[1], lr.ref.starts.shape[1]
    out = np.zeros((n_loop, e.shape[1]))
    cnt = np.zeros(n_loop)
    for k in range(start + n_loop, len(e)):
        i = (k - start) % n_loop
        out[i] += e[k]
        cnt[i] += 1
    return out / np.maximum(cnt, 1)[:, None], ro.fell


PATTERNS = {
    "legs": ("hip", "knee", "ankle"),
    "pitch": ("hip_pitch", "knee", "ankle_pitch"),
    "roll": ("hip_roll", "ankle_roll"),
}


def patterned(names, pattern):
    """``jitter_draws`` with only ``pattern``'s servos as drawn (see the module doc)."""
    from imitwalk.sim.types import jitter_draws

    def draws(opt, nbody, joint_names):
        mass, kp = jitter_draws(opt, nbody, joint_names)
        kp = kp.copy()
        if pattern == "uniform":
            kp[:] = kp.mean()
        elif pattern == "sym":
            for i, n in enumerate(names):
                if n.startswith("r_") and "l_" + n[2:] in names:
                    kp[i] = kp[names.index("l_" + n[2:])]
        elif pattern != "all":
            leg = [any(s in n for s in PATTERNS["legs"]) for n in names]
            for i, n in enumerate(names):
                keep = not leg[i] if pattern == "upper" else any(s in n for s in PATTERNS[pattern])
                if not keep:
                    kp[i] = 1.0
        return mass, kp

    return draws


def walk(job):
    import imitwalk.sim.mujoco as sim
    from imitwalk.sim.types import jitter_draws

    run_dir, controller, seed, proto, only, tau, e_nom, seconds, exact, oracle, pattern, track = job
    robot = load_robot("hoap2")
    if pattern:
        sim.jitter_draws = patterned(list(robot.joint_names), pattern)
    lr = load_run(run_dir)
    p = load_protocol(proto)
    if only:
        p = p.only(only.split(","))
    d = p.draw(seed, robot, seconds=seconds)
    pol = lr.policy(controller, robot, seconds=seconds)
    plant = sim.make_plant(robot, lr.ref.sim_options(d.options))
    if tau > 0 and not pattern:
        pol = ServoId(pol, lr.ref, e_nom, tau, lr.ref.dt, exact)
        pol.track = track
        if oracle:  # the true factors, held: a diagnosis of the compensation alone
            _, kp = jitter_draws(plant.options, plant.model.nbody, tuple(robot.joint_names))
            keep = oracle.split(",") if isinstance(oracle, str) else []
            pol.mask[:] = [not keep or any(k in n for k in keep) for n in robot.joint_names]
            pol.a, pol.sxx = 1.0, np.full(len(kp), 1e9)
            pol.sxy = pol.sxx / kp
    ro = sim.run(plant, pol, round(seconds / lr.ref.dt))
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
    ap.add_argument("--by-tick", action="store_true", help="e_nom per tick of the walk")
    ap.add_argument("--exact", action="store_true", help="scale the lag measured now, not e_nom")
    ap.add_argument("--track", type=float, default=0.0, help="gain on the lag less e_nom")
    ap.add_argument("--oracle", action="store_true", help="the true factors (a diagnosis)")
    ap.add_argument("--oracle-joints", default="", help="the oracle on these joints only")
    ap.add_argument("--pattern", default="", help="which servos keep their draw (no --taus)")
    a = ap.parse_args()
    robot = load_robot("hoap2")
    e_nom, _ = nominal_lag(a.run_dir, a.controller, robot, a.seconds, a.by_tick)
    taus = [0.0] if a.pattern else [float(t) for t in a.taus.split(",")]
    for tau in taus:
        jobs = [
            (a.run_dir, a.controller, a.first + s, a.protocol, a.only, tau, e_nom, a.seconds,
             a.exact, a.oracle_joints or a.oracle, a.pattern, a.track)
            for s in range(a.robots)
        ]  # fmt: skip
        res = run_parallel(walk, jobs, None)
        falls = [a.first + s for s, (f, _) in enumerate(res) if f]
        row = {"tau_s": tau, "protocol": a.protocol, "only": a.only, "controller": a.controller,
               "exact": a.exact, "oracle": a.oracle_joints or a.oracle, "pattern": a.pattern, "track": a.track,
               "falls": len(falls), "of": a.robots, "fallen": falls}  # fmt: skip
        print(json.dumps(row), flush=True)


if __name__ == "__main__":
    main()
