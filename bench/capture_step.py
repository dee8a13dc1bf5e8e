"""Does a step placed at the capture point, then let go of, save hard's kicked robots?
A diagnosis with the simulator's true state, not a product option.

On top of a per-tick run's learned controller, every tick of single support moves the
swing foot (in the heading frame, through the swing leg's 6-joint Jacobian at the
commanded posture, the sole kept level and at its planned height) towards
``k × (ξ − ξ_nom)``: ξ = c + ċ/ω₀ is the divergent component of motion (capture point)
relative to the stance sole, from the simulator's true centre of mass (an upper bound for
any estimate), and ξ_nom the same on the nominal robot at that tick. The offset reaches
its target at the planned landing. Then, in stance, it is let go of over ``release`` s
(the body is asked to come over the foot where it landed; ``--release inf`` holds it, as
an earlier prototype did, so the body keeps its planned world path). Offsets are clipped
to ``--clip`` m (across the body: ``--inward``).

Usage: ``python bench/capture_step.py RUN [--robots 20] [--first 300000] [--gains 0,0.5,1]
[--release 0.2,inf] [--variants pushes,hard,eval]``; prints JSON.
"""

from __future__ import annotations

import argparse
import json
import sys

import mujoco
import numpy as np

from imitwalk.balance.feedback import TickPolicy
from imitwalk.judge.protocol import load_protocol
from imitwalk.judge.replay import load_run
from imitwalk.parallel import run_parallel
from imitwalk.retarget.feedforward import walk_offsets
from imitwalk.robots import load_robot
from imitwalk.sim.metrics import walk_metrics
from imitwalk.sim.mujoco import make_plant, run

SECONDS = 30.0
LEGS = {"l": ("l_hip_yaw", "l_hip_roll", "l_hip_pitch", "l_knee", "l_ankle_pitch", "l_ankle_roll"),
        "r": ("r_hip_yaw", "r_hip_roll", "r_hip_pitch", "r_knee", "r_ankle_pitch", "r_ankle_roll")}  # fmt: skip


def _yaw(quat) -> float:
    w, x, y, z = quat
    return float(np.arctan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z)))


class CaptureStep:
    """``policy(k, obs)``: the run's policy, its swing foot moved to the capture point."""

    def __init__(self, policy, plant, robot, plan, gain, release, clip, inward, nominal=None,
                 predict=False):  # fmt: skip
        self.policy, self.plant, self.robot = policy, plant, robot
        self.predict = predict
        self.gain, self.clip, self.inward = gain, clip, inward
        self.decay = 0.0 if not np.isfinite(release) else 1.0 / max(release / 0.01, 1.0)
        self.m = robot.compile()
        self.d = mujoco.MjData(self.m)
        names = robot.joint_names
        self.leg_idx = {f: [names.index(j) for j in LEGS[f]] for f in LEGS}
        jid = [self.m.joint(robot.mj_joints[i]).id for i in range(len(names))]
        self.qadr = self.m.jnt_qposadr[jid]
        self.dadr = {f: self.m.jnt_dofadr[[jid[i] for i in self.leg_idx[f]]] for f in LEGS}
        self.site = {f: self.m.site(robot.soles[f]).id for f in LEGS}
        pm = plant.model
        self.psite = {f: pm.site(robot.soles[f]).id for f in LEGS}
        self.up = {f: plan[f + "_sole"][:, 2] > 1e-5 for f in LEGS}  # (M+N,) planned swing
        self.M, self.N = policy.start, policy.n_loop
        self.z = float(np.mean(plan["pelvis_z"]))  # the centre of mass is near the hips
        self.w0 = np.sqrt(9.81 / max(self.z, 0.05))
        self.nominal = nominal  # (T, 2) ξ relative to the stance sole, or None: record it
        self.record = np.full((int(SECONDS * 100) + 5, 2), np.nan)
        self.off = {f: np.zeros(2) for f in LEGS}

    def _row(self, k: int) -> int:
        return k if k < self.M else self.M + (k - self.M) % self.N

    def _xi_rel(self, stance: str) -> np.ndarray:
        m, d = self.plant.model, self.plant.data
        mujoco.mj_subtreeVel(m, d)
        c, v = d.subtree_com[1], d.subtree_linvel[1]
        xi = c[:2] + v[:2] / self.w0
        yaw = _yaw(self.plant.torso_pose()[1])
        rel = xi - d.site_xpos[self.psite[stance]][:2]
        cy, sy = np.cos(yaw), np.sin(yaw)
        return np.array([cy * rel[0] + sy * rel[1], -sy * rel[0] + cy * rel[1]])

    def _joint_offsets(self, q: np.ndarray) -> np.ndarray:
        m, d = self.m, self.d
        d.qpos[:] = 0.0
        d.qpos[3] = 1.0
        d.qpos[self.qadr] = q * self.robot.signs
        mujoco.mj_kinematics(m, d)
        mujoco.mj_comPos(m, d)
        dq = np.zeros(len(q))
        for f in LEGS:
            o = self.off[f]
            if not np.any(o):
                continue
            jp, jr = np.zeros((3, m.nv)), np.zeros((3, m.nv))
            mujoco.mj_jacSite(m, d, jp, jr, self.site[f])
            J = np.vstack([jp, jr])[:, self.dadr[f]]  # (6, 6)
            x = np.linalg.solve(J, np.array([o[0], o[1], 0.0, 0.0, 0.0, 0.0]))
            dq[self.leg_idx[f]] = x * self.robot.signs[self.leg_idx[f]]
        return dq

    def __call__(self, k: int, obs) -> np.ndarray:
        q = self.policy(k, obs)
        k = self.policy.clock.clock if self.policy.clock is not None else k  # reference tick
        row = self._row(min(k, len(self.policy.q_cmd) - 1))
        up = {f: bool(self.up[f][row]) for f in LEGS}
        for f in LEGS:
            stance = "r" if f == "l" else "l"
            if up[f] and not up[stance]:
                xi = self._xi_rel(stance)
                if self.nominal is None:
                    if k < len(self.record):
                        self.record[k] = xi
                    continue
                nom = self.nominal[k] if k < len(self.nominal) else np.nan
                if np.any(np.isnan(nom)):
                    continue
                left = 1
                while row + left < len(self.up[f]) and self.up[f][row + left]:
                    left += 1
                grow = np.exp(self.w0 * left * 0.01) if self.predict else 1.0
                target = self.gain * grow * (xi - nom)  # at the landing, if predicted
                side = 1.0 if f == "l" else -1.0  # +y is outward for the left foot
                lo, hi = (-self.inward, self.clip) if side > 0 else (-self.clip, self.inward)
                target = np.array([np.clip(target[0], -self.clip, self.clip),
                                   np.clip(target[1], lo, hi)])  # fmt: skip
                self.off[f] = self.off[f] + (target - self.off[f]) / left
            elif not up[f]:
                self.off[f] = self.off[f] * (1.0 - self.decay)
        if self.nominal is not None and any(np.any(o) for o in self.off.values()):
            q = q + self._joint_offsets(q)
        return q


def walk(job) -> dict:
    path, seed, options, gain, release, clip, inward, nominal, predict, wait = job
    r = load_run(path)
    robot = load_robot(r.metrics.robot if hasattr(r.metrics, "robot") else "hoap2")
    ref, s = r.ref, r.settings_of("learned")
    wait = s["wait"] if wait is None else wait
    offsets = walk_offsets(ref, robot, r.scale, SECONDS, s["feedforward"])
    pol = TickPolicy(ref, r.scale, r.laws["learned"], robot.joint_names, SECONDS,
                     offsets=offsets, wait=wait)  # fmt: skip
    plant = make_plant(robot, ref.sim_options(options), "mujoco")
    cs = CaptureStep(pol, plant, robot, ref.plan_at(r.scale), gain, release, clip, inward,
                     nominal, predict)  # fmt: skip
    ro = run(plant, cs, len(pol.q_ref))
    m = walk_metrics(ro, ref.expected_distance(r.scale, ro.seconds), pol.q_ref,
                     ref.track(r.scale, ro.seconds))  # fmt: skip
    return {"seed": seed, "fell": bool(m.fell), "t": float(m.seconds),
            "d": float(m.forward_distance_m), "record": cs.record if nominal is None else None}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("run_dir")
    ap.add_argument("--robots", type=int, default=20)
    ap.add_argument("--first", type=int, default=300_000)
    ap.add_argument("--gains", default="0,0.5,1")
    ap.add_argument("--release", default="0.2,inf")
    ap.add_argument("--clip", type=float, default=0.04)
    ap.add_argument("--inward", type=float, default=0.01)
    ap.add_argument("--variants", default="pushes,hard,eval")
    ap.add_argument("--predict", action="store_true", help="the deviation grown to the landing")
    ap.add_argument("--waits", default="", help="the clock's waits tried (default: the run's)")
    a = ap.parse_args()
    r = load_run(a.run_dir)
    robot = load_robot("hoap2")
    base = r.ref.sim_options()
    waits = [float(w) for w in a.waits.split(",")] if a.waits else [None]
    nominal = {w: walk((a.run_dir, 0, base, 0.0, np.inf, a.clip, a.inward, None, False, w))["record"]
               for w in waits}  # fmt: skip
    hard = load_protocol("hard")
    protos = {"pushes": hard.only(("pushes",)), "hard": hard, "eval": load_protocol("eval")}
    out = []
    for v in a.variants.split(","):
        p = protos[v]
        draws = [p.draw(a.first + i, robot, base, SECONDS) for i in range(a.robots)]
        for w, g, rel in [(w, g, rel) for w in waits for g in map(float, a.gains.split(","))
                          for rel in (map(float, a.release.split(",")) if g else [np.inf])]:
            if True:
                jobs = [(a.run_dir, d.seed, d.options, g, rel, a.clip, a.inward, nominal[w],
                         a.predict, w) for d in draws]  # fmt: skip
                res = run_parallel(walk, jobs)
                row = {"variant": v, "wait": w, "gain": g, "release": rel,
                       "falls": sum(x["fell"] for x in res), "robots": len(res),
                       "d": float(np.mean([x["d"] for x in res])),
                       "fall_t": sorted(round(x["t"], 1) for x in res if x["fell"])}  # fmt: skip
                out.append(row)
                print(json.dumps(row), file=sys.stderr, flush=True)
    print(json.dumps(out, indent=1))


if __name__ == "__main__":
    main()
