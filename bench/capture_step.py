"""A prototype: a step placed for the capture point, held through the stance it lands in.

The two placement laws measured before (``bench/foot_placement.py`` and the deviation law
of docs/RESULTS.md) moved the swing leg by the gyro *every tick*, so the offset vanished
the moment the foot landed and its hip came back under load. Here each leg keeps the
offset it landed with through the stance that follows, and only blends it towards the
new target over the first half of its next swing:

    u_leg ← (1 − b(s)) u_landed + b(s) · k · c      while the leg swings (s: swing progress),
    u_leg  = u_landed                               while it stands,

with ``b`` a smoothstep over the first half of the swing. The hip roll (pitch) of the leg
moves by ``u`` and its ankle roll (pitch) by ``−u``, so the sole lands flat. ``c`` is the
deviation of the capture point's velocity term from the nominal robot's at that loop tick:

- ``--mode imu``: c = Δgyro + ω₀ Δtilt (rad/s), torso roll for the lateral step and
  pitch for the sagittal one, from the robot's own IMU estimate (ω₀ = √(g / h), h the
  torso's standing height);
- ``--mode cp``: c = Δξ / h, ξ = the true centre of mass less the midpoint of the soles
  plus its velocity over ω₀ (the capture point, simulator ground truth; an upper bound);
- ``--mode oracle``: c = Δv_CoM / h (rad/s), the simulator's true centre-of-mass velocity,
  an upper bound for what a measured estimate could give (not a controller imitwalk
  could ship).

``--axis hurry`` instead runs the reference's clock faster, by ``1 + min(1, k · max(0,
|Δv_CoM| / h − DEADBAND))`` ticks per tick (the paper's phase advance, eq. 9, made by the
kick; ``DEADBAND`` from the environment, 0.3 rad/s by default), oracle mode only. With
``FOLLOW=1`` the clock follows the body instead: ``clip(1 + k · Δv_x / 0.2 m/s, −1, 2)``
ticks per tick, Δv_x the true forward velocity's deviation (a kick back slows, stops or
rewinds the gait).

Walks the run's learned controller with each gain on validation robots (seeds from
``--first``) of the hard protocol's kicks alone and of eval.

Usage: ``python bench/capture_step.py RUN [--mode imu] [--axis roll] [--gains ...]
[--robots 20] [--first 300000]``; prints JSON lines.
"""

from __future__ import annotations

import argparse
import json

import mujoco
import numpy as np

from imitwalk.balance.feedback import TickPolicy
from imitwalk.judge.protocol import load_protocol
from imitwalk.judge.replay import load_run
from imitwalk.parallel import run_parallel
from imitwalk.retarget.feedforward import walk_offsets
from imitwalk.robots import load_robot
from imitwalk.sim.mujoco import make_plant, run
from imitwalk.sim.types import SimOptions

FOLLOW = bool(int(__import__("os").environ.get("FOLLOW", "0")))
DEADBAND = float(__import__("os").environ.get("DEADBAND", "0.3"))
ROLES = {
    "roll": ("hip_roll", "ankle_roll"),
    "pitch": ("hip_pitch", "ankle_pitch"),
    "hurry": ("hip_roll", "ankle_roll"),
}


class StepPolicy(TickPolicy):
    """The run's policy plus the held capture-point step of the module doc."""

    def __init__(self, *a, plant, gain, axis, mode, nominal, h, **kw):
        super().__init__(*a, **kw)
        if axis == "hurry":  # a reference long enough for a clock that runs fast
            ref, scale, seconds = a[0], a[1], a[4]
            q = ref.trajectory(scale, 2 * seconds)
            off = kw.get("offsets")
            self.q_cmd = q if off is None else q + off[: len(q)]
            self.heading_ref = ref.track(scale, 2 * seconds)[:, 2]
        self.plant, self.gain, self.axis, self.mode, self.h = plant, gain, axis, mode, h
        self.nominal = nominal  # (N,) c's nominal profile (None: record it)
        self.seen: list[tuple[int, float]] = []
        names = plant.joint_names
        hip, ankle = ROLES[axis]
        self.idx = [(names.index(f"{s}_{hip}"), names.index(f"{s}_{ankle}")) for s in "lr"]
        self.u, self.landed = np.zeros(2), np.zeros(2)
        self.w0 = np.sqrt(9.81 / h)
        self._com_prev = None
        self._swing_len = [max(1, int((~self.stance[:, j]).sum()) // 2) for j in range(2)]
        self._since = np.zeros(2, dtype=int)

    @property
    def stance(self):
        return self._stance

    def signal(self, obs) -> float:
        if self.mode == "cp":
            d, m = self.plant.data, self.plant.model
            com = d.subtree_com[1].copy()
            v = np.zeros(3) if self._com_prev is None else (com - self._com_prev) / 0.01
            self._com_prev = com
            feet = [d.site_xpos[m.site(self.plant.robot.soles[s]).id] for s in "lr"]
            mid = 0.5 * (feet[0] + feet[1])
            xi = com - mid + v / self.w0
            return float(xi[1] if self.axis == "roll" else xi[0]) / self.h
        if self.mode == "oracle":
            d, m = self.plant.data, self.plant.model
            com = d.subtree_com[1].copy()
            v = np.zeros(3) if self._com_prev is None else (com - self._com_prev) / 0.01
            self._com_prev = com
            if self.axis == "hurry":
                return (float(v[0]), float(v[1]))
            return float(v[1] if self.axis == "roll" else v[0]) / self.h
        est = self.estimator  # updated by the parent's call just before
        f = self._f[-1]
        rate, tilt = (f[0], f[3]) if self.axis == "roll" else (f[1], f[4])
        del est
        return float(rate + self.w0 * tilt)

    def _tick(self, k, obs):
        if self.axis != "hurry":
            return super()._tick(k, obs)
        if not hasattr(self, "_tau"):
            self._tau, self._dev, self._dvx = 0.0, 0.0, 0.0
        out = int(round(self._tau))
        if FOLLOW:
            self._tau = max(0.0, self._tau + float(np.clip(1.0 + self.gain * self._dvx / 0.2, -1.0, 2.0)))
        else:
            self._tau += 1.0 + min(1.0, self.gain * max(0.0, self._dev - DEADBAND))
        return out

    def __call__(self, k, obs):
        if self.axis == "hurry":
            q = super().__call__(k, obs)
            i = self._phase[-1]
            c = self.signal(obs)
            self.seen.append((i, c[0], c[1]))
            if self.nominal is not None:
                start, loop = self.nominal
                ref = start[k] if k < len(start) else loop[i]
                self._dev = float(np.hypot(c[0] - ref[0], c[1] - ref[1])) / self.h
                self._dvx = float(c[0] - ref[0])
            return q
        q = super().__call__(k, obs)
        i = self._phase[-1]
        c = self.signal(obs)
        self.seen.append((i, c))
        if self.nominal is None or self.gain == 0.0:
            return q
        start, loop = self.nominal
        dev = c - (start[k, 0] if k < len(start) else loop[i, 0])
        for j in range(2):
            if self._stance[i, j]:
                self._since[j] = 0
                self.landed[j] = self.u[j]
            else:
                self._since[j] += 1
                s = min(1.0, self._since[j] / self._swing_len[j])
                b = s * s * (3.0 - 2.0 * s)
                self.u[j] = (1.0 - b) * self.landed[j] + b * self.gain * dev
            u = float(np.clip(self.u[j], -0.3, 0.3))
            hi, ai = self.idx[j]
            q[hi] += u
            q[ai] -= u
        return q


def walk(job) -> dict:
    run_, robot, options, seconds, gain, axis, mode, nominal, h = job
    ref = run_.ref
    settings = run_.settings_of("learned")
    offsets = walk_offsets(ref, robot, run_.scale, 2 * seconds, settings["feedforward"])
    plant = make_plant(robot, ref.sim_options(options))
    pol = StepPolicy(ref, run_.scale, tuple(run_.laws["learned"]), robot.joint_names, seconds,
                     offsets=offsets, wait=settings["wait"], plant=plant, gain=gain, axis=axis,
                     mode=mode, nominal=nominal, h=h)  # fmt: skip
    ro = run(plant, pol, len(pol.q_ref))
    return {"fell": bool(ro.fell), "t": ro.fall_time, "seen": pol.seen}


def _stance_patch():
    # TickPolicy keeps the reference's stance schedule only through its channel maps.
    orig = TickPolicy.__init__

    def init(self, ref, *a, **kw):
        self._stance = np.asarray(ref.stance, dtype=bool)
        orig(self, ref, *a, **kw)

    TickPolicy.__init__ = init


def profile(seen: np.ndarray, start: int, n: int) -> tuple[np.ndarray, np.ndarray]:
    """The nominal walk's c: per control tick over the start-up, per loop tick after it."""
    loop = seen[start:]
    return seen[:start, 1:], np.array([loop[loop[:, 0] == i, 1:].mean(axis=0) for i in range(n)])


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("run_dir")
    ap.add_argument("--mode", default="imu", choices=("imu", "oracle", "cp"))
    ap.add_argument("--axis", default="roll", choices=tuple(ROLES))
    ap.add_argument("--gains", default="0,0.02,0.05,0.1,-0.02,-0.05,-0.1")
    ap.add_argument("--robots", type=int, default=20)
    ap.add_argument("--first", type=int, default=300_000)
    ap.add_argument("--protocols", default="kicks,eval")
    a = ap.parse_args()
    _stance_patch()
    robot, run_ = load_robot("hoap2"), load_run(a.run_dir)
    h = float(robot.torso_height)
    ref = run_.ref
    N = ref.loops.shape[1]
    nom_walk = walk((run_, robot, SimOptions(), 20.0, 0.0, a.axis, a.mode, None, h))
    nominal = profile(np.array(nom_walk["seen"]), ref.starts.shape[1], N)
    hard = load_protocol("hard")
    protos = {"kicks": hard.only(("pushes",)), "eval": load_protocol("eval"), "hard": hard}
    for g in [float(x) for x in a.gains.split(",")]:
        row = {"mode": a.mode, "axis": a.axis, "gain": g}
        for p in a.protocols.split(","):
            draws = [protos[p].draw(a.first + s, robot, ref.sim_options(), 30.0)
                     for s in range(a.robots)]  # fmt: skip
            jobs = [(run_, robot, d.options, 30.0, g, a.axis, a.mode, nominal, h) for d in draws]
            res = run_parallel(walk, jobs)
            row[p] = sum(r["fell"] for r in res)
        print(json.dumps(row), flush=True)


if __name__ == "__main__":
    mujoco  # the oracle reads the plant's data
    main()
