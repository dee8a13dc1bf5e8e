"""The step-level balance channels' settings and names (pure NumPy).

:class:`StepConfig` is what :class:`imitwalk.balance.StepController` decides with: which
channels it may use, their box, the step objective's weights (eq. 6 extended) and the
step model's size. The names of the channels and of the step state live here too, so
that a run's settings can be read without the controller.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from imitwalk.errors import ConfigError, unknown_name

__all__ = [
    "ALWAYS_DRAWN",
    "LAG_JOINTS",
    "LATERAL",
    "LIFT",
    "SERVO_STATE",
    "STEP_CHANNELS",
    "STEP_STATE",
    "TASK_OFFSETS",
    "TIME",
    "StepConfig",
]

#: The channels, in the order of every channel vector (see :mod:`imitwalk.balance`).
STEP_CHANNELS = ("dx", "dy", "yaw", "sway", "lean", "time", "lift")
#: The channels of the first releases: their search candidates and exploration noise are
#: always drawn (zero when off), so that runs written before ``time`` replay exactly.
ALWAYS_DRAWN = 5
#: Index of the ``time`` channel.
TIME = STEP_CHANNELS.index("time")
#: Index of the ``lift`` channel (the last; runs written before it have one value less).
LIFT = STEP_CHANNELS.index("lift")
#: The task-space offsets the channels turn into (per foot: landing x, y, yaw; the centre of
#: mass y, x; per foot: swing height), in the order of every offset vector; the robot's
#: IK adds them to its plan (:data:`imitwalk.retarget.ik.CHANNELS` is this tuple).
TASK_OFFSETS = ("l_x", "l_y", "l_yaw", "r_x", "r_y", "r_yaw", "com_y", "com_x", "l_z", "r_z")
#: Step state, in the stance side's mirrored frame.
STEP_STATE = (
    "roll",
    "pitch",
    "heading",
    "roll_rate",
    "pitch_rate",
    "yaw_rate",
    "stance_load",
    "cop_x",
)
#: The :data:`STEP_STATE` entries whose sign flips when a right step is mirrored.
LATERAL = np.array([1, 0, 1, 1, 0, 1, 0, 0], dtype=bool)
#: Step state added by ``StepConfig.servo_state``: each ankle-pitch servo's mean tracking
#: error (commanded − measured, from the joint encoders) over the last gait cycle [rad],
#: the coming stance leg's first. Under load a softer servo lags more, so these tell the
#: step model which kind of robot it is on. (Raw order: left, right.)
SERVO_STATE = ("ankle_lag_stance", "ankle_lag_other")
#: The joints whose tracking error :data:`SERVO_STATE` measures (left, right).
LAG_JOINTS = ("l_ankle_pitch", "r_ankle_pitch")


@dataclass(frozen=True)
class StepConfig:
    """Step-level channel learning.

    Attributes:
        channels: which of :data:`STEP_CHANNELS` the learner may use (default: all but
            ``time`` and ``lift``).
        c_max: box half-width per channel in :data:`STEP_CHANNELS` order
            [m, m, rad, m, m, fraction of the step's duration, m].
            ``dy`` only goes outwards: the feet of a HOAP-2-class robot pass a centimetre
            apart, and a narrower step lands one foot on the other. ``lift`` goes both
            ways, by at most 0.02 m (the plan's swing is about 15 mm high).
        weights: λ per :data:`STEP_STATE` dimension of the step objective (eq. 6 extended),
            on the deviation from the target state (the walk's own mean state, heading 0).
        effort: weight of Σ ((c − offset) / c_max)² in the objective.
        horizon: steps predicted ahead (later steps take the nominal channels: ``offset``).
        candidates: random candidates per decision (plus the nominal, ``offset``).
        explore: exploration noise, a fraction of c_max, in the first iteration at a scale.
        n_centers, ridge: of the step model's RBF network (which also has linear terms).
        ensemble: step models fitted to bootstrap resamples of the recorded episodes
            (:class:`~imitwalk.ensemble.ModelEnsemble`); a candidate is scored by its
            predicted gain over the nominal channels in the least favourable one (1: one
            model on all the data, scored as it predicts).
        margin: act only if every member predicts a gain over the nominal channels of at
            least this fraction of the nominal channels' own predicted cost (0: any gain).
            The model is least trustworthy where its predicted gains are small; a
            margin keeps the walk on the reference there.
        gain: the search's correction (its channel values minus ``offset``) is
            multiplied by this (a trust factor on the model's corrections: 1 applies them
            as predicted, 0 turns them off). The learner can pick it from measured
            trials (``LearnConfig.gains``).
        servo_state: add :data:`SERVO_STATE` to the step state (off by default). It is
            not in the objective (weight 0); the step model may use it to predict.
        offset: a constant value per channel in :data:`STEP_CHANNELS` order (empty: all
            0) that every step takes before the search's correction: the search's nominal
            candidate, the centre of its box and of the exploration noise. The learner
            picks it from measured trials (``LearnConfig.offsets``); units as ``c_max``.
        ramp_scale: the step model's stride-scale input follows the start-up: a step of
            the start-up, whose stride is still growing, is labelled with the schedule
            scale × its stride's fraction of a steady one (off: every step is labelled
            with the schedule scale, as in the first releases).
    """

    channels: tuple[str, ...] = ("dx", "dy", "yaw", "sway", "lean")
    c_max: tuple[float, ...] = (0.015, 0.012, 0.04, 0.008, 0.01, 0.15, 0.005)
    weights: tuple[float, ...] = (20.0, 20.0, 2.0, 0.5, 0.5, 0.5, 0.0, 0.0)
    effort: float = 0.05
    horizon: int = 2
    candidates: int = 256
    explore: float = 0.3
    n_centers: int = 24
    ridge: float = 1e-2
    ensemble: int = 1
    margin: float = 0.0
    gain: float = 1.0
    servo_state: bool = False
    offset: tuple[float, ...] = ()
    ramp_scale: bool = False

    @property
    def state_names(self) -> tuple[str, ...]:
        """The step state's names, in order."""
        return STEP_STATE + (SERVO_STATE if self.servo_state else ())

    @property
    def offset_vector(self) -> np.ndarray:
        """``(len(STEP_CHANNELS),)`` the constant channel values (zeros if none) [c_max units]."""
        return np.zeros(len(STEP_CHANNELS)) if not self.offset else np.asarray(self.offset, float)

    @property
    def state_weights(self) -> np.ndarray:
        """``(len(state_names),)`` λ of the step objective (0 for :data:`SERVO_STATE`)."""
        w = np.zeros(len(self.state_names))
        w[: len(STEP_STATE)] = self.weights
        return w

    def __post_init__(self):
        for c in self.channels:
            if c not in STEP_CHANNELS:
                raise unknown_name("step channel", c, STEP_CHANNELS, ConfigError)
        if len(self.c_max) == ALWAYS_DRAWN:  # a run written before the time channel
            c_max = list(self.c_max)
            c_max.insert(TIME, 0.0)
            object.__setattr__(self, "c_max", tuple(c_max))
        for key in ("c_max", "offset"):  # a run written before the lift channel: lift 0
            if len(getattr(self, key)) == LIFT:
                object.__setattr__(self, key, (*getattr(self, key), 0.0))
        if len(self.c_max) != len(STEP_CHANNELS):
            raise ConfigError(
                f"step.c_max has {len(self.c_max)} values: expected one per channel of "
                f"{', '.join(STEP_CHANNELS)}"
            )
        if "time" in self.channels and not 0.0 <= self.c_max[TIME] < 0.5:
            raise ConfigError(f"step.c_max for time={self.c_max[TIME]}: expected 0 <= c < 0.5")
        if "lift" in self.channels and not 0.0 <= self.c_max[LIFT] <= 0.02:
            raise ConfigError(f"step.c_max for lift={self.c_max[LIFT]}: expected 0 <= c <= 0.02 m")
        if not 0.0 <= self.margin < 1.0:
            raise ConfigError(f"step.margin={self.margin}: expected 0 <= margin < 1")
        if len(self.weights) != len(STEP_STATE):
            raise ConfigError(
                f"step.weights has {len(self.weights)} values: expected one per state entry of "
                f"{', '.join(STEP_STATE)}"
            )
        if self.offset:
            if len(self.offset) != len(STEP_CHANNELS):
                raise ConfigError(
                    f"step.offset has {len(self.offset)} values: expected one per channel of "
                    f"{', '.join(STEP_CHANNELS)}"
                )
            for name, v, hi in zip(STEP_CHANNELS, self.offset, self.c_max, strict=True):
                on = name in self.channels
                lo = 0.0 if name == "dy" else -hi
                if v != 0.0 and not (on and lo <= v <= hi):
                    why = f"outside {lo:g}..{hi:g} (step.c_max)" if on else "not in step.channels"
                    raise ConfigError(f"step.offset for {name}={v:g}: {why}")
        if not 0.0 <= self.gain <= 2.0:
            raise ConfigError(f"step.gain={self.gain}: expected 0 <= gain <= 2")
