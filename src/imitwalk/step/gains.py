"""The stepping gait's gains: what learning chooses, each with its valid range.

:class:`StepGains` holds every number of the stepping controller that is not the
robot's (its MJCF) or the clip's style (:mod:`imitwalk.step.style`). Its defaults,
:data:`MODEL_GAINS`, are what the linear inverted pendulum alone prescribes (the
"model" baseline of the tables: follow the plan, no lead, no feedforward); the learner
(:mod:`imitwalk.step.learn`) chooses them all together with CMA-ES on training robots.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, fields

import numpy as np

from imitwalk.errors import ConfigError

__all__ = ["BOUNDS", "MODEL_GAINS", "StepGains"]

#: Each gain's valid range (inclusive), what it is, and its unit.
BOUNDS: dict[str, tuple[float, float, str]] = {
    "dcm": (1.0, 6.0, "the commanded body's ZMP feedback on its DCM error, p = p_plan + dcm (ξ_cmd − ξ_ref) [-]"),
    "ankle": (0.0, 6.0, "the ankles' ZMP shift on the measured DCM's error from the commanded one [-]"),
    "follow": (0.0, 0.5, "pull of the commanded centre of mass towards the measured one, per tick [-]"),
    "lead": (0.0, 0.06, "the centre of mass commanded this far ahead along its velocity [s]"),
    "step_weight": (-3.0, 1.0, "log10 of the cost of moving a step off its nominal spot [-]"),
    "zmp_weight": (-3.0, 2.0, "log10 of the cost of the DCM moved by shifting the ZMP within the sole [-]"),
    "time_weight": (-3.0, 2.0, "log10 of the cost of changing a step's timing [-]"),
    "unload": (0.05, 1.0, "the trailing foot lifts off once it carries at most this share of the weight [-]"),
    "ss_min": (0.3, 1.0, "shortest single support, a fraction of the nominal [-]"),
    "zmp_roll": (0.0, 0.8, "ZMP heel-to-toe travel in single support, a fraction of the half sole [-]"),
    "zmp_out": (-0.5, 1.0, "the ZMP planned this far outside the sole's centre line, a fraction of the half sole width [-]"),
    "support": (0.3, 1.0, "the ZMP kept within this fraction of the sole [-]"),
    "crouch": (0.0, 0.25, "the hip lowered below the style's height, a fraction of the leg [-]"),
    "heading": (0.0, 1.0, "each step turns this fraction of the heading error back [-]"),
    "feedforward": (0.0, 1.0, "fraction of the servos' static sag added to their targets [-]"),
    "torso": (-1.0, 1.0, "the torso's pitch and roll error fed to the stance hip [-]"),
}


@dataclass(frozen=True)
class StepGains:
    """The stepping controller's gains (see :data:`BOUNDS` for each one's meaning)."""

    dcm: float = 2.0
    ankle: float = 1.0
    follow: float = 0.0
    lead: float = 0.0
    step_weight: float = -1.0
    time_weight: float = 0.0
    zmp_weight: float = 0.0
    unload: float = 0.3
    ss_min: float = 0.5
    zmp_roll: float = 0.3
    zmp_out: float = 0.0
    support: float = 0.7
    crouch: float = 0.05
    heading: float = 0.5
    feedforward: float = 1.0
    torso: float = 0.0

    def __post_init__(self) -> None:
        for f in fields(self):
            v = getattr(self, f.name)
            lo, hi, what = BOUNDS[f.name]
            if not (isinstance(v, int | float) and np.isfinite(v) and lo <= v <= hi):
                raise ConfigError(f"gain {f.name}={v!r}: expected {lo:g} <= {f.name} <= {hi:g} ({what})")

    def to_dict(self) -> dict[str, float]:
        """Plain dictionary."""
        return {k: float(v) for k, v in asdict(self).items()}

    @classmethod
    def from_dict(cls, d: dict) -> StepGains:
        """Gains from a dictionary; unknown names are refused with the valid ones."""
        unknown = sorted(set(d) - set(BOUNDS))
        if unknown:
            raise ConfigError(f"unknown gain {unknown[0]!r}; valid gains: {', '.join(BOUNDS)}")
        return cls(**{k: float(v) for k, v in d.items()})

    def vector(self, names: tuple[str, ...]) -> np.ndarray:
        """The gains ``names`` as a vector, each scaled to [0, 1] of its range."""
        return np.array([(getattr(self, n) - BOUNDS[n][0]) / (BOUNDS[n][1] - BOUNDS[n][0]) for n in names])

    def with_vector(self, names: tuple[str, ...], x: np.ndarray) -> StepGains:
        """These gains with ``names`` set from ``x`` (each in [0, 1] of its range, clipped)."""
        d = self.to_dict()
        for n, v in zip(names, np.clip(x, 0.0, 1.0), strict=True):
            lo, hi, _ = BOUNDS[n]
            d[n] = float(lo + (hi - lo) * v)
        return StepGains(**d)


#: The gains the pendulum model prescribes alone: the "model" baseline.
MODEL_GAINS = StepGains()
