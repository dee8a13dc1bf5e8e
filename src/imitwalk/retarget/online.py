"""Re-solving the walkable reference tick by tick, with task-space offsets.

The balance channels (:mod:`imitwalk.balance`) move the swing foot's landing spot and
height and the centre of mass in task space. :class:`OnlineIK` turns such offsets into
joint angles exactly, by solving the reference's own task-space plan with the offsets
added, warm-started from the previous tick (so zero offsets give back the reference).
The controller only sees it as a function ``(tick, offsets) -> joint angles``.
"""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np

from imitwalk.retarget.ik import WalkIK
from imitwalk.retarget.reference import UPPER, Reference
from imitwalk.robots import Robot

__all__ = ["OnlineIK"]


class OnlineIK:
    """``online(k, offsets) -> (n,)`` joint angles at control tick ``k`` from standing.

    Args:
        robot: the robot; ref: a walkable reference (with its plan); scale: stride scale.
    """

    def __init__(self, robot: Robot, ref: Reference, scale: float):
        self.ik = WalkIK(robot)
        self.ref = ref
        self.plan = ref.plan_at(scale)
        self.motion = ref.motion_at(scale)
        self.pitch = float(np.radians(ref.gait_command().slope_deg))
        self._fresh = True
        self.ik.start(robot.stand_qpos)

    def _tick_plan(self, k: float) -> SimpleNamespace:
        """The plan at tick ``k``, linear between ticks for a fractional ``k``; past the
        stored start-up and loop, the loop repeats, moved on by one cycle's motion."""
        k0 = int(np.floor(k))
        row = self.ref.plan_row(self.plan, self.motion, k0)
        a = k - k0
        if a > 0.0:
            nxt = self.ref.plan_row(self.plan, self.motion, k0 + 1)
            row = {key: (1.0 - a) * row[key] + a * nxt[key] for key in row}
        return SimpleNamespace(
            l_sole=row["l_sole"][None],
            r_sole=row["r_sole"][None],
            com=row["com"][None],
            pelvis_z=np.atleast_1d(row["pelvis_z"]),
            upper={u: row["upper"][j : j + 1] for j, u in enumerate(UPPER)},
            yaw=row["yaw"][None],
            path=row["path"][None],
            pitch=self.pitch,
        )

    def __call__(self, k: float, offsets: np.ndarray) -> np.ndarray:
        """Joint angles [rad] at tick ``k`` (fractional: between two ticks) with
        ``offsets`` ``(10,)`` in :data:`imitwalk.retarget.ik.CHANNELS` order."""
        it = 30 if self._fresh else 10
        self._fresh = False
        return self.ik.solve_tick(self._tick_plan(k), 0, offsets, max_iter=it)
