"""An exported controller's per-tick latency through :mod:`imitwalk.runtime`, on one core.

The export walks the nominal robot in MuJoCo for ``--seconds`` from standing; each
``Controller.step(sensors)`` call (the sensor vector in, the joint targets out: what a
robot's main loop pays) is timed, and the simulator's own time is not. The best of
``--repeat`` walks is kept, per percentile.

Usage: ``python bench/runtime_latency.py EXPORT [--seconds 10] [--repeat 3]``; prints JSON.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import time

# one core, as on a robot's computer
os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("MKL_NUM_THREADS", "1")

import numpy as np

from imitwalk.runtime import Controller
from imitwalk.sim.mujoco import MujocoPlant, run
from imitwalk.sim.types import SimOptions


def walk(export: str, seconds: float) -> np.ndarray:
    """Each tick's ``step`` time [ms] over one walk."""
    ctl = Controller.load(export)
    # the plant: the export's own compiled model (any robot, no source files needed)
    plant = MujocoPlant(ctl.bundle.robot, SimOptions(control_hz=ctl.rate_hz))
    ms: list[float] = []

    def policy(k, obs):
        v = ctl.sensors.vector(obs)
        t = time.perf_counter()
        q = ctl.reset(v) if k == 0 else ctl.step(v)
        ms.append(1e3 * (time.perf_counter() - t))
        return q

    run(plant, policy, round(seconds * ctl.rate_hz), q0=ctl.q0, stop_on_fall=False)
    return np.array(ms[1:])  # the first tick builds the estimator


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("export", help="a folder written by imitwalk export")
    ap.add_argument("--seconds", type=float, default=10.0, help="simulated seconds per walk")
    ap.add_argument("--repeat", type=int, default=3, help="walks; the best is kept")
    args = ap.parse_args()
    walks = [walk(args.export, args.seconds) for _ in range(args.repeat)]
    q = {p: min(float(np.percentile(w, p)) for w in walks) for p in (50, 90, 99)}
    ctl = Controller.load(args.export)
    out = {
        "export": args.export,
        "controller": ctl.bundle.kind,
        "rate_hz": ctl.rate_hz,
        "ticks": len(walks[0]),
        "machine": platform.processor() or platform.machine(),
        "step_ms_median": round(q[50], 4),
        "step_ms_p90": round(q[90], 4),
        "step_ms_p99": round(q[99], 4),
        "budget_share_median": round(q[50] * 1e-3 * ctl.rate_hz, 4),
    }
    print(json.dumps(out, indent=2))


if __name__ == "__main__":
    main()
