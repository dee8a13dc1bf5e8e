"""Settings of the learning loop, and the two named variants.

``faithful`` is the paper as written: k = 3 principal components, the data's angle as
the phase, the 2nd-order RBF model of the gyro, and the per-tick predictive search in
the local box of eqs. 9–13, learned on the nominal robot. ``extended`` keeps that
structure and adds, each as its own option: k = 6, the time phase, the reference's
posture outside the subspace added back (so the nominal action is the reference), the step-level
balance channels with their own step model and search (:mod:`imitwalk.balance`), a
bootstrap ensemble of step models that the search must all convince
(:mod:`imitwalk.ensemble`), training on perturbed robots as well as the nominal one, and
the channel gain picked by measured trials (:mod:`imitwalk.trust`); the cadence can be
picked the same way (``cadences``, off: on our clips it kept the human's).
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import ClassVar

from imitwalk.errors import ConfigError, unknown_name
from imitwalk.gait import GaitConfig
from imitwalk.perturb import FRICTION_RANGE
from imitwalk.simtypes import ENGINES
from imitwalk.stepconfig import STEP_CHANNELS, StepConfig

__all__ = ["BACK_OFF_EVIDENCE", "VARIANTS", "LearnConfig", "ScheduleConfig", "TickConfig", "preset"]


#: What the back-off (``LearnConfig.back_off_when``) may act on.
BACK_OFF_EVIDENCE = ("consolidation", "trials")


@dataclass(frozen=True)
class ScheduleConfig:
    """The scale schedule (paper §6: start small, where the motion is stable, scale up).

    Attributes:
        start, step, stop: scales tried, in order.
        iterations: execute/record/retrain iterations per scale (the paper: three).
        seconds: simulated time per episode [s], start-up from standing included.
        retries: more attempts at a scale after a fall before learning stops.
        consolidate: iterations at the scale reached once the schedule has stopped.
        confirm: consecutive fall-free iterations without exploration that pass a scale
            (the paper: one).
    """

    start: float = 0.3
    step: float = 0.1
    stop: float = 1.0
    iterations: int = 3
    seconds: float = 12.0
    retries: int = 3
    consolidate: int = 0
    confirm: int = 1

    def scales(self) -> tuple[float, ...]:
        """The schedule's scales."""
        n = int(round((self.stop - self.start) / self.step)) + 1
        return tuple(round(self.start + i * self.step, 6) for i in range(max(n, 1)))


@dataclass(frozen=True)
class TickConfig:
    """The paper's per-tick model-predictive search (§5).

    Attributes:
        enabled: search each tick (else follow the nominal actions).
        state: ``"gyro"`` (the paper's ω) or ``"full"`` (ω, roll, pitch).
        weights: λ of eq. (6) per state dimension.
        eps_phi: ε_φ as a multiple of the nominal phase step per tick (eq. 9).
        eps_r, eps_h: ε_r, ε_h as fractions of the loop's mean radius (eqs. 10-11).
        grid: (n_φ, n_r, n_h) candidates; horizon: ticks predicted ahead.
        explore: noise on (r, h), a fraction of (ε_r, ε_h), in a scale's first iteration.
        n_centers, ridge: of the gyro model's RBF network.
    """

    CHOICES: ClassVar[dict] = {"state": ("gyro", "full")}

    enabled: bool = True
    state: str = "gyro"
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
    """Everything a learning run depends on (with the seed, it fixes the result).

    Attributes:
        variant: the preset these settings started from (a label).
        gait: representation; schedule: scales; tick: the paper's per-tick search.
        steps: use the step-level balance channels; step: their settings.
        train_models: robots per iteration: the nominal one + training perturbations.
        fresh_robots: draw new training perturbations at every iteration (else the same
            ones throughout); a scale then passes only on robots it has not learned on.
        train_friction: the range the training and trial robots draw their floor friction
            from (the evaluation robots draw from 0.7-1.0; the nominal robot's is 1.0).
        gains: candidate channel gains tried once the schedule has ended, each on the
            same ``gain_robots`` robots for ``gain_seconds``; the one that measures best
            is kept (:mod:`imitwalk.trust`). Empty: keep ``step.gain``.
        cadences: candidate cadence rates (the loop played that many times as fast,
            :func:`imitwalk.retarget.cadence.with_cadence`) tried after the gains, with
            the gain kept, on the same robots; list the human's own rate, 1, first.
            Empty: the reference's cadence.
        offsets: candidate constant values of the channel ``offset_channel`` (its
            ``step.offset``), tried on the ``gain_robots`` when the schedule would stop at
            a scale; if another value measures better there, the schedule goes on at that
            scale with it. The scale reached gets the same trials before the gain trials
            (once per scale). Empty: off.
        offset_channel: the channel those offsets are for (one of ``step.channels``).
        stratify_trials: the ``gain_robots`` trial robots' floor frictions cover
            ``train_friction`` evenly, one per band (:func:`imitwalk.perturb.trial_seeds`),
            instead of being the first trial seeds' draws. Off by default.
        back_off_to: a scale, or ``None`` (off). If set, and the gain kept by the trials
            at the top scale passed still falls on some trial robot, the same gain trials
            run one passed scale lower; if the best gain there falls on fewer trial
            robots, the walk settles there (and the search goes on lower while it still
            falls), never below this scale. The scale settled at is ``scale_reached``
            (:func:`imitwalk.tuning.back_off`). Needs ``gains``.
        back_off_when: the evidence the back-off acts on (:data:`BACK_OFF_EVIDENCE`):
            ``"trials"``, the gain trials above; ``"consolidation"``, the consolidation
            iterations at the scale reached: if they fall on any training robot, the
            scale is given back and the consolidation runs again one passed scale lower
            (never below ``back_off_to``; needs ``schedule.consolidate``), before the gain
            trials (:func:`imitwalk.tuning.give_back_scale`). Default: the trials only.
        seed: random seed; workers: parallel processes (``None``: one per core).
        engine: the physics engine the robot learns on (:data:`imitwalk.simtypes.ENGINES`;
            ``bullet`` is about ten times slower than MuJoCo).
    """

    variant: str = "extended"
    gait: GaitConfig = field(default_factory=GaitConfig)
    schedule: ScheduleConfig = field(default_factory=ScheduleConfig)
    tick: TickConfig = field(default_factory=TickConfig)
    steps: bool = True
    step: StepConfig = field(default_factory=StepConfig)
    train_models: int = 3
    fresh_robots: bool = False
    train_friction: tuple[float, float] = FRICTION_RANGE
    gains: tuple[float, ...] = ()
    cadences: tuple[float, ...] = ()
    offsets: tuple[float, ...] = ()
    offset_channel: str = "dx"
    gain_robots: int = 12
    gain_seconds: float = 24.0
    stratify_trials: bool = False
    back_off_to: float | None = None
    back_off_when: tuple[str, ...] = ("trials",)
    seed: int = 0
    workers: int | None = None
    engine: str = "mujoco"

    def __post_init__(self):
        if self.engine not in ENGINES:
            raise unknown_name("engine", self.engine, ENGINES, ConfigError)
        for g in self.gains:  # each candidate must be a valid step.gain (its check)
            replace(self.step, gain=g)
        for r in self.cadences:
            if not 0.5 <= r <= 2.0:
                raise ConfigError(f"cadences: {r} is not a rate in 0.5..2")
        if self.steps and "time" in self.step.channels and self.tick.enabled:
            raise ConfigError(
                "step channel 'time' needs tick.enabled=false: the per-tick search acts "
                "on the plan's ticks, which the time channel stretches"
            )
        lo_hi = tuple(self.train_friction)
        if len(lo_hi) != 2 or not 0.0 < lo_hi[0] <= lo_hi[1] <= 3.0:
            raise ConfigError(
                f"train_friction={self.train_friction}: expected two values 0 < low <= high <= 3"
            )
        if self.offsets:
            if self.offset_channel not in self.step.channels:
                raise unknown_name(
                    "offset_channel", self.offset_channel, self.step.channels, ConfigError
                )
            for v in self.offsets:  # each candidate must be a valid step.offset
                self._step_with_offset(v)
        if self.back_off_to is not None and not (self.gains and self.steps):
            raise ConfigError("back_off_to needs the gain trials: set gains (and steps=true)")
        if self.back_off_to is not None and not 0.0 < self.back_off_to <= 2.0:
            raise ConfigError(f"back_off_to={self.back_off_to}: expected a scale in 0..2")
        for what in self.back_off_when:
            if what not in BACK_OFF_EVIDENCE:
                raise unknown_name("back_off_when", what, BACK_OFF_EVIDENCE, ConfigError)
        if self.back_off_to is None and tuple(self.back_off_when) != ("trials",):
            raise ConfigError("back_off_when needs back_off_to: the lowest scale to give back to")
        if self.back_off_to is not None and not self.back_off_when:
            raise ConfigError(f"back_off_when is empty: list one or more of {BACK_OFF_EVIDENCE}")
        if "consolidation" in self.back_off_when and self.schedule.consolidate < 1:
            raise ConfigError("back_off_when=consolidation needs schedule.consolidate >= 1")
        if (self.gains or self.cadences or self.offsets) and self.gain_robots < 1:
            raise ConfigError(f"gain_robots={self.gain_robots}: expected at least 1")

    def with_offset(self, value: float | None) -> LearnConfig:
        """These settings with ``step.offset`` set to ``value`` on ``offset_channel``
        (``None``: unchanged)."""
        return self if value is None else replace(self, step=self._step_with_offset(value))

    def _step_with_offset(self, value: float) -> StepConfig:
        off = self.step.offset_vector
        off[STEP_CHANNELS.index(self.offset_channel)] = value
        return replace(self.step, offset=tuple(float(v) for v in off))


VARIANTS: dict[str, LearnConfig] = {
    "faithful": LearnConfig(
        variant="faithful",
        gait=GaitConfig(n_components=3, phase_source="angle"),
        tick=TickConfig(enabled=True),
        steps=False,
        train_models=1,
    ),
    "extended": LearnConfig(
        variant="extended",
        gait=GaitConfig(n_components=6, phase_source="time", residual=True),
        schedule=ScheduleConfig(seconds=16.0, retries=6, consolidate=2, confirm=2),
        tick=TickConfig(enabled=False),
        steps=True,
        step=StepConfig(ensemble=5),
        train_models=6,
        fresh_robots=True,
        gains=(0.0, 0.5, 1.0),
    ),
}


def preset(name: str, **changes) -> LearnConfig:
    """The named variant's settings, with ``changes`` applied."""
    if name not in VARIANTS:
        raise unknown_name("variant", name, VARIANTS, ConfigError)
    return replace(VARIANTS[name], **changes)
