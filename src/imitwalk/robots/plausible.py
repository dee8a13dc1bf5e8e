"""The physical plausibility bounds every robot is held to, stated once here.

MuJoCo compiles a model with a mass of 1e308 kg or a servo of 1e30 Nm/rad; a humanoid
cannot have them, and the learning would run on numbers that mean nothing. A robot is
refused with a one-line :class:`~imitwalk.errors.RobotError` naming its file and the
range unless (generous ranges: any real humanoid, from a toy to a full-size one, fits):

* its total mass is within :data:`TOTAL_MASS_KG` (0.1-500 kg);
* each body's mass is at most :data:`BODY_MASS_KG` (200 kg) and each principal moment
  of inertia at most :data:`BODY_INERTIA_KGM2` (100 kg m²);
* its standing height is within :data:`HEIGHT_M` (0.1-3 m), its torso above the soles
  and no higher than that;
* the model's timestep is within :data:`TIMESTEP_S` (1 µs-0.1 s);
* each walking joint's range lies within :data:`JOINT_RANGE_RAD` (±2π rad) and is not
  empty;
* each walking joint's servo stiffness is within :data:`SERVO_KP` (above 0, up to
  10^5 Nm/rad).

The robots imitwalk is measured on sit well inside: hoap2 7.2 kg and 0.48 m, ROBOTIS OP3
3.1 kg and 0.51 m, Unitree G1 33 kg and 1.33 m, servo stiffness 3-500 Nm/rad.
"""

from __future__ import annotations

import math
from pathlib import Path

import mujoco
import numpy as np

from imitwalk.errors import RobotError

__all__ = [
    "BODY_INERTIA_KGM2",
    "BODY_MASS_KG",
    "HEIGHT_M",
    "JOINT_RANGE_RAD",
    "SERVO_KP",
    "TIMESTEP_S",
    "TOTAL_MASS_KG",
    "check_masses",
    "check_standing",
]

#: Accepted total mass of the robot [kg].
TOTAL_MASS_KG: tuple[float, float] = (0.1, 500.0)
#: Largest accepted mass of one body [kg].
BODY_MASS_KG = 200.0
#: Largest accepted principal moment of inertia of one body [kg m²].
BODY_INERTIA_KGM2 = 100.0
#: Accepted standing height, soles to the top of the model [m].
HEIGHT_M: tuple[float, float] = (0.1, 3.0)
#: Accepted physics timestep of the model [s].
TIMESTEP_S: tuple[float, float] = (1e-6, 0.1)
#: Accepted joint limits of a walking joint [rad].
JOINT_RANGE_RAD: tuple[float, float] = (-2 * math.pi, 2 * math.pi)
#: Accepted servo stiffness of a walking joint [Nm/rad] (the lower bound excluded).
SERVO_KP: tuple[float, float] = (0.0, 1e5)


def _within(where: str, what: str, value: float, bounds: tuple[float, float], unit: str) -> None:
    """Refuse ``value`` [``unit``] outside ``bounds`` (inclusive), in one line."""
    lo, hi = bounds
    if not lo <= value <= hi:
        raise RobotError(f"{where}: {what} {value:.4g} {unit} is outside {lo:g}-{hi:g} {unit}")


def check_masses(model: mujoco.MjModel, mjcf: Path, total_mass: float) -> None:
    """Refuse a model whose total mass [kg], a body's mass or inertia, or timestep is
    outside the bounds of this module (before any physics runs on it).

    Raises:
        RobotError: one line naming the file, the value and the accepted range.
    """
    where = mjcf.name
    _within(where, "total mass", total_mass, TOTAL_MASS_KG, "kg")
    for b in range(1, model.nbody):
        name = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_BODY, b) or f"#{b}"
        if model.body_mass[b] > BODY_MASS_KG:
            raise RobotError(
                f"{where}: body {name!r} has a mass of {model.body_mass[b]:.4g} kg; "
                f"expected at most {BODY_MASS_KG:g} kg"
            )
        if model.body_inertia[b].max() > BODY_INERTIA_KGM2:
            raise RobotError(
                f"{where}: body {name!r} has an inertia of {model.body_inertia[b].max():.4g} "
                f"kg m^2; expected at most {BODY_INERTIA_KGM2:g} kg m^2"
            )
    _within(where, "timestep", float(model.opt.timestep), TIMESTEP_S, "s")


def check_standing(
    mjcf: Path,
    *,
    height: float,
    torso_height: float,
    roles: tuple[str, ...],
    limits: np.ndarray,
    kp: np.ndarray,
) -> None:
    """Refuse a robot whose standing size, joint ranges or servos are outside the bounds
    of this module.

    Args:
        mjcf: the robot's file (named in the message).
        height: soles to the top when standing [m]; torso_height: soles to the torso
            when standing [m].
        roles: ``n`` walking-joint roles; limits: ``(n, 2)`` their ranges [rad];
            kp: ``(n,)`` their servo stiffness [Nm/rad].

    Raises:
        RobotError: one line naming the file, the value and the accepted range.
    """
    where = mjcf.name
    _within(where, "standing height", height, HEIGHT_M, "m")
    if not 0.0 < torso_height <= height:
        raise RobotError(
            f"{where}: the torso stands {torso_height:.4g} m above the soles; expected "
            f"above 0 and at most the robot's height, {height:.4g} m"
        )
    lo, hi = JOINT_RANGE_RAD
    for role, (a, b), k in zip(roles, limits, kp, strict=True):
        if not lo <= a < b <= hi:
            raise RobotError(
                f"{where}: joint {role!r} has the range {a:.4g} to {b:.4g} rad; expected a "
                f"non-empty range within {lo:.4g} to {hi:.4g} rad"
            )
        if not SERVO_KP[0] < k <= SERVO_KP[1]:
            raise RobotError(
                f"{where}: the servo of joint {role!r} has a stiffness of {k:.4g} Nm/rad; "
                f"expected above {SERVO_KP[0]:g} and at most {SERVO_KP[1]:g} Nm/rad"
            )
