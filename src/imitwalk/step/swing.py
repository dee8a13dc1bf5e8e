"""The swing foot: the style's path shape, re-aimed every tick (pure NumPy).

The human's swing foot moves forward along a progress profile ``X(σ)`` (0 → 1) and lifts
along ``Z(σ)`` (0 → 1 → 0) over the swing's progress ``σ``
(:class:`~imitwalk.step.style.GaitStyle`). Here the landing and the swing's duration
change every tick (:mod:`imitwalk.step.planner`), so each tick the foot covers the share
of the *remaining* way that the profile covers between the last ``σ`` and this one:
``Δ = (X(σ) − X(σ₀)) / (1 − X(σ₀))`` of the distance to the landing. A landing that moves
late is then reached without a jump, and an unchanged one gives the style's path
exactly. When the floor is late the foot keeps descending (down to half its clearance
below the stance sole). What the encoders say the sole lags behind its command is
integrated away (``rate``), so a weak or sagging servo still lands the foot where
planned.
"""

from __future__ import annotations

import numpy as np

from imitwalk.step.kinematics import FootPose

__all__ = ["SwingFoot"]


def _profile(grid: np.ndarray, p: np.ndarray, s: float) -> float:
    return float(np.interp(s, grid, p))


class SwingFoot:
    """One swing, from lift-off to touchdown (positions in the stance frame [m]).

    Args:
        shape_x, shape_z: ``(P,)`` the style's forward progress and lift profiles;
        clearance: the peak lift [m]; late_s: how long a late floor is waited for [s];
        rate: how fast the sole's measured lag is integrated away [1/s]; limit: that
        correction's bound per axis [m].
    """

    def __init__(
        self,
        shape_x: np.ndarray,
        shape_z: np.ndarray,
        clearance: float,
        late_s: float,
        rate: float,
        limit: float,
    ) -> None:
        self.shape_x, self.shape_z = np.asarray(shape_x), np.asarray(shape_z)
        self._gx = np.linspace(0.0, 1.0, len(self.shape_x))  # σ of each profile sample
        self._gz = np.linspace(0.0, 1.0, len(self.shape_z))
        self.clearance, self.late_s, self.rate, self.limit = clearance, late_s, rate, limit
        self.lift_off(FootPose(np.zeros(3), 0.0))

    def lift_off(self, pose: FootPose) -> None:
        """Start a swing from ``pose`` (the foot on the floor)."""
        self.pose = FootPose(pose.pos.copy(), pose.yaw)
        self.sigma = 0.0
        self.fix = np.zeros(3)

    def advance(
        self,
        elapsed: float,
        duration: float,
        landing: np.ndarray,
        yaw: float,
        measured: np.ndarray,
        dt: float,
        slope: tuple[float, float] | np.ndarray = (0.0, 0.0),
    ) -> FootPose:
        """Move the foot for the tick ending ``elapsed`` [s] into a swing of ``duration``
        [s] towards ``landing`` ``(2,)`` [m] and heading ``yaw`` [rad]; ``measured``
        ``(3,)``: where the encoders put the sole [m]; ``slope``: the floor's rise per
        metre along x and y (the lift is over the floor, from the lift-off spot's height
        to the landing's as the foot progresses). Returns the foot's planned pose."""
        s = min(elapsed / max(duration, 1e-3), 1.0)
        x0 = _profile(self._gx, self.shape_x, self.sigma)
        x1 = _profile(self._gx, self.shape_x, s)
        frac = 1.0 if 1.0 - x0 < 1e-6 else (x1 - x0) / (1.0 - x0)
        frac = min(max(frac, 0.0), 1.0)
        pos = self.pose.pos.copy()
        pos[:2] += frac * (landing - pos[:2])
        turned = self.pose.yaw + frac * (yaw - self.pose.yaw)
        # the floor under the foot: the lift-off spot's at first, the landing's at the end
        floor = x1 * float(slope[0] * landing[0] + slope[1] * landing[1])
        if s < 1.0:
            pos[2] = floor + self.clearance * _profile(self._gz, self.shape_z, s)
        else:  # the floor is late: keep descending
            down = 0.5 * self.clearance * dt / self.late_s
            pos[2] = max(pos[2] - down, floor - 0.5 * self.clearance)
        self.pose, self.sigma = FootPose(pos, turned), s
        fix = self.fix + self.rate * dt * (pos - measured)
        self.fix = np.minimum(np.maximum(fix, -self.limit), self.limit)  # np.clip, cheaper
        return self.pose

    def command(self) -> FootPose:
        """Where the joints are told to put the sole: the planned pose plus the
        integrated correction of its measured lag."""
        return FootPose(self.pose.pos + self.fix, self.pose.yaw)
