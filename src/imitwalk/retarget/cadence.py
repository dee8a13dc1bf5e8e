"""The same gait at another cadence: the loop resampled in time (pure NumPy).

Step timing is one of the balance handles the paper's action already has: eq. (9) lets
the controller choose how far the phase advances each tick (ε_φ). :func:`with_cadence`
sets it once for a whole reference: the loop is played ``rate`` times as fast — the same
strides and postures, cycles a whole number of ticks shorter. The start-up from standing
keeps the human's cadence (played faster, it tips the robot over within three seconds),
and its last tick still flows into the loop's first; the balance channels then start
their step clock at the loop (:class:`imitwalk.paper.policy.WalkPolicy`).
``imitwalk retarget --set cadence=R`` writes such a reference.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
from scipy.interpolate import make_interp_spline

from imitwalk.errors import ConfigError
from imitwalk.retarget.reference import Reference

__all__ = ["with_cadence"]


def _resample(a: np.ndarray, u: np.ndarray, after: np.ndarray) -> np.ndarray:
    """``a`` ``(S, N, ...)`` at fractional ticks ``u`` ``(N2,)`` in [0, N), linearly;
    ``after`` ``(S, ...)`` is the value at tick N (the loop's first tick, or it a stride
    ahead for what moves forward)."""
    ext = np.concatenate([a, after[:, None]], axis=1)
    return make_interp_spline(np.arange(ext.shape[1]), ext, k=1, axis=1)(u)


def with_cadence(ref: Reference, rate: float) -> Reference:
    """``ref`` with its loop played ``rate`` times as fast.

    Args:
        ref: a reference; rate: cadence factor, 0.5 ≤ rate ≤ 2 (1: ``ref`` itself).

    Returns:
        a :class:`Reference` whose loop has N' = round(N / rate) ticks (the period N' dt;
        the rate actually played is N / N'); the start-up, strides and travel per cycle
        are unchanged, so the commanded speed grows by N / N'.
        ``settings["cadence"]`` records the rate relative to the human's (rates compound).
    """
    rate = float(rate)
    if not 0.5 <= rate <= 2.0:
        raise ConfigError(f"cadence rate={rate}: expected 0.5 <= rate <= 2")
    n = ref.loops.shape[1]
    n2 = max(4, round(n / rate))
    if n2 == n:
        return ref
    m = ref.starts.shape[1]
    u = np.arange(n2) * (n / n2)  # (N2,) source ticks of the loop
    near = np.rint(u).astype(int) % n
    loops = _resample(ref.loops, u, ref.loops[:, 0])
    plan = {}
    # the tick after the loop: its first tick, one cycle on (a stride ahead, or turned)
    after = (
        [ref.plan_row(ref.plan_at(s), ref.motion_at(s), m + n) for s in ref.scales]
        if ref.plan
        else []
    )
    for key, arr in ref.plan.items():
        loop = arr[:, m:]
        ahead = np.stack([a[key] for a in after])
        plan[key] = np.concatenate([arr[:, :m], _resample(loop, u, ahead)], axis=1)
    phase = _resample(ref.phase[None], u, np.ones(1))[0] % 1.0
    residual = np.concatenate([ref.residual_mm[:, :m], ref.residual_mm[:, m:][:, near]], axis=1)
    return replace(
        ref,
        period=n2 * ref.dt,
        loops=loops,
        phase=phase,
        stance=ref.stance[near],
        residual_mm=residual,
        plan=plan,
        settings={**ref.settings, "cadence": float(ref.settings.get("cadence", 1.0)) * n / n2},
    )
