"""How far to trust the learned corrections: the channel gain, picked by measured trials.

The step search (:mod:`imitwalk.balance`) applies the corrections its model predicts
will help. A model learned from a few hundred steps is over-confident: applied in full,
its corrections can make marginal robots fall that the reference alone would carry.
After the scale schedule, the learner therefore runs its controller with each candidate
gain (the searched channel values × gain; 0 is the reference alone) on the same robots
— ones it never learned on (:func:`imitwalk.perturb.trial_seeds`) — and keeps the gain
that measures best: fewest falls, then the longest time up, then the least heading
drift. This is the paper's execute-and-measure loop applied to one policy parameter;
nothing here predicts, it only counts (pure NumPy). The same trials then pick the
cadence (:func:`imitwalk.retarget.cadence.with_cadence`; ``key="cadence"``): how fast
the loop is played, the step-timing handle of eq. (9), with the gain kept. With
``LearnConfig.offsets`` they also pick a constant channel offset (``key="offset"``,
``StepConfig.offset``), where the scale schedule stalls and at the scale reached.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np

__all__ = ["LABELS", "GainChoice", "select_gain", "tune_gain"]

#: What the trials tune, by ``key``, in words (progress lines, the report).
LABELS = {"gain": "channel gain", "cadence": "cadence", "offset": "channel offset"}


@dataclass(frozen=True)
class GainChoice:
    """The outcome of the trials.

    Attributes:
        gain: the value kept (of the parameter ``key``); seeds: the trial robots (the
            same for every candidate).
        table: one row per candidate: ``key``, ``falls``, ``mean_time_up_s`` (a fall
            counts its fall time), ``mean_abs_yaw_deg``.
        sim_seconds: simulated time the trials used [s]; wall_seconds: their wall time.
        key: the parameter tried: ``"gain"`` (the channel gain), ``"cadence"`` or
            ``"offset"`` (the channel offset).
    """

    gain: float
    seeds: tuple[int, ...]
    table: list[dict] = field(default_factory=list)
    sim_seconds: float = 0.0
    wall_seconds: float = 0.0
    key: str = "gain"

    def to_dict(self) -> dict:
        return {
            self.key: self.gain,
            "seeds": list(self.seeds),
            "table": self.table,
            "sim_seconds": self.sim_seconds,
            "wall_seconds": self.wall_seconds,
        }


def _row(gain: float, runs: Sequence[dict], key: str = "gain") -> dict:
    up = [r["fall_time_s"] if r["fell"] else r["seconds"] for r in runs]
    return {
        key: float(gain),
        "falls": int(sum(bool(r["fell"]) for r in runs)),
        "mean_time_up_s": float(np.mean(up)),
        "mean_abs_yaw_deg": float(np.mean([abs(r["yaw_drift_deg"]) for r in runs])),
    }


def select_gain(
    gains: Sequence[float], trials: Sequence[Sequence[dict]], key: str = "gain"
) -> tuple[int, list]:
    """Index of the best gain and the table of all.

    Args:
        gains: candidates, in order of preference on an exact tie (list the smallest
            first: an unproven correction should not be trusted more).
        trials: per gain, the episode metrics (``fell``, ``fall_time_s``, ``seconds``,
            ``yaw_drift_deg``: :class:`imitwalk.metrics.WalkMetrics` as a dict) on the
            same robots in the same order.
        key: the parameter's name in the table.
    """
    if not gains or len(gains) != len(trials):
        raise ValueError("select_gain: one list of trials per candidate gain")
    table = [_row(g, t, key) for g, t in zip(gains, trials, strict=True)]
    keys = [(r["falls"], -r["mean_time_up_s"], r["mean_abs_yaw_deg"]) for r in table]
    return min(range(len(keys)), key=keys.__getitem__), table


def tune_gain(
    run_episodes: Callable[[float, tuple[int, ...]], list[dict]],
    gains: Sequence[float],
    seeds: tuple[int, ...],
    progress=None,
    key: str = "gain",
) -> GainChoice:
    """Run ``run_episodes(value, seeds) -> [metrics dict]`` for every candidate value of
    the parameter ``key`` and keep the best (:func:`select_gain`)."""
    label = LABELS[key]
    trials = []
    for g in gains:
        trials.append(run_episodes(g, seeds))
        if progress:
            row = _row(g, trials[-1])
            progress(
                f"{label} {g:g}: fell {row['falls']}/{len(seeds)}, "
                f"time up {row['mean_time_up_s']:.1f} s, |yaw| {row['mean_abs_yaw_deg']:.1f} deg"
            )
    best, table = select_gain(gains, trials, key)
    sim = float(sum(r["seconds"] for t in trials for r in t))
    return GainChoice(float(gains[best]), tuple(seeds), table, sim, key=key)
