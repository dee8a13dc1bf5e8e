"""The stepping gait's nominal schedule (pure NumPy): how a walk starts from standing,
when its steps come, and how far they carry it.

From standing, the controller (:mod:`imitwalk.step.controller`) first settles for
:data:`SETTLE` step times (the pelvis lowered to its walking height, both feet down),
then shifts the weight onto the right foot for :data:`SHIFT` step times, then steps,
the stride growing over the first :data:`START_STEPS` steps to the style's. After that
a step takes the style's step time. :func:`nominal_distance` is how far this schedule
carries the body, what a walk's progress is measured against.
"""

from __future__ import annotations

import numpy as np

__all__ = [
    "LATE",
    "MAX_STEP_YAW",
    "SETTLE",
    "SHIFT",
    "START_STEPS",
    "nominal_distance",
    "nominal_track",
    "start_seconds",
    "stride_at",
]

#: A step turns the foot by at most this much from the stance foot's heading [rad],
#: picked by trials on training robots (``eval`` seeds 100-119, 30 s; pybullet's walker
#: clips ``turn_left1`` and ``turn_right1``, which turn 55.6° and 53.0° a loop, each held
#: at :data:`~imitwalk.step.style.MAX_TURN`): none of 40 fell at 0.45, 0.5 or 0.55 rad,
#: and the slowest robot turned 35.7°, 41.3° and 44.4° a cycle of the 45° asked (the
#: heading's feedback needs room above the turn fed forward). The least of the two that
#: kept up.
MAX_STEP_YAW = 0.5
#: Steps over which the stride grows from nothing to the style's.
START_STEPS = 3
#: Settling from the standing posture to the walking one, and shifting the weight
#: onto the first stance foot, in step times.
SETTLE, SHIFT = 0.6, 1.0
#: A foot whose floor is late keeps descending for at most this share of a step time,
#: and a trailing foot that will not unload is lifted after at most that much more.
LATE = 0.3


def start_seconds(step_time: float) -> float:
    """When the first foot lifts off [s], for steps of ``step_time`` [s]."""
    return (SETTLE + SHIFT) * step_time


def stride_at(step: int, step_length: float) -> float:
    """The length of step ``step`` (counted from 1) [m]: the style's ``step_length``
    [m], grown to over :data:`START_STEPS` steps."""
    return step_length * min(step, START_STEPS) / START_STEPS


def nominal_distance(step_length: float, step_time: float, seconds: float) -> float:
    """Forward travel [m] of the nominal schedule over ``seconds`` from standing: the
    midpoint of the last two footholds, moved linearly over each step."""
    n = (seconds - start_seconds(step_time)) / step_time
    if n <= 0:
        return 0.0
    k = int(n)
    steps = [stride_at(j, step_length) for j in range(1, k + 2)]
    feet = np.concatenate([[0.0], np.cumsum(steps)])  # footholds after each step
    mid = 0.5 * (feet[1:] + feet[:-1])  # (k + 1,) midpoints after steps 1 … k + 1
    before = 0.0 if k == 0 else mid[k - 1]
    return float(before + (n - k) * (mid[k] - before))


def nominal_track(
    step_length: float, step_time: float, turn: float, dt: float, seconds: float
) -> np.ndarray:
    """``(T, 3)`` the nominal schedule's forward travel [m] (:func:`nominal_distance`),
    sideways travel (none) and heading [rad] at the end of each control tick of ``dt``
    [s] over ``seconds`` [s], for a walk turning ``turn`` [rad per step] (its heading
    grows by a step's turn per step time from the first lift-off)."""
    ticks = max(1, round(seconds / dt))
    t = (np.arange(ticks) + 1) * dt
    out = np.zeros((ticks, 3))
    out[:, 0] = [nominal_distance(step_length, step_time, s) for s in t]
    if turn:
        out[:, 2] = turn * np.maximum(t - start_seconds(step_time), 0.0) / step_time
    return out
