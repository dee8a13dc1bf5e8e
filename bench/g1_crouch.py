"""G1's crouch: a reference whose hip height is set for a shorter stride than 1.0, and
optionally a forward centre of mass from a linear inverted pendulum (one-off prototypes,
not in the product; docs/RESULTS.md, "Other robots").

The plan's hip height is the lower of ``height`` × the straight-leg height and the
highest that keeps the knee bent at the longest stride (``plan.knee_cap`` at
``cap_scale`` 1.0), at every scale. ``--cap S`` sets ``cap_scale`` to S (the cap is then
taken at the larger of S and the scale walked). ``--pendulum`` moves the plan's centre of
mass along its heading to the pendulum's path whose ZMP stays at the stance sole's centre
in single support and crosses over in double support (p = c − c̈/ω², solved as a banded
system, at rest at both ends, the plan extended by two steady cycles).

Usage: ``python bench/g1_crouch.py --cap 0.4 [--pendulum] -- retarget --robot g1.json
--no-search --set params.sway=0.4 --set params.height=0.95 --out R.npz``, then
``python bench/feedforward.py R.npz --robot g1.json --scale 0.4 --robots 6 --seconds 10
--variants train --fractions 1 --wait 0.3 --gains pitch=0.05``.
"""

from __future__ import annotations

import argparse
import sys
from dataclasses import replace

import numpy as np
from scipy.linalg import solve_banded

import imitwalk.retarget.plan as plan_module
import imitwalk.retarget.walkable as walkable_module
from imitwalk.cli.main import main as cli

GRAVITY = 9.81


def lipm_com(zmp: np.ndarray, dt: float, height: float) -> np.ndarray:
    """``(N,)`` the centre of mass [m] whose pendulum ZMP is ``zmp`` ``(N,)`` [m]."""
    n = len(zmp)
    a = height / (GRAVITY * dt * dt)
    bands = np.zeros((3, n))
    bands[0, 2:] = -a
    bands[1, 1:-1] = 1.0 + 2.0 * a
    bands[2, :-2] = -a
    bands[1, [0, -1]] = 1.0
    return solve_banded((1, 1), bands, zmp)


def support(psi: np.ndarray, ds: float) -> np.ndarray:
    """``(N,)`` the left sole's share of the weight (the right swings in [ds, ½))."""
    s = lambda x: np.clip(x, 0, 1) ** 2 * (3 - 2 * np.clip(x, 0, 1))  # noqa: E731
    w = np.where(psi < 0.5, 1.0, 0.0)
    w = np.where(psi < ds, s(psi / ds), w)
    return np.where((psi >= 0.5) & (psi < 0.5 + ds), 1.0 - s((psi - 0.5) / ds), w)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--cap", type=float, default=1.0, help="the stride the hip is set for")
    ap.add_argument("--pendulum", action="store_true")
    ap.add_argument("--com-above-pelvis", type=float, default=0.0, help="[m], for --pendulum")
    ap.add_argument("args", nargs=argparse.REMAINDER, help="-- then imitwalk's arguments")
    a = ap.parse_args()
    original = plan_module.plan_walk

    def plan_walk(template, geom, params, scale, dt, cycles=1, start=False, cap_scale=1.0,
                  command=None):  # fmt: skip
        cap = None if cap_scale is None else a.cap
        p = original(template, geom, params, scale, dt, cycles, start, cap, command)
        if not a.pendulum or p.path is None:
            return p
        n_cyc = round(p.period / dt)
        w = support(p.phase, float(np.clip(params.ds, 0.0, 0.45)))
        zmp = w[:, None] * p.l_sole[:, :2] + (1 - w[:, None]) * p.r_sole[:, :2]
        head = np.stack([np.cos(p.path[:, 2]), np.sin(p.path[:, 2])], axis=1)
        u = p.path[:, 3] + np.sum((zmp - p.path[:, :2]) * head, axis=1)
        ext = np.concatenate([u, u[-n_cyc:] + p.stride, u[-n_cyc:] + 2 * p.stride])
        z = float(p.pelvis_z[0]) + a.com_above_pelvis
        lead = lipm_com(ext, dt, z)[: len(u)] - p.path[:, 3]
        # the plan's centre of mass runs at the walking frame's speed: move it along
        return replace(p, com=p.com + lead[:, None] * head)

    plan_module.plan_walk = plan_walk
    walkable_module.plan_walk = plan_walk
    args = a.args[1:] if a.args[:1] == ["--"] else a.args
    sys.exit(cli(args))


if __name__ == "__main__":
    main()
