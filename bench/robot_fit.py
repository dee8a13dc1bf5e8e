"""How a robot fits the walkable reference: its size, its pendulum, its servos, its soles.

For each robot (a built-in name or a joint map) prints one JSON object with: mass, leg
length and the ankles' half spacing and foot size the reference uses
(:func:`imitwalk.retarget.ik.leg_geometry`); the centre of mass's height standing and
``ω² z / g`` at the default clip's cycle time (ω = 2π / period: below 1 the centre of
mass sways in phase with the pressure under the feet, above 1 the sway is driven past
the body's pendulum frequency); the leg servos' mean ``kv / kp`` [s] (servo damping and
the joints' own damping over stiffness); and the sole sensors' total over the last second
of standing ``--seconds`` on MuJoCo and on Bullet, beside the robot's weight.

Usage: ``python bench/robot_fit.py hoap2 op3.json g1.json [--seconds 3]``
"""

from __future__ import annotations

import argparse
import json

import mujoco
import numpy as np

from imitwalk.mocap import default_clip, load_motion
from imitwalk.retarget import extract_template
from imitwalk.retarget.ik import leg_geometry
from imitwalk.robots import load_robot
from imitwalk.sim.mujoco import make_plant, run


def fit(name: str, period: float, seconds: float) -> dict:
    r = load_robot(name)
    m = r.compile()
    d = mujoco.MjData(m)
    d.qpos[:] = r.stand_qpos
    mujoco.mj_forward(m, d)
    root = int(m.body_rootid[m.body(r.torso).id])
    sole_z = min(d.site_xpos[m.site(r.soles[s]).id][2] for s in "lr")
    z = float(d.subtree_com[root][2] - sole_z)
    g = float(np.linalg.norm(m.opt.gravity))
    legs = [i for i, role in enumerate(r.joint_names) if role[2:5] in ("hip", "kne", "ank")]
    ratio = []
    for i in legs:
        j = m.joint(r.mj_joints[i]).id
        a = next(a for a in range(m.nu) if m.actuator_trnid[a, 0] == j)
        kv = -m.actuator_biasprm[a, 2] + m.dof_damping[m.jnt_dofadr[j]]
        ratio.append(kv / m.actuator_gainprm[a, 0])
    geom = leg_geometry(r)
    out = {
        "robot": r.name,
        "mass_kg": r.total_mass,
        "leg_m": geom.leg,
        "ankle_half_spacing_m": geom.hip_y,
        "foot_m": [geom.foot_length, geom.foot_width],
        "com_height_m": z,
        "omega2_z_over_g": (2 * np.pi / period) ** 2 * z / g,
        "leg_kv_over_kp_s": float(np.mean(ratio)),
        "weight_n": r.total_mass * g,
    }
    steps = max(1, round(seconds * 100))
    for engine in ("mujoco", "bullet"):
        ro = run(make_plant(r, None, engine), lambda k, obs: r.stand, steps, stop_on_fall=False)
        out[f"sole_force_n_{engine}"] = float(ro.foot_force[-100:].sum(axis=(1, 2)).mean())
        out[f"fell_{engine}"] = bool(ro.fell)
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("robots", nargs="+", help="built-in names or joint-map .json files")
    ap.add_argument("--seconds", type=float, default=3.0, help="standing time per engine (3)")
    args = ap.parse_args()
    period = extract_template(load_motion(default_clip())).period
    rows = [fit(name, period, args.seconds) for name in args.robots]
    print(json.dumps({"cycle_period_s": period, "robots": rows}, indent=2))


if __name__ == "__main__":
    main()
