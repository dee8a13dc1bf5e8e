"""Robots: the built-in HOAP-2-class humanoid and user MJCF files with a joint map."""

from __future__ import annotations

import re
from collections.abc import Callable
from pathlib import Path

from imitwalk.errors import RobotError, unknown_name
from imitwalk.robots.jointmap import JointMap, load_joint_map, parse_joint_map
from imitwalk.robots.spec import ARM_ROLES, LEG_ROLES, ROLES, TRUNK_ROLES, Robot

__all__ = [
    "ARM_ROLES",
    "BUILTIN",
    "LEG_ROLES",
    "ROLES",
    "TRUNK_ROLES",
    "Robot",
    "load_joint_map",
    "load_robot",
]

_HERE = Path(__file__).parent
#: Built-in robots: name -> joint map shipped with the package.
BUILTIN: dict[str, Path] = {"hoap2": _HERE / "hoap2" / "hoap2.json"}

#: A message that names a robot file (an MJCF or a joint map) already.
_NAMES_A_FILE = re.compile(r"\.(xml|json)\b", re.IGNORECASE)

_CACHE: dict[tuple[str, str | None], Robot] = {}


def load_robot(robot: str | Path, joint_map: str | Path | None = None) -> Robot:
    """Load a built-in robot by name, or a user's MJCF file with its joint map.

    Args:
        robot: ``"hoap2"``, a path to an MJCF ``.xml`` (then ``joint_map`` is required),
            or a path to a joint-map ``.json`` that names its MJCF.
        joint_map: joint-map JSON for an MJCF given as ``robot``.

    Raises:
        RobotError: unknown name, invalid MJCF, missing gyro, unknown joint, ...
    """
    key = (str(robot), None if joint_map is None else str(joint_map))
    if key in _CACHE:
        return _CACHE[key]
    name = str(robot)
    if name in BUILTIN and joint_map is None:
        path = BUILTIN[name]
        spec = _named(path, None, lambda: Robot.from_map(_read(path), path.parent))
    else:
        path = Path(name)
        if path.suffix.lower() == ".json" and joint_map is None:
            spec = _named(path, None, lambda: Robot.from_map(_read(path), path.parent))
        elif path.suffix.lower() == ".xml":
            if joint_map is None:
                raise RobotError(f"{path} needs a joint map (--joint-map FILE.json)")
            jm = Path(joint_map)
            spec = _named(jm, path, lambda: Robot.from_map(_read(jm), jm.parent, mjcf=path))
        elif not path.exists() and path.suffix == "":
            raise unknown_name("robot", name, BUILTIN)
        else:
            raise RobotError(
                f"robot must be a built-in name ({', '.join(BUILTIN)}), an .xml or a .json"
            )
    _CACHE[key] = spec
    return spec


def _named(jmap: Path, mjcf: Path | None, load: Callable[[], Robot]) -> Robot:
    """``load()``, its :class:`RobotError` naming the joint map (and the MJCF) if its
    message names no file (an unknown joint, sensor or key found while matching them)."""
    try:
        return load()
    except RobotError as exc:
        msg = str(exc)
        if _NAMES_A_FILE.search(msg):
            raise
        where = f"joint map {jmap}" + (f" (for {mjcf})" if mjcf is not None else "")
        raise type(exc)(f"{where}: {msg}") from None


def _read(path: Path) -> JointMap:
    """The joint map at ``path``, checked (:func:`parse_joint_map`)."""
    return parse_joint_map(load_joint_map(path), str(path))
