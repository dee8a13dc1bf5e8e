"""The sensor vector an exported controller reads each tick (pure NumPy).

A robot's computer hands the controller one flat vector of floats per control tick, its
blocks in this order (:class:`SensorLayout`):

==============  ==========  ======  ========================================================
block           size        unit    meaning
==============  ==========  ======  ========================================================
``gyro``        3           rad/s   the torso IMU's angular velocity, in the IMU's frame
``accel``       3           m/s²    its specific force (reads +9.81 along the IMU's up
                                    axis when the robot stands still), in the IMU's frame
``foot_force``  2 k         N       the normal force of each sole sensor: the left sole's
                                    k sensors, then the right's, in the manifest's order
``joints``      n           rad     each joint's encoder, in the manifest's joint order and
                                    signs (``sign × the MJCF joint's angle``)
==============  ==========  ======  ========================================================

:meth:`SensorLayout.observation` checks a vector (its length, every entry finite) and
turns it into the :class:`~imitwalk.sim.types.Observation` record every imitwalk
controller reads; :meth:`SensorLayout.vector` is its inverse.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np
import numpy.typing as npt

from imitwalk.errors import SensorError
from imitwalk.sim.types import Observation

__all__ = ["BLOCKS", "SensorLayout"]

#: The blocks of the sensor vector, in order, with their units.
BLOCKS = (("gyro", "rad/s"), ("accel", "m/s^2"), ("foot_force", "N"), ("joints", "rad"))


@dataclass(frozen=True)
class SensorLayout:
    """The sensor vector of a robot with ``sole_sensors`` force sensors under each sole
    and ``joints`` joints (see the module doc).

    Attributes:
        sole_sensors: k, the sensors under each sole; joints: n, the joints.
    """

    sole_sensors: int
    joints: int

    @cached_property
    def sizes(self) -> dict[str, int]:
        """Each block's length, in order."""
        return {"gyro": 3, "accel": 3, "foot_force": 2 * self.sole_sensors, "joints": self.joints}

    @cached_property
    def size(self) -> int:
        """The vector's length, ``6 + 2 k + n``."""
        return sum(self.sizes.values())

    @cached_property
    def _slices(self) -> dict[str, slice]:
        out, at = {}, 0
        for name, n in self.sizes.items():
            out[name] = slice(at, at + n)
            at += n
        return out

    def slices(self) -> dict[str, slice]:
        """Each block's slice of the vector (computed once: a controller asks every tick)."""
        return dict(self._slices)

    def observation(self, sensors: npt.ArrayLike, t: float = 0.0) -> Observation:
        """The readings ``sensors`` ``(6 + 2k + n,)`` as an observation at time ``t`` [s].

        Raises:
            SensorError: the vector is not 1-D of :attr:`size` numbers, or one is not
                finite (the message names the blocks and the entries at fault).
        """
        try:
            v = np.asarray(sensors, dtype=float)
        except (TypeError, ValueError):
            got = type(sensors).__name__
            raise SensorError(f"sensors must be {self._expected()}; got {got}") from None
        if v.shape != (self.size,):
            raise SensorError(f"sensors must be {self._expected()}; got shape {v.shape}")
        bad = np.flatnonzero(~np.isfinite(v))
        if bad.size:
            where = ", ".join(self._name_of(int(i)) for i in bad[:4])
            verb = "is" if bad.size == 1 else "are"
            raise SensorError(f"sensors must be finite; {where} {verb} not")
        s = self._slices
        return Observation(
            t=float(t),
            gyro=v[s["gyro"]].copy(),
            accel=v[s["accel"]].copy(),
            foot_force=v[s["foot_force"]].reshape(2, self.sole_sensors).copy(),
            joints=v[s["joints"]].copy(),
        )

    def vector(self, obs: Observation) -> np.ndarray:
        """``(6 + 2k + n,)`` the vector of an observation (the inverse of
        :meth:`observation`)."""
        return np.concatenate(
            [
                np.asarray(obs.gyro, float).ravel(),
                np.asarray(obs.accel, float).ravel(),
                np.asarray(obs.foot_force, float).ravel(),
                np.asarray(obs.joints, float).ravel(),
            ]
        )

    def _expected(self) -> str:
        parts = " + ".join(f"{n} {name}" for name, n in self.sizes.items())
        return f"a vector of {self.size} numbers ({parts})"

    def _name_of(self, i: int) -> str:
        for name, sl in self.slices().items():
            if sl.start <= i < sl.stop:
                return f"{name}[{i - sl.start}]"
        raise AssertionError(i)  # pragma: no cover
