"""``imitwalk/Walk-v0``: a Gymnasium environment of a humanoid walking a clip.

One episode is one robot drawn from a protocol (:mod:`imitwalk.sim.protocol`: its
friction, masses, servos, slope, noise and kicks), walking for ``seconds``:

- **observation** (:mod:`imitwalk.rl.observation`): only what the robot measures,
  the gait phase, the previous action and, in ``residual`` mode, the stepping gait's
  command;
- **action**: joint targets [rad] (``joints``), or offsets [rad] added to the stepping
  gait's command (``residual``), within a box;
- **reward** (:mod:`imitwalk.envs.rewards`): named, weighted terms, each in
  ``info["reward_terms"]``;
- **termination** on a fall (the judge's own test), truncation at ``seconds``.

Seeding is exact: ``reset(seed=s)`` draws the same robot and the same walk. ``reset``'s
``options={"robot_seed": k}`` walks protocol robot ``k`` itself, a whole number ≥ 0 (the
judge's robots are 0 … 39; training draws from 1001 on). Only the simulator
(:mod:`imitwalk.sim`) steps the physics.

Bad input is refused in one line (:class:`~imitwalk.errors.ConfigError`): an unknown
keyword argument, an action that is not a ``(n,)`` array of finite numbers (the action
space's shape; nothing is broadcast or reshaped), an unknown reset option. A finite
action outside the box is clipped to it.
"""

from __future__ import annotations

from dataclasses import fields, replace
from typing import TYPE_CHECKING, Any

import gymnasium as gym
import numpy as np

from imitwalk.envs.rewards import TickState, reward_terms, total
from imitwalk.envs.setup import WalkConfig, WalkSetup, build_setup
from imitwalk.envs.tracking import sole_offsets
from imitwalk.errors import ConfigError, unknown_name
from imitwalk.sim.mujoco import MujocoPlant
from imitwalk.sim.truth import body_truth
from imitwalk.sim.types import checked_targets
from imitwalk.step.fields import shown

if TYPE_CHECKING:
    from imitwalk.sim.render import Renderer
    from imitwalk.sim.types import Observation

__all__ = ["RENDER_MODES", "WalkEnv"]

RENDER_MODES = ("rgb_array",)
#: The options :meth:`WalkEnv.reset` takes.
RESET_OPTIONS = ("robot_seed",)


def _heading(quat: np.ndarray) -> float:
    w, x, y, z = (float(v) for v in quat)
    return float(np.arctan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z)))


def _robot_seed(v: Any) -> int:
    """``reset``'s ``robot_seed`` option: a whole number ≥ 0 (not a bool or a float)."""
    if isinstance(v, bool) or not isinstance(v, int | np.integer) or v < 0:
        raise ConfigError(f"robot_seed={shown(v)}: must be a whole number ≥ 0")
    return int(v)


class WalkEnv(gym.Env):
    """A humanoid walking a clip (see the module doc); the keyword arguments are
    :class:`~imitwalk.envs.setup.WalkConfig`'s, plus ``render_mode`` (``"rgb_array"``
    or ``None``) and ``setup``, an already built :class:`WalkSetup` (shared by many
    environments of one process)."""

    metadata: dict[str, Any] = {  # noqa: RUF012 (Gymnasium's own attribute)
        "render_modes": list(RENDER_MODES),
        "render_fps": 30,
    }

    def __init__(
        self, render_mode: str | None = None, setup: WalkSetup | None = None, **config: Any
    ):
        if render_mode is not None and render_mode not in RENDER_MODES:
            raise unknown_name("render mode", str(render_mode), RENDER_MODES, ConfigError)
        valid = (*(f.name for f in fields(WalkConfig)), "render_mode", "setup")
        for name in config:
            if name not in valid:
                raise unknown_name("keyword argument", str(name), valid, ConfigError)
        if setup is not None and config:
            raise ConfigError(
                f"give a built setup or the settings ({', '.join(sorted(config))}), not both"
            )
        self.setup = setup if setup is not None else build_setup(WalkConfig.from_dict(config))
        self.render_mode = render_mode
        s = self.setup
        self.action_space = gym.spaces.Box(
            s.low.astype(np.float32), s.high.astype(np.float32), dtype=np.float32
        )
        self.observation_space = gym.spaces.Box(
            -np.inf, np.inf, shape=(s.layout.size,), dtype=np.float32
        )
        self._renderer: Renderer | None = None
        self.plant: MujocoPlant | None = None

    # -- the episode ------------------------------------------------------------
    def reset(
        self, *, seed: int | None = None, options: dict | None = None
    ) -> tuple[np.ndarray, dict[str, Any]]:
        options = options or {}
        if not isinstance(options, dict):
            raise ConfigError(f"options={shown(options)}: expected a dictionary or None")
        for name in options:  # checked before anything changes
            if name not in RESET_OPTIONS:
                raise unknown_name("reset option", str(name), RESET_OPTIONS, ConfigError)
        chosen = _robot_seed(options["robot_seed"]) if "robot_seed" in options else None
        super().reset(seed=seed)
        s, cfg = self.setup, self.setup.config
        if chosen is not None:
            robot_seed = chosen
        else:
            robot_seed = cfg.first_robot + int(self.np_random.integers(cfg.robots))
        draw = s.protocol.draw(robot_seed, s.robot, seconds=cfg.seconds)
        self.plant = MujocoPlant(s.robot, replace(draw.options, control_hz=1.0 / s.dt))
        self.robot_seed = robot_seed
        self.controller = None
        if cfg.action == "residual":
            from imitwalk.step.controller import SteppingController

            self.controller = SteppingController(s.robot, s.style, s.gains, s.dt)
            q0 = self.controller.q0
        else:
            q0 = s.target.q[0]
        obs = self.plant.reset(q0)
        self.k = 0
        self.previous = s.layout.action_center.copy()
        self.q_prev = obs.joints.copy()
        self.com_prev = body_truth(self.plant).com.copy()
        self.com_start = self.com_prev.copy()
        self.base = self.controller(0, obs) if self.controller is not None else None
        self.base_prev = self.base
        return self._observe(obs), {"robot_seed": robot_seed}

    def step(self, action: np.ndarray) -> tuple[np.ndarray, float, bool, bool, dict[str, Any]]:
        """One control tick with ``action``: ``(n,)`` joint targets or offsets [rad] (the
        action space's shape), finite; clipped to the box.

        Raises:
            ConfigError: an action of another shape, not numbers, or not finite.
        """
        if self.plant is None:
            raise gym.error.ResetNeeded("call reset() before step()")
        s, cfg = self.setup, self.setup.config
        a = np.clip(
            checked_targets(action, s.robot.joint_names, s.robot.name, "action"), s.low, s.high
        )
        targets = a + self.base if self.base is not None else a
        self.plant.command(targets)
        obs = self.plant.step()
        truth = body_truth(self.plant)
        row = s.target.row(self.k)
        if self.base is not None:  # the stepping gait's command is the pose to keep
            q_ref, dq_ref = self.base, (self.base - self.base_prev) / s.dt
            com_ref = np.array([s.style.speed, 0.0])
        else:
            q_ref, dq_ref = s.target.q[row], s.target.dq[row]
            com_ref = np.array([s.target.speed[row], 0.0])
        pair = np.stack([truth.soles["l"], truth.soles["r"]])
        state = TickState(
            q=obs.joints,
            q_ref=q_ref,
            dq=(obs.joints - self.q_prev) / s.dt,
            dq_ref=dq_ref,
            soles=sole_offsets(pair, truth.com, _heading(truth.torso_quat)),
            soles_ref=s.target.soles[row],
            com_vel=(truth.com - self.com_prev)[:2] / s.dt,
            com_vel_ref=com_ref,
            action=s.layout.normalised(a),
            previous=s.layout.normalised(self.previous),
        )
        terms = reward_terms(state)
        reward = total(terms, cfg.reward_weights)
        self.k += 1
        self.previous, self.q_prev, self.com_prev = a, obs.joints.copy(), truth.com.copy()
        terminated = bool(self.plant.fell)
        truncated = not terminated and self.k >= s.ticks
        if self.controller is not None and not terminated:
            self.base_prev, self.base = self.base, self.controller(self.k, obs)
        info = {
            "reward_terms": terms,
            "robot_seed": self.robot_seed,
            "t": float(obs.t),
            "distance": float(truth.com[0] - self.com_start[0]),
        }
        return self._observe(obs), reward, terminated, truncated, info

    def _observe(self, obs: Observation) -> np.ndarray:
        s = self.setup
        if self.controller is not None:
            phase = self.controller.phase
        else:
            phase = s.target.phase(self.k)
        return s.layout.encode(obs, phase, self.previous, self.base)

    # -- pictures ---------------------------------------------------------------
    def render(self) -> np.ndarray | None:
        if self.render_mode is None or self.plant is None:
            return None
        if self._renderer is None:
            from imitwalk.sim.render import Renderer

            self._renderer = Renderer(self.setup.robot, width=320, height=240)
        return self._renderer.frame(self.plant.qpos())

    def close(self) -> None:
        if self._renderer is not None:
            self._renderer.close()
            self._renderer = None
