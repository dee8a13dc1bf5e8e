"""The robustness grid: one perturbation per cell, learned and open loop side by side.

Cells (each on top of the evaluation robots, seed 0 nominal and the rest perturbed):
floor friction × 0.5, 0.75, 1.25, 1.5; every mass × 0.8, 0.9, 1.1, 1.2; every servo's
stiffness × 0.9, 1.1; gyro noise;
a servo delay of one and of two control periods; a ±3° slope along the walk; and a
lateral kick in the middle of the walk, in two sizes (impulses of 1 and 2 N·s, as
velocity changes of the robot's mass).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from imitwalk.evaluate import judged_gain, per_seed
from imitwalk.robots import Robot
from imitwalk.runs import RunDir
from imitwalk.sim import SimOptions

__all__ = ["CELLS", "robustness_grid"]

#: Push size: an impulse [N s] on the whole robot (a kick of impulse / mass [m/s]).
PUSHES = {"push_small": 1.0, "push_large": 2.0}
#: Gyro noise standard deviation in its cell [rad/s].
GYRO_NOISE = 0.03


def _cells(seconds: float, mass: float = 1.0) -> dict[str, SimOptions]:
    base = SimOptions()
    cells = {"nominal": base}
    for f in (0.5, 0.75, 1.25, 1.5):
        cells[f"friction_x{f:g}"] = replace(base, friction_scale=f)
    for m in (0.8, 0.9, 1.1, 1.2):
        cells[f"mass_x{m:g}"] = replace(base, mass_scale=m)
    for k in (0.9, 1.1):
        cells[f"servo_kp_x{k:g}"] = replace(base, kp_scale=k)
    cells["gyro_noise"] = replace(base, gyro_noise=GYRO_NOISE)
    dt = 1.0 / base.control_hz
    cells["delay_1"] = replace(base, servo_delay=dt)
    cells["delay_2"] = replace(base, servo_delay=2 * dt)
    cells["slope_up_3deg"] = replace(base, slope_deg=3.0)
    cells["slope_down_3deg"] = replace(base, slope_deg=-3.0)
    for name, impulse in PUSHES.items():
        cells[name] = replace(base, pushes=((seconds / 2, 0.0, impulse / mass),))
    return cells


#: The cell names, in order.
CELLS = tuple(_cells(20.0))


def robustness_grid(
    run_dir,
    robot: Robot,
    seconds: float = 20.0,
    seeds: int = 5,
    workers=None,
    progress=None,
    cells: tuple[str, ...] | None = None,
    scale: float | None = None,
    engine: str = "mujoco",
    gain: float | None = None,
) -> dict:
    """Survival and distance per cell, learned vs open loop (at ``scale``, default the
    scale the run reached), on ``engine`` (:data:`imitwalk.sim.ENGINES`); ``gain``: the
    learned controller's channel gain instead of the one the run's trials kept.

    Returns:
        ``{"cells": {name: {"learned": {...}, "open_loop": {...}}}, "totals": {...}}`` where
        each side has ``survived`` (of ``seeds``) and ``distance_m`` (mean), and totals
        count the cells in which every seed survived.
    """
    grid = _cells(seconds, robot.total_mass)
    names = cells or tuple(grid)
    out: dict = {"seconds": seconds, "seeds": seeds, "scale": scale, "engine": engine}
    metrics = RunDir(run_dir).read_json("metrics.json")
    out.update(channel_gain=judged_gain(metrics, gain), cells={})
    for name in names:
        res = per_seed(
            run_dir,
            robot,
            seconds,
            list(range(seeds)),
            grid[name],
            workers,
            scale=scale,
            engine=engine,
            gain=gain,
        )
        row = {}
        for mode, runs in res.items():
            row[mode] = {
                "survived": int(sum(not r["fell"] for r in runs)),
                "of": len(runs),
                "distance_m": float(np.mean([r["forward_distance_m"] for r in runs])),
                "yaw_drift_deg": float(np.mean([abs(r["yaw_drift_deg"]) for r in runs])),
            }
        out["cells"][name] = row
        if progress:
            progress(
                f"  {name:>16}: learned {row['learned']['survived']}/{seeds}, "
                f"open loop {row['open_loop']['survived']}/{seeds}"
            )
    out["totals"] = {
        mode: {
            "cells_all_survived": int(
                sum(c[mode]["survived"] == c[mode]["of"] for c in out["cells"].values())
            ),
            "survived": int(sum(c[mode]["survived"] for c in out["cells"].values())),
            "runs": int(sum(c[mode]["of"] for c in out["cells"].values())),
        }
        for mode in ("learned", "open_loop")
    }
    return out
