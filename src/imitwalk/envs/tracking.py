"""What the environment's rewards track: the clip retargeted to the robot, by the clock.

DeepMimic rewards a policy for matching its reference motion at the reference's own
time. Here the reference is the clip's walkable retargeting at full stride
(:func:`~imitwalk.retarget.pipeline.retarget` at scale 1, no parameter search): its
start-up from standing, then its loop repeated. :class:`TrackingTarget` holds, per
control tick, the joint angles and velocities, where each sole is relative to the
centre of mass, and the forward speed the reference travels at.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from imitwalk.retarget.reference import Reference
from imitwalk.rl.observation import clock_phase

__all__ = ["TrackingTarget", "sole_offsets"]


def sole_offsets(soles: np.ndarray, com: np.ndarray, heading: float) -> np.ndarray:
    """``(2, 3)`` each sole (left, right) relative to the centre of mass in the heading
    frame: x, y of ``soles[i] − com`` turned by ``−heading`` [rad], and the sole's own
    height z [m]. ``soles``: ``(2, 3)`` [m]; ``com``: ``(2,)`` or ``(3,)`` [m]."""
    c, s = np.cos(heading), np.sin(heading)
    d = np.asarray(soles, dtype=float)[:, :2] - np.asarray(com, dtype=float)[:2]
    x = c * d[:, 0] + s * d[:, 1]
    y = -s * d[:, 0] + c * d[:, 1]
    return np.stack([x, y, np.asarray(soles, dtype=float)[:, 2]], axis=1)


@dataclass(frozen=True)
class TrackingTarget:
    """The reference per control tick, for ``T`` ticks from standing.

    Attributes:
        dt: control period [s]; q: ``(T, n)`` joint angles [rad]; dq: ``(T, n)`` their
        rates [rad/s]; soles: ``(T, 2, 3)`` :func:`sole_offsets` of the plan [m];
        speed: ``(T,)`` forward speed [m/s]; start_ticks, loop_ticks, phase0: the
        clock (:func:`~imitwalk.rl.observation.clock_phase`).
    """

    dt: float
    q: np.ndarray
    dq: np.ndarray
    soles: np.ndarray
    speed: np.ndarray
    start_ticks: int
    loop_ticks: int
    phase0: float

    @classmethod
    def from_reference(cls, ref: Reference, seconds: float) -> TrackingTarget:
        """The target of ``ref`` at its largest scale over ``seconds`` [s]."""
        scale = float(ref.scales[-1])
        q = ref.trajectory(scale, seconds)
        T = len(q)
        dq = np.gradient(q, ref.dt, axis=0) if T > 1 else np.zeros_like(q)
        plan, motion = ref.plan_at(scale), ref.motion_at(scale)
        soles = np.zeros((T, 2, 3))
        for k in range(T):
            row = ref.plan_row(plan, motion, k)
            pair = np.stack([row["l_sole"], row["r_sole"]])
            heading = float(row["path"][2]) if "path" in row else 0.0
            soles[k] = sole_offsets(pair, row["com"], heading)
        dist = np.array([ref.expected_distance(scale, (k + 1) * ref.dt) for k in range(T + 1)])
        speed = np.diff(dist) / ref.dt
        return cls(
            dt=ref.dt,
            q=q,
            dq=dq,
            soles=soles,
            speed=speed,
            start_ticks=int(ref.starts.shape[1]),
            loop_ticks=int(ref.loops.shape[1]),
            phase0=float(ref.phase[0]),
        )

    @property
    def ticks(self) -> int:
        """``T``."""
        return len(self.q)

    def phase(self, k: int) -> float:
        """The reference's gait phase ψ at tick ``k``."""
        return clock_phase(k, self.start_ticks, self.loop_ticks, self.phase0)

    def row(self, k: int) -> int:
        """The stored tick for tick ``k`` (the last one after the end)."""
        return min(max(k, 0), self.ticks - 1)
