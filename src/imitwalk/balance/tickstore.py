"""A per-tick run's laws as stored: the trial-picked gains, the learned law, the recorded
episodes, and the controllers a finished run builds (:func:`load_laws`)."""

from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from imitwalk.balance.feedback import Episode, FeedbackLaw
from imitwalk.balance.tickconfig import TickLearnConfig
from imitwalk.config import from_dict
from imitwalk.errors import RunError
from imitwalk.runs import RunDir

__all__ = [
    "TRIAL_GAINS",
    "TrialGain",
    "feedback_law",
    "load_laws",
    "load_learned",
    "save_learned",
    "stack_episodes",
    "unstack_episodes",
]


@dataclass(frozen=True)
class TrialGain:
    """One trial-picked gain: ``feature`` → ``channel``, its candidates the setting
    ``name`` of :class:`~imitwalk.balance.tickconfig.TrialConfig`.

    Attributes:
        steers: the walk's heading drift limits it (:meth:`~imitwalk.balance.tickrun.Trial.rank`).
        profiled: its feature is measured against the nominal robot's own profile per
            loop tick (walked once, before its trials), not against 0.
        protocol: the :class:`~imitwalk.balance.tickconfig.TrialConfig` setting naming
            the protocol its training robots come from (``None``: the learner's
            ``train_protocol``).
    """

    name: str
    channel: str
    feature: str
    steers: bool = False
    profiled: bool = False
    protocol: str | None = None


#: The trial-picked gains, in the order they are tried. The torso's pitch, measured,
#: is held to the nominal robot's through both hip pitches: a servo spread along a
#: leg's pitch chain changes how much the torso leans (docs/RESULTS.md). The balance
#: gains are picked on robots with a wider servo spread than eval's, where a clip
#: without feedback falls often enough to choose by. The same pitch through both ankle
#: pitches (tilt) holds the whole body's lean, on robots that also stand on slopes. The
#: heading is last: how far a walk drifts depends on every balance gain.
TRIAL_GAINS = (
    TrialGain("pitch", "ankle_pitch", "gyro_y", protocol="balance_protocol"),
    TrialGain("roll", "ankle_roll", "gyro_x", protocol="balance_protocol"),
    TrialGain("torso", "hip_pitch", "pitch", profiled=True, protocol="balance_protocol"),
    TrialGain("tilt", "ankle_pitch", "pitch", profiled=True, protocol="tilt_protocol"),
    TrialGain("heading", "turn", "heading", steers=True),
)


def feedback_law(cfg: TickLearnConfig, gains: dict, profiles: dict | None = None) -> FeedbackLaw:
    """The trial-picked law with ``gains`` by setting name (a missing one is 0) and the
    nominal ``profiles`` by feature, each ``(N,)`` per loop tick (a missing one is 0)."""
    channels = tuple(dict.fromkeys(g.channel for g in TRIAL_GAINS))
    features = tuple(dict.fromkeys(g.feature for g in TRIAL_GAINS))
    profiles = profiles or {}
    n = max((len(p) for p in profiles.values()), default=1)
    nominal = np.zeros((n, len(features)))
    for feature, profile in profiles.items():
        nominal[:, features.index(feature)] = profile
    law = replace(FeedbackLaw.zero(channels, features, cfg.trials.box), nominal=nominal)
    for g in TRIAL_GAINS:
        law = law.with_gain(g.channel, g.feature, float(gains.get(g.name, 0.0)))
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


def load_laws(run_dir: str | Path) -> dict[str, tuple[FeedbackLaw, ...]]:
    """The controllers a finished per-tick run can build, by name: ``feedback`` (the
    trial-picked law), ``learned`` (with the kept fraction of the model-based law on top)
    and ``fixed`` (the named hand-set baseline: 0.05 × gyro_y on both ankle pitches)."""
    rd = RunDir(run_dir)
    kept = rd.read_summary().tick()
    cfg = from_dict(TickLearnConfig, rd.read_json("config.json", ("learn",))["learn"])
    if kept.feedback_gains is None:
        raise RunError(f"{rd.file('metrics.json')} has no feedback_gains: not a per-tick run")
    profiles = rd.read_json("checkpoint.json").get("profiles", {})  # none before 2026-12-04
    base = feedback_law(cfg, kept.feedback_gains, profiles)
    fixed = FeedbackLaw.zero(("ankle_pitch",), ("gyro_y",), cfg.trials.box).with_gain(
        "ankle_pitch", "gyro_y", 0.05
    )
    learned: tuple[FeedbackLaw, ...] = (base,)
    frac = float(kept.trust or 0.0)
    law = load_learned(rd)
    if frac > 0 and law is not None:
        learned = (base, replace(law, gains=law.gains * frac))
    return {"learned": learned, "feedback": (base,), "fixed": (fixed,)}
