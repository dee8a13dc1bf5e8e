"""Ground truth of a MuJoCo plant, for rewards and metrics only.

A controller never reads this (it sees only the :class:`~imitwalk.sim.types.Observation`).
The reinforcement-learning environment (:mod:`imitwalk.envs`) scores its tracking
terms with it, as DeepMimic scores its rewards from the simulator's state.
"""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np

from imitwalk.sim.mujoco import MujocoPlant

__all__ = ["BodyTruth", "body_truth"]


@dataclass(frozen=True)
class BodyTruth:
    """Where the robot is, in the world frame.

    Attributes:
        com: ``(3,)`` the whole robot's centre of mass [m].
        soles: ``{"l", "r"}`` → ``(3,)`` each sole's centre [m].
        torso_pos: ``(3,)`` [m]; torso_quat: ``(4,)`` (w, x, y, z).
    """

    com: np.ndarray
    soles: dict[str, np.ndarray]
    torso_pos: np.ndarray
    torso_quat: np.ndarray


def _point(plant: MujocoPlant, name: str) -> np.ndarray:
    m, d = plant.model, plant.data
    if mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_SITE, name) >= 0:
        return d.site_xpos[m.site(name).id].copy()
    return d.xpos[m.body(name).id].copy()


def body_truth(plant: MujocoPlant) -> BodyTruth:
    """The plant's :class:`BodyTruth` now (after its last step or reset)."""
    pos, quat = plant.torso_pose()
    return BodyTruth(
        com=plant.com(),
        soles={side: _point(plant, plant.robot.soles[side]) for side in ("l", "r")},
        torso_pos=pos,
        torso_quat=quat,
    )
