"""Replaying a faithful run's controller, and the paired statistics of judging.

:func:`load_gait` rebuilds the paper's learned controller from a ``faithful`` run
folder (:mod:`imitwalk.paper.learner`); :mod:`imitwalk.judge.verdict` walks it beside open loop on a
protocol's robots. :func:`wilson` and :func:`compare_falls` are the statistics every
judgement reports.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from scipy.stats import binomtest

from imitwalk.paper.gait import GaitModel
from imitwalk.paper.learnconfig import LearnConfig
from imitwalk.paper.models import build_policy, fit_model, unstack_episodes
from imitwalk.paper.policy import WalkPolicy
from imitwalk.retarget.reference import Reference
from imitwalk.runs import LearnSummary, RunDir

__all__ = ["LearnedGait", "compare_falls", "load_gait", "wilson"]


class LearnedGait:
    """Everything needed to replay a faithful run's learned controller."""

    def __init__(self, ref: Reference, config: LearnConfig, data: list, metrics: LearnSummary):
        self.ref, self.config, self.metrics = ref, config, metrics
        self.scale = float(metrics.scale_reached) or config.schedule.start
        self.gait = GaitModel(ref, config.schedule.scales(), config.gait)
        self.model = fit_model(data, config)

    def policy(self, scale: float | None = None) -> WalkPolicy:
        """A fresh controller (no exploration) at ``scale`` (default: the scale reached)."""
        s = self.scale if scale is None else scale
        return build_policy(self.gait, s, self.config, self.model)


def load_gait(run_dir: str | Path) -> LearnedGait:
    """Rebuild the learned controller of a finished faithful run folder."""
    from imitwalk.config import from_dict

    rd = RunDir(run_dir)
    metrics = rd.read_summary()
    cfg = from_dict(LearnConfig, rd.read_json("config.json", ("learn",))["learn"])
    data = unstack_episodes(rd.read_arrays("data.npz")) if rd.exists("data.npz") else []
    return LearnedGait(Reference.load(rd.file("reference.npz")), cfg, data, metrics)


def wilson(k: int, n: int) -> tuple[float, float]:
    """95 % Wilson score interval of a rate ``k / n`` (``(0, 1)`` when ``n`` is 0)."""
    if n == 0:
        return 0.0, 1.0
    ci = binomtest(k, n).proportion_ci(confidence_level=0.95, method="wilson")
    return float(ci.low), float(ci.high)


def compare_falls(learned: list[bool], open_loop: list[bool]) -> dict:
    """Falls of two controllers on the same robots, as a paired comparison.

    Returns the fall rates with their 95 % Wilson intervals, the discordant robots
    (``learned_only``: fell with the first but not the second; ``open_only``: the
    reverse) and the two-sided exact McNemar p-value (a binomial test on the discordant
    robots). Ten robots rarely decide it: a 0/10 against 2/10 has p = 0.5.
    """
    if len(learned) != len(open_loop):
        raise ValueError("compare_falls: the two lists must cover the same robots")
    n = len(learned)
    lo = sum(1 for a, b in zip(learned, open_loop, strict=True) if a and not b)
    oo = sum(1 for a, b in zip(learned, open_loop, strict=True) if b and not a)
    p = float(binomtest(lo, lo + oo, 0.5).pvalue) if lo + oo else 1.0
    out: dict[str, Any] = {"robots": n, "learned_only": lo, "open_only": oo, "mcnemar_p": p}
    for name, fell in (("learned", learned), ("open_loop", open_loop)):
        k = int(sum(fell))
        out[f"{name}_fall_rate"] = k / n if n else 0.0
        out[f"{name}_fall_rate_ci95"] = list(wilson(k, n))
    return out
