"""A lead, not a product option: each step's width placed by the measured capture point.

On G1 and on hoap2's grippy floors the sideways sway grows from step to step in single
support until the body leaves over the stance foot's outer edge (docs/RESULTS.md, "Other
robots" and "The hard robots"). A linear inverted pendulum stepping at a fixed width and
a fixed time is unstable sideways (its step-to-step map has an eigenvalue e^{ω T}); what
stabilises it is where the next foot lands. This bench places it:

- **Measured** (sensors only): the centre of mass relative to the *stance* sole, from
  forward kinematics of the encoders on the nominal model, turned into the gravity frame
  by the complementary filter's tilt (τ 2 s), sideways; its rate is the first difference
  low-passed over 30 ms. The capture point is ``ξ = y + ẏ/ω₀``, ``ω₀ = √(g/z)`` with ``z``
  the standing centre of mass height. The plan's ``ξ`` comes from the same computation on
  the reference's postures, feet flat.
- **Action:** while the plan has one foot up, that foot's sideways offset from the pelvis
  [m] moves (low-passed over a quarter of the swing) to ``o_stance + k·(ξ − ξ_plan)``,
  clipped to ±``--clip``: the stance foot's own offset (so the step's width, not the
  pelvis, changes) plus the capture-point error. Each leg holds its offset while its foot
  is down. The offset is made on that leg's hip and ankle rolls, the sole kept flat (a
  Jacobian solved once on the first posture).
- Optionally ``--shift kp,kd``: the pelvis shift of ``git show 071df11:bench/sway_feedback.py``
  while both feet are down (G1's start-up needs it).

A law is ``k``. With a reference (``.npz``) instead of a run, the reference is walked open
loop at ``--scale`` on training robots (variant ``train``). Prints one JSON line per
(variant, law): falls, their times, the mean distance [m] (ground truth, for the figure
only), the mean and largest |offset| [m]; then a summary.

Usage: ``python bench/step_width.py RUN [--controller learned] [--robots 40] [--first
300000] [--seconds 30] [--variants friction,nokicks,eval] [--laws 0,0.5,1]``, or ``python
bench/step_width.py REF.npz --robot g1.json --scale 0.3 --robots 4 --seconds 10
--variants train --clip 0.06 --shift=-2,-0.1 --laws 0,1``.
"""

from __future__ import annotations

import argparse
import json

import mujoco
import numpy as np

from imitwalk.balance.estimator import StateEstimator
from imitwalk.balance.feedback import FeedbackLaw, TickPolicy
from imitwalk.judge.protocol import load_protocol
from imitwalk.judge.replay import OPEN_LOOP, load_run
from imitwalk.parallel import run_parallel
from imitwalk.retarget import Reference
from imitwalk.robots import load_robot
from imitwalk.sim.perturb import perturbed, train_seeds

ROLLS = ("l_hip_roll", "r_hip_roll", "l_ankle_roll", "r_ankle_roll")
SIDES = ("l", "r")


class Kinematics:
    """Forward kinematics of the nominal model from canonical joint angles (base frame)."""

    def __init__(self, robot):
        self.r, self.m = robot, robot.compile()
        self.d = mujoco.MjData(self.m)
        self.qadr = self.m.jnt_qposadr[[self.m.joint(j).id for j in robot.mj_joints]]
        self.torso = self.m.body(robot.torso).id
        self.soles = [self.m.site(robot.soles[s]).id for s in SIDES]

    def pose(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Centre of mass [m], sole positions ``(2, 3)`` [m], torso and left-sole rotations."""
        m, d = self.m, self.d
        d.qpos[:] = self.r.stand_qpos
        d.qpos[:3], d.qpos[3:7] = 0.0, (1, 0, 0, 0)
        d.qpos[self.qadr] = q * self.r.signs
        mujoco.mj_kinematics(m, d)
        mujoco.mj_comPos(m, d)
        return (
            d.subtree_com[0].copy(),
            d.site_xpos[self.soles].copy(),
            d.xmat[self.torso].reshape(3, 3).copy(),
            d.site_xmat[self.soles[0]].reshape(3, 3).copy(),
        )

    def leg_direction(self, q0: np.ndarray, side: int) -> np.ndarray:
        """``(n,)`` joint change per metre of sideways sole offset from the pelvis, sole flat."""
        idx = [self.r.joint_names.index(f"{SIDES[side]}_{j}") for j in ("hip_roll", "ankle_roll")]

        def feat(q):
            self.pose(q)
            R = self.d.site_xmat[self.soles[side]].reshape(3, 3)
            return np.array([self.d.site_xpos[self.soles[side]][1], np.arctan2(R[2, 1], R[2, 2])])

        f0, J = feat(q0), np.zeros((2, 2))
        for c, j in enumerate(idx):
            dq = q0.copy()
            dq[j] += 1e-4
            J[:, c] = (feat(dq) - f0) / 1e-4
        out = np.zeros(len(q0))
        out[idx] = np.linalg.solve(J, np.array([1.0, 0.0]))
        return out

    def shift_direction(self, q0: np.ndarray) -> np.ndarray:
        """``(n,)`` joint change per metre of sideways pelvis shift over the soles [rad/m]."""
        idx = [self.r.joint_names.index(j) for j in ROLLS]

        def feat(q):
            com, soles, tor, left = self.pose(q)
            right = left.T @ self.d.site_xmat[self.soles[1]].reshape(3, 3)
            t = left.T @ tor
            y = (left.T @ (com - soles.mean(axis=0)))[1]
            return np.array([y, np.arctan2(right[2, 1], right[2, 2]), np.arctan2(t[2, 1], t[2, 2])])

        f0, J = feat(q0), np.zeros((3, 4))
        for i, j in enumerate(idx):
            dq = q0.copy()
            dq[j] += 1e-4
            J[:, i] = (feat(dq) - f0) / 1e-4
        out = np.zeros(len(q0))
        out[idx] = np.linalg.lstsq(J, np.array([1.0, 0.0, 0.0]), rcond=None)[0]
        return out


def _rot(roll: float, pitch: float) -> np.ndarray:
    cr, sr, cp, sp = np.cos(roll), np.sin(roll), np.cos(pitch), np.sin(pitch)
    return np.array([[cp, 0, sp], [0, 1, 0], [-sp, 0, cp]]) @ np.array(
        [[1, 0, 0], [0, cr, -sr], [0, sr, cr]]
    )


class StepPolicy:
    """A run's :class:`TickPolicy` plus capture-point step width (and the optional shift)."""

    def __init__(self, ref, scale, laws, robot, seconds, k, clip, shift):
        self.inner = TickPolicy(ref, scale, laws, robot.joint_names, seconds)
        self.kin, self.k, self.clip, (self.kp, self.kd) = Kinematics(robot), k, clip, shift
        q0 = self.inner.q0
        self.dirs = [self.kin.leg_direction(q0, s) for s in (0, 1)]
        self.u = self.kin.shift_direction(q0)
        com, soles, _, _ = self.kin.pose(q0)
        self.w0 = float(np.sqrt(9.81 / (com[2] - soles[:, 2].mean())))
        self.est = StateEstimator(ref.dt, tau=2.0)
        self.dt, self.a = ref.dt, ref.dt / (ref.dt + 0.03)
        plan_y = []  # (T, 3): the plan's com less the left, the right sole and their middle
        for q in self.inner.q_ref:
            com, soles, _, left = self.kin.pose(q)
            rel = np.vstack([com - soles, com - soles.mean(axis=0)])
            plan_y.append((rel @ left)[:, 1])  # left.T @ v for each row
        self.y_plan = np.array(plan_y)
        self.xi_plan = self.y_plan + np.gradient(self.y_plan, ref.dt, axis=0) / self.w0
        plan = ref.plan_at(scale)
        self.lifted = np.stack([plan["l_sole"][:, 2], plan["r_sole"][:, 2]], 1) > 1e-4
        swing = self.lifted[ref.starts.shape[1] :, 0].sum() * ref.dt  # one swing [s]
        self.b = ref.dt / (ref.dt + max(swing, 0.04) / 4)
        self.off = np.zeros(2)  # each leg's sideways offset from the pelvis [m]
        self.y_prev: np.ndarray | None = None
        self.rate = np.zeros(3)
        self.e_prev = self.e_rate = 0.0
        self.offsets: list[float] = []

    @property
    def q0(self) -> np.ndarray:
        return self.inner.q0

    def __call__(self, k: int, obs) -> np.ndarray:
        s = self.est.update(obs.gyro, obs.accel, obs.foot_force)
        com, soles, tor, _ = self.kin.pose(obs.joints)
        g = _rot(s.roll, s.pitch) @ tor.T  # base frame → gravity frame
        rel = np.vstack([com - soles, com - soles.mean(axis=0)])
        y = (rel @ g.T)[:, 1]  # (3,) measured: com less the left, right sole, middle [m]
        self.y_prev = y if self.y_prev is None else self.y_prev
        self.rate = (1 - self.a) * self.rate + self.a * (y - self.y_prev) / self.dt
        self.y_prev = y
        i = min(k, len(self.y_plan) - 1)
        n0, nl = self.inner.start, self.inner.n_loop
        up = self.lifted[min(i if i < n0 else n0 + (i - n0) % nl, len(self.lifted) - 1)]
        q = self.inner(i, obs)
        if up.sum() == 1:  # single support: place the swing foot
            st, sw = (1, 0) if up[0] else (0, 1)
            err = (y[st] + self.rate[st] / self.w0) - self.xi_plan[i, st]
            target = float(np.clip(self.off[st] + self.k * err, -self.clip, self.clip))
            self.off[sw] += self.b * (target - self.off[sw])
            self.offsets.append(abs(self.off[sw]))
        e = y[2] - self.y_plan[i, 2]
        self.e_rate = (1 - self.a) * self.e_rate + self.a * (e - self.e_prev) / self.dt
        self.e_prev = e
        q = q + self.off[0] * self.dirs[0] + self.off[1] * self.dirs[1]
        if not up.any() and (self.kp or self.kd):
            q = q + float(np.clip(self.kp * e + self.kd * self.e_rate, -0.04, 0.04)) * self.u
        return q


def _walk(job) -> tuple[bool, float | None, float, float, float]:
    path, robot_name, scale, laws, options, seconds, k, clip, shift = job
    from imitwalk.sim.mujoco import make_plant, run

    ref, robot = Reference.load(path), load_robot(robot_name)
    policy = StepPolicy(ref, scale, laws, robot, seconds, k, clip, shift)
    ro = run(make_plant(robot, ref.sim_options(options)), policy, round(seconds / ref.dt))
    distance = float(ro.torso_pos[-1, 0] - ro.torso_pos[0, 0]) if len(ro.t) else 0.0
    o = policy.offsets or [0.0]
    return bool(ro.fell), ro.fall_time, distance, float(np.mean(o)), float(np.max(o))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("source", help="a per-tick run folder, or a reference (.npz)")
    ap.add_argument("--robot", default="hoap2")
    ap.add_argument("--controller", default="learned")
    ap.add_argument("--scale", type=float, default=0.3, help="with a reference")
    ap.add_argument("--robots", type=int, default=40)
    ap.add_argument("--first", type=int, default=300_000)
    ap.add_argument("--seconds", type=float, default=30.0)
    ap.add_argument("--variants", default="friction,nokicks,eval")
    ap.add_argument("--laws", default="0,1", help="capture-point gains k, comma-separated")
    ap.add_argument("--clip", type=float, default=0.03, help="largest offset per leg [m]")
    ap.add_argument("--shift", default="0,0", help="kp,kd of the feet-down pelvis shift")
    ap.add_argument("--gains", default=None, help="with a reference: pitch,roll,heading gains")
    args = ap.parse_args()
    robot = load_robot(args.robot)
    shift = tuple(float(x) for x in args.shift.split(","))
    if args.source.endswith(".npz"):
        path, ref, scale, laws = args.source, Reference.load(args.source), args.scale, ()
        if args.gains:  # channel:feature=gain items, e.g. ankle_pitch:gyro_y=0.05
            items = [x.split("=") for x in args.gains.split(",")]
            pairs = [tuple(k.split(":")) for k, _ in items]
            law = FeedbackLaw.zero(
                tuple(dict.fromkeys(c for c, _ in pairs)),
                tuple(dict.fromkeys(f for _, f in pairs)),
                0.15,
            )
            for (c, f), (_, v) in zip(pairs, items, strict=True):
                law = law.with_gain(c, f, float(v))
            laws = (law,)
    else:
        run = load_run(args.source)
        path, ref, scale = run.path + "/reference.npz", run.ref, run.scale
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
        if name == "train":
            options = [perturbed(s, ref.sim_options()) for s in train_seeds(args.robots)]
        else:
            p = protos[name]
            options = [p.draw(args.first + s, robot, ref.sim_options(), args.seconds).options
                       for s in range(args.robots)]  # fmt: skip
        for text in args.laws.split(","):
            jobs = [(path, args.robot, scale, laws, o, args.seconds, float(text), args.clip, shift)
                    for o in options]  # fmt: skip
            res = run_parallel(_walk, jobs)
            times = sorted(round(t, 2) for f, t, *_ in res if f)
            row = {
                "variant": name,
                "k": float(text),
                "falls": len(times),
                "fall_times_s": times,
                "distance_m": round(float(np.mean([r[2] for r in res])), 2),
                "offset_mean_m": round(float(np.mean([r[3] for r in res])), 4),
                "offset_max_m": round(float(np.max([r[4] for r in res])), 4),
            }
            summary[f"{name} {text}"] = len(times)
            print(json.dumps(row), flush=True)
    print(json.dumps({"source": args.source, "clip_m": args.clip, "shift": shift,
                      "falls": summary}))  # fmt: skip


if __name__ == "__main__":
    main()
