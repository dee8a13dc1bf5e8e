"""The canonical joint roles every robot's joints are mapped to (pure Python).

A trajectory's columns, a joint map's keys and a reference's joints all use these names;
:mod:`imitwalk.robots.spec` re-exports them.
"""

from __future__ import annotations

__all__ = ["ARM_ROLES", "LEG_ROLES", "ROLES", "SIDES", "TRUNK_ROLES"]

#: The two sides, left first.
SIDES = ("l", "r")
_LEG = ("hip_yaw", "hip_roll", "hip_pitch", "knee", "ankle_pitch", "ankle_roll")
_ARM = ("shoulder_pitch", "shoulder_roll", "arm_yaw", "elbow", "hand")
#: Leg roles, per side: yaw about +z, roll about +x, pitch about +y (right-hand rule,
#: x forward, y left, z up); knee flexion positive.
LEG_ROLES: tuple[str, ...] = tuple(f"{s}_{j}" for s in SIDES for j in _LEG)
#: Arm roles, per side; zero hangs the arm straight down.
ARM_ROLES: tuple[str, ...] = tuple(f"{s}_{j}" for s in SIDES for j in _ARM)
TRUNK_ROLES: tuple[str, ...] = ("waist_yaw", "neck_yaw", "neck_pitch")
#: Every canonical role, in the order trajectories use.
ROLES: tuple[str, ...] = LEG_ROLES + ARM_ROLES + TRUNK_ROLES
