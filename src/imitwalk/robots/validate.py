"""What MuJoCo accepts in an MJCF file but imitwalk must refuse, in one line each.

:func:`check_text` runs before MuJoCo sees the file: bytes that are not UTF-8, and
numbers that are NaN or infinite (MuJoCo takes ``range="nan 1"`` and ``mass="inf"``).
:func:`check_model` runs on the compiled model: every array imitwalk reads must be
finite, every name UTF-8, and the robot must have mass.
"""

from __future__ import annotations

import math
import re
from pathlib import Path

import mujoco
import numpy as np

from imitwalk.errors import RobotError

__all__ = ["check_model", "check_text"]

_NUMBERS = re.compile(r'([A-Za-z_:]+)\s*=\s*"([^"]*)"')
#: Attributes that hold names, not numbers.
_NAMES = frozenset(
    "name class childclass file mesh material texture joint joint1 joint2 body body1 body2 "
    "site target objname refname tendon geom geom1 geom2 model prefix actuator sensor key "
    "plugin instance slidersite cranksite targetbody meshdir texturedir assetdir".split()
)
_TOKEN = re.compile(r"^[+-]?(nan|inf|infinity|\d[\d.]*e[+-]?\d{3,})$", re.IGNORECASE)


def check_text(path: Path) -> None:
    """Refuse an MJCF file that is not UTF-8 or writes a NaN or an infinite number."""
    try:
        text = path.read_bytes().decode("utf-8")
    except UnicodeDecodeError as exc:
        raise RobotError(f"{path} is not UTF-8 text (byte {exc.start})") from None
    except OSError as exc:
        raise RobotError(f"{path} cannot be read: {exc.strerror}") from None
    for lineno, line in enumerate(text.splitlines(), 1):
        for attr, value in _NUMBERS.findall(line):
            if attr in _NAMES:
                continue
            for tok in value.split():
                if _TOKEN.match(tok) and not math.isfinite(_float(tok)):
                    raise RobotError(f"{path.name} line {lineno}: {attr}={value!r} is not finite")


def _float(tok: str) -> float:
    try:
        return float(tok)
    except (ValueError, OverflowError):
        return math.inf


#: Compiled-model arrays that must be finite: array -> (object type, what it is).
_FINITE = {
    "body_pos": (mujoco.mjtObj.mjOBJ_BODY, "position"),
    "body_quat": (mujoco.mjtObj.mjOBJ_BODY, "orientation"),
    "body_mass": (mujoco.mjtObj.mjOBJ_BODY, "mass"),
    "body_inertia": (mujoco.mjtObj.mjOBJ_BODY, "inertia"),
    "body_ipos": (mujoco.mjtObj.mjOBJ_BODY, "centre of mass"),
    "jnt_range": (mujoco.mjtObj.mjOBJ_JOINT, "range"),
    "jnt_axis": (mujoco.mjtObj.mjOBJ_JOINT, "axis"),
    "jnt_pos": (mujoco.mjtObj.mjOBJ_JOINT, "position"),
    "dof_damping": (mujoco.mjtObj.mjOBJ_DOF, "damping"),
    "dof_armature": (mujoco.mjtObj.mjOBJ_DOF, "armature"),
    "geom_size": (mujoco.mjtObj.mjOBJ_GEOM, "size"),
    "geom_pos": (mujoco.mjtObj.mjOBJ_GEOM, "position"),
    "geom_friction": (mujoco.mjtObj.mjOBJ_GEOM, "friction"),
    "site_pos": (mujoco.mjtObj.mjOBJ_SITE, "position"),
    "actuator_gainprm": (mujoco.mjtObj.mjOBJ_ACTUATOR, "gain"),
    "actuator_biasprm": (mujoco.mjtObj.mjOBJ_ACTUATOR, "bias"),
    "actuator_ctrlrange": (mujoco.mjtObj.mjOBJ_ACTUATOR, "ctrlrange"),
    "actuator_gear": (mujoco.mjtObj.mjOBJ_ACTUATOR, "gear"),
    "key_qpos": (mujoco.mjtObj.mjOBJ_KEY, "qpos"),
    "qpos0": (mujoco.mjtObj.mjOBJ_UNKNOWN, "qpos0"),
}


def check_model(model: mujoco.MjModel, mjcf: Path) -> None:
    """Refuse a compiled model with a non-finite array imitwalk reads, a name that is not
    UTF-8, or no mass."""
    for attr, (objtype, what) in _FINITE.items():
        a = getattr(model, attr)
        bad = ~np.isfinite(a)
        if bad.any():
            i = int(np.argwhere(bad)[0][0])
            name = _name(model, objtype, i) if objtype != mujoco.mjtObj.mjOBJ_UNKNOWN else ""
            kind = str(objtype).split("_")[-1].lower()
            raise RobotError(f"{mjcf.name}: {kind} {name or i!r} has a non-finite {what}")
    for objtype, count in ((mujoco.mjtObj.mjOBJ_BODY, model.nbody),):
        for i in range(count):
            _name(model, objtype, i)
    if not model.body_mass[1:].sum() > 0:
        raise RobotError(f"{mjcf.name}: the model has no mass")


def _name(model: mujoco.MjModel, objtype: mujoco.mjtObj, i: int) -> str:
    try:
        return mujoco.mj_id2name(model, objtype, i) or ""
    except UnicodeDecodeError:
        raise RobotError("the model has a name that is not UTF-8 text") from None
