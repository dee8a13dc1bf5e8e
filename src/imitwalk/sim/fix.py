"""A position fix: where the robot is, measured from outside it, with noise.

It stands for the paper's "visual information" (Chalodhorn et al. 2007, section 7: a
camera seeing the robot, or the robot seeing landmarks) and for a motion-capture room:
the torso's position on the floor, in the frame the robot started in, ``rate_hz`` times
a second, each with Gaussian noise of ``sigma_m`` per axis. The simulator reads it from
its ground truth, as a real room reads it from its cameras; a controller receives only
the noisy reading.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from imitwalk.errors import ConfigError
from imitwalk.sim.metrics import yaw_rad

__all__ = ["FixSensor", "PositionFix"]


@dataclass(frozen=True)
class PositionFix:
    """The fix's rate ``rate_hz`` [Hz] (> 0) and noise ``sigma_m`` [m] (≥ 0)."""

    rate_hz: float = 1.0
    sigma_m: float = 0.05

    def __post_init__(self) -> None:
        if not (np.isfinite(self.rate_hz) and self.rate_hz > 0):
            raise ConfigError(f"position fix rate {self.rate_hz!r}: expected > 0 Hz")
        if not (np.isfinite(self.sigma_m) and self.sigma_m >= 0):
            raise ConfigError(f"position fix noise {self.sigma_m!r}: expected >= 0 m")


class FixSensor:
    """Reads a :class:`PositionFix` off a plant (one with ``torso_pose()``).

    Args:
        fix: the rate and noise; seed: the noise's seed.
    """

    def __init__(self, fix: PositionFix, seed: int):
        self.fix = fix
        self._rng = np.random.default_rng([seed, 4242])
        self._origin: np.ndarray | None = None
        self._next = 1.0 / fix.rate_hz

    def read(self, plant: Any, t: float) -> np.ndarray | None:
        """``(2,)`` the fix [m] in the start frame if one is due at time ``t`` [s], else
        ``None``. The first call (at the start) sets the frame."""
        pos, quat = plant.torso_pose()
        if self._origin is None:
            yaw = float(yaw_rad(quat)[0])
            c, s = np.cos(yaw), np.sin(yaw)
            self._origin, self._rot = pos[:2].copy(), np.array([[c, s], [-s, c]])
            return None
        if t + 1e-9 < self._next:
            return None
        self._next += 1.0 / self.fix.rate_hz
        xy = self._rot @ (pos[:2] - self._origin)
        return xy + self._rng.normal(0.0, self.fix.sigma_m, 2)
