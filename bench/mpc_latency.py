"""Decision latency of the model-predictive action search (paper §5), on synthetic data.

Prints JSON. The pipeline is the real one, the data synthetic but realistic in size and
shape: 25 joint trajectories [rad] generated from a gait-like loop → PostureSubspace(3) →
GaitEmbedding → a SensoryMotorModel (40 kernels) fitted on a synthetic 3-axis gyro that a
nonlinear 2nd-order system produces from the actions → ActionSelector, run in closed loop
on that system. Each decision (build + solve) is timed; median and p90 are reported per
configuration (grid 5×5×5 = 125 candidates at horizon 1 is the target: ≤ 1 ms median).

Usage: ``python bench/mpc_latency.py [--ticks 2000]``
"""

from __future__ import annotations

import argparse
import json
import platform
import time

import numpy as np
import sklearn

from imitwalk.paper.controller import ActionSelector
from imitwalk.paper.embedding import GaitEmbedding
from imitwalk.paper.predictor import SensoryMotorModel
from imitwalk.paper.subspace import PostureSubspace

TWO_PI = 2.0 * np.pi


def gyro_step(s: np.ndarray, s_prev: np.ndarray, a: np.ndarray, a_prev: np.ndarray) -> np.ndarray:
    """A nonlinear 2nd-order 'torso gyro' [rad/s] driven by actions (φ, r, h)."""
    u = np.array([a[1] * np.cos(a[0]), np.sin(a[0]) * a[2], (a[1] - 1.0) ** 2])
    u_prev = np.array([a_prev[1] * np.cos(a_prev[0]), 0.0, 0.0])
    return 1.6 * s - 0.7 * s_prev + 0.3 * u - 0.2 * u_prev + 0.05 * np.tanh(s) * s_prev


def setup(rng: np.random.Generator):
    phase = np.arange(600) / 120.0  # 5 cycles at 120 ticks per cycle
    phi = TWO_PI * phase
    latent = np.column_stack([0.6 * np.cos(phi), 0.35 * np.sin(phi), 0.1 * np.sin(2 * phi)])
    W = np.linalg.qr(rng.normal(size=(25, 3)))[0].T  # (3, 25)
    Q = rng.uniform(-0.3, 0.3, 25) + latent @ W + 0.002 * rng.normal(size=(600, 25))
    ps = PostureSubspace(3).fit(Q)
    emb = GaitEmbedding().fit(ps.transform(Q))
    episodes = []
    for _ in range(8):  # 8 × 300 ticks of exploration around the loop
        p = rng.uniform(0, TWO_PI) + np.cumsum(TWO_PI / 120 + 0.01 * rng.standard_normal(300))
        A = np.column_stack([p, emb.g(p) + 0.02 * rng.standard_normal((300, 2))])
        S = np.zeros((300, 3))
        for t in range(1, 299):
            S[t + 1] = gyro_step(S[t], S[t - 1], A[t], A[t - 1]) + 0.002 * rng.normal(size=3)
        episodes.append((S, A))
    model = SensoryMotorModel(n_centers=40).fit(episodes)
    return emb, model


def run(emb, model, ticks: int, **kw) -> dict:
    sel = ActionSelector(emb, model, eps_phi=2 * TWO_PI / 120, eps_r=0.02, eps_h=0.02, **kw)
    s, s_prev = np.zeros(3), np.zeros(3)
    a_prev = np.array([0.0, *emb.g(0.0)])
    times = np.empty(ticks)
    for t in range(ticks):
        t0 = time.perf_counter()
        d = sel.select(s, s_prev, a_prev)
        times[t] = time.perf_counter() - t0
        s, s_prev = gyro_step(s, s_prev, d.action, a_prev), s
        a_prev = d.action
    times_ms = times[ticks // 10 :] * 1e3  # drop warm-up
    return {
        "mode": "samples" if kw.get("samples") else "grid",
        "candidates": d.n_candidates,
        "kernels": len(model.network_.centers_),
        "horizon": kw.get("horizon", 1),
        "median_ms": round(float(np.median(times_ms)), 4),
        "p90_ms": round(float(np.percentile(times_ms, 90)), 4),
        "decisions": len(times_ms),
        "cycles_walked": round(float(a_prev[0] / TWO_PI), 2),
    }


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--ticks", type=int, default=2000, help="decisions per configuration")
    args = ap.parse_args()
    emb, model = setup(np.random.default_rng(0))
    runs = [
        run(emb, model, args.ticks),  # the target: 125 candidates, horizon 1
        run(emb, model, args.ticks, samples=125),
        run(emb, model, args.ticks, n_phi=7, n_r=7, n_h=7),
        run(emb, model, args.ticks, horizon=3),
    ]
    out = dict(runs[0])
    out["runs"] = runs
    out.update(numpy=np.__version__, sklearn=sklearn.__version__, cpu=platform.machine())
    print(json.dumps(out, indent=2))


if __name__ == "__main__":
    main()
