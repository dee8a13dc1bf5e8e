"""The servos of an engine without rotor inertia, integrated implicitly (pure NumPy).

Bullet has no rotor inertia (MuJoCo's ``armature``), and without it an explicit PD servo
rings or diverges on the robot's light links: at 5 kHz ``kv·dt / M_jj`` is 1.7 at the
ankle roll and 1.6 at the hands' twist (``M_jj`` is the joint's own inertia from the mass
matrix); at 1 kHz the robot blew up. :class:`StablePD` integrates each servo implicitly,
one joint at a time (the diagonal form of the stable PD of Tan, Liu and Turk, 2011):

    τ = (kp e − D q̇ − r τ_o) / (1 + r),   e = q* − q,  D = kp dt + kv + d,  r = D dt / M_jj,

with ``τ_o`` the joint's other torques over the last step (gravity, contacts, the rest of
the body), measured from its acceleration and smoothed by :data:`SMOOTH`. At rest
(``q̇ = 0``) with the other torques balanced by the servo it gives ``kp e``: the static
stiffness stays exactly ``kp``. :class:`imitwalk.sim.bullet.BulletPlant` uses it.
"""

from __future__ import annotations

import numpy as np

__all__ = ["SMOOTH", "StablePD"]

#: Weight of the newest estimate in the running mean of each joint's "other torques",
#: per physics step. Unsmoothed (1) the estimate made the hands' twist
#: (``M_jj`` ≈ 6e-6 kg m²) chatter at the torque limit.
SMOOTH = 0.5


class StablePD:
    """Implicit PD servos for ``n`` joints.

    Args:
        kp: ``(n,)`` stiffness [Nm/rad]; kd: ``(n,)`` damping, the servo's and the joint's
            [Nm s/rad]; limit: ``(n,)`` torque limit [Nm]; dt: physics step [s].
    """

    def __init__(self, kp: np.ndarray, kd: np.ndarray, limit: np.ndarray, dt: float):
        self.kp, self.limit, self.dt = np.asarray(kp, float), np.asarray(limit, float), dt
        self.damp = self.kp * dt + np.asarray(kd, float)
        self.reset()

    def reset(self) -> None:
        """Forget the last step (torques, velocities and other torques zero)."""
        n = len(self.kp)
        self.tau, self._qd, self._other = np.zeros(n), np.zeros(n), np.zeros(n)

    def torque(
        self, target: np.ndarray, q: np.ndarray, qd: np.ndarray, mjj: np.ndarray
    ) -> np.ndarray:
        """``(n,)`` torques [Nm] for this physics step, clipped to the limits.

        Args:
            target, q: ``(n,)`` target and measured angles [rad]; qd: ``(n,)`` joint
                velocities [rad/s]; mjj: ``(n,)`` each joint's own inertia [kg m²].
        """
        dt = self.dt
        now = (qd - self._qd) / dt * mjj - self.tau  # the other torques over the last step
        self._other = other = self._other + SMOOTH * (now - self._other)
        ratio = self.damp * dt / mjj
        tau = (self.kp * (target - q) - self.damp * qd - ratio * other) / (1.0 + ratio)
        self.tau, self._qd = np.clip(tau, -self.limit, self.limit), np.asarray(qd, float)
        return self.tau
