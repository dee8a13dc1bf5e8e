"""Settings of the per-tick balance learner (:mod:`imitwalk.balance.ticklearn`).

The defaults are the measured best (docs/RESULTS.md gives the measurements). Every
range here is a search range or a budget; no gain is set by hand.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

from imitwalk.balance.channels import CHANNELS, FEATURES, PHASED, check_names
from imitwalk.config import schedule_scales
from imitwalk.errors import ConfigError
from imitwalk.sim.protocol import load_protocol
from imitwalk.sim.seeds import TRAIN_FIRST, VALIDATION_FIRST
from imitwalk.sim.types import ENGINES

__all__ = ["STATE_COSTS", "ChoiceConfig", "LqrConfig", "TickLearnConfig", "TrialConfig"]

#: The model-based law's default λ per feature [per unit²]: eq. 6's 1 on each gyro axis
#: [(rad/s)²], and 30 on each tilt and the heading [rad²] (a 0.1 rad tilt costs as much as
#: a 0.55 rad/s rotation).
STATE_COSTS = {
    "gyro_x": 1.0,
    "gyro_y": 1.0,
    "gyro_z": 1.0,
    "roll": 30.0,
    "pitch": 30.0,
    "heading": 30.0,
}


def _range(name: str, values: Sequence[float], lo: float, hi: float) -> None:
    if not values:
        raise ConfigError(f"{name}: give at least one value in {lo:g}..{hi:g}")
    for v in values:
        if not lo <= v <= hi:
            raise ConfigError(f"{name}: {v:g} is outside the valid range {lo:g}..{hi:g}")


@dataclass(frozen=True)
class TrialConfig:
    """The trial-picked feedback law: each gain chosen in turn from its candidates by
    trials on training robots (:class:`imitwalk.balance.ticklearn.Trial`): the fewest falls,
    then, for the heading gain, the least mean |yaw| (plus one standard error) beyond
    ``yaw_limit_deg``, then the smallest gain (the least feedback that does as well: the
    one-standard-error rule of model selection, at a standard error of zero falls). The
    signs searched follow the joints' conventions (x forward, y left, z up): a positive
    ankle offset on a positive gyro rate pushes back against the fall.

    Attributes:
        feedforward: candidate fractions of the servo feedforward added to the reference
            (:mod:`imitwalk.retarget.feedforward`), tried first, with no feedback.
        wait: candidate load shares above which the reference's clock waits before a
            lift-off (0: it never waits; :class:`~imitwalk.balance.feedback.TickPolicy`),
            tried next, with no feedback.
        pitch: candidate gains gyro_y → ankle_pitch [rad per rad/s].
        roll: candidate gains gyro_x → ankle_roll [rad per rad/s].
        heading: candidate gains heading → turn [rad of turn per step per rad of heading
            error]; a negative gain steers back.
        torso: candidate gains pitch → hip_pitch [rad per rad]: the torso's measured
            pitch less the nominal robot's at that loop tick, fed to both hip pitches; a
            negative gain leans a torso that pitches forward back.
        tilt: candidate gains pitch → ankle_pitch [rad per rad]: the same measured pitch
            less the nominal robot's, fed to both ankle pitches, which tilt the whole
            body; a positive gain pitches a body that leans forward back. The gyro_y
            gain damps a fall; this one holds the lean against a steady push (a slope, a
            sagging servo), which the gyro's rate does not see. On validation robots
            0.1 did no better than 0.2 on any clip and 0.5 fell more than 0.2 on 07_04
            (docs/RESULTS.md), so neither is a candidate.
        tilt_protocol: the protocol the tilt gain's training robots are drawn from: on
            ``servo``'s flat floors trials of a few robots rarely see what it is for
            (``slope``: ``servo``'s robots on the hard protocol's slopes).
        balance_protocol: the protocol the training robots of the reference's settings
            and of the balance gains (pitch, roll, torso) are drawn from (a shipped name
            or a ``.json``): on ``eval``'s, trials of a few robots see no falls under any
            candidate, and 07_04 keeps no roll gain where the validation robots show it
            needs one (docs/RESULTS.md). The settings' last kept walks, with no feedback,
            are the pitch gain's first candidate's.
        yaw_limit_deg: the mean |yaw drift| a walk of ``heading_seconds`` may keep [deg]
            (the acceptance's 10° in 30 s), with one standard error of the trial's mean
            to spare.
        box: each channel's limit [rad].
        robots, seconds: training robots per candidate (the reference's settings and
            the balance gains) and simulated time each [s]; 20 s walks, where 10 s ones
            on twice the robots kept a pitch gain that fells 07_06 (docs/RESULTS.md).
        heading_robots, heading_seconds: the same for the heading's candidates (whole
            walks: how far a walk drifts depends on how long it walks, and not in
            proportion).
    """

    feedforward: tuple[float, ...] = (0.0, 0.5, 1.0)
    wait: tuple[float, ...] = (0.0, 0.3)
    pitch: tuple[float, ...] = (0.0, 0.05, 0.1, 0.2)
    roll: tuple[float, ...] = (0.0, 0.05, 0.1)
    heading: tuple[float, ...] = (0.0, -0.25, -0.5)
    torso: tuple[float, ...] = (0.0, -0.15, -0.3)
    tilt: tuple[float, ...] = (0.0, 0.2, 0.3)
    tilt_protocol: str = "slope"
    balance_protocol: str = "servo"
    yaw_limit_deg: float = 10.0
    box: float = 0.15
    robots: int = 7
    seconds: float = 20.0
    heading_robots: int = 6
    heading_seconds: float = 30.0

    def __post_init__(self) -> None:
        _range("trials.feedforward", self.feedforward, 0.0, 1.0)
        _range("trials.wait", self.wait, 0.0, 0.95)
        _range("trials.pitch", self.pitch, -0.5, 0.5)
        _range("trials.roll", self.roll, -0.5, 0.5)
        _range("trials.heading", self.heading, -2.0, 2.0)
        _range("trials.torso", self.torso, -1.0, 1.0)
        _range("trials.tilt", self.tilt, -1.0, 1.0)
        load_protocol(self.balance_protocol)  # a one-line error if unknown
        load_protocol(self.tilt_protocol)
        _range("trials.yaw_limit_deg", (self.yaw_limit_deg,), 0.0, 180.0)
        _range("trials.box", (self.box,), 0.001, 0.5)
        _range("trials.robots", (self.robots,), 1, 1000)
        _range("trials.seconds", (self.seconds,), 1.0, 600.0)
        _range("trials.heading_robots", (self.heading_robots,), 1, 1000)
        _range("trials.heading_seconds", (self.heading_seconds,), 1.0, 600.0)


@dataclass(frozen=True)
class LqrConfig:
    """The paper's loop per tick: a model of eqs. 3–4 and receding-horizon gains.

    Attributes:
        enabled: learn the model-based law on top of the trial-picked one.
        channels: what it acts on; features: its model's states.
        state_cost: λ per feature, in ``features`` order [per unit²] (empty: each
            feature's :data:`STATE_COSTS`).
        action_cost, change_cost: ρ and σ [per rad²]; horizon: ticks looked ahead.
        width, ridge: the model's phase kernels [ticks] and regularisation.
        explore: exploration amplitude [rad] in a scale's first iteration.
        box: each channel's limit [rad].
        trust: the fractions of the learned law tried at the trials' scale (its gains ×
            each), the smallest first; the smallest that falls least is kept.
    """

    enabled: bool = True
    channels: tuple[str, ...] = ("l_ankle_pitch", "r_ankle_pitch", "l_ankle_roll", "r_ankle_roll")
    features: tuple[str, ...] = ("gyro_x", "gyro_y", "gyro_z", "roll", "pitch")
    state_cost: tuple[float, ...] = ()
    action_cost: float = 300.0
    change_cost: float = 100.0
    horizon: int = 20
    width: float = 2.0
    ridge: float = 1e-4
    explore: float = 0.02
    box: float = 0.15
    trust: tuple[float, ...] = (0.0, 1.0)

    def __post_init__(self) -> None:
        check_names("lqr channel", self.channels, [c for c in CHANNELS if c not in PHASED])
        check_names("lqr feature", self.features, FEATURES)
        if self.state_cost and len(self.state_cost) != len(self.features):
            raise ConfigError(
                f"lqr.state_cost has {len(self.state_cost)} weights for "
                f"{len(self.features)} features ({', '.join(self.features)})"
            )
        if self.state_cost:
            _range("lqr.state_cost", self.state_cost, 0.0, 1e6)
        _range("lqr.explore", (self.explore,), 0.0, 0.2)
        _range("lqr.box", (self.box,), 0.001, 0.5)
        _range("lqr.action_cost", (self.action_cost,), 1e-6, 1e6)
        _range("lqr.change_cost", (self.change_cost,), 0.0, 1e6)
        _range("lqr.ridge", (self.ridge,), 0.0, 1e3)
        _range("lqr.trust", self.trust, 0.0, 2.0)
        _range("lqr.width", (self.width,), 0.1, 100.0)
        _range("lqr.horizon", (self.horizon,), 1, 1000)

    def costs(self) -> tuple[float, ...]:
        """λ per feature: ``state_cost``, or each feature's :data:`STATE_COSTS`."""
        return tuple(self.state_cost) or tuple(STATE_COSTS[f] for f in self.features)


@dataclass(frozen=True)
class ChoiceConfig:
    """The reference choice of ``imitwalk learn CLIP`` (:mod:`imitwalk.learning.refchoice`).

    Attributes:
        robots: the training robots each pass's learned controller walks (0: no second
            pass; the open-loop search's reference is learned and kept, as where the
            reference is not searched at all). seconds:
            simulated time each [s]. first: the first robot's seed, a training robot
            (:data:`~imitwalk.sim.seeds.TRAIN_FIRST` … below
            :data:`~imitwalk.sim.seeds.VALIDATION_FIRST`: no evaluation or validation robot).
    """

    robots: int = 40
    seconds: float = 30.0
    first: int = TRAIN_FIRST

    def __post_init__(self) -> None:
        _range("choice.robots", (self.robots,), 0, 1000)
        _range("choice.seconds", (self.seconds,), 1.0, 600.0)
        _range("choice.first", (self.first,), TRAIN_FIRST, VALIDATION_FIRST - max(self.robots, 1))


@dataclass(frozen=True)
class TickLearnConfig:
    """The per-tick learner (paper §5 steps 3–7 with §6's scale schedule).

    Attributes:
        start, step, stop: the scale schedule (the paper starts at 0.3).
        iterations: most iterations per scale before learning stops there; a scale is
            passed by an iteration without exploration in which no training robot falls.
        robots: training robots per iteration; seconds: simulated time each [s].
        train_protocol: the protocol the training robots (the trials' and the
            schedule's) are drawn from, with seeds no evaluation uses.
        trials: the trial-picked law; lqr: the model-based law; choice: the reference
            choice of ``imitwalk learn CLIP`` (a given reference is learned as it is).
        seed: random seed; workers: processes (``None``: one per core); engine: the
            physics engine learned on.
    """

    start: float = 0.3
    step: float = 0.1
    stop: float = 1.0
    iterations: int = 3
    robots: int = 4
    seconds: float = 6.0
    train_protocol: str = "eval"
    trials: TrialConfig = field(default_factory=TrialConfig)
    lqr: LqrConfig = field(default_factory=LqrConfig)
    choice: ChoiceConfig = field(default_factory=ChoiceConfig)
    seed: int = 0
    workers: int | None = None
    engine: str = "mujoco"

    def __post_init__(self) -> None:
        if self.engine not in ENGINES:
            raise ConfigError(f"engine {self.engine!r}; valid: {', '.join(ENGINES)}")
        if not 0.0 < self.start <= self.stop <= 2.0 or not self.step > 0:
            raise ConfigError(
                f"schedule start={self.start}, step={self.step}, stop={self.stop}: "
                "expected 0 < start <= stop <= 2 and step > 0"
            )
        _range("iterations", (self.iterations,), 1, 100)
        _range("robots", (self.robots,), 1, 1000)
        _range("seconds", (self.seconds,), 1.0, 600.0)
        if self.workers is not None:
            _range("workers", (self.workers,), 1, 256)
        load_protocol(self.train_protocol)  # a one-line error if unknown

    def scales(self) -> tuple[float, ...]:
        """The schedule's scales."""
        return schedule_scales(self.start, self.step, self.stop)
