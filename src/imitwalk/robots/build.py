"""Building a robot's MuJoCo model: the user's MJCF plus what imitwalk needs (``MjSpec``).

The user's file is never written to. :func:`compile_model` reads it with
:class:`mujoco.MjSpec`, adds what an :class:`Additions` record lists — a floor and a light,
sole sites, four touch sensors under each sole, an IMU site with a gyro and an
accelerometer, position servos on joints that have a motor (torque) actuator or none —
and compiles it. Meshes and other assets are found relative to the MJCF file, so a robot
folder loads from any working directory. The compiled model is cached per process and
handed out as a copy.

The file and the compiled model are checked (:mod:`imitwalk.robots.validate`) for what
MuJoCo accepts but imitwalk must not: bytes that are not UTF-8, non-finite numbers.
"""

from __future__ import annotations

import copy
import math
from collections.abc import Container
from dataclasses import dataclass
from pathlib import Path

import mujoco
import numpy as np

from imitwalk.errors import RobotError
from imitwalk.robots.jointmap import SoleSpec
from imitwalk.robots.validate import check_model, check_text

__all__ = ["FSR_LAYOUT", "Additions", "ServoGains", "TouchPads", "compile_model", "free_name"]

#: The four touch sensors under a sole, in the order the state estimator reads them.
FSR_LAYOUT = ("fl", "fr", "rl", "rr")
#: Added touch pads reach past the sole's edge by this fraction of its half length, and
#: are this fraction of its half width thick on each side of the sole plane.
PAD_MARGIN, PAD_THICKNESS = 0.1, 0.2


@dataclass(frozen=True)
class TouchPads:
    """Four touch sensors under one sole: each covers one quadrant of the sole box
    (``body``, centre ``pos`` ``(3,)`` and frame ``quat`` in the body frame, half sizes
    ``size`` ``(2,)`` [m]), reaching a little past its edge; ``names`` in
    :data:`FSR_LAYOUT` order (the sensors' and their sites')."""

    body: str
    pos: tuple[float, float, float]
    quat: tuple[float, float, float, float]
    size: tuple[float, float]
    names: tuple[str, str, str, str]


@dataclass(frozen=True)
class ServoGains:
    """A position servo for MJCF joint ``joint``: ``kp`` [Nm/rad], ``kv`` [Nm s/rad],
    ``torque_limit`` [Nm] (``inf``: none); ``ctrlrange`` ``(2,)`` [rad]."""

    joint: str
    kp: float
    kv: float
    torque_limit: float
    ctrlrange: tuple[float, float]


@dataclass(frozen=True)
class Additions:
    """What imitwalk adds to a user's MJCF (all hashable, so a model can be cached).

    Attributes:
        floor: add a floor plane that touches every colliding geom; light, sky: add a
            light shining down and a sky (for rendering).
        soles: ``(site name, SoleSpec)`` sole sites to add.
        pads: :class:`TouchPads` to add.
        imu: ``(body, site, pos, quat)`` an IMU site to add (``None``: none).
        gyro, accelerometer: ``(name, site)`` sensors to add (``None``: none).
        servos: :class:`ServoGains` that replace a joint's actuator (or add one).
    """

    floor: bool = False
    light: bool = False
    sky: bool = False
    soles: tuple[tuple[str, SoleSpec], ...] = ()
    pads: tuple[TouchPads, ...] = ()
    imu: tuple[str, str, tuple, tuple] | None = None
    gyro: tuple[str, str] | None = None
    accelerometer: tuple[str, str] | None = None
    servos: tuple[ServoGains, ...] = ()

    @property
    def empty(self) -> bool:
        """Nothing is added: the model is the file's own."""
        return self == Additions()


def load_spec(mjcf: Path) -> mujoco.MjSpec:
    """The user's MJCF as an :class:`mujoco.MjSpec`; one-line :class:`RobotError` if not."""
    if not mjcf.is_file():
        raise RobotError(f"robot file not found: {mjcf}")
    check_text(mjcf)
    path = mjcf.resolve()
    try:
        if path.suffix == ".xml":
            return mujoco.MjSpec.from_file(str(path))
        # MuJoCo picks its decoder by a lower-case suffix: read any other name (``.XML``)
        # as text, its meshes and textures still relative to its folder
        spec = mujoco.MjSpec.from_string(path.read_text(encoding="utf-8"))
        spec.modelfiledir = str(path.parent) + "/"
        return spec
    except (ValueError, mujoco.FatalError) as exc:
        raise RobotError(f"{mjcf} is not valid MJCF: {' '.join(str(exc).split())}") from None


def _load_binary(mjb: Path, add: Additions) -> mujoco.MjModel:
    """A model compiled before (``mj_saveModel``, as an export writes it), loaded as it
    is: what building adds is already in it."""
    if not add.empty:
        raise RobotError(f"{mjb} is a compiled model: nothing can be added to it")
    try:
        model = mujoco.MjModel.from_binary_path(str(mjb))
    except (ValueError, mujoco.FatalError) as exc:
        raise RobotError(
            f"{mjb} is not a compiled MuJoCo model this MuJoCo ({mujoco.__version__}) "
            f"reads: {' '.join(str(exc).split())}"
        ) from None
    check_model(model, mjb)
    return model


def _compile_spec(spec: mujoco.MjSpec, mjcf: Path) -> mujoco.MjModel:
    try:
        model = spec.compile()
    except (ValueError, mujoco.FatalError) as exc:
        raise RobotError(f"{mjcf} is not valid MJCF: {' '.join(str(exc).split())}") from None
    check_model(model, mjcf)
    return model


def free_name(taken: Container[str | None], wanted: str) -> str:
    """``wanted``, or ``imitwalk_<wanted>`` (repeated) if ``taken`` has it."""
    while wanted in taken:
        wanted = f"imitwalk_{wanted}"
    return wanted


def _add_floor(spec: mujoco.MjSpec, model: mujoco.MjModel) -> None:
    robot = (model.geom_bodyid > 0) & ((model.geom_contype | model.geom_conaffinity) > 0)
    contype = int(np.bitwise_or.reduce(model.geom_conaffinity[robot])) if robot.any() else 1
    conaff = int(np.bitwise_or.reduce(model.geom_contype[robot])) if robot.any() else 1
    names = {t.name for t in spec.textures} | {m.name for m in spec.materials}
    tex, mat = free_name(names, "imitwalk_grid"), free_name(names, "imitwalk_floor")
    spec.add_texture(
        name=tex,
        type=mujoco.mjtTexture.mjTEXTURE_2D,
        builtin=mujoco.mjtBuiltin.mjBUILTIN_CHECKER,
        rgb1=[0.82, 0.84, 0.86],
        rgb2=[0.72, 0.74, 0.76],
        width=512,
        height=512,
    )
    material = spec.add_material(name=mat, texrepeat=[8, 8], reflectance=0.0)
    material.textures[mujoco.mjtTextureRole.mjTEXROLE_RGB] = tex
    spec.worldbody.add_geom(
        name=free_name({g.name for g in spec.geoms}, "floor"),
        type=mujoco.mjtGeom.mjGEOM_PLANE,
        size=[0.0, 0.0, 0.05],
        material=mat,
        contype=contype,
        conaffinity=conaff,
    )


def _add_pads(spec: mujoco.MjSpec, pads: TouchPads) -> None:
    body = spec.body(pads.body)
    hx, hy = pads.size
    margin, thick = PAD_MARGIN * max(hx, hy), PAD_THICKNESS * hy
    mat = np.zeros(9)
    mujoco.mju_quat2Mat(mat, np.asarray(pads.quat, dtype=float))
    rot = mat.reshape(3, 3)
    half = [(hx + margin) / 2, (hy + margin) / 2, thick]
    for name, (sx, sy) in zip(pads.names, ((1, 1), (1, -1), (-1, 1), (-1, -1)), strict=True):
        centre = np.asarray(pads.pos) + rot @ np.array([sx * half[0], sy * half[1], 0.0])
        body.add_site(
            name=name,
            pos=centre.tolist(),
            quat=list(pads.quat),
            size=half,
            type=mujoco.mjtGeom.mjGEOM_BOX,
            group=3,
            rgba=[0.2, 0.8, 0.2, 0.4],
        )
        spec.add_sensor(
            name=name,
            type=mujoco.mjtSensor.mjSENS_TOUCH,
            objtype=mujoco.mjtObj.mjOBJ_SITE,
            objname=name,
        )


def _add_servo(spec: mujoco.MjSpec, s: ServoGains) -> None:
    acts = [a for a in spec.actuators if a.target == s.joint]
    act = (
        acts[0]
        if acts
        else spec.add_actuator(
            name=free_name({a.name for a in spec.actuators}, f"{s.joint}_servo"), target=s.joint
        )
    )
    act.trntype = mujoco.mjtTrn.mjTRN_JOINT
    act.set_to_position(kp=s.kp, kv=s.kv)
    act.gear = [1.0, 0, 0, 0, 0, 0]
    act.ctrlrange = list(s.ctrlrange)
    act.ctrllimited = mujoco.mjtLimited.mjLIMITED_TRUE
    limited = math.isfinite(s.torque_limit)
    act.forcerange = [-s.torque_limit, s.torque_limit] if limited else [0.0, 0.0]
    act.forcelimited = (
        mujoco.mjtLimited.mjLIMITED_TRUE if limited else mujoco.mjtLimited.mjLIMITED_FALSE
    )


def apply(spec: mujoco.MjSpec, add: Additions, model: mujoco.MjModel) -> None:
    """Add to ``spec`` (the file's, compiled as ``model``) what ``add`` lists."""
    if add.floor:
        _add_floor(spec, model)
    if add.sky:
        spec.add_texture(
            name=free_name({t.name for t in spec.textures}, "imitwalk_sky"),
            type=mujoco.mjtTexture.mjTEXTURE_SKYBOX,
            builtin=mujoco.mjtBuiltin.mjBUILTIN_GRADIENT,
            rgb1=[0.78, 0.85, 0.93],
            rgb2=[0.97, 0.98, 1.0],
            width=256,
            height=256,
        )
    if add.light:
        spec.worldbody.add_light(
            name=free_name({x.name for x in spec.lights}, "imitwalk_sun"),
            pos=[0.0, 0.0, 4.0],
            dir=[0.0, 0.0, -1.0],
            type=mujoco.mjtLightType.mjLIGHT_DIRECTIONAL,
            castshadow=False,
        )
    for name, sole in add.soles:
        spec.body(sole.body).add_site(
            name=name,
            pos=list(sole.pos),
            quat=list(sole.quat),
            size=[0.004, 0.004, 0.004],
            rgba=[0.9, 0.2, 0.2, 0.5],
            group=4,
        )
    for pads in add.pads:
        _add_pads(spec, pads)
    if add.imu is not None:
        body, site, pos, quat = add.imu
        spec.body(body).add_site(
            name=site, pos=list(pos), quat=list(quat), size=[0.005] * 3, group=4
        )
    for sensor, kind in (
        (add.gyro, mujoco.mjtSensor.mjSENS_GYRO),
        (add.accelerometer, mujoco.mjtSensor.mjSENS_ACCELEROMETER),
    ):
        if sensor is not None:
            spec.add_sensor(
                name=sensor[0], type=kind, objtype=mujoco.mjtObj.mjOBJ_SITE, objname=sensor[1]
            )
    for servo in add.servos:
        _add_servo(spec, servo)


#: Compiled models: (file, its size and time, additions) -> model.
_MODELS: dict[tuple, mujoco.MjModel] = {}


def compile_model(mjcf: str | Path, add: Additions | None = None) -> mujoco.MjModel:
    """A fresh copy of ``mjcf``'s model with ``add`` added (compiled once per process).
    A ``.mjb`` file is a model compiled before (an export's) and is loaded as it is.

    Raises:
        RobotError: the file is missing, not UTF-8, not valid MJCF, writes a non-finite
            number, or compiles to a model with a non-finite array.
    """
    mjcf, add = Path(mjcf), add or Additions()
    try:
        st = mjcf.resolve().stat()
    except OSError:
        raise RobotError(f"robot file not found: {mjcf}") from None
    key = (str(mjcf.resolve()), st.st_size, st.st_mtime_ns, add)
    if key not in _MODELS and mjcf.suffix.lower() == ".mjb":
        _MODELS[key] = _load_binary(mjcf, add)
    if key not in _MODELS:
        spec = load_spec(mjcf)
        raw = _compile_spec(spec, mjcf)
        if not add.empty:
            try:
                apply(spec, add, raw)
            except (ValueError, KeyError, mujoco.FatalError) as exc:
                raise RobotError(f"{mjcf.name}: cannot add {' '.join(str(exc).split())}") from None
            raw = _compile_spec(spec, mjcf)
        _MODELS[key] = raw
    return copy.copy(_MODELS[key])
