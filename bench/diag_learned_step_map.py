"""A one-off prototype (committed, cited by its SHA, then deleted): the step planner's DCM
at touchdown from a linear map learned on the robot's own steps (the paper's
sensory-motor model at the step level, issue 58 part 5) in place of the LIPM's
closed form; hoap2, the default clip.

``python d.py collect PROTOCOL FIRST N OUT.pkl [MAP.pkl]``: N robots walk 30 s (the
shipped gains, or ``G=name=value,...``); every planner tick of each single support from
the third step on is kept with the DCM measured at its touchdown.
``python d.py fit TRAIN.pkl TEST.pkl MAP.pkl``: least squares per axis (a right stance
mirrored) of the DCM at touchdown on [DCM, planned ZMP, each × the time left, the time
left and its square, the time elapsed, 1]; prints the LIPM's and the map's RMS errors.
``python d.py offset S.pkl``: the DCM's offset from the landing foot at touchdown,
measured and the planner's.
``python d.py walk PROTOCOL FIRST N MAP.pkl|none``: falls in 30 s with the map in the
planner (``OFIX=dx,dy``: the nominal offset moved to the measured one; ``ZMP=none``: no
ZMP shift).
``python d.py learn OUT [learn_gains options]``: ``bench/learn_gains.py``'s CMA-ES with
the map in the planner (``MAPF=MAP.pkl``).
"""

import os
import pickle
import sys
from multiprocessing import Pool

import numpy as np

import imitwalk.step.controller as cm
import imitwalk.step.planner as planner
from imitwalk.mocap import default_clip, load_motion
from imitwalk.robots import load_robot
from imitwalk.sim.mujoco import MujocoPlant
from imitwalk.sim.protocol import load_protocol
from imitwalk.step.controller import SteppingController
from imitwalk.step.gains import StepGains
from imitwalk.step.pipeline import gait_from_motion

ROBOT = load_robot("hoap2")
GAIT = gait_from_motion(load_motion(default_clip()), ROBOT)
ORIG = planner.plan_step
MAP = None  # (2, F) coefficients per axis
ZMP = os.environ.get("ZMP", "keep")
OFIX = np.array([float(v) for v in os.environ.get("OFIX", "0,0").split(",")])  # keep | none
GAINS = StepGains(
    **{k: float(v) for k, v in (kv.split("=") for kv in os.environ.get("G", "").split(",") if kv)}
)


def feats(xi, zmp, left, elapsed):
    """(G, F) per axis: xi, zmp scalars; left (G,)."""
    one = np.ones_like(left)
    return np.stack(
        [xi * one, zmp * one, xi * left, zmp * left, left, left**2, elapsed * one, one], axis=1
    )


def predict(xi, side, zmp_now, left, elapsed):
    sg = np.array([1.0, side])
    x, z = xi * sg, zmp_now * sg
    out = np.stack([feats(x[a], z[a], left, elapsed) @ MAP[a] for a in (0, 1)], axis=1)
    return out * sg


def plan_map(
    xi,
    side,
    gait,
    limits,
    weights,
    *,
    elapsed,
    zmp_now,
    swing_at,
    nominal_step,
    offset,
    zmp_box,
    grid=24,
    sweeps=6,
):
    _, _, _toe = gait.zmp_points(side)
    offset = offset + OFIX * np.array([1.0, side])
    lo = max(limits.ss_min - elapsed, 0.01)
    left = np.linspace(lo, max(limits.ss_max - elapsed, lo), grid)
    xi_end = predict(xi, side, zmp_now, left, elapsed)
    ss = elapsed + left
    y_lo, y_hi = (limits.inner, limits.outer) if -side > 0 else (-limits.outer, -limits.inner)
    reach = limits.swing_speed * left[:, None]
    box_lo = np.maximum(np.array([-limits.backward, y_lo]), swing_at - reach)
    box_hi = np.maximum(np.minimum(np.array([limits.forward, y_hi]), swing_at + reach), box_lo)
    ws, wo, wz = weights.step, weights.offset, weights.zmp
    gain = 1.0 - np.exp(gait.omega * left)[:, None]
    z_lo, z_hi = zmp_box if ZMP == "keep" else (np.zeros(2), np.zeros(2))
    delta, u = np.zeros_like(xi_end), np.clip(nominal_step, box_lo, box_hi)
    for _ in range(sweeps):
        delta = np.clip(-wo * (xi_end - u - offset) / ((wz + wo) * gain), z_lo, z_hi)
        u = np.clip(
            (ws * nominal_step + wo * (xi_end + gain * delta - offset)) / (ws + wo), box_lo, box_hi
        )
    end = xi_end + gain * delta
    err = end - u - offset
    cost = (
        wz * np.sum((gain * delta) ** 2, 1)
        + ws * np.sum((u - nominal_step) ** 2, 1)
        + wo * np.sum(err**2, 1)
        + weights.time * (ss - gait.ss) ** 2
    )
    k = int(np.argmin(cost))
    return planner.StepChoice(u[k], float(left[k]), float(ss[k]), end[k], err[k], delta[k])


REC = []


def recording(xi, side, gait, limits, weights, **kw):
    ch = (plan_map if MAP is not None else ORIG)(xi, side, gait, limits, weights, **kw)
    _, _, toe = gait.zmp_points(side)
    REC.append(
        (
            CUR[0].steps,
            side,
            xi.copy(),
            kw["zmp_now"].copy(),
            toe.copy(),
            kw["elapsed"],
            gait.omega,
            ch.landing.copy(),
            kw["offset"].copy(),
            kw["nominal_step"].copy(),
        )
    )
    return ch


CUR = [None]


def walk(prot, seed, record=False):
    REC.clear()
    cm.plan_step = recording if record else (plan_map if MAP is not None else ORIG)
    draw = load_protocol(prot).draw(seed, ROBOT, seconds=30)
    ctrl = SteppingController(ROBOT, GAIT.style, GAINS, 0.01)
    CUR[0] = ctrl
    plant = MujocoPlant(ROBOT, draw.options)
    obs = plant.reset(ctrl.q0)
    for k in range(3000):
        plant.command(ctrl(k, obs))
        obs = plant.step()
        if plant.fell:
            break
    return plant.fell, list(REC)


def samples(rec):
    """Per planner call: (side, xi, zmp_now, toe, elapsed, omega, left_actual, xi_td)."""
    by = {}
    for r in rec:
        by.setdefault(r[0], []).append(r)
    out = []
    for s, rs in by.items():
        if s < 3 or len(rs) < 10:
            continue
        rs = rs[:-1]  # the touchdown tick may be logged with the new stance
        t_end = rs[-1][5]
        xi_td = rs[-1][2]
        for r in rs[:-1]:
            out.append(
                (
                    r[1],
                    r[2],
                    r[3],
                    r[4],
                    r[5],
                    r[6],
                    t_end - r[5] + 0.0,
                    xi_td,
                    rs[-1][7],
                    rs[-1][8],
                    rs[-1][9],
                )
            )
    return out


def fit(S, alpha=1e-6):
    coefs = []
    for a in (0, 1):
        X, y = [], []
        for side, xi, z, _toe, el, _om, left, td, *_ in S:
            sg = 1.0 if a == 0 else side
            X.append(feats(xi[a] * sg, z[a] * sg, np.array([left]), el)[0])
            y.append(td[a] * sg)
        X, y = np.array(X), np.array(y)
        c = np.linalg.solve(X.T @ X + alpha * np.eye(X.shape[1]), X.T @ y)
        coefs.append(c)
    return np.array(coefs)


def errors(S, coef):
    from imitwalk.step.lipm import dcm_after

    el, ei = [], []
    for side, xi, z, toe, e, om, left, td, *_ in S:
        lip = dcm_after(xi, z, toe, max(left, 1e-3), om)
        global MAP
        MAP = coef
        lr = predict(xi, side, z, np.array([left]), e)[0]
        el.append(lip - td)
        ei.append(lr - td)
    return np.sqrt(np.mean(np.square(el), 0)) * 1e3, np.sqrt(np.mean(np.square(ei), 0)) * 1e3


if __name__ == "__main__":
    cmd = sys.argv[1]
    if cmd == "learn":
        sys.path.insert(0, "bench")
        import learn_gains

        MAP = pickle.load(open(os.environ["MAPF"], "rb"))
        cm.plan_step = plan_map
        sys.argv = [sys.argv[0], *sys.argv[2:]]
        learn_gains.main()
    elif cmd == "collect":  # PROT FIRST N OUT [MAPIN]
        prot, first, n, out = sys.argv[2], int(sys.argv[3]), int(sys.argv[4]), sys.argv[5]
        if len(sys.argv) > 6:
            MAP = pickle.load(open(sys.argv[6], "rb"))
        with Pool(2) as pool:
            res = pool.starmap(walk, [(prot, s, True) for s in range(first, first + n)])
        S = [x for f, rec in res for x in samples(rec)]
        print("fell", sum(f for f, _ in res), "of", n, "samples", len(S))
        pickle.dump(S, open(out, "wb"))
    elif cmd == "fit":  # TRAIN.pkl TEST.pkl OUT
        S, T = pickle.load(open(sys.argv[2], "rb")), pickle.load(open(sys.argv[3], "rb"))
        c = fit(S)
        print("coef", c.round(3))
        print("train LIPM, map RMS [mm]", *errors(S, c))
        print("test  LIPM, map RMS [mm]", *errors(T, c))
        pickle.dump(c, open(sys.argv[4], "wb"))
    elif cmd == "offset":  # S.pkl
        S = pickle.load(open(sys.argv[2], "rb"))
        seen, rows = set(), []
        for side, _xi, _z, _toe, _el, _om, _left, td, land, off, nom in S:
            key = (round(float(td[0]), 9), round(float(td[1]), 9))
            if key in seen:
                continue
            seen.add(key)
            sg = np.array([1.0, side])
            rows.append(np.r_[(td - land) * sg, off * sg, land * sg, nom * sg])
        r = np.array(rows) * 1000
        print("steps", len(r))
        print(
            "measured offset at touchdown, mean / sd [mm]",
            r[:, :2].mean(0).round(1),
            r[:, :2].std(0).round(1),
        )
        print("planner's nominal offset b_nom [mm]", r[:, 2:4].mean(0).round(1))
        print(
            "landing chosen, nominal [mm]", r[:, 4:6].mean(0).round(1), r[:, 6:8].mean(0).round(1)
        )
    elif cmd == "walk":  # PROT FIRST N MAP
        prot, first, n = sys.argv[2], int(sys.argv[3]), int(sys.argv[4])
        MAP = pickle.load(open(sys.argv[5], "rb")) if sys.argv[5] != "none" else None
        with Pool(2) as pool:
            res = pool.starmap(walk, [(prot, s) for s in range(first, first + n)])
        print(
            prot,
            "map",
            sys.argv[5],
            "ZMP",
            ZMP,
            "G",
            os.environ.get("G", ""),
            "fell",
            sum(f for f, _ in res),
            "of",
            n,
        )
