"""The reference's clock, made by the sole forces: the phase wait (paper eq. 9's phase
advance, held back before a lift-off while the foot is still loaded).

Before a planned lift-off the clock stands still while the sole about to lift carries
more than ``wait`` of the measured load, at most :data:`MAX_WAIT_S` per lift-off. It reads
only the soles' force sensors; the per-tick policy
(:class:`~imitwalk.balance.feedback.TickPolicy`) runs it. NumPy only.
"""

from __future__ import annotations

import numpy as np

__all__ = ["MAX_WAIT_S", "LoadClock"]

#: The longest the reference's clock waits at one lift-off [s].
MAX_WAIT_S = 0.5


class LoadClock:
    """The reference's tick at each control tick.

    Args:
        down: ``(T, 2)`` bool, the plan's feet down (left, right) at each reference tick
            (:meth:`~imitwalk.retarget.reference.Reference.planned_load`).
        wait: the load share in [0, 1) above which the clock waits before a lift-off.
        dt: the control period [s].
    """

    def __init__(self, down: np.ndarray, wait: float, dt: float):
        self.down = np.asarray(down, dtype=bool)
        self.wait, self.max_wait = float(wait), round(MAX_WAIT_S / dt)
        self.clock = self.waited = 0  # the reference's tick; ticks waited at it

    def tick(self, k: int, foot_force: np.ndarray) -> int:
        """The reference's tick at control tick ``k``, given ``(2, c)`` the soles' measured
        forces [N] (each row summed to the sole's load)."""
        if k:
            load = np.asarray(foot_force).sum(axis=1)  # (2,)
            share = load / max(float(load.sum()), 1e-9)
            j = min(self.clock, len(self.down) - 2)
            lifting = self.down[j] & ~self.down[j + 1]
            if np.any(lifting & (share > self.wait)) and self.waited < self.max_wait:
                self.waited += 1
            else:
                self.waited, self.clock = 0, self.clock + 1
        return self.clock
