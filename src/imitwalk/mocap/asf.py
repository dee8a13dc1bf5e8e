"""Acclaim ASF skeleton reader (the CMU database's own format), validated line by line.

* ``:units``: ``length L`` means 1 unit = 1/L inch (CMU: L = 0.45, 1 unit = 5.64 cm),
  L finite and > 0; ``angle deg|rad`` applies to the ``axis``/``orientation`` values.
* ``:root``: ``order`` names each of TX TY TZ RX RY RZ at most once, ``axis`` is an
  order of X, Y, Z, ``position`` and ``orientation`` are 3 finite numbers each.
* ``:bonedata``: ``direction`` 3 finite numbers, ``length`` one finite number >= 0,
  ``axis`` 3 finite numbers and an order of X, Y, Z, ``dof`` each of rx ry rz at most
  once (translation DOFs only on the root).
* ``:hierarchy``: every bone named is defined, has one parent, and reaches the root
  (a cycle is refused, never followed).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from imitwalk.errors import MocapError
from imitwalk.mocap._common import check_axes, finite_floats, read_lines

__all__ = ["Bone", "Skeleton", "read_asf"]

_ROOT_DOFS = ("tx", "ty", "tz", "rx", "ry", "rz")


@dataclass
class Bone:
    """One ASF bone. ``direction`` is a world-frame unit vector, ``length`` in ASF units."""

    name: str
    direction: np.ndarray = field(default_factory=lambda: np.zeros(3))
    length: float = 0.0
    axis: np.ndarray = field(default_factory=lambda: np.zeros(3))  # (3,) angles, ASF angle unit
    axis_order: str = "xyz"
    dof: tuple[str, ...] = ()
    parent: str | None = None


@dataclass
class Skeleton:
    """A parsed ASF: bones in hierarchy order (parents first; ``bones[0]`` is the root)."""

    bones: dict[str, Bone]
    metres_per_unit: float
    angle_scale: float  # ASF angle unit -> degrees
    root_position: np.ndarray
    source: str


def _vector(tok: list[str], n: int, where: str, what: str) -> np.ndarray:
    if len(tok) != n:
        raise MocapError(f"{where}: {what} has {len(tok)} values, expected {n}")
    return finite_floats(tok, where)


def _dofs(tok: list[str], valid: tuple[str, ...], where: str) -> tuple[str, ...]:
    dof = tuple(t.lower() for t in tok)
    bad = [d for d in dof if d not in valid]
    if bad:
        raise MocapError(f"{where}: unknown dof {bad[0]!r}; valid: {', '.join(valid)}")
    if len(set(dof)) != len(dof):
        raise MocapError(f"{where}: dof {' '.join(tok)!r} repeats a degree of freedom")
    return dof


def _order(token: str, where: str) -> str:
    order = check_axes(token, where, "axis order")
    if len(order) != 3:
        raise MocapError(f"{where}: axis order {token!r} must name X, Y and Z")
    return order


def _root_line(tok: list[str], root: Bone, where: str) -> np.ndarray | None:
    """Apply a ``:root`` line to ``root``; return the root position if the line gives it."""
    key = tok[0].lower()
    if key == "order":
        root.dof = _dofs(tok[1:], _ROOT_DOFS, where)
    elif key == "axis":
        root.axis_order = _order(tok[1] if len(tok) == 2 else "", where)
    elif key == "position":
        return _vector(tok[1:], 3, where, "root position")
    elif key == "orientation":
        root.axis = _vector(tok[1:], 3, where, "root orientation")
    return None


def _bone_line(
    tok: list[str], bone: Bone | None, bones: dict[str, Bone], where: str
) -> Bone | None:
    key = tok[0].lower()
    if key == "begin":
        return Bone("")
    if bone is None:
        return None
    if key == "end":
        if not bone.name:
            raise MocapError(f"{where}: bone without a name")
        if bone.name in bones or bone.name == "root":
            raise MocapError(f"{where}: bone {bone.name!r} is defined twice")
        bones[bone.name] = bone
        return None
    if key == "name" and len(tok) == 2:
        bone.name = tok[1]
    elif key == "direction":
        bone.direction = _vector(tok[1:], 3, where, "direction")
    elif key == "length":
        bone.length = float(_vector(tok[1:], 1, where, "length")[0])
        if bone.length < 0:
            raise MocapError(f"{where}: bone length {bone.length} < 0")
    elif key == "axis":
        bone.axis = _vector(tok[1:4], 3, where, "axis")
        bone.axis_order = _order(tok[4], where) if len(tok) == 5 else "xyz"
        if len(tok) > 5:
            raise MocapError(f"{where}: axis has {len(tok) - 1} values, expected 3 and an order")
    elif key == "dof":
        bone.dof = _dofs(tok[1:], _ROOT_DOFS[3:], where)
    elif key == "name":
        raise MocapError(f"{where}: name needs one word")
    return bone


def _units(tok: list[str], where: str) -> tuple[str, float]:
    key = tok[0].lower()
    if key == "length":
        value = float(_vector(tok[1:], 1, where, "length unit")[0])
        if value <= 0:
            raise MocapError(f"{where}: :units length {tok[1]} must be > 0")
        return "length", value
    if key == "angle":
        unit = tok[1].lower() if len(tok) == 2 else ""
        if unit not in ("deg", "rad"):
            raise MocapError(f"{where}: :units angle {' '.join(tok[1:])!r}; valid: deg, rad")
        return "angle", 1.0 if unit == "deg" else float(np.degrees(1.0))
    return key, 0.0


def _ordered(
    root: Bone, bones: dict[str, Bone], lines: list[tuple[int, list[str]]], src: str
) -> dict[str, Bone]:
    """Bones in hierarchy order (parents first) from the ``:hierarchy`` lines."""
    parent_of: dict[str, str] = {}
    kids: dict[str, list[str]] = {}
    for i, tok in lines:
        where = f"{src}: line {i}"
        if tok[0] != "root" and tok[0] not in bones:
            raise MocapError(f"{where}: :hierarchy names unknown bone {tok[0]!r}")
        for child in tok[1:]:
            if child not in bones:
                raise MocapError(f"{where}: :hierarchy names unknown bone {child!r}")
            if child in parent_of:
                raise MocapError(
                    f"{where}: bone {child!r} has two parents ({parent_of[child]}, {tok[0]})"
                )
            parent_of[child] = tok[0]
            kids.setdefault(tok[0], []).append(child)
    for name in parent_of:  # every bone must reach the root, and no bone may reach itself
        seen, at = {name}, parent_of[name]
        while at != "root":
            if at in seen:
                raise MocapError(f"{src}: the :hierarchy has a cycle through bone {at!r}")
            if at not in parent_of:
                raise MocapError(f"{src}: bone {at!r} of the :hierarchy has no path to the root")
            seen.add(at)
            at = parent_of[at]
    ordered = {"root": root}
    queue = ["root"]
    while queue:
        parent = queue.pop(0)
        for child in kids.get(parent, []):
            bones[child].parent = parent
            ordered[child] = bones[child]
            queue.append(child)
    return ordered


def read_asf(path: str | Path) -> Skeleton:
    """Parse an ASF skeleton file (see the module docstring for what is checked)."""
    src = str(path)
    lines = [ln.split("#", 1)[0].strip() for ln in read_lines(path)]
    root = Bone("root", dof=())
    bones: dict[str, Bone] = {}
    hierarchy: list[tuple[int, list[str]]] = []
    units = {"length": 1.0, "angle": 1.0}
    root_pos = np.zeros(3)
    section, bone = "", None
    for i, ln in enumerate(lines):
        tok = ln.split()
        if not tok:
            continue
        where = f"{src}: line {i + 1}"
        try:
            if tok[0].startswith(":"):
                section = tok[0][1:].lower()
                if section == "bonedata" and len(tok) > 1:
                    raise MocapError(f"{where}: malformed ASF line {ln[:40]!r}")
            elif section == "units":
                key, value = _units(tok, where)
                if key in units:
                    units[key] = value
            elif section == "root":
                pos = _root_line(tok, root, where)
                root_pos = root_pos if pos is None else pos
            elif section == "bonedata":
                bone = _bone_line(tok, bone, bones, where)
            elif section == "hierarchy" and tok[0] not in ("begin", "end"):
                hierarchy.append((i + 1, tok))
        except IndexError:
            raise MocapError(f"{where}: malformed ASF line {ln[:40]!r}") from None
    if not bones or not hierarchy:
        raise MocapError(f"{src}: no :bonedata or :hierarchy section (not an ASF file?)")
    ordered = _ordered(root, bones, hierarchy, src)
    return Skeleton(ordered, 0.0254 / units["length"], units["angle"], root_pos, src)
