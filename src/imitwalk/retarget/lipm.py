"""The centre of mass a planned ZMP asks for: the linear inverted pendulum (pure NumPy).

A robot whose centre of mass stays at height ``z`` above the floor obeys, along each
horizontal axis, the linear inverted pendulum (LIPM; Kajita et al., IROS 2001),

    p = c − c̈ / ω²,   ω² = g / z,

with ``c`` the centre of mass and ``p`` the zero-moment point (ZMP): the point of the
floor about which gravity and inertia balance, where the soles must push. Given the ZMP a
motion should keep, :func:`lipm_com` returns the one bounded centre-of-mass path that
keeps it: the two-sided exponential smoothing ``c(t) = ω/2 ∫ exp(−ω|t − s|) p(s) ds``,
solved as the banded linear system of the equation above on the control ticks, at rest at
both ends. The path moves before the ZMP does (the pendulum must start to fall towards a
foot before its weight can be put there). The walkable plan's start-up uses it to shift
the weight onto the first stance foot (:mod:`imitwalk.retarget.plan`).
"""

from __future__ import annotations

import numpy as np
from scipy.linalg import solve_banded

__all__ = ["GRAVITY", "lipm_com", "lipm_zmp"]

#: Standard gravity [m/s²].
GRAVITY = 9.81


def lipm_com(zmp: np.ndarray, dt: float, height: float) -> np.ndarray:
    """``(N, ...)`` the centre of mass [m] whose LIPM ZMP is ``zmp`` ``(N, ...)`` [m].

    Args:
        zmp: the ZMP at each tick, along one or more horizontal axes [m].
        dt: tick [s]; height: the centre of mass above the floor [m].

    The robot is at rest at the first and the last tick (``c = p`` there), so the
    ZMP there should be where the robot stands.
    """
    p = np.asarray(zmp, dtype=float)
    flat = p.reshape(len(p), -1)
    n = len(flat)
    if n < 3:
        return p.copy()
    a = height / (GRAVITY * dt * dt)  # 1 / (ω dt)²
    bands = np.zeros((3, n))
    bands[0, 2:] = -a  # above the diagonal
    bands[1, 1:-1] = 1.0 + 2.0 * a
    bands[2, :-2] = -a  # below it
    bands[1, [0, -1]] = 1.0  # the ends: c = p
    return solve_banded((1, 1), bands, flat).reshape(p.shape)


def lipm_zmp(com: np.ndarray, dt: float, height: float) -> np.ndarray:
    """``(N, ...)`` the LIPM ZMP [m] of a centre-of-mass path ``(N, ...)`` [m]: the
    inverse of :func:`lipm_com` (the acceleration by central differences, zero at the
    ends)."""
    c = np.asarray(com, dtype=float)
    acc = np.zeros_like(c)
    acc[1:-1] = (c[2:] - 2.0 * c[1:-1] + c[:-2]) / (dt * dt)
    return c - acc * height / GRAVITY
