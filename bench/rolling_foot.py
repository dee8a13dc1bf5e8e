"""A rolling foot (heel strike, toe-off) in the reference's plan: a prototype for G1.

The product's plan keeps every stance sole flat (:mod:`imitwalk.retarget.plan`). This
bench retargets with a foot that rolls: over the double support before its lift-off the
trailing foot pitches nose-down about its toe edge by up to ``--toe`` degrees, through the
swing it turns to ``--heel`` degrees toe-up, and over the double support after it lands
it rolls flat about its heel edge. Both angles are at scale 1.0 and grow with the stride
(× scale × the start-up's envelope). The sole's centre moves as the rotation about the
edge asks, and the whole-body IK takes each sole's pitch as well as its yaw.

``retarget`` patches :func:`imitwalk.retarget.walkable.plan_walk` and ``WalkIK._targets``
for this process only, stores each sole's pitch with the plan (``plan_pitch``), then runs
``imitwalk retarget`` with the remaining arguments. ``walk`` runs ``bench/feedforward.py``
with the servo feedforward taught the rolling foot: a sole is down while its lowest edge
is, and the floating base is turned so that the stance sole has its planned pitch.

Usage: ``python bench/rolling_foot.py retarget --toe 20 --heel 10 -- --robot g1.json
--no-search --set params.sway=0.4 --out R.npz``, then ``python bench/rolling_foot.py walk
R.npz --robot g1.json --scale 0.4 ...`` (``bench/feedforward.py``'s arguments), or
``ROLL_ROBOT=g1.json python bench/rolling_foot.py cli learn --reference R.npz --robot
g1.json --out RUN`` (any ``imitwalk`` command, with the feedforward taught the pitch).
"""

from __future__ import annotations

import argparse
import sys

import numpy as np


def _smooth(x):
    x = np.clip(x, 0.0, 1.0)
    return x * x * x * (x * (6.0 * x - 15.0) + 10.0)


def _ry(th: float) -> np.ndarray:
    c, s = np.cos(th), np.sin(th)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def rolled(plan, geom, params, scale: float, toe: float, heel: float, start: bool):
    """The plan with each sole's centre moved for its pitch; the pitch ``(N, 2)`` [rad]."""
    half = geom.foot_length / 2
    n_cyc = round(plan.period / plan.dt)
    ds = float(np.clip(params.ds, 0.0, 0.45))
    psi, e = plan.phase, plan.envelope
    windows = {0: (0.5 + ds, 1.0), 1: (ds, 0.5)}  # left, right swing windows in phase
    pitch = np.zeros((len(psi), 2))
    soles = [plan.l_sole.copy(), plan.r_sole.copy()]
    k = np.arange(len(psi))
    stepping = k >= (n_cyc if start else 0)
    for j in (0, 1):
        a, b = windows[j]
        yaw = plan.yaw[:, j]
        u = np.stack([np.cos(yaw), np.sin(yaw), np.zeros_like(yaw)], axis=1)
        z = np.array([0.0, 0.0, 1.0])
        amp = scale * e * stepping
        th_off, th_s = np.radians(toe) * amp, np.radians(heel) * amp
        for i in range(len(psi)):
            p = psi[i]
            t_off = ((p - (a - ds)) % 1.0) / ds if ds > 0 else 9.0
            t_land = ((p - b) % 1.0) / ds if ds > 0 else 9.0
            if a <= p < b:  # swing: toe-off angle → heel-strike angle
                w = _smooth((p - a) / (b - a))
                th = th_off[i] * (1 - w) - th_s[i] * w
                d_off = half * (1 - np.cos(th_off[i])) * u[i] + half * np.sin(th_off[i]) * z
                d_on = -half * (1 - np.cos(th_s[i])) * u[i] + half * np.sin(th_s[i]) * z
                d = (1 - w) * d_off + w * d_on
            elif t_off < 1.0:  # toe-off: rotate nose-down about the toe edge
                th = th_off[i] * _smooth(t_off)
                d = half * (1 - np.cos(th)) * u[i] + half * np.sin(th) * z
            elif t_land < 1.0:  # heel strike: toe-up rolled flat about the heel edge
                th = -th_s[i] * (1 - _smooth(t_land))
                d = -half * (1 - np.cos(-th)) * u[i] + half * np.sin(-th) * z
            else:
                continue
            pitch[i, j] = th
            soles[j][i] += d
    return soles, pitch


def _install_walk() -> None:
    """Teach the feedforward (:mod:`imitwalk.retarget.feedforward`) the planned pitch."""
    import mujoco

    import imitwalk.retarget.feedforward as ff
    from imitwalk.retarget.reference import Reference

    state: dict = {}
    planned_load = Reference.planned_load

    def load(self, scale, T):
        down, share = planned_load(self, scale, T)
        plan = self.plan_at(scale)
        if "pitch" not in plan:
            state.pop("pitch", None)
            return down, share
        rows = self.loop_index(np.arange(T))[0]
        pitch = plan["pitch"][rows]
        half = 0.5 * state["foot_length"]
        z = np.stack([plan["l_sole"][rows, 2], plan["r_sole"][rows, 2]], 1)
        down = z - half * np.sin(np.abs(pitch)) <= 1e-4
        yl, yr, yc = plan["l_sole"][rows, 1], plan["r_sole"][rows, 1], plan["com"][rows, 1]
        share = np.clip((yc - yr) / np.maximum(yl - yr, 1e-6), 0.0, 1.0)
        one = np.where(down[:, 1] & ~down[:, 0], 0.0, share)
        state["pitch"] = pitch
        return down, np.where(down[:, 0] & ~down[:, 1], 1.0, one)

    servo_offsets = ff.servo_offsets

    def offsets(robot, q_ref, stance, share, dt):

        if "pitch" not in state:
            return servo_offsets(robot, q_ref, stance, share, dt)
        pitch = state["pitch"]
        original = mujoco.mju_mat2Quat

        def turned(quat, mat):  # the base turned so the stance sole has its planned pitch
            t = min(turned.t, len(pitch) - 1)  # servo_offsets calls this once per tick
            turned.t += 1
            j = 0 if share[t] >= 0.5 else 1
            original(quat, (_ry(pitch[t, j]) @ mat.reshape(3, 3)).ravel())

        turned.t = 0
        mujoco.mju_mat2Quat = turned
        try:
            return servo_offsets(robot, q_ref, stance, share, dt)
        finally:
            mujoco.mju_mat2Quat = original

    Reference.planned_load = load
    ff.servo_offsets = offsets
    state["foot_length"] = None
    return state


def main() -> None:
    if sys.argv[1:2] == ["cli"]:  # any imitwalk command, with the feedforward taught the pitch
        state = _install_walk()
        import os

        from imitwalk.retarget.ik import leg_geometry
        from imitwalk.robots import load_robot

        state["foot_length"] = leg_geometry(load_robot(os.environ["ROLL_ROBOT"])).foot_length
        from imitwalk.cli import main as cli_main

        sys.argv = ["imitwalk", *sys.argv[2:]]
        cli_main()
        return
    if sys.argv[1:2] == ["walk"]:
        state = _install_walk()
        import runpy

        from imitwalk.retarget.ik import leg_geometry
        from imitwalk.robots import load_robot

        robot_arg = sys.argv[sys.argv.index("--robot") + 1]
        state["foot_length"] = leg_geometry(load_robot(robot_arg)).foot_length
        sys.argv = ["feedforward.py", *sys.argv[2:]]
        runpy.run_path(
            str(__import__("pathlib").Path(__file__).with_name("feedforward.py")),
            run_name="__main__",
        )
        return
    sys.argv = [a for a in sys.argv if a != "retarget"]
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--toe", type=float, default=20.0, help="toe-off pitch at scale 1 [deg]")
    ap.add_argument("--heel", type=float, default=10.0, help="heel-strike pitch at scale 1 [deg]")
    ap.add_argument("--start-cycles", type=int, default=None, help="start-up cycles (plan's 3)")
    args, rest = ap.parse_known_args()
    rest = [r for r in rest if r != "--"]

    import dataclasses

    import mink

    import imitwalk.retarget.ik as ik
    import imitwalk.retarget.plan as plan_module
    import imitwalk.retarget.walkable as walkable

    if args.start_cycles:
        plan_module.START_CYCLES = args.start_cycles
    from imitwalk.retarget.plan import plan_walk

    def patched_plan(template, geom, params, scale, dt, cycles=1, start=False, **kw):
        plan = plan_walk(template, geom, params, scale, dt, cycles=cycles, start=start, **kw)
        soles, pitch = rolled(
            plan, geom, params.for_leg(geom.leg), scale, args.toe, args.heel, start
        )
        out = dataclasses.replace(plan, l_sole=soles[0], r_sole=soles[1])
        object.__setattr__(out, "foot_pitch", pitch)
        return out

    original = ik.WalkIK._targets

    def patched_targets(self, plan, i, base):
        original(self, plan, i, base)
        fp = getattr(plan, "foot_pitch", None)
        if fp is None:
            return
        yaw = np.zeros(2) if plan.yaw is None else plan.yaw[i]
        for k, (s, sole) in enumerate((("l", plan.l_sole), ("r", plan.r_sole))):
            pose = np.eye(4)
            pose[:3, :3] = ik._rz(yaw[k]) @ _ry(fp[i, k]) @ self._sole_rot[s]
            pose[:3, 3] = sole[i]
            self.tasks[s].set_target(mink.SE3.from_matrix(pose))

    arrays = walkable.plan_arrays

    def with_pitch(plan):
        return {
            **arrays(plan),
            "pitch": getattr(plan, "foot_pitch", np.zeros((len(plan.phase), 2))),
        }

    walkable.plan_walk = patched_plan
    walkable.plan_arrays = with_pitch
    walkable.PLAN_KEYS = (*walkable.PLAN_KEYS, "pitch")
    ik.WalkIK._targets = patched_targets
    from imitwalk.cli import main as cli_main

    sys.argv = ["imitwalk", "retarget", *rest]
    cli_main()


if __name__ == "__main__":
    main()
