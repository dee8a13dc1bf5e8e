"""A per-tick run's laws as stored: the trial-picked gains, the learned law, the recorded
episodes, and the controllers a finished run builds (:func:`load_laws`)."""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from imitwalk.balance.feedback import Episode, FeedbackLaw
from imitwalk.balance.tickconfig import TickLearnConfig
from imitwalk.config import from_dict
from imitwalk.errors import RunError
from imitwalk.runs import RunDir

__all__ = [
    "TRIAL_GAINS",
    "feedback_law",
    "load_laws",
    "load_learned",
    "save_learned",
    "stack_episodes",
    "unstack_episodes",
]

#: The trial-picked gains, in the order they are tried: (setting, channel, feature,
#: whether the walk's heading drift limits it: :meth:`Trial.rank`).
TRIAL_GAINS = (
    ("pitch", "ankle_pitch", "gyro_y", False),
    ("roll", "ankle_roll", "gyro_x", False),
    ("heading", "turn", "heading", True),
)


def feedback_law(cfg: TickLearnConfig, gains: dict) -> FeedbackLaw:
    """The trial-picked law with ``gains`` by setting name (a missing one is 0)."""
    channels = tuple(c for _, c, _, _ in TRIAL_GAINS)
    features = tuple(dict.fromkeys(f for _, _, f, _ in TRIAL_GAINS))
    law = FeedbackLaw.zero(channels, features, cfg.trials.box)
    for name, channel, feature, _ in TRIAL_GAINS:
        law = law.with_gain(channel, feature, float(gains.get(name, 0.0)))
    return law


def stack_episodes(data: list[tuple[float, Episode]]) -> dict[str, np.ndarray]:
    if not data:
        return {}
    return {
        "scale": np.array([s for s, _ in data]),
        "length": np.array([len(e.phase) for _, e in data]),
        "phase": np.concatenate([e.phase for _, e in data]),
        "features": np.vstack([e.features for _, e in data]),
        "actions": np.vstack([e.actions for _, e in data]),
    }


def unstack_episodes(arrays: dict) -> list[tuple[float, Episode]]:
    if "length" not in arrays:
        return []
    cut = np.cumsum(arrays["length"])[:-1]
    parts = [np.split(arrays[k], cut) for k in ("phase", "features", "actions")]
    return [(float(s), Episode(*p)) for s, *p in zip(arrays["scale"], *parts, strict=True)]


def save_learned(rd: RunDir, law: FeedbackLaw | None) -> None:
    if law is not None:
        rd.write_arrays("learned.npz", law.to_arrays(""))


def load_learned(rd: RunDir) -> FeedbackLaw | None:
    if not rd.exists("learned.npz"):
        return None
    return FeedbackLaw.from_arrays(rd.read_arrays("learned.npz"), "")


def load_laws(run_dir) -> dict[str, tuple[FeedbackLaw, ...]]:
    """The controllers a finished per-tick run can build, by name: ``feedback`` (the
    trial-picked law), ``learned`` (with the kept fraction of the model-based law on top)
    and ``fixed`` (the named hand-set baseline: 0.05 × gyro_y on both ankle pitches)."""
    rd = RunDir(run_dir)
    metrics = rd.read_summary()
    cfg = from_dict(TickLearnConfig, rd.read_json("config.json")["learn"])
    if metrics.feedback_gains is None:
        raise RunError(f"{rd.file('metrics.json')} has no feedback_gains: not a per-tick run")
    base = feedback_law(cfg, metrics.feedback_gains)
    fixed = FeedbackLaw.zero(("ankle_pitch",), ("gyro_y",), cfg.trials.box).with_gain(
        "ankle_pitch", "gyro_y", 0.05
    )
    learned: tuple[FeedbackLaw, ...] = (base,)
    frac = float(metrics.trust or 0.0)
    law = load_learned(rd)
    if frac > 0 and law is not None:
        learned = (base, replace(law, gains=law.gains * frac))
    return {"learned": learned, "feedback": (base,), "fixed": (fixed,)}
