"""The support under the stepping gait: where its ZMP may go and how its weight is shared
between the soles (pure NumPy).

Every point is in the stance sole's frame [m]: the stance sole is centred at the origin,
the other (trailing) sole at ``other``; a sole spans ``±half`` ``(2,)`` [m] (half its
length and width), shrunk by the gain ``support`` (:class:`~imitwalk.step.gains.StepGains`).
"""

from __future__ import annotations

import numpy as np

__all__ = ["other_side", "press_point", "weight_shares", "within_support", "zmp_box"]


def other_side(side: str) -> str:
    """The other foot: ``"l"`` for ``"r"`` and back."""
    return "l" if side == "r" else "r"


def zmp_box(
    half: np.ndarray, support: float, plan_support: float, now: np.ndarray, end: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """The ZMP shifts ``(lo, hi)``, each ``(2,)`` [m], that keep the rest of a single
    support's ZMP plan (from ``now`` to ``end``) within the stance sole shrunk by
    ``support`` and again by ``plan_support``."""
    lim = half * support * plan_support
    lo = -lim - np.minimum(now, end)
    hi = lim - np.maximum(now, end)
    return np.minimum(lo, 0.0), np.maximum(hi, 0.0)


def within_support(
    p: np.ndarray, half: np.ndarray, support: float, single: bool, other: np.ndarray
) -> np.ndarray:
    """``p`` ``(2,)`` kept within the support: the stance sole shrunk by ``support``, or in
    double support the box spanning both soles (the other sole at ``other`` ``(2,)``)."""
    lim = half * support
    if single:
        return np.minimum(np.maximum(p, -lim), lim)
    lo = np.minimum(-lim, other - lim)
    hi = np.maximum(lim, other + lim)
    return np.minimum(np.maximum(p, lo), hi)


def press_point(
    side: str, stance: str, single: bool, zmp: np.ndarray, other: np.ndarray
) -> np.ndarray:
    """Where ``side``'s sole presses ``(3,)`` [m]: the stance sole at the commanded ZMP
    ``zmp`` ``(2,)`` in single support, each sole's centre in double support (the other
    sole's at ``other`` ``(3,)``)."""
    if side == stance:
        return np.array([*zmp, 0.0]) if single else np.zeros(3)
    return other.copy()


def weight_shares(
    stance: str, single: bool, zmp: np.ndarray, other: np.ndarray
) -> dict[str, float]:
    """The robot's weight on each sole, as planned: all on the stance sole in single
    support; in double support shared by where the commanded ZMP ``zmp`` ``(2,)`` lies
    between the stance sole and the other one at ``other`` ``(2,)``."""
    trailing = other_side(stance)
    if single:
        return {stance: 1.0, trailing: 0.0}
    w = float(min(max(np.dot(zmp, other) / max(np.dot(other, other), 1e-9), 0.0), 1.0))
    return {stance: 1.0 - w, trailing: w}
