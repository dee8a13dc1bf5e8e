"""A lead, not a product option: the sideways centre of mass closed every tick, with a run's laws.

On G1 this law made the body follow its first weight shift (docs/RESULTS.md, "Other
robots"). hoap2's grippy-floor start-up falls look alike: the start-up rocks the robot onto
one sole's edge before the plan lifts a foot (docs/RESULTS.md, "The hard robots"). This
bench adds the law to a run's controller and walks validation robots of protocol
variants (seeds from ``--first``; neither training nor evaluation robots):

- **Measured:** the centre of mass relative to the middle of the soles, from forward
  kinematics of the *encoders* on the nominal model, turned into the gravity frame by
  the torso's tilt from a complementary filter (gyro + accelerometer, τ 2 s); its planned
  value is the same on the reference's posture, feet flat. ``e`` [m] is measured −
  planned, sideways, and ``ė`` [m/s] its first difference low-passed over 30 ms.
- **Action:** ``Δ = kp·e + kd·ė`` [m], clipped to ±``--clip``, moves the pelvis sideways
  over the soles on both hip and ankle rolls (torso and soles keep their tilt; a Jacobian
  solved once on the first posture). With ``--double-only`` it acts only while the plan
  has both feet down, with ``--startup-only`` only in the reference's start-up.

Usage: ``python bench/sway_feedback.py RUN [--controller learned] [--robots 40]
[--first 300000] [--seconds 30] [--variants friction,nokicks,eval] [--laws '0,0;-1,-0.1']
[--double-only] [--startup-only]``; prints one JSON line per (variant, law), then a summary.
"""

from __future__ import annotations

import argparse
import json

import mujoco
import numpy as np

from imitwalk.balance.estimator import StateEstimator
from imitwalk.balance.feedback import TickPolicy
from imitwalk.judge.protocol import load_protocol
from imitwalk.judge.replay import OPEN_LOOP, load_run
from imitwalk.parallel import run_parallel
from imitwalk.retarget import Reference
from imitwalk.robots import load_robot

ROLLS = ("l_hip_roll", "r_hip_roll", "l_ankle_roll", "r_ankle_roll")


class Kinematics:
    """Forward kinematics of the nominal model from canonical joint angles."""

    def __init__(self, robot):
        self.r, self.m = robot, robot.compile()
        self.d = mujoco.MjData(self.m)
        self.qadr = self.m.jnt_qposadr[[self.m.joint(j).id for j in robot.mj_joints]]
        self.torso = self.m.body(robot.torso).id
        self.soles = [self.m.site(robot.soles[s]).id for s in ("l", "r")]

    def pose(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Centre of mass less the soles' middle [m], torso and left-sole rotations."""
        m, d = self.m, self.d
        d.qpos[:] = self.r.stand_qpos
        d.qpos[:3], d.qpos[3:7] = 0.0, (1, 0, 0, 0)
        d.qpos[self.qadr] = q * self.r.signs
        mujoco.mj_kinematics(m, d)
        mujoco.mj_comPos(m, d)
        com = d.subtree_com[0] - d.site_xpos[self.soles].mean(axis=0)
        return (
            com,
            d.xmat[self.torso].reshape(3, 3).copy(),
            d.site_xmat[self.soles[0]].reshape(3, 3).copy(),
        )

    def features(self, q: np.ndarray) -> np.ndarray:
        """(com_y, right sole roll, torso roll), in the left sole's frame."""
        com, tor, left = self.pose(q)
        right = left.T @ self.d.site_xmat[self.soles[1]].reshape(3, 3)
        tor = left.T @ tor
        return np.array(
            [
                (left.T @ com)[1],
                np.arctan2(right[2, 1], right[2, 2]),
                np.arctan2(tor[2, 1], tor[2, 2]),
            ]
        )

    def shift_direction(self, q0: np.ndarray) -> np.ndarray:
        """``(n,)`` joint change per metre of sideways pelvis shift [rad/m] (least norm)."""
        idx = [self.r.joint_names.index(j) for j in ROLLS]
        f0, J = self.features(q0), np.zeros((3, 4))
        for i, j in enumerate(idx):
            dq = q0.copy()
            dq[j] += 1e-4
            J[:, i] = (self.features(dq) - f0) / 1e-4
        out = np.zeros(len(q0))
        out[idx] = np.linalg.lstsq(J, np.array([1.0, 0.0, 0.0]), rcond=None)[0]
        return out


def _rot(roll: float, pitch: float) -> np.ndarray:
    cr, sr, cp, sp = np.cos(roll), np.sin(roll), np.cos(pitch), np.sin(pitch)
    return np.array([[cp, 0, sp], [0, 1, 0], [-sp, 0, cp]]) @ np.array(
        [[1, 0, 0], [0, cr, -sr], [0, sr, cr]]
    )


class SwayPolicy:
    """A run's :class:`TickPolicy` plus the sideways centre-of-mass law."""

    def __init__(self, ref, scale, laws, robot, seconds, kp, kd, clip, double_only, startup_only):
        self.inner = TickPolicy(ref, scale, laws, robot.joint_names, seconds)
        self.kin, self.kp, self.kd, self.clip = Kinematics(robot), kp, kd, clip
        self.u = self.kin.shift_direction(self.inner.q0)
        self.est = StateEstimator(ref.dt, tau=2.0)
        self.a, self.dt = ref.dt / (ref.dt + 0.03), ref.dt
        plan = ref.plan_at(scale)
        self.lifted = (np.stack([plan["l_sole"][:, 2], plan["r_sole"][:, 2]], 1) > 1e-4).any(1)
        self.double_only, self.startup_only = double_only, startup_only
        self.e_prev = self.rate = 0.0

    @property
    def q0(self) -> np.ndarray:
        return self.inner.q0

    def __call__(self, k: int, obs) -> np.ndarray:
        q = self.inner(k, obs)
        s = self.est.update(obs.gyro, obs.accel, obs.foot_force)
        plan_q = self.inner.q_ref[min(k, len(self.inner.q_ref) - 1)]
        com, tor, _ = self.kin.pose(obs.joints)
        meas = (_rot(s.roll, s.pitch) @ tor.T @ com)[1]
        com, _, left = self.kin.pose(plan_q)
        e = float(meas - (left.T @ com)[1])
        self.rate = (1 - self.a) * self.rate + self.a * (e - self.e_prev) / self.dt
        self.e_prev = e
        n0, nl = self.inner.start, self.inner.n_loop
        if self.startup_only and k >= n0:
            return q
        if self.double_only:
            i = k if k < n0 else n0 + (k - n0) % nl
            if self.lifted[min(i, len(self.lifted) - 1)]:
                return q
        return q + float(np.clip(self.kp * e + self.kd * self.rate, -self.clip, self.clip)) * self.u


def _walk(job) -> tuple[bool, float | None]:
    path, robot_name, scale, laws, options, seconds, kp, kd, clip, double_only, startup_only = job
    from imitwalk.sim.mujoco import make_plant, run

    ref, robot = Reference.load(path), load_robot(robot_name)
    policy = SwayPolicy(ref, scale, laws, robot, seconds, kp, kd, clip, double_only, startup_only)
    ro = run(make_plant(robot, ref.sim_options(options)), policy, len(policy.inner.q_ref))
    return bool(ro.fell), ro.fall_time


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("run_dir")
    ap.add_argument("--robot", default="hoap2")
    ap.add_argument("--controller", default="learned")
    ap.add_argument("--robots", type=int, default=40)
    ap.add_argument("--first", type=int, default=300_000)
    ap.add_argument("--seconds", type=float, default=30.0)
    ap.add_argument("--variants", default="friction,nokicks,eval")
    ap.add_argument("--laws", default="0,0;-1,-0.1", help="kp,kd pairs, ';'-separated")
    ap.add_argument("--clip", type=float, default=0.02, help="largest shift [m]")
    ap.add_argument("--double-only", action="store_true")
    ap.add_argument("--startup-only", action="store_true", help="act in the start-up alone")
    args = ap.parse_args()
    run, robot = load_run(args.run_dir), load_robot(args.robot)
    laws = () if args.controller == OPEN_LOOP else tuple(run.laws[args.controller])
    hard = load_protocol("hard")
    protos = {
        "friction": hard.only(("friction",)),
        "nokicks": hard.only(tuple(f for f in hard.factors if f != "pushes")),
        "hard": hard,
        "eval": load_protocol("eval"),
    }
    summary = {}
    for name in args.variants.split(","):
        p = protos[name]
        draws = [p.draw(args.first + s, robot, run.ref.sim_options(), args.seconds)
                 for s in range(args.robots)]  # fmt: skip
        for law in args.laws.split(";"):
            kp, kd = (float(x) for x in law.split(","))
            jobs = [(run.path + "/reference.npz", args.robot, run.scale, laws, d.options,
                     args.seconds, kp, kd, args.clip, args.double_only, args.startup_only)
                    for d in draws]  # fmt: skip
            res = run_parallel(_walk, jobs)
            times = sorted(round(t, 2) for f, t in res if f)
            row = {"variant": name, "kp": kp, "kd": kd, "falls": len(times), "fall_times_s": times}
            summary[f"{name} {law}"] = len(times)
            print(json.dumps(row), flush=True)
    print(json.dumps({"run": args.run_dir, "clip_m": args.clip, "double_only": args.double_only,
                      "startup_only": args.startup_only, "falls": summary}))  # fmt: skip


if __name__ == "__main__":
    main()
