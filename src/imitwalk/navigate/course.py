"""A course of waypoints on the floor, in the robot's start frame (pure NumPy).

The start frame (:mod:`imitwalk.step.odometry`): origin midway between the soles when
the walk starts, x along the robot's heading then, y to its left [m].
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from imitwalk.errors import ConfigError

__all__ = ["DEFAULT_COURSE", "MAX_WAYPOINT_M", "REACH_M", "Course", "parse_waypoints"]

#: A waypoint lies at most this far from the start along x or y [m] (a walk of 90 s
#: covers a few metres; a larger number is a typing error, and its square overflows).
MAX_WAYPOINT_M = 1000.0
#: A waypoint is reached when the robot's centre of mass passes within this of it [m].
REACH_M = 0.25
#: The course ``imitwalk navigate`` walks by default: five waypoints 0.6 to 0.8 m apart,
#: turning 90° left, 90° right, 90° right and 90° left between legs.
DEFAULT_COURSE = ((0.8, 0.0), (0.8, 0.6), (1.4, 0.6), (1.4, 0.0), (2.0, 0.0))


@dataclass(frozen=True)
class Course:
    """Waypoints to reach in order.

    Attributes:
        waypoints: ``(K, 2)`` x, y in the start frame [m], K ≥ 1; reach: the distance
            within which a waypoint counts as reached [m].
    """

    waypoints: np.ndarray
    reach: float = REACH_M

    def __post_init__(self) -> None:
        w = np.asarray(self.waypoints, dtype=float)
        if w.ndim != 2 or w.shape[1] != 2 or len(w) == 0:
            raise ConfigError(f"waypoints of shape {w.shape}: expected (K, 2) with K >= 1")
        if not np.all(np.isfinite(w)):
            bad = int(np.flatnonzero(~np.all(np.isfinite(w), axis=1))[0])
            raise ConfigError(f"waypoint {bad + 1} is {w[bad].tolist()}: expected finite x,y [m]")
        if not (np.isfinite(self.reach) and self.reach > 0):
            raise ConfigError(f"reach {self.reach!r}: expected a distance > 0 m")
        object.__setattr__(self, "waypoints", w)

    @property
    def legs(self) -> np.ndarray:
        """``(K,)`` each leg's length [m], the first from the start."""
        pts = np.vstack([np.zeros(2), self.waypoints])
        return np.linalg.norm(np.diff(pts, axis=0), axis=1)

    @property
    def turns_deg(self) -> np.ndarray:
        """``(K,)`` the heading change onto each leg [deg], the first from the start's
        heading (+x); positive turns left."""
        pts = np.vstack([np.zeros(2), self.waypoints])
        d = np.diff(pts, axis=0)
        bearing = np.arctan2(d[:, 1], d[:, 0])
        prev = np.concatenate([[0.0], bearing[:-1]])
        return np.degrees(np.angle(np.exp(1j * (bearing - prev))))


def parse_waypoints(items: Sequence[str]) -> np.ndarray:
    """``(K, 2)`` waypoints [m] from strings ``"x,y"``.

    Raises:
        ConfigError: no waypoint, or one that is not two finite numbers.
    """
    if not items:
        raise ConfigError("no waypoints: expected at least one x,y [m]")
    out = []
    for i, s in enumerate(items, 1):
        parts = s.split(",")
        try:
            xy = [float(p) for p in parts]
        except ValueError:
            xy = []
        if len(xy) != 2 or not all(np.isfinite(xy)) or max(map(abs, xy)) > MAX_WAYPOINT_M:
            raise ConfigError(
                f"waypoint {i} {s!r}: expected two finite numbers x,y [m] within "
                f"±{MAX_WAYPOINT_M:g} m of the start"
            )
        out.append(xy)
    return np.asarray(out, dtype=float)
