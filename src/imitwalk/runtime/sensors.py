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

:meth:`SensorLayout.observation` checks a vector (its length; every entry a real number,
int or float, not a bool, complex number, text or other object; finite; and within
:data:`MAX_READING` in size) and turns it into the
:class:`~imitwalk.sim.types.Observation` record every imitwalk controller reads;
:meth:`SensorLayout.vector` is its inverse.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np
import numpy.typing as npt

from imitwalk.errors import SensorError
from imitwalk.sim.types import Observation

__all__ = ["BLOCKS", "MAX_READING", "SensorLayout"]

#: The blocks of the sensor vector, in order, with their units.
BLOCKS = (("gyro", "rad/s"), ("accel", "m/s^2"), ("foot_force", "N"), ("joints", "rad"))
#: The largest reading taken, in any block's unit (rad/s, m/s², N, rad): 1e6 is beyond any
#: sensor of a walking robot (a gyro saturates near 35 rad/s, an IMU's accelerometer near
#: 2000 m/s², a sole sensor near 1e4 N), and keeps every sum and square inside the
#: controller finite (a reading near 1e308 would overflow). A larger one is a fault.
MAX_READING = 1e6
#: The NumPy kinds of an array taken as numbers: float, signed and unsigned int.
_NUMBER_KINDS = "fiu"


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
            SensorError: the vector is not 1-D of :attr:`size` entries, an entry is not a
                real number (a bool, complex number, text, ``None`` or other object), or
                one is not finite or beyond :data:`MAX_READING` in size (the message
                names the blocks and the entries at fault).
        """
        v = self._numbers(sensors)
        if not (np.abs(v) <= MAX_READING).all():  # NaN fails it too: one pass a tick
            bad = np.flatnonzero(~np.isfinite(v))
            if bad.size:
                raise SensorError(f"sensors must be finite; {self._entries(bad)} not")
            bad = np.flatnonzero(np.abs(v) > MAX_READING)
            raise SensorError(
                f"sensors must be within +-{MAX_READING:g} (a larger reading is a sensor "
                f"fault); {self._entries(bad)} not"
            )
        s = self._slices
        return Observation(
            t=float(t),
            gyro=v[s["gyro"]].copy(),
            accel=v[s["accel"]].copy(),
            foot_force=v[s["foot_force"]].reshape(2, self.sole_sensors).copy(),
            joints=v[s["joints"]].copy(),
        )

    def _numbers(self, sensors: npt.ArrayLike) -> np.ndarray:
        """``sensors`` as a ``(size,)`` float array, if it is one of real numbers."""
        as_objects = isinstance(sensors, list | tuple)  # [0.1, True] would become floats
        try:
            raw = np.asarray(sensors, dtype=object if as_objects else None)
        except (TypeError, ValueError):
            raw = np.asarray(None, dtype=object)
        if raw.ndim == 0:
            got = type(sensors).__name__
            raise SensorError(f"sensors must be {self._expected()}; got {got}")
        if raw.shape != (self.size,):
            raise SensorError(f"sensors must be {self._expected()}; got shape {raw.shape}")
        if raw.dtype.kind in _NUMBER_KINDS:
            return raw.astype(float, copy=False)
        if raw.dtype.kind == "O":
            number = (int, float, np.integer, np.floating)
            odd = [i for i, x in enumerate(raw) if isinstance(x, bool) or not isinstance(x, number)]
        else:  # bool, complex, text, bytes, dates: every entry
            odd = list(range(self.size))
        if odd:
            kinds = sorted({type(raw[i]).__name__ for i in odd})
            raise SensorError(
                f"sensors must be real numbers (int or float); {self._entries(np.array(odd))} "
                f"not (a {' or '.join(kinds)})"
            )
        try:
            return raw.astype(float)
        except OverflowError:  # an int beyond any float: refused as beyond MAX_READING
            big = 2 * MAX_READING
            return np.array([x if abs(x) <= MAX_READING else big for x in raw], dtype=float)

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

    def _entries(self, bad: np.ndarray) -> str:
        """The first few entries of indices ``bad``, named, with ``is`` or ``are``."""
        where = ", ".join(self._name_of(int(i)) for i in bad[:4])
        more = f" and {bad.size - 4} more" if bad.size > 4 else ""
        return f"{where}{more} {'is' if bad.size == 1 else 'are'}"

    def _name_of(self, i: int) -> str:
        for name, sl in self.slices().items():
            if sl.start <= i < sl.stop:
                return f"{name}[{i - sl.start}]"
        raise AssertionError(i)  # pragma: no cover
