"""Gymnasium environments of imitwalk's robots, clips and protocols.

Importing this package registers ``imitwalk/Walk-v0`` (:class:`~imitwalk.envs.walk.WalkEnv`)::

    import gymnasium as gym
    import imitwalk.envs  # noqa: F401  (registers the environment)

    env = gym.make("imitwalk/Walk-v0", robot="hoap2", protocol="eval", action="residual")

``gym.make("imitwalk.envs:imitwalk/Walk-v0", ...)`` imports and registers in one call.
"""

from gymnasium.envs.registration import register, registry

from imitwalk.envs.rewards import TERMS, RewardWeights
from imitwalk.envs.setup import WalkConfig, build_setup

__all__ = ["ENV_ID", "TERMS", "RewardWeights", "WalkConfig", "build_setup"]

#: The environment's Gymnasium id.
ENV_ID = "imitwalk/Walk-v0"

if ENV_ID not in registry:
    register(id=ENV_ID, entry_point="imitwalk.envs.walk:WalkEnv")
