"""A one-off diagnosis (committed, cited by its SHA, then deleted): how well the linear
inverted pendulum (LIPM) that the stepping gait's planner steps by predicts hoap2's DCM,
and what happens when it steps more by it.

``python bench/diag_step_map.py walk MODE FIRST [E0]``: 40 ``hard`` robots from seed FIRST,
the default clip, the shipped gains, 30 s; MODE ``est`` (the controller's own estimate),
``oracle`` (the simulator's true centre of mass and velocity in its place), ``oracle30``
(the true velocity low-passed over 30 ms). E0 [m]: the part of each step's offset
error beyond E0 is stepped in full (the planner's blend of nominal and DCM-led step
keeps the rest); prints the falls.

``python bench/diag_step_map.py predict PROTOCOL FIRST N``: N robots' single supports
(from the third step on); the DCM at touchdown predicted from the one at lift-off by the
LIPM (driven tick by tick by the commanded pendulum's ZMP, by that plus the ankles'
share, or by the measured centre of pressure), held (persistence), or by a linear map
fitted on every other step (the DCM at lift-off, the same ZMP integral, e^{ωT} times the
DCM, T, 1; a right stance mirrored); prints each one's RMS error [mm] per axis.
"""

from __future__ import annotations

import sys
from dataclasses import replace
from multiprocessing import Pool

import mujoco
import numpy as np

import imitwalk.step.controller as controller_module
import imitwalk.step.planner as planner
from imitwalk.mocap import default_clip, load_motion
from imitwalk.robots import load_robot
from imitwalk.sim.mujoco import MujocoPlant
from imitwalk.sim.protocol import load_protocol
from imitwalk.step.controller import SteppingController
from imitwalk.step.gains import StepGains
from imitwalk.step.kinematics import rot_z
from imitwalk.step.pipeline import gait_from_motion

ROBOT = load_robot("hoap2")
GAIT = gait_from_motion(load_motion(default_clip()), ROBOT)
E0 = float(sys.argv[4]) if sys.argv[1] == "walk" and len(sys.argv) > 4 else None


def plan_step_e0(xi, side, gait, limits, weights, *, elapsed, zmp_now, swing_at,
                 nominal_step, offset, zmp_box, grid=24, sweeps=6):  # fmt: skip
    """planner.plan_step with the offset error beyond E0 stepped in full."""
    _, _, toe = gait.zmp_points(side)
    lo = max(limits.ss_min - elapsed, 0.01)
    left = np.linspace(lo, max(limits.ss_max - elapsed, lo), grid)
    xi_end = planner.dcm_after(xi, zmp_now, toe, left, gait.omega)
    ss = elapsed + left
    y_lo, y_hi = (limits.inner, limits.outer) if -side > 0 else (-limits.outer, -limits.inner)
    reach = limits.swing_speed * left[:, None]
    box_lo = np.maximum(np.array([-limits.backward, y_lo]), swing_at - reach)
    box_hi = np.maximum(np.minimum(np.array([limits.forward, y_hi]), swing_at + reach), box_lo)
    ws, wo, wz = weights.step, weights.offset, weights.zmp
    gain = 1.0 - np.exp(gait.omega * left)[:, None]
    delta, u = np.zeros_like(xi_end), np.clip(nominal_step, box_lo, box_hi)
    for _ in range(sweeps):
        delta = np.clip(-wo * (xi_end - u - offset) / ((wz + wo) * gain), *zmp_box)
        e = xi_end + gain * delta - offset - nominal_step
        a = wo / (ws + wo)
        big = np.sign(e) * np.maximum(np.abs(e) - E0, 0.0)
        u = np.clip(nominal_step + a * e + (1 - a) * big, box_lo, box_hi)
    end = xi_end + gain * delta
    err = end - u - offset
    cost = (wz * np.sum((gain * delta) ** 2, 1) + ws * np.sum((u - nominal_step) ** 2, 1)
            + wo * np.sum(err**2, 1) + weights.time * (ss - gait.ss) ** 2)  # fmt: skip
    k = int(np.argmin(cost))
    return planner.StepChoice(u[k], float(left[k]), float(ss[k]), end[k], err[k], delta[k])


if E0 is not None:
    controller_module.plan_step = plan_step_e0


def walk(mode: str, seed: int) -> bool:
    draw = load_protocol("hard").draw(seed, ROBOT, seconds=30)
    ctrl = SteppingController(ROBOT, GAIT.style, StepGains(), 0.01)
    plant = MujocoPlant(ROBOT, draw.options)
    m, d = plant.model, plant.data
    sole = {s: m.site(ROBOT.soles[s]).id for s in "lr"}
    obs = plant.reset(ctrl.q0)
    for k in range(3000):
        if k == 1 and mode != "est":
            est, estimate = ctrl.est, ctrl.est.update

            def truth(o, hint, est=est, estimate=estimate):
                e = estimate(o, hint)
                mujoco.mj_subtreeVel(m, d)  # divided by the nominal mass: rescaled
                rot = d.site_xmat[sole[est.stance]].reshape(3, 3)
                turn = rot_z(-np.arctan2(rot[1, 0], rot[0, 0]))[:2, :2]
                c = turn @ (plant.com()[:2] - d.site_xpos[sole[est.stance]][:2])
                v = turn @ (d.subtree_linvel[1][:2] * m.body_subtreemass[1] / plant.mass)
                if mode == "oracle30" and getattr(est, "vf", None) is not None:
                    v = est.vf + 0.25 * (v - est.vf)  # 10 ms of 40: a 30 ms time constant
                est.vf = v
                est._x = np.stack([c, v], axis=1)
                com = np.array([c[0], c[1], e.com[2]])
                return replace(e, com=com, com_vel=v, dcm=c + v / ctrl.omega)

            est.update = truth
        plant.command(ctrl(k, obs))
        obs = plant.step()
        if plant.fell:
            return True
    return False


def segments(seed: int, protocol: str) -> list[tuple]:
    """Each tick of a walk: (steps, single, stance, DCM, pendulum ZMP, + ankles, CoP)."""
    draw = load_protocol(protocol).draw(seed, ROBOT, seconds=30)
    ctrl = SteppingController(ROBOT, GAIT.style, StepGains(), 0.01)
    plant = MujocoPlant(ROBOT, draw.options)
    seen = {}
    update = ctrl_update = None

    def keep(obs, hint):
        seen["e"] = update(obs, hint)
        return seen["e"]

    obs = plant.reset(ctrl.q0)
    rows = []
    for k in range(3000):
        q = ctrl(k, obs)
        if k == 0:
            update, ctrl_update = ctrl.est.update, True
            ctrl.est.update = keep
        elif ctrl_update:
            e = seen["e"]
            cop = e.cop if e.cop is not None else np.full(2, np.nan)
            rows.append((ctrl.steps, ctrl.single, ctrl.stance, e.dcm.copy(), ctrl.zmp.copy(),
                         ctrl.zmp + ctrl.ankle_zmp, np.asarray(cop, float)))  # fmt: skip
        plant.command(q)
        obs = plant.step()
        if plant.fell:
            break
    return [(ctrl.omega, rows)]


def predict(runs: list) -> None:
    err: dict[str, list] = {"pendulum ZMP": [], "+ ankles": [], "measured CoP": [], "held": []}
    feats, targ = [], []
    for omega, rows in runs:
        a = np.exp(omega * 0.01)
        steps: dict[int, list[int]] = {}
        for i, r in enumerate(rows):
            if r[1]:
                steps.setdefault(r[0], []).append(i)
        for s, idx in steps.items():
            idx = idx[1:-1]  # the switching ticks log the new stance with the old frame
            if len(idx) < 15 or s < 3:
                continue
            sg = np.array([1.0, 1.0 if rows[idx[0]][2] == "l" else -1.0])
            xi = np.array([rows[i][3] for i in idx]) * sg
            zmps = [np.array([rows[i][c] for i in idx]) * sg for c in (4, 5, 6)]
            if np.isnan(zmps[2]).any():
                continue
            for name, p in zip(list(err)[:3], zmps, strict=True):
                x = xi[0].copy()
                for j in range(len(idx) - 1):
                    x = p[j] + (x - p[j]) * a
                err[name].append(x - xi[-1])
            err["held"].append(xi[0] - xi[-1])
            n = len(idx) - 1
            w = (1 - a) * a ** (n - 1 - np.arange(n))
            feats.append(np.r_[xi[0], w @ zmps[1][:-1], a**n * xi[0], n * 0.01, 1.0])
            targ.append(xi[-1])
    for name, v in err.items():
        print(
            f"LIPM, {name}" if name != "held" else "held", np.sqrt(np.mean(np.square(v), 0)) * 1e3
        )
    f, t = np.array(feats), np.array(targ)
    fit = np.arange(len(f)) % 2 == 0
    for ax in (0, 1):
        x = f[:, [ax, 2 + ax, 4 + ax, 6, 7]]
        c, *_ = np.linalg.lstsq(x[fit], t[fit, ax], rcond=None)
        e = x[~fit] @ c - t[~fit, ax]
        print("learned linear map, axis", "xy"[ax], np.sqrt(np.mean(e**2)) * 1e3, len(e))


if __name__ == "__main__":
    if sys.argv[1] == "walk":
        first = int(sys.argv[3])
        with Pool(2) as pool:
            fell = pool.starmap(walk, [(sys.argv[2], s) for s in range(first, first + 40)])
        print(sys.argv[2], "E0", E0, sum(fell), "of 40 fell")
    else:
        prot, first, n = sys.argv[2], int(sys.argv[3]), int(sys.argv[4])
        with Pool(2) as pool:
            runs = pool.starmap(segments, [(s, prot) for s in range(first, first + n)])
        predict([r for rs in runs for r in rs])
