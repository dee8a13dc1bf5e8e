"""Settings of the paper's own learner (the ``faithful`` variant, :mod:`imitwalk.paper.learner`).

``faithful`` is the paper as written: k = 3 principal components, the data's angle as
the phase, the 2nd-order RBF model of the gyro (eqs. 3–4), and the per-tick predictive
search over actions (φ, r, h) in the local box of eqs. 9–13, learned on the nominal
robot with the scale schedule of §6. It is kept as the reproduction; the default
learner is the per-tick balance learner (:mod:`imitwalk.balance.ticklearn`).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import ClassVar

from imitwalk.config import schedule_scales
from imitwalk.errors import ConfigError, unknown_name
from imitwalk.paper.gait import GaitConfig
from imitwalk.sim.types import ENGINES

__all__ = ["LearnConfig", "ScheduleConfig", "TickConfig"]


@dataclass(frozen=True)
class ScheduleConfig:
    """The scale schedule (paper §6: start small, where the motion is stable, scale up).

    Attributes:
        start, step, stop: scales tried, in order.
        iterations: execute/record/retrain iterations per scale (the paper: three).
        seconds: simulated time per episode [s], start-up from standing included.
        retries: more attempts at a scale after a fall before learning stops.
    """

    start: float = 0.3
    step: float = 0.1
    stop: float = 1.0
    iterations: int = 3
    seconds: float = 12.0
    retries: int = 3

    def scales(self) -> tuple[float, ...]:
        """The schedule's scales."""
        return schedule_scales(self.start, self.step, self.stop)


@dataclass(frozen=True)
class TickConfig:
    """The paper's per-tick model-predictive search (§5).

    Attributes:
        weights: λ of eq. (6) per gyro axis.
        eps_phi: ε_φ as a multiple of the nominal phase step per tick (eq. 9).
        eps_r, eps_h: ε_r, ε_h as fractions of the loop's mean radius (eqs. 10-11).
        grid: (n_φ, n_r, n_h) candidates; horizon: ticks predicted ahead.
        explore: noise on (r, h), a fraction of (ε_r, ε_h), in a scale's first iteration.
        n_centers, ridge: of the gyro model's RBF network.
    """

    weights: tuple[float, ...] = (1.0, 1.0, 1.0)
    eps_phi: float = 2.0
    eps_r: float = 0.05
    eps_h: float = 0.05
    grid: tuple[int, ...] = (5, 5, 5)
    horizon: int = 1
    explore: float = 0.5
    n_centers: int = 40
    ridge: float = 1e-3


@dataclass(frozen=True)
class LearnConfig:
    """Everything a faithful learning run depends on (with the seed, it fixes the result).

    Attributes:
        gait: representation; schedule: scales; tick: the paper's per-tick search.
        train_models: robots per iteration: the nominal one + training perturbations.
        seed: random seed; workers: parallel processes (``None``: one per core).
        engine: the physics engine the robot learns on (:data:`imitwalk.sim.types.ENGINES`).
    """

    CHOICES: ClassVar[dict] = {"engine": ENGINES}

    gait: GaitConfig = field(default_factory=GaitConfig)
    schedule: ScheduleConfig = field(default_factory=ScheduleConfig)
    tick: TickConfig = field(default_factory=TickConfig)
    train_models: int = 1
    seed: int = 0
    workers: int | None = None
    engine: str = "mujoco"

    def __post_init__(self) -> None:
        if self.engine not in ENGINES:
            raise unknown_name("engine", self.engine, ENGINES, ConfigError)
        if self.train_models < 1:
            raise ConfigError(f"train_models={self.train_models}: expected at least 1")
