"""imitwalk: a humanoid robot learns to walk by imitating human motion capture.

An implementation, and extension, of Chalodhorn, Grimes, Grochow & Rao,
*Learning to Walk through Imitation*, IJCAI 2007, on a HOAP-2-class humanoid
simulated in MuJoCo.
"""

from __future__ import annotations

import os

# Offscreen rendering on the CPU: MuJoCo reads MUJOCO_GL when it is first imported.
os.environ.setdefault("MUJOCO_GL", "egl")

from imitwalk.errors import (
    ConfigError,
    ImitwalkError,
    MocapError,
    RetargetError,
    RobotError,
    RunError,
)

__version__ = "0.1.0"

__all__ = [
    "ConfigError",
    "ImitwalkError",
    "MocapError",
    "RetargetError",
    "RobotError",
    "RunError",
    "__version__",
]
