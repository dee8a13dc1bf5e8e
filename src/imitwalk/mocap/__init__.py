"""Motion-capture readers (BVH, ASF/AMC, C3D, DeepMimic) -> one :class:`Motion` record,
plus smoothing and gait-cycle detection.

>>> m = load_motion(default_clip())  # doctest: +SKIP
>>> find_cycles(m)  # doctest: +SKIP
[(0, 38)]
"""

from __future__ import annotations

from pathlib import Path

from imitwalk.errors import MocapError
from imitwalk.mocap.amc import read_amc
from imitwalk.mocap.bvh import read_bvh
from imitwalk.mocap.cycles import cycle_period, find_cycles, foot_contacts, heel_strikes, leg_angles
from imitwalk.mocap.deepmimic import read_deepmimic
from imitwalk.mocap.filters import smooth
from imitwalk.mocap.motion import KEYPOINTS, LOWER_BODY, Motion
from imitwalk.mocap.vicon import read_c3d

__all__ = [
    "EXTENSIONS",
    "KEYPOINTS",
    "LOWER_BODY",
    "Motion",
    "cycle_period",
    "default_clip",
    "find_cycles",
    "foot_contacts",
    "heel_strikes",
    "leg_angles",
    "load_motion",
    "smooth",
]

#: File extensions :func:`load_motion` reads -> format.
EXTENSIONS = {
    ".bvh": "bvh",
    ".amc": "amc",
    ".c3d": "c3d",
    ".txt": "deepmimic",
    ".json": "deepmimic",
}

DEFAULT_CLIP = "humanoid3d_walk.txt"


def _skeleton_for(amc: Path, skeleton: str | Path | None) -> Path:
    if skeleton is not None:
        return Path(skeleton)
    try:
        found = sorted(p for p in amc.parent.iterdir() if p.suffix.lower() == ".asf")
    except OSError as exc:
        raise MocapError(f"{amc}: cannot list its folder for the ASF: {exc}") from None
    if len(found) != 1:
        which = ", ".join(p.name for p in found) if found else "none"
        raise MocapError(
            f"{amc}: name its ASF with --skeleton (skeleton= in Python); {len(found)} .asf "
            f"files beside it ({which})"
        )
    return found[0]


def load_motion(
    path: str | Path,
    *,
    skeleton: str | Path | None = None,
    units: str | None = None,
    up: str | None = None,
    joint_names: str | Path | dict[str, str] | None = None,
) -> Motion:
    """Read a motion-capture file, choosing the reader by extension.

    Args:
        path: a ``.bvh``, ``.amc``, ``.c3d`` or DeepMimic ``.txt``/``.json`` file.
        skeleton: the ``.asf`` of an ``.amc`` (default: the single ``.asf`` beside it).
        units: BVH length unit (``"m"``, ``"cm"``, ``"mm"``, ``"inch"``, ``"cmu"``);
            None guesses it. Other formats state their units and reject this option.
        up: the file's up axis (``x y z -x -y -z``) for BVH, ASF/AMC and C3D; None
            tells it from the motion. DeepMimic is y-up by definition.
        joint_names: BVH only: a JSON file (or dict) keypoint -> joint name.

    Returns:
        the :class:`Motion` (keypoints ``(T, 3)`` [m], z up, world frame), within the
        bounds of :mod:`imitwalk.mocap.bounds`.

    Raises:
        MocapError: missing file, unknown extension, or a file that cannot be read.
    """
    p = Path(path)
    kind = EXTENSIONS.get(p.suffix.lower())
    if kind is None:
        raise MocapError(
            f"unknown mocap file extension {p.suffix or '(none)'!r} of {p.name}; "
            f"valid: {', '.join(EXTENSIONS)}"
        )
    if p.is_dir():
        raise MocapError(f"{p} is a folder, not a mocap file")
    if not p.is_file():
        raise MocapError(f"mocap file not found: {p}")
    if units is not None and kind != "bvh":
        raise MocapError(f"--units applies to BVH files only; {p.name} is {kind}")
    if joint_names is not None and kind != "bvh":
        raise MocapError(f"--joint-names applies to BVH files only; {p.name} is {kind}")
    if up is not None and kind == "deepmimic":
        raise MocapError(f"--up does not apply to DeepMimic files (y-up by definition): {p.name}")
    if skeleton is not None and kind != "amc":
        raise MocapError(f"--skeleton applies to AMC files only; {p.name} is {kind}")
    if kind == "bvh":
        return read_bvh(p, units=units, up=up, joint_names=joint_names)
    if kind == "amc":
        return read_amc(p, _skeleton_for(p, skeleton), up=up)
    if kind == "c3d":
        return read_c3d(p, up=up)
    return read_deepmimic(p)


def default_clip() -> Path:
    """Path of the product's default clip, DeepMimic ``humanoid3d_walk.txt``, as shipped in
    the installed ``pybullet_data`` package (``data/motions/``)."""
    try:
        import pybullet_data
    except ImportError:
        raise MocapError("the default clip needs the pybullet package (pybullet_data)") from None
    path = Path(pybullet_data.getDataPath()) / "data" / "motions" / DEFAULT_CLIP
    if not path.is_file():
        raise MocapError(f"default clip not found: {path}")
    return path
