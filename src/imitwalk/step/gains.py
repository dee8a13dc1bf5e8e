"""The stepping gait's gains: what learning chooses, each with its valid range.

:class:`StepGains` holds every number of the stepping controller that is neither the
robot's (its MJCF) nor the clip's style (:mod:`imitwalk.step.style`). Its defaults are
the gains imitwalk ships, themselves learned: CMA-ES over all of them but ``heading``
(:mod:`imitwalk.step.learn`; 25 generations of 12 candidates, each walked 10 s on 8
training robots of the ``hard`` protocol drawn from seed 1001 on, new robots every
generation; the default clip on ``hoap2``), then the best of the generations' winners
on 16 fresh robots (``python bench/learn_gains.py OUT``; 17,900 simulated seconds,
16 minutes on 2 cores). They are the ``default`` controller of every stepping run and
where ``imitwalk learn`` starts from. ``heading`` is the learner's start, a half. A
backward walk (``learn --backward``) ships its own, :data:`BACKWARD`
(:func:`shipped_gains` gives either).
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, fields
from typing import NamedTuple

import numpy as np

from imitwalk.errors import ConfigError

__all__ = ["BACKWARD", "BOUNDS", "GainRange", "StepGains", "shipped_gains"]


class GainRange(NamedTuple):
    """A gain's valid range (inclusive) and what it is."""

    lo: float
    hi: float
    what: str


#: Each gain's valid range and meaning.
BOUNDS: dict[str, GainRange] = {
    "dcm": GainRange(1.0, 6.0, "the commanded body's ZMP feedback on its DCM error [-]"),
    "ankle": GainRange(0.0, 6.0, "the ankles' ZMP shift per metre of measured DCM error [-]"),
    "follow": GainRange(0.0, 0.5, "the commanded body's pull to the measured one, per tick [-]"),
    "lead": GainRange(0.0, 0.06, "the centre of mass commanded ahead along its velocity [s]"),
    "step_weight": GainRange(-3.0, 1.0, "log10 of the cost of moving a step off its spot [-]"),
    "time_weight": GainRange(-3.0, 2.0, "log10 of the cost of changing a step's timing [-]"),
    "zmp_weight": GainRange(-3.0, 2.0, "log10 of the cost of the ankles' share of a step [-]"),
    "unload": GainRange(0.05, 1.0, "the trailing foot lifts at most this share of weight [-]"),
    "ss_min": GainRange(0.3, 1.0, "the shortest single support, of the style's [-]"),
    "zmp_roll": GainRange(0.0, 0.8, "the ZMP's heel-to-toe roll, of the half sole [-]"),
    "zmp_out": GainRange(-0.5, 1.0, "the ZMP outside the sole's centre line, of its half [-]"),
    "support": GainRange(0.3, 1.0, "the ZMP kept within this share of the sole [-]"),
    "plan_support": GainRange(0.0, 1.0, "the share of that the step planner counts on [-]"),
    "crouch": GainRange(0.0, 0.25, "the hips lowered below the style's, of the leg [-]"),
    "heading": GainRange(0.0, 1.0, "the share of the heading error each step turns back [-]"),
    "observer": GainRange(-1.0, 1.5, "log10 of the velocity observer's model error [m/s²]"),
    "swing_fix": GainRange(0.0, 30.0, "the swing sole's measured lag integrated away [1/s]"),
    "feedforward": GainRange(0.0, 1.0, "the share of the servos' sag and lag fed forward [-]"),
}


@dataclass(frozen=True)
class StepGains:
    """The stepping controller's gains (see :data:`BOUNDS` for each one's meaning; the
    module doc for where the defaults come from)."""

    dcm: float = 5.142
    ankle: float = 4.700
    follow: float = 0.02371
    lead: float = 0.04417
    step_weight: float = 0.2370
    time_weight: float = -0.4532
    zmp_weight: float = -1.677
    unload: float = 0.2815
    ss_min: float = 0.8627
    zmp_roll: float = 0.2392
    zmp_out: float = -0.1717
    support: float = 0.8563
    plan_support: float = 0.4330
    crouch: float = 0.05022
    heading: float = 0.5
    observer: float = 0.5923
    swing_fix: float = 20.16
    feedforward: float = 0.7141

    def __post_init__(self) -> None:
        for f in fields(self):
            v = getattr(self, f.name)
            lo, hi, what = BOUNDS[f.name]
            ok = isinstance(v, int | float) and bool(np.isfinite(v)) and lo <= v <= hi
            if not ok:
                raise ConfigError(
                    f"gain {f.name}={v!r}: expected {lo:g} <= {f.name} <= {hi:g} ({what})"
                )

    def to_dict(self) -> dict[str, float]:
        """Plain dictionary."""
        return {k: float(v) for k, v in asdict(self).items()}

    @classmethod
    def from_dict(cls, d: dict) -> StepGains:
        """Gains from a dictionary (missing ones at their defaults); an unknown name is
        refused with the valid ones."""
        if not isinstance(d, dict):
            raise ConfigError(
                f"gains must be a mapping of names to numbers, not {type(d).__name__}"
            )
        unknown = sorted(set(d) - set(BOUNDS))
        if unknown:
            raise ConfigError(f"unknown gain {unknown[0]!r}; valid gains: {', '.join(BOUNDS)}")
        try:
            return cls(**{k: float(v) for k, v in d.items()})
        except (TypeError, ValueError):
            raise ConfigError(f"gains must be numbers: {d}") from None

    def vector(self, names: tuple[str, ...]) -> np.ndarray:
        """The gains ``names`` as a vector, each scaled to [0, 1] of its range."""
        return np.array(
            [(getattr(self, n) - BOUNDS[n].lo) / (BOUNDS[n].hi - BOUNDS[n].lo) for n in names]
        )

    def with_vector(self, names: tuple[str, ...], x: np.ndarray) -> StepGains:
        """These gains with ``names`` set from ``x`` (each in [0, 1] of its range, clipped)."""
        d = self.to_dict()
        for n, v in zip(names, np.clip(x, 0.0, 1.0), strict=True):
            lo, hi, _ = BOUNDS[n]
            d[n] = float(lo + (hi - lo) * v)
        return StepGains(**d)


#: The shipped gains of a backward walk (a style played backward in time, ``imitwalk
#: learn --backward``): what ``learn --backward`` kept on the embedded walk from the
#: forward walk's shipped gains (0 of 40 ``eval`` robots fall with them; 10 of 10 with
#: the forward ones). A longer search from them (``python bench/learn_gains.py OUT
#: --backward --start G.json --generations 10 --population 10 --robots 6 --seconds 10
#: --final 16``, 3,279 simulated seconds) kept them: 7 of 16 fresh ``hard`` robots fell,
#: 10 or more with every generation's winner.
BACKWARD = StepGains(
    dcm=4.230,
    ankle=4.484,
    follow=0.05306,
    lead=0.04590,
    step_weight=-0.3759,
    time_weight=1.014,
    zmp_weight=-2.611,
    unload=0.4480,
    ss_min=0.7577,
    zmp_roll=0.1804,
    zmp_out=0.003451,
    support=0.7538,
    plan_support=0.2765,
    crouch=0.001856,
    heading=0.3326,
    observer=0.8430,
    swing_fix=27.67,
    feedforward=0.7553,
)


def shipped_gains(backward: bool = False) -> StepGains:
    """The gains imitwalk ships: the ``default`` controller of a stepping run and where
    its ``learn`` starts, for a forward walk (:class:`StepGains`'s defaults) or a
    backward one (:data:`BACKWARD`)."""
    return BACKWARD if backward else StepGains()
