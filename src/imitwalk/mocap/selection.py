"""Which of a clip's gait cycles to learn from: the straight, steady ones, and why.

A long clip may turn and wander. Of the whole cycles :func:`~imitwalk.mocap.cycles.
find_cycles` gives, :func:`choose_cycles` keeps those that

* **go straight**: the walking direction (the hip line's normal, :func:`~imitwalk.
  mocap.cycles.heading`) changes by at most :data:`MAX_TURN_DEG` from the cycle's first
  heel strike to its last (the same phase of the step, so the pelvis's own swing
  cancels); with a commanded turn (``allow_turn``), up to :data:`MAX_TURN_DEG_TURNING`;
* **are steady**: last within :data:`PERIOD_TOLERANCE` of the median of the cycles
  that go straight.

Every cycle is reported with its figures and the reason it was used or left out
(:meth:`CycleChoice.summary`). A loop (a DeepMimic ``wrap`` clip) is one cycle by
definition and is used as it is; its turn per loop is reported.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from imitwalk.errors import MocapError
from imitwalk.mocap.cycles import heading
from imitwalk.mocap.filters import period_frames
from imitwalk.mocap.motion import Motion

__all__ = [
    "MAX_TURN_DEG",
    "MAX_TURN_DEG_TURNING",
    "PERIOD_TOLERANCE",
    "CycleCheck",
    "CycleChoice",
    "choose_cycles",
]

#: Largest heading change over a cycle that still counts as straight [deg].
MAX_TURN_DEG = 10.0
#: The same with a commanded turn (``--turn``) [deg].
MAX_TURN_DEG_TURNING = 45.0
#: Largest relative difference of a cycle's duration from the median [-].
PERIOD_TOLERANCE = 0.2


@dataclass(frozen=True)
class CycleCheck:
    """One cycle's figures. ``start``/``end``: frames (end exclusive); ``turn_deg``:
    heading change over it [deg], + left; ``period_s``: duration [s]; ``used`` and why."""

    start: int
    end: int
    turn_deg: float
    period_s: float
    used: bool
    reason: str


@dataclass(frozen=True)
class CycleChoice:
    """The cycles kept (``cycles``) and every cycle's check (``checks``)."""

    cycles: tuple[tuple[int, int], ...]
    checks: tuple[CycleCheck, ...]

    def summary(self) -> str:
        """One line: the frames used and why, and those left out and why."""
        used = [c for c in self.checks if c.used]
        out = [c for c in self.checks if not c.used]
        text = "frames " + ", ".join(f"{c.start}-{c.end}" for c in used)
        text += f" ({used[0].reason})" if len(used) == 1 else " (" + _span(used) + ")"
        if out:
            text += "; left out " + ", ".join(f"{c.start}-{c.end}: {c.reason}" for c in out)
        return text


def _span(checks: list[CycleCheck]) -> str:
    turns = [abs(c.turn_deg) for c in checks]
    periods = [c.period_s for c in checks]
    return (
        f"{_straight(max(turns))}: turn <= {max(turns):.1f} deg per cycle; steady: "
        f"{min(periods):.2f}-{max(periods):.2f} s"
    )


def _straight(turn: float) -> str:
    """How a kept cycle that turns ``turn`` [deg] is described: ``straight`` within
    :data:`MAX_TURN_DEG`, else ``turning`` (kept because a turn was commanded)."""
    return "straight" if abs(turn) <= MAX_TURN_DEG else "turning, allowed by --turn"


def _yaw(fwd: np.ndarray) -> np.ndarray:
    return np.degrees(np.unwrap(np.arctan2(fwd[:, 1], fwd[:, 0])))


def _loop(motion: Motion, cycles: list[tuple[int, int]]) -> CycleChoice:
    k, p = motion.keypoints, period_frames(motion)
    left = k["l_hip"] - k["r_hip"]
    ends = np.array([left[0], left[min(p, motion.n_frames - 1)]])
    yaw = _yaw(ends)
    turn = float(yaw[1] - yaw[0])
    checks = tuple(
        CycleCheck(
            a,
            b,
            turn,
            (b - a) / motion.fps,
            True,
            f"a loop, used whole; its hips turn {turn:.1f} deg per loop",
        )
        for a, b in cycles
    )
    return CycleChoice(tuple(cycles), checks)


def choose_cycles(
    motion: Motion, cycles: list[tuple[int, int]], *, allow_turn: bool = False
) -> CycleChoice:
    """Keep the straight, steady ones of ``cycles`` (see the module docstring).

    Args:
        motion: the (smoothed) clip; cycles: its ``(start, end)`` cycles.
        allow_turn: a turn was commanded, so turning cycles (up to
            :data:`MAX_TURN_DEG_TURNING`) may be used.

    Raises:
        MocapError: one line, if no cycle goes straight and steadily.
    """
    if motion.loop:
        return _loop(motion, cycles)
    yaw = _yaw(heading(motion))
    limit = MAX_TURN_DEG_TURNING if allow_turn else MAX_TURN_DEG
    turns = [float(yaw[min(b, motion.n_frames - 1)] - yaw[a]) for a, b in cycles]
    periods = [(b - a) / motion.fps for a, b in cycles]
    straight = [abs(t) <= limit for t in turns]
    if not any(straight):
        hint = "" if allow_turn else "; a commanded turn (--turn) may use turning cycles"
        raise MocapError(
            f"no straight walking cycle in {motion.source}: {len(cycles)} cycle(s) turn "
            f"{min(map(abs, turns)):.0f}-{max(map(abs, turns)):.0f} deg each, at most "
            f"{limit:g} deg allowed{hint}"
        )
    median = float(np.median([p for p, s in zip(periods, straight, strict=True) if s]))
    checks = []
    for (a, b), turn, period, ok in zip(cycles, turns, periods, straight, strict=True):
        steady = abs(period - median) <= PERIOD_TOLERANCE * median
        if not ok:
            reason = f"turns {turn:.0f} deg (at most {limit:g})"
        elif not steady:
            reason = f"lasts {period:.2f} s, the median is {median:.2f} s"
        else:
            reason = f"{_straight(turn)}: turn {turn:.1f} deg; steady: {period:.2f} s"
        checks.append(CycleCheck(a, b, turn, period, ok and steady, reason))
    kept = tuple((c.start, c.end) for c in checks if c.used)
    if not kept:
        raise MocapError(
            f"no steady walking cycle in {motion.source}: the straight cycles last "
            f"{min(periods):.2f}-{max(periods):.2f} s, none within "
            f"{PERIOD_TOLERANCE:.0%} of their median"
        )
    return CycleChoice(kept, tuple(checks))
