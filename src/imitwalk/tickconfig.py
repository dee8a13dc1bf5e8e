"""Settings of the per-tick balance learner (:mod:`imitwalk.ticklearn`).

The defaults are the measured best (docs/RESULTS.md gives the measurements). Every
range here is a search range or a budget; no gain is set by hand.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from imitwalk.errors import ConfigError
from imitwalk.protocol import load_protocol
from imitwalk.simtypes import ENGINES

__all__ = ["LqrConfig", "TickLearnConfig", "TrialConfig"]


def _range(name: str, values, lo: float, hi: float) -> None:
    if not values:
        raise ConfigError(f"{name}: give at least one value in {lo:g}..{hi:g}")
    for v in values:
        if not lo <= v <= hi:
            raise ConfigError(f"{name}: {v:g} is outside the valid range {lo:g}..{hi:g}")


@dataclass(frozen=True)
class TrialConfig:
    """The trial-picked feedback law: each gain chosen in turn from its candidates by
    trials on training robots (:class:`imitwalk.ticklearn.Trial`: fewest falls where
    robots walk, then fewest falls on hard robots and the longest walks before them,
    then the least measured eq.-6 cost Γ, or for the heading gain the least |yaw|).
    The signs searched follow the joints' conventions (x forward, y left, z up): a
    positive ankle offset on a positive gyro rate pushes back against the fall.

    Attributes:
        pitch: candidate gains gyro_y → ankle_pitch [rad per rad/s].
        roll: candidate gains gyro_x → ankle_roll [rad per rad/s].
        heading: candidate gains heading → turn [rad of turn per step per rad of heading
            error]; a negative gain steers back.
        box: each channel's limit [rad].
        robots, seconds: robots of each protocol per candidate (``robots`` from the
            schedule's, as many from ``trial_protocol``) and simulated time each [s].
    """

    pitch: tuple[float, ...] = (0.0, 0.05, 0.1, 0.2)
    roll: tuple[float, ...] = (0.0, 0.05, 0.1, 0.2)
    heading: tuple[float, ...] = (-1.0, -0.5, -0.25, 0.0)
    box: float = 0.15
    robots: int = 4
    seconds: float = 12.0

    def __post_init__(self):
        _range("trials.pitch", self.pitch, -0.5, 0.5)
        _range("trials.roll", self.roll, -0.5, 0.5)
        _range("trials.heading", self.heading, -2.0, 2.0)
        _range("trials.box", (self.box,), 0.0, 0.5)
        _range("trials.robots", (self.robots,), 1, 1000)
        _range("trials.seconds", (self.seconds,), 1.0, 600.0)


@dataclass(frozen=True)
class LqrConfig:
    """The paper's loop per tick: a model of eqs. 3–4 and receding-horizon gains.

    Attributes:
        enabled: learn the model-based law on top of the trial-picked one.
        channels: what it acts on; features: its model's states.
        state_cost: λ per state (eq. 6's on the gyro, then the tilt's) [per unit²].
        action_cost, change_cost: ρ and σ [per rad²]; horizon: ticks looked ahead.
        width, ridge: the model's phase kernels [ticks] and regularisation.
        explore: exploration amplitude [rad] in a scale's first iteration.
        box: each channel's limit [rad].
        trust: the fractions of the learned law tried at the top scale (its gains ×
            each); the one that falls least, then costs least, is kept.
    """

    enabled: bool = True
    channels: tuple[str, ...] = ("l_ankle_pitch", "r_ankle_pitch", "l_ankle_roll", "r_ankle_roll")
    features: tuple[str, ...] = ("gyro_x", "gyro_y", "gyro_z", "roll", "pitch")
    state_cost: tuple[float, ...] = (1.0, 1.0, 1.0, 30.0, 30.0)
    action_cost: float = 300.0
    change_cost: float = 100.0
    horizon: int = 20
    width: float = 2.0
    ridge: float = 1e-4
    explore: float = 0.02
    box: float = 0.15
    trust: tuple[float, ...] = (0.0, 0.5, 1.0)

    def __post_init__(self):
        if len(self.state_cost) != len(self.features):
            raise ConfigError(
                f"lqr.state_cost has {len(self.state_cost)} weights for "
                f"{len(self.features)} features ({', '.join(self.features)})"
            )
        _range("lqr.explore", (self.explore,), 0.0, 0.2)
        _range("lqr.box", (self.box,), 0.0, 0.5)
        _range("lqr.trust", self.trust, 0.0, 2.0)
        _range("lqr.width", (self.width,), 0.1, 100.0)
        _range("lqr.horizon", (self.horizon,), 1, 1000)


@dataclass(frozen=True)
class TickLearnConfig:
    """The per-tick learner (paper §5 steps 3–7 with §6's scale schedule).

    Attributes:
        start, step, stop: the scale schedule (the paper starts at 0.3).
        iterations: most iterations per scale before learning stops there; a scale is
            passed by an iteration without exploration in which no training robot falls.
        robots: training robots per iteration; seconds: simulated time each [s].
        train_protocol: the protocol the schedule's training robots are drawn from;
            trial_protocol: the one the trials' robots are drawn from (both with seeds no
            evaluation uses).
        trials: the trial-picked law; lqr: the model-based law.
        seed: random seed; workers: processes (``None``: one per core); engine: the
            physics engine learned on.
    """

    start: float = 0.3
    step: float = 0.1
    stop: float = 1.0
    iterations: int = 3
    robots: int = 4
    seconds: float = 12.0
    train_protocol: str = "eval"
    trial_protocol: str = "hard"
    trials: TrialConfig = field(default_factory=TrialConfig)
    lqr: LqrConfig = field(default_factory=LqrConfig)
    seed: int = 0
    workers: int | None = None
    engine: str = "mujoco"

    def __post_init__(self):
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
        load_protocol(self.train_protocol)  # a one-line error if unknown
        load_protocol(self.trial_protocol)

    def scales(self) -> tuple[float, ...]:
        """The schedule's scales."""
        n = int(round((self.stop - self.start) / self.step)) + 1
        return tuple(round(min(self.start + i * self.step, self.stop), 6) for i in range(n))
