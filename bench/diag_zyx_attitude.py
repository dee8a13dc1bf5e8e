"""One-off diagnosis (committed to be cited, then deleted): the tilt filter
(:class:`imitwalk.balance.estimator.StateEstimator`) integrating the gyro's body rates by
the ZYX Euler kinematics (roll' = p + tan(pitch)(q sin(roll) + r cos(roll)), pitch' = q
cos(roll) − r sin(roll), heading' = (q sin(roll) + r cos(roll)) / cos(pitch)) in place
of the product's roll' = p, pitch' = q, heading' = r, paired on the same robots.

Usage: ``python d.py RUN:learned --protocol hard --seeds 40 --first 1001`` with
``ZYX=1`` for the kinematics, without for the product (``bench/paired.py``'s arguments;
prints its JSON).
"""

import math
import os
import runpy
import sys

import numpy as np

from imitwalk.balance import estimator as E
from imitwalk.balance.estimator import GRAVITY, Estimate


def _rates(est, gyro):
    p, q, r = (float(v) for v in gyro)
    sr, cr = math.sin(est.roll), math.cos(est.roll)
    cp = max(math.cos(est.pitch), 0.1)
    yz = q * sr + r * cr
    return p + math.sin(est.pitch) / cp * yz, q * cr - r * sr, yz / cp


def update(self, gyro, accel, foot_force):
    gyro = np.asarray(gyro, dtype=float)
    ax, ay, az = np.asarray(accel, dtype=float)
    acc_roll = float(np.arctan2(ay, az))
    acc_pitch = float(np.arctan2(-ax, np.hypot(ay, az)))
    feels_gravity = np.hypot(np.hypot(ax, ay), az) > 0.5 * GRAVITY
    dr, dp, dy = _rates(self, gyro)
    if self.prior is not None:
        self.roll += dr * self.dt
        self.pitch += dp * self.dt
        if feels_gravity and np.isfinite(acc_roll):
            w = self.dt / (min(self.tau, self.prior + self._elapsed) + self.dt)
            self.roll += w * (acc_roll - self.roll)
            self.pitch += w * (acc_pitch - self.pitch)
            self._elapsed += self.dt
    elif not self._started or not np.isfinite(acc_roll):
        if feels_gravity and np.isfinite(acc_roll):
            self.roll, self.pitch, self._started = acc_roll, acc_pitch, True
    else:
        a = self.tau / (self.tau + self.dt)
        self.roll = a * (self.roll + dr * self.dt) + (1 - a) * acc_roll
        self.pitch = a * (self.pitch + dp * self.dt) + (1 - a) * acc_pitch
    self.heading += dy * self.dt
    f = np.asarray(foot_force, dtype=float)
    total = f.sum()
    load = float(f[0].sum() / total) if total > 1e-6 else 0.5
    cop = (
        float((f[:, :2].sum() - f[:, 2:].sum()) / total)
        if f.shape[1] == 4 and total > 1e-6
        else 0.0
    )
    return Estimate(gyro.copy(), self.roll, self.pitch, self.heading, load, cop)


if os.environ.get("ZYX"):
    E.StateEstimator.update = update
sys.argv = ["paired.py", *sys.argv[1:]]
runpy.run_path(os.path.join(os.path.dirname(__file__), "paired.py"), run_name="__main__")
