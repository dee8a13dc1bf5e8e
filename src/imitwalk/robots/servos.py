"""Position servos for joints whose MJCF actuator is a motor (a torque), or that have none.

imitwalk commands joint angles, so every role joint needs a position servo. An MJCF
``<position>`` actuator is used as it is. A ``<motor>`` (or a joint without an actuator)
gets a servo with gains from the joint map's ``servos`` or, by default, from the robot's
size: a leg servo's stiffness is :data:`KP_PER_MGL` times the robot's weight times its leg
length (HOAP-2's 40 Nm/rad, OP3's 21.1 and G1's 500 are 2.8, 3.1 and 2.6 times it), its
damping ``kv = KV_PER_KP · kp``, and the other joints' servos are :data:`UPPER_FRACTION`
as stiff. The torque limit is the motor's own (``|gear| × ctrlrange`` and ``forcerange``,
and the joint's ``actuatorfrcrange``), else :data:`TORQUE_PER_MGL` times weight × leg
length (a quarter of it for the other joints).
"""

from __future__ import annotations

import math

import mujoco
import numpy as np

__all__ = [
    "KP_PER_MGL",
    "KV_PER_KP",
    "TORQUE_PER_MGL",
    "UPPER_FRACTION",
    "actuator_kind",
    "default_gains",
    "torque_limit",
]

#: Leg servo stiffness [Nm/rad] per unit of weight × leg length [N m].
KP_PER_MGL = 3.0
#: Servo damping over stiffness [s].
KV_PER_KP = 0.05
#: Other joints' servos (arms, waist, head) are this fraction of a leg servo.
UPPER_FRACTION = 0.25
#: Torque limit [Nm] per unit of weight × leg length [N m], where the motor gives none.
TORQUE_PER_MGL = 0.6


def actuator_kind(model: mujoco.MjModel, a: int) -> str:
    """``"position"`` (a servo: ``kp`` gain, ``-kp`` position bias), ``"motor"`` (force =
    gain × control, no bias) or ``"other"``."""
    if model.actuator_gaintype[a] != mujoco.mjtGain.mjGAIN_FIXED:
        return "other"
    bias = model.actuator_biastype[a]
    kp, b = model.actuator_gainprm[a, 0], model.actuator_biasprm[a, :3]
    if bias == mujoco.mjtBias.mjBIAS_NONE and model.actuator_dyntype[a] == 0:
        return "motor"
    if bias == mujoco.mjtBias.mjBIAS_AFFINE and kp > 0 and np.isclose(b[1], -kp) and b[0] == 0:
        return "position"
    return "other"


def torque_limit(model: mujoco.MjModel, a: int | None, joint: int) -> float:
    """The largest torque [Nm] actuator ``a`` (``None``: none) can put on ``joint``:
    its force range (a motor's also its control range × gear) and the joint's
    ``actuatorfrcrange``; ``inf`` if nothing limits it."""
    out = math.inf
    if model.jnt_actfrclimited[joint]:
        out = float(np.abs(model.jnt_actfrcrange[joint]).max())
    if a is None:
        return out
    if model.actuator_forcelimited[a]:
        out = min(out, float(np.abs(model.actuator_forcerange[a]).max()))
    if actuator_kind(model, a) == "motor" and model.actuator_ctrllimited[a]:
        reach = abs(model.actuator_gear[a, 0] * model.actuator_gainprm[a, 0])
        out = min(out, float(reach * np.abs(model.actuator_ctrlrange[a]).max()))
    return out


def default_gains(
    leg: bool, mass: float, leg_length: float, gravity: float = 9.81
) -> tuple[float, float, float]:
    """``(kp [Nm/rad], kv [Nm s/rad], torque limit [Nm])`` of a servo for a robot of
    ``mass`` [kg] and ``leg_length`` [m]; ``leg``: a leg joint (else a quarter of it)."""
    mgl = mass * gravity * leg_length
    share = 1.0 if leg else UPPER_FRACTION
    kp = share * KP_PER_MGL * mgl
    return kp, KV_PER_KP * kp, share * TORQUE_PER_MGL * mgl
