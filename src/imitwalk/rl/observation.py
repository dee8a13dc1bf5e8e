"""What a learned policy sees: the robot's own sensors, scaled, in named blocks.

The vector is the concatenation of :attr:`ObservationLayout.blocks`, in order:

========  =========  ==============================================================
block     size       content
========  =========  ==============================================================
gyro      3          torso angular velocity [rad/s] × 0.2
accel     3          torso specific force [m/s²] ÷ g
soles     2 k        each sole sensor's normal force ÷ the robot's weight
joints    n          encoder angles minus the standing posture [rad]
phase     2          sin and cos of 2π ψ, the gait phase
previous  n          the previous action, centred and ÷ its box's half-width (optional)
base      n          the stepping gait's command minus standing [rad] (residual only)
========  =========  ==============================================================

Nothing here reads the simulator: only the :class:`~imitwalk.sim.types.Observation`.
The scales are fixed (no running normalisation), so an exported policy needs no
statistics beside its weights.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from imitwalk.sim.types import Observation

__all__ = ["ACTIONS", "GYRO_SCALE", "ObservationLayout", "clock_phase"]

#: The action modes: ``joints``, the policy's action is the joint targets [rad];
#: ``residual``, it is added [rad] to the stepping gait's own command.
ACTIONS = ("joints", "residual")
#: The gyro's scale in the observation [s/rad].
GYRO_SCALE = 0.2
GRAVITY = 9.81


def clock_phase(k: int, start_ticks: int, loop_ticks: int, phase0: float) -> float:
    """The gait phase ψ ∈ [0, 1) of tick ``k`` of a reference played by the clock: its
    loop's phase ``phase0`` at tick ``start_ticks`` (after the start-up), advancing one
    cycle every ``loop_ticks`` ticks, before and after."""
    return float((phase0 + (k - start_ticks) / max(loop_ticks, 1)) % 1.0)


@dataclass(frozen=True)
class ObservationLayout:
    """The observation vector of one robot and action mode (see the module doc).

    Attributes:
        stand: ``(n,)`` the standing posture [rad]; weight: the robot's weight [N];
        sole_sensors: force sensors per sole (``k``); action: one of :data:`ACTIONS`;
        action_center, action_scale: ``(n,)`` the centre and half-width of the action
        box [rad], for ``previous``; previous: include the previous action.
    """

    stand: np.ndarray
    weight: float
    sole_sensors: int
    action: str
    action_center: np.ndarray
    action_scale: np.ndarray
    previous: bool = True

    @property
    def blocks(self) -> tuple[tuple[str, int], ...]:
        """``(name, size)`` of each block, in order."""
        n = len(self.stand)
        out = [
            ("gyro", 3),
            ("accel", 3),
            ("soles", 2 * self.sole_sensors),
            ("joints", n),
            ("phase", 2),
        ]
        if self.previous:
            out.append(("previous", n))
        if self.action == "residual":
            out.append(("base", n))
        return tuple(out)

    @property
    def size(self) -> int:
        """The vector's length."""
        return sum(s for _, s in self.blocks)

    def slices(self) -> dict[str, slice]:
        """Each block's slice of the vector."""
        out, at = {}, 0
        for name, s in self.blocks:
            out[name] = slice(at, at + s)
            at += s
        return out

    def normalised(self, action: np.ndarray) -> np.ndarray:
        """``(n,)`` an action [rad] as a share of its box: −1 … 1 from edge to edge."""
        return (np.asarray(action, dtype=float) - self.action_center) / self.action_scale

    def encode(
        self,
        obs: Observation,
        phase: float,
        previous: np.ndarray,
        base: np.ndarray | None = None,
    ) -> np.ndarray:
        """The ``(size,)`` float32 vector of ``obs`` at gait phase ``phase``, after the
        action ``previous`` ``(n,)``, with the stepping gait's command ``base`` ``(n,)``
        [rad] (residual mode only)."""
        parts = [
            np.asarray(obs.gyro, dtype=float) * GYRO_SCALE,
            np.asarray(obs.accel, dtype=float) / GRAVITY,
            np.asarray(obs.foot_force, dtype=float).reshape(-1) / self.weight,
            np.asarray(obs.joints, dtype=float) - self.stand,
            np.array([np.sin(2 * np.pi * phase), np.cos(2 * np.pi * phase)]),
        ]
        if self.previous:
            parts.append(self.normalised(previous))
        if self.action == "residual":
            assert base is not None, "a residual policy sees the stepping gait's command"
            parts.append(np.asarray(base, dtype=float) - self.stand)
        return np.concatenate(parts).astype(np.float32)
