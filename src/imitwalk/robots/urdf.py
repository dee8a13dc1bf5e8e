"""A robot's MJCF, written out as URDF for a second physics engine (``imitwalk.sim.bullet``).

The URDF is built from the *compiled* MuJoCo model, so it carries exactly the masses,
inertias (MuJoCo's, from the geometric primitives), joint axes, ranges and collision
shapes that MuJoCo simulates. What URDF cannot say is left out and listed in
:data:`NOT_CARRIED`; :class:`imitwalk.sim.bullet.BulletPlant` adds the servos itself.

Frames: each URDF link sits at its MuJoCo body's frame moved to the body's hinge (URDF
joints turn about the child link's origin), with the body's orientation. Bodies without
a joint are fixed to their parent; the free-floating root is the URDF's base link.
"""

from __future__ import annotations

import tempfile
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from xml.sax.saxutils import quoteattr

import mujoco
import numpy as np

from imitwalk.errors import RobotError
from imitwalk.robots.spec import LEG_ROLES, Robot

__all__ = ["NOT_CARRIED", "UrdfRobot", "rotor_note", "rotor_ratio", "to_urdf", "urdf_file"]

#: MuJoCo features of the robot model that the URDF (and so Bullet) does not get.
NOT_CARRIED = (
    "visual meshes (collision meshes are carried, as the convex hulls MuJoCo collides)",
    "joint armature (rotor inertia)",
    "joint friction loss",
    "position servos (BulletPlant adds them as torque-controlled PD servos)",
    "MuJoCo's soft contact model (Bullet uses its own)",
    "foot-to-foot collisions",
)


@dataclass(frozen=True)
class UrdfRobot:
    """A robot as URDF.

    Attributes:
        text: the URDF document.
        links: URDF link name of every MuJoCo body (index = MuJoCo body id; ``""`` for
            the world).
        base: the base link (the free-floating root body).
        joint_links: for each of the robot's ``n`` roles, the link its hinge moves.
        friction: ``(nbody,)`` sliding friction of each body's geoms (MuJoCo's first
            coefficient, the largest of the body's geoms; 0 without geoms).
        meshes: file name -> OBJ text of each collision mesh the URDF refers to (written
            next to it).
    """

    text: str
    links: tuple[str, ...]
    base: str
    joint_links: tuple[str, ...]
    friction: np.ndarray
    meshes: dict[str, str] = field(default_factory=dict)


def _v(x: Iterable[float]) -> str:
    return " ".join(f"{float(a):.9g}" for a in x)


def _rpy(quat: np.ndarray) -> np.ndarray:
    """URDF's fixed-axis roll, pitch, yaw [rad] of a (w, x, y, z) quaternion."""
    mat = np.zeros(9)
    mujoco.mju_quat2Mat(mat, np.asarray(quat, dtype=float))
    r = mat.reshape(3, 3)
    pitch = np.arcsin(-np.clip(r[2, 0], -1.0, 1.0))
    if abs(r[2, 0]) < 1 - 1e-9:
        roll, yaw = np.arctan2(r[2, 1], r[2, 2]), np.arctan2(r[1, 0], r[0, 0])
    else:  # gimbal lock: put it all in yaw
        roll, yaw = 0.0, np.arctan2(-r[0, 1], r[1, 1])
    return np.array([roll, pitch, yaw])


def _geom(m: mujoco.MjModel, g: int, shift: np.ndarray, meshes: dict | None) -> str | None:
    size = m.geom_size[g]
    kind = m.geom_type[g]
    if kind == mujoco.mjtGeom.mjGEOM_BOX:
        shape = f'<box size="{_v(2 * size)}"/>'
    elif kind == mujoco.mjtGeom.mjGEOM_SPHERE:
        shape = f'<sphere radius="{size[0]:.9g}"/>'
    elif kind == mujoco.mjtGeom.mjGEOM_CAPSULE:
        shape = f'<capsule radius="{size[0]:.9g}" length="{2 * size[1]:.9g}"/>'
    elif kind == mujoco.mjtGeom.mjGEOM_CYLINDER:
        shape = f'<cylinder radius="{size[0]:.9g}" length="{2 * size[1]:.9g}"/>'
    elif kind == mujoco.mjtGeom.mjGEOM_MESH and meshes is not None:
        mid = int(m.geom_dataid[g])
        meshes[mid] = f"mesh{mid}.obj"
        shape = f'<mesh filename="{meshes[mid]}"/>'
    else:
        return None
    pos = m.geom_pos[g] - shift
    origin = f'<origin xyz="{_v(pos)}" rpy="{_v(_rpy(m.geom_quat[g]))}"/>'
    return f"<collision>{origin}<geometry>{shape}</geometry></collision>"


def to_urdf(robot: Robot, com_shift: Sequence[float] = (0.0, 0.0, 0.0)) -> UrdfRobot:
    """Write ``robot``'s compiled MuJoCo model as URDF, with the torso's centre of mass
    moved by ``com_shift`` ``(3,)`` [m] in its own frame (as ``SimOptions.com_shift``).

    Raises:
        RobotError: a body with more than one joint, or a joint other than a hinge below
            the root (URDF has one joint per link).
    """
    m = robot.compile()
    m.body_ipos[m.body(robot.torso).id] += np.asarray(com_shift, dtype=float)
    names = [m.body(b).name or f"body{b}" for b in range(m.nbody)]
    shift, joint_of, base = _joint_layout(m, names)
    out = [f"<robot name={quoteattr(robot.name)}>"]
    friction = np.zeros(m.nbody)
    meshes: dict[int, str] = {}  # mesh id -> file name, for the collision meshes used
    for b in range(1, m.nbody):
        link, friction[b] = _link(m, b, names[b], shift[b], meshes)
        out.append(link)
    for b in range(1, m.nbody):
        if b == base:
            continue
        out.append(_joint(m, b, names, shift, joint_of))
    out.append("</robot>")
    moved = tuple(names[m.joint(mj).bodyid[0]] for mj in robot.mj_joints)
    objs = {name: _obj(m, mid) for mid, name in meshes.items()}
    return UrdfRobot("\n".join(out), ("", *names[1:]), names[base], moved, friction, objs)


def _joint_layout(m: mujoco.MjModel, names: list[str]) -> tuple[np.ndarray, dict[int, int], int]:
    """Each body's hinge position ``(nbody, 3)`` in its frame [m] (0 without one), body ->
    its hinge joint, and the free-floating root body."""
    shift = np.zeros((m.nbody, 3))
    joint_of: dict[int, int] = {}
    base = None
    for b in range(1, m.nbody):
        n, j0 = m.body_jntnum[b], m.body_jntadr[b]
        if n > 1:
            raise RobotError(f"body {names[b]!r} has {n} joints; URDF export needs one per body")
        if n == 1 and m.jnt_type[j0] == mujoco.mjtJoint.mjJNT_FREE:
            if base is not None:
                raise RobotError("URDF export needs one free-floating root body")
            base = b
        elif n == 1:
            if m.jnt_type[j0] != mujoco.mjtJoint.mjJNT_HINGE:
                name = m.joint(j0).name
                raise RobotError(f"joint {name!r} is not a hinge; URDF export needs hinges")
            joint_of[b] = j0
            shift[b] = m.jnt_pos[j0]
    if base is None:
        raise RobotError("URDF export needs a free-floating root body (a freejoint)")
    return shift, joint_of, base


def _link(
    m: mujoco.MjModel, b: int, name: str, shift: np.ndarray, meshes: dict[int, str]
) -> tuple[str, float]:
    """Body ``b``'s ``<link>`` (origin at its hinge, ``shift`` ``(3,)`` [m] in its frame),
    and the largest sliding friction of its colliding geoms (0 without any)."""
    friction = 0.0
    mass = max(float(m.body_mass[b]), 1e-6)
    ipos = m.body_ipos[b] - shift
    inertia = np.maximum(m.body_inertia[b], 1e-9)
    body = [f"<link name={quoteattr(name)}><inertial>"]
    body.append(f'<origin xyz="{_v(ipos)}" rpy="{_v(_rpy(m.body_iquat[b]))}"/>')
    body.append(f'<mass value="{mass:.9g}"/>')
    body.append(
        f'<inertia ixx="{inertia[0]:.9g}" iyy="{inertia[1]:.9g}" izz="{inertia[2]:.9g}"'
        ' ixy="0" ixz="0" iyz="0"/></inertial>'
    )
    for g in range(m.body_geomadr[b], m.body_geomadr[b] + m.body_geomnum[b]):
        if m.geom_contype[g] == 0 and m.geom_conaffinity[g] == 0:
            continue  # visual only
        xml = _geom(m, g, shift, meshes)
        if xml is not None:
            body.append(xml)
            friction = max(friction, float(m.geom_friction[g, 0]))
    body.append("</link>")
    return "".join(body), friction


def _joint(
    m: mujoco.MjModel,
    b: int,
    names: list[str],
    shift: np.ndarray,
    joint_of: dict[int, int],
) -> str:
    """The ``<joint>`` that hangs body ``b`` from its parent: revolute at its hinge, else
    fixed (``shift`` ``(nbody, 3)`` each body's hinge position [m])."""
    p = m.body_parentid[b]
    if p == 0:
        raise RobotError(f"body {names[b]!r} hangs from the world; URDF export needs one tree")
    mat = np.zeros(9)
    mujoco.mju_quat2Mat(mat, m.body_quat[b])
    xyz = m.body_pos[b] + mat.reshape(3, 3) @ shift[b] - shift[p]
    origin = f'<origin xyz="{_v(xyz)}" rpy="{_v(_rpy(m.body_quat[b]))}"/>'
    link = f"<parent link={quoteattr(names[p])}/><child link={quoteattr(names[b])}/>"
    if b in joint_of:
        j = joint_of[b]
        lo, hi = m.jnt_range[j] if m.jnt_limited[j] else (-np.pi, np.pi)
        return (
            f'<joint name={quoteattr(m.joint(j).name)} type="revolute">{origin}{link}'
            f'<axis xyz="{_v(m.jnt_axis[j])}"/>'
            f'<limit lower="{lo:.9g}" upper="{hi:.9g}" effort="1000" velocity="1000"/>'
            "</joint>"
        )
    fixed = quoteattr(names[b] + "_fixed")
    return f'<joint name={fixed} type="fixed">{origin}{link}</joint>'


def _obj(m: mujoco.MjModel, mid: int) -> str:
    """Mesh ``mid`` of the compiled model (MuJoCo's convex hull data frame) as OBJ text."""
    v0, nv = m.mesh_vertadr[mid], m.mesh_vertnum[mid]
    f0, nf = m.mesh_faceadr[mid], m.mesh_facenum[mid]
    lines = [f"v {_v(x)}" for x in m.mesh_vert[v0 : v0 + nv]]
    lines += ["f " + " ".join(str(int(i) + 1) for i in f) for f in m.mesh_face[f0 : f0 + nf]]
    return "\n".join(lines) + "\n"


#: One URDF file per robot, torso shift and process: ``(name, mjcf, shift) -> (path, UrdfRobot)``.
_FILES: dict[tuple, tuple[Path, UrdfRobot]] = {}


def urdf_file(robot: Robot, com_shift: Sequence[float] = (0.0, 0.0, 0.0)) -> tuple[Path, UrdfRobot]:
    """``robot`` as URDF (see :func:`to_urdf`), written once per process to a temporary
    folder."""
    shift = tuple(float(x) for x in com_shift)
    key = (robot.name, str(robot.mjcf), shift)
    if key not in _FILES:
        u = to_urdf(robot, shift)
        path = Path(tempfile.mkdtemp(prefix="imitwalk-")) / f"{robot.name}.urdf"
        for name, text in u.meshes.items():
            (path.parent / name).write_text(text)
        path.write_text(u.text)
        _FILES[key] = (path, u)
    return _FILES[key]


def rotor_ratio(robot: Robot) -> float:
    """How much of what the leg joints carry is rotor, which Bullet leaves out: the median
    over the leg joints of the rotor inertia (MuJoCo's ``armature``) over the joint's own
    inertia (the mass matrix's diagonal less the rotor) at the standing posture [-].
    hoap2: 3.5; ROBOTIS OP3 as MuJoCo Menagerie ships it: 38; Unitree G1: 0.2."""
    m = robot.compile()
    d = mujoco.MjData(m)
    d.qpos[:] = robot.stand_qpos
    mujoco.mj_forward(m, d)
    full = np.zeros((m.nv, m.nv))
    mujoco.mj_fullM(m, d, full)
    legs = [robot.mj_joints[robot.index(r)] for r in LEG_ROLES]
    dof = m.jnt_dofadr[[m.joint(j).id for j in legs]]
    rotor = m.dof_armature[dof]
    return float(np.median(rotor / np.maximum(np.diag(full)[dof] - rotor, 1e-12)))


def rotor_note(robot: Robot) -> str:
    """One line on what Bullet's copy of ``robot`` lacks: its rotors (:func:`rotor_ratio`)."""
    ratio = rotor_ratio(robot)
    return (
        f"Bullet's robot has no rotor inertia (MuJoCo's armature): {robot.name}'s leg "
        f"rotors are {ratio:.1f} x their joints' own inertia (median)"
    )
