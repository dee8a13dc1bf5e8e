"""The parts of a walking environment that do not change between episodes.

:class:`WalkConfig` is what a user chooses (clip, robot, protocol, action mode, ...);
:func:`build_setup` turns it into a :class:`WalkSetup`: the robot, the clip's stepping
style and the gains of the stepping gait a residual policy adds to, the tracking target
(:mod:`imitwalk.envs.tracking`), the protocol that draws each episode's robot, and the
observation layout. Every choice is checked here, in one line each.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, fields
from typing import TYPE_CHECKING

import numpy as np

from imitwalk.envs.rewards import TERMS, RewardWeights
from imitwalk.envs.tracking import TrackingTarget
from imitwalk.errors import ConfigError, unknown_name
from imitwalk.rl.observation import ACTIONS, ObservationLayout
from imitwalk.robots import Robot
from imitwalk.sim.protocol import Protocol, load_protocol
from imitwalk.sim.seeds import TRAIN_FIRST
from imitwalk.step.gains import StepGains
from imitwalk.step.gait import StepGait
from imitwalk.step.style import GaitStyle

if TYPE_CHECKING:
    from imitwalk.mocap import Motion

__all__ = ["BOX", "MAX_SECONDS", "TRAIN_ROBOTS", "WalkConfig", "WalkSetup", "build_setup"]

#: The action box's default half-width [rad] by action mode.
BOX = {"residual": 0.15, "joints": 0.5}
#: How many training robots an episode draws from (seeds ``TRAIN_FIRST`` on, which no
#: judge uses).
TRAIN_ROBOTS = 100_000
#: The longest episode [s]: one simulated hour (the tracking target holds every tick of it).
MAX_SECONDS = 3600.0


@dataclass(frozen=True)
class WalkConfig:
    """A walking environment's settings.

    Attributes:
        clip: a mocap file (``None``: the default clip); robot: a built-in robot's name
        or a joint-map file; protocol: a shipped protocol's name or a protocol file;
        action: one of :data:`~imitwalk.rl.observation.ACTIONS`; run: a stepping run
        folder whose style and learned gains a residual policy adds to (``None``: the
        clip's style with the gains imitwalk ships); seconds: an episode's length [s],
        at most :data:`MAX_SECONDS` (one simulated hour);
        box: the action box's half-width [rad] (``None``: :data:`BOX`'s for the mode),
        around zero (``residual``) or the standing posture (``joints``, as
        humanoid-gym's default pose plus a scaled action); previous_action:
        observe the last action (a bool); weights: the reward's, a
        :class:`RewardWeights` or its ``{term: weight}`` dictionary (``None``: the action
        mode's, :meth:`RewardWeights.for_action`); first_robot, robots: each episode's
        robot is drawn from protocol seeds ``first_robot … first_robot + robots − 1``.

    Every value is checked here (a one-line :class:`~imitwalk.errors.ConfigError`); a
    bool is not taken for a number.
    """

    clip: str | None = None
    robot: str = "hoap2"
    protocol: str = "eval"
    action: str = "residual"
    run: str | None = None
    seconds: float = 20.0
    box: float | None = None
    previous_action: bool = True
    weights: RewardWeights | None = None
    first_robot: int = TRAIN_FIRST
    robots: int = TRAIN_ROBOTS

    def __post_init__(self) -> None:
        if self.action not in ACTIONS:
            raise unknown_name("action", str(self.action), ACTIONS, ConfigError)
        for name in ("seconds", "box"):
            v = getattr(self, name)
            if name == "box" and v is None:
                continue
            if not _is_number(v) or not np.isfinite(v) or v <= 0:
                raise ConfigError(f"{name}={v!r}: must be a finite number > 0")
        if self.seconds > MAX_SECONDS:
            raise ConfigError(
                f"seconds={self.seconds!r}: an episode lasts at most {MAX_SECONDS:g} s "
                "(one simulated hour)"
            )
        if self.run is not None and self.clip is not None:
            raise ConfigError("give a clip or a stepping run (whose clip it walks), not both")
        if not _is_whole(self.robots) or self.robots < 1:
            raise ConfigError(f"robots={self.robots!r}: must be a whole number ≥ 1")
        if not _is_whole(self.first_robot) or self.first_robot < 0:
            raise ConfigError(f"first_robot={self.first_robot!r}: must be a whole number ≥ 0")
        if not isinstance(self.previous_action, bool):
            raise ConfigError(f"previous_action={self.previous_action!r}: must be True or False")
        if isinstance(self.weights, dict):  # as to_dict wrote it
            object.__setattr__(self, "weights", RewardWeights.from_dict(self.weights))
        elif self.weights is not None and not isinstance(self.weights, RewardWeights):
            raise ConfigError(
                f"weights={self.weights!r}: must be RewardWeights, a {{term: weight}} "
                f"dictionary (terms: {', '.join(TERMS)}) or None"
            )

    def to_dict(self) -> dict:
        """Plain-JSON dictionary (the keyword arguments of ``gym.make``)."""
        d = asdict(self)
        d["weights"] = None if self.weights is None else self.weights.to_dict()
        return d

    @classmethod
    def from_dict(cls, d: dict) -> WalkConfig:
        """What :meth:`to_dict` wrote (a one-line :class:`ConfigError` listing the
        settings for an unknown one)."""
        valid = [f.name for f in fields(cls)]
        for k in d:
            if k not in valid:
                raise unknown_name("environment setting", str(k), valid, ConfigError)
        return cls(**d)

    @property
    def reward_weights(self) -> RewardWeights:
        """The weights in use."""
        return self.weights or RewardWeights.for_action(self.action)


def _is_number(v: object) -> bool:
    """A real number, not a bool (``True`` is no length of time)."""
    return isinstance(v, int | float) and not isinstance(v, bool)


def _is_whole(v: object) -> bool:
    """A whole number, not a bool."""
    return isinstance(v, int) and not isinstance(v, bool)


@dataclass(frozen=True)
class WalkSetup:
    """A :class:`WalkConfig` resolved (see the module doc).

    Attributes:
        config: the settings; robot: the robot; gait: the clip's stepping gait at scale
        1 (:class:`~imitwalk.step.gait.StepGait`, its style and source); gains: the
        stepping gait's gains (the residual's base); target: the tracking target;
        protocol: draws each episode's robot; layout: the observation; low, high:
        ``(n,)`` the action box [rad].
    """

    config: WalkConfig
    robot: Robot
    gait: StepGait
    gains: StepGains
    target: TrackingTarget
    protocol: Protocol
    layout: ObservationLayout
    low: np.ndarray
    high: np.ndarray

    @property
    def style(self) -> GaitStyle:
        """The stepping style at scale 1."""
        return self.gait.style

    @property
    def dt(self) -> float:
        """The control period [s]."""
        return self.target.dt

    @property
    def ticks(self) -> int:
        """An episode's length in control ticks."""
        return max(1, round(self.config.seconds / self.dt))


def _base(cfg: WalkConfig, robot: Robot) -> tuple[Motion, StepGait, StepGains]:
    """The clip (a :class:`~imitwalk.mocap.Motion`), its stepping gait and the residual's
    gains: a stepping run's, or the clip's with the shipped gains."""
    from imitwalk.mocap import default_clip
    from imitwalk.retarget.motionfiles import load_clip
    from imitwalk.retarget.provenance import Provenance
    from imitwalk.step.pipeline import gait_from_motion

    if cfg.run is not None:
        from imitwalk.judge.replay import load_run

        loaded = load_run(cfg.run)
        if loaded.learner != "step":
            raise ConfigError(
                f"run {cfg.run} is a {loaded.learner} run; a residual adds to a "
                "stepping run (learned by 'imitwalk learn')"
            )
        if loaded.step_gait.robot != robot.name:
            raise ConfigError(
                f"run {cfg.run} is of robot {loaded.step_gait.robot!r}, not {robot.name!r}"
            )
        assert loaded.step_gains is not None
        gait = loaded.step_gait
        return load_clip(gait.source, robot), gait, loaded.step_gains["learned"]
    motion = load_clip(cfg.clip or default_clip(), robot)
    where = Provenance(robot=cfg.robot)  # as a run records its robot
    return motion, gait_from_motion(motion, robot, where), StepGains()


def build_setup(cfg: WalkConfig) -> WalkSetup:
    """Resolve ``cfg`` (a one-line :class:`~imitwalk.errors.ImitwalkError` for an unknown
    robot, clip or protocol, listing the valid choices where there is a list).

    Raises:
        ConfigError: a protocol on another engine than MuJoCo (the rewards read MuJoCo's
            state), a run of another robot or learner.
    """
    from imitwalk.retarget.pipeline import RetargetConfig, retarget
    from imitwalk.robots import load_robot

    protocol = load_protocol(cfg.protocol)
    if protocol.engine != "mujoco":
        raise ConfigError(
            f"protocol {cfg.protocol!r} runs on {protocol.engine}; the environment "
            "steps MuJoCo (valid engines: mujoco)"
        )
    robot = load_robot(cfg.robot)
    motion, gait, gains = _base(cfg, robot)
    ref = retarget(motion, robot, RetargetConfig(scales=(1.0,), search=False)).reference
    target = TrackingTarget.from_reference(ref, cfg.seconds)
    half = np.full(robot.dof, float(cfg.box if cfg.box is not None else BOX[cfg.action]))
    centre = np.zeros(robot.dof) if cfg.action == "residual" else robot.stand.copy()
    low, high = centre - half, centre + half
    layout = ObservationLayout(
        stand=robot.stand.copy(),
        weight=float(robot.total_mass * 9.81),
        sole_sensors=len(robot.foot_force["l"]),
        action=cfg.action,
        action_center=(high + low) / 2,
        action_scale=(high - low) / 2,
        previous=cfg.previous_action,
    )
    return WalkSetup(cfg, robot, gait, gains, target, protocol, layout, low, high)
