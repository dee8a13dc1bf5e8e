"""An exported controller on the robot's computer: sensor readings in, joint targets out.

::

    from imitwalk.runtime import Controller

    ctl = Controller.load("EXPORT")            # what `imitwalk export RUN --out EXPORT` wrote
    q = ctl.reset(read_sensors())              # the robot standing: the first tick
    while walking:                             # every ctl.dt seconds (ctl.rate_hz)
        send_joint_targets(q)                  # (n,) [rad], ctl.joint_names order and signs
        try:
            q = ctl.step(read_sensors())       # (6 + 2k + n,), see imitwalk.runtime.sensors
        except SensorError:
            pass                               # refused: q is held, the tick not counted

Every target is within its joint's range (the manifest's ``range``, ``ctl.limits``): the
controller clamps its output to it, as the simulator's position servos clamp their
control. A reading :meth:`Controller.step` refuses changes nothing: the tick is not
counted and the controller's state is as before, so the robot should hold the last
targets it was sent and, if readings stay refused, stop by its own safe stop.

:class:`Controller` plays the same objects the judge plays (the stepping gait's
:class:`~imitwalk.step.controller.SteppingController`, a PPO run's
:class:`~imitwalk.rl.actor.PolicyActor`), built from a
:class:`~imitwalk.runtime.bundle.Bundle`: ``imitwalk evaluate`` builds its bundle from
the run folder, :meth:`Controller.load` from the export, so a walk through either is the
same, tick for tick. It imports NumPy and MuJoCo (for the robot's kinematics; it never
steps physics or renders), no SciPy, Bullet, mink or matplotlib.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
import numpy.typing as npt

from imitwalk.errors import SensorError
from imitwalk.runtime.bundle import Bundle, read_bundle
from imitwalk.runtime.sensors import SensorLayout

if TYPE_CHECKING:
    from imitwalk.rl.actor import PolicyActor
    from imitwalk.sim.types import Observation
    from imitwalk.step.controller import SteppingController

__all__ = ["Controller"]


def _policy(b: Bundle) -> SteppingController | PolicyActor:
    """The controller object ``b`` describes: a policy ``(tick, observation) -> (n,)``."""
    from imitwalk.step.controller import SteppingController

    base = None
    if b.style is not None and b.gains is not None:
        base = SteppingController(b.robot, b.style, b.gains, b.dt)
    if b.actor is None:
        assert base is not None  # Bundle checks its parts
        return base
    from imitwalk.rl.actor import PolicyActor

    spec, net = b.actor
    return PolicyActor(spec, net, base)


class Controller:
    """A controller that turns one tick's sensor vector into joint targets.

    Args:
        bundle: what it plays (see :mod:`imitwalk.runtime.bundle`).

    Attributes:
        bundle: that; sensors: the :class:`~imitwalk.runtime.sensors.SensorLayout` it
        reads; joint_names: the ``n`` joints of its output, in order; dt: the control
        period [s]; rate_hz: ``1 / dt``; q0: ``(n,)`` the standing posture [rad] the
        robot should hold before :meth:`reset`; limits: ``(n, 2)`` each joint's range
        ``[lo, hi]`` [rad] (the manifest's ``range``), to which every target is clamped.
    """

    def __init__(self, bundle: Bundle):
        self.bundle = bundle
        self.sensors: SensorLayout = bundle.sensors
        self.joint_names = bundle.robot.joint_names
        self.dt = bundle.dt
        self.rate_hz = 1.0 / bundle.dt
        self._policy = _policy(bundle)
        self.q0 = np.asarray(self._policy.q0, dtype=float).copy()
        self.limits = np.asarray(bundle.robot.limits, dtype=float).copy()  # (n, 2)
        self._tick: int | None = None

    @classmethod
    def load(cls, folder: str | Path) -> Controller:
        """The controller exported to ``folder``.

        Raises:
            RunError: the folder is not a complete, unchanged export this imitwalk reads.
        """
        return cls(read_bundle(folder))

    def reset(self, sensors: npt.ArrayLike) -> np.ndarray:
        """Start a walk from the robot standing: its readings now ``(6 + 2k + n,)``. Returns
        the joint targets of this first tick ``(n,)`` [rad], each within its joint's range.

        Raises:
            SensorError: a reading :meth:`step` refuses; the controller is then as before
                (a walk under way goes on at the next :meth:`step`; before the first
                reset, :meth:`step` is still refused).
        """
        return self._decide(sensors, 0)

    def step(self, sensors: npt.ArrayLike) -> np.ndarray:
        """One control tick: the readings now ``(6 + 2k + n,)`` → joint targets ``(n,)``
        [rad], each clamped to its joint's range (:attr:`limits`), to be sent to the
        position servos until the next tick.

        Raises:
            SensorError: a vector of the wrong length, an entry not a real number (bool,
                complex, text, other objects), not finite, or beyond
                :data:`~imitwalk.runtime.sensors.MAX_READING`; or no :meth:`reset` before.
                A refused reading is not counted as a tick and leaves the controller as
                it was: hold the last targets sent.
        """
        if self._tick is None:
            raise SensorError("call reset(sensors) with the robot standing before step(sensors)")
        return self._decide(sensors, self._tick + 1)

    def _decide(self, sensors: npt.ArrayLike, tick: int) -> np.ndarray:
        """Tick ``tick``'s targets ``(n,)`` [rad]; the tick counts only once the readings
        are taken."""
        obs = self.sensors.observation(sensors, tick * self.dt)
        self._tick = tick
        q = np.asarray(self._policy(tick, obs), dtype=float)
        return np.clip(q, self.limits[:, 0], self.limits[:, 1])

    def as_policy(self) -> _AsPolicy:
        """This controller as a policy ``(tick, observation) -> targets`` for
        :func:`imitwalk.sim.mujoco.run`: each observation goes through the sensor vector,
        as on the robot."""
        return _AsPolicy(self)


class _AsPolicy:
    """:meth:`Controller.as_policy`."""

    def __init__(self, ctl: Controller):
        self.ctl, self.q0 = ctl, ctl.q0

    def __call__(self, k: int, obs: Observation) -> np.ndarray:
        v = self.ctl.sensors.vector(obs)
        return self.ctl.reset(v) if k == 0 else self.ctl.step(v)
