"""The text of a BVH file -> its joints and its ``(T, C)`` channel values, validated.

Every number is checked where it is read: OFFSETs are three finite numbers, CHANNELS a
count of 0-6 whose names give each position and rotation axis at most once, ``Frames:``
a whole number >= 1, ``Frame Time:`` a finite time whose rate is within
:data:`~imitwalk.mocap.bounds.FPS_RANGE`. Motion values may be non-finite here; the
reader decides whether the channel matters (:func:`~imitwalk.mocap.bounds.drop_channels`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from imitwalk.errors import MocapError
from imitwalk.mocap._common import check_axes, count, finite_floats
from imitwalk.mocap.bounds import check_rate
from imitwalk.mocap.skeleton import Joint

__all__ = ["BvhFile", "parse_bvh"]

#: Largest ``Frames:`` accepted (a day at 1000 fps would be 8.6e7).
MAX_FRAMES = 10**8


@dataclass(frozen=True)
class BvhFile:
    """A parsed BVH.

    Attributes:
        joints: the hierarchy, parents first (End Sites included).
        channels: ``C`` column names ``"<joint>.<Xrotation|...>"``.
        values: ``(T, C)`` channel values as written (degrees, file units).
        frame_time: seconds per frame [s], as written.
        rows: ``(T,)`` 1-based line number of each frame.
    """

    joints: list[Joint]
    channels: tuple[str, ...]
    values: np.ndarray
    frame_time: float
    rows: np.ndarray


def _channels(tok: list[str], where: str) -> tuple[str, ...]:
    n = count(tok[1], where, "CHANNELS count", 0, 6) if len(tok) > 1 else -1
    if n < 0 or len(tok) != n + 2:
        raise MocapError(f"{where}: malformed CHANNELS (expected a count, then that many names)")
    chans = tuple(c.lower() for c in tok[2:])
    for c, raw in zip(chans, tok[2:], strict=True):
        if c[:1] not in ("x", "y", "z") or c[1:] not in ("position", "rotation"):
            raise MocapError(
                f"{where}: unknown channel {raw!r}; valid: Xposition, Yposition, Zposition, "
                "Xrotation, Yrotation, Zrotation"
            )
    for kind in ("position", "rotation"):
        axes = "".join(c[0] for c in chans if c.endswith(kind))
        check_axes(axes, where, f"{kind} channels")
    return chans


def _hierarchy(lines: list[str], src: str) -> tuple[list[Joint], int]:
    """Parse HIERARCHY; return joints (parents first) and the index of the MOTION line."""
    joints: list[dict] = []
    stack: list[int] = []
    pending: int | None = None
    for i, raw in enumerate(lines):
        tok = raw.split()
        if not tok:
            continue
        key = tok[0].upper()
        where = f"{src}: line {i + 1}"
        if pending is not None and key != "{":
            raise MocapError(
                f"{where}: expected '{{' after {joints[pending]['name'] or 'End Site'}"
            )
        if key == "MOTION":
            if stack or not joints:
                raise MocapError(f"{where}: MOTION before the hierarchy is closed")
            return [Joint(**j) for j in joints], i
        if key in ("ROOT", "JOINT") or (key == "END" and len(tok) > 1):
            is_end = key == "END"
            if not is_end and (len(tok) < 2 or tok[1] == "{"):
                raise MocapError(f"{where}: {tok[0]} without a name")
            name = "" if is_end else raw.split(None, 1)[1].strip().rstrip("{").strip()
            parent = stack[-1] if stack else -1
            if is_end:
                name = f"{joints[parent]['name']}_end" if parent >= 0 else "end"
            joints.append(
                {"name": name, "parent": parent, "offset": None, "end_site": is_end, "line": i + 1}
            )
            pending = len(joints) - 1
            if raw.rstrip().endswith("{"):
                stack.append(pending)
                pending = None
        elif key == "{":
            if pending is None:
                raise MocapError(f"{where}: '{{' without a joint")
            stack.append(pending)
            pending = None
        elif key == "}":
            if not stack:
                raise MocapError(f"{where}: unbalanced '}}'")
            if joints[stack[-1]]["offset"] is None:
                raise MocapError(f"{where}: joint {joints[stack[-1]]['name']!r} has no OFFSET")
            stack.pop()
        elif key == "OFFSET":
            if not stack or len(tok) != 4:
                raise MocapError(f"{where}: malformed OFFSET (expected 3 numbers)")
            joints[stack[-1]]["offset"] = finite_floats(tok[1:4], where)
        elif key == "CHANNELS":
            if not stack:
                raise MocapError(f"{where}: CHANNELS outside a joint")
            joints[stack[-1]]["channels"] = _channels(tok, where)
        elif key != "HIERARCHY":
            raise MocapError(f"{where}: unexpected {tok[0][:20]!r} in the hierarchy")
    raise MocapError(f"{src}: line {len(lines)}: file ends without a MOTION section (truncated?)")


def _header(lines: list[str], i: int, want: str, src: str) -> tuple[str, int]:
    while i < len(lines) and not lines[i].strip():
        i += 1
    if i >= len(lines) or ":" not in lines[i]:
        raise MocapError(f"{src}: line {i + 1}: expected '{want}:' (file truncated?)")
    k, v = lines[i].split(":", 1)
    if k.strip().lower() != want.lower():
        raise MocapError(f"{src}: line {i + 1}: expected '{want}:', got {k.strip()[:20]!r}")
    return v.strip(), i


def _motion(
    lines: list[str], start: int, n_chan: int, src: str
) -> tuple[np.ndarray, float, np.ndarray]:
    """Parse MOTION from line index ``start``: ``(T, C)`` values, dt [s], row line numbers."""
    frames, i = _header(lines, start + 1, "Frames", src)
    n_frames = count(frames, f"{src}: line {i + 1}", "Frames:", 0, MAX_FRAMES)
    if n_frames == 0:
        raise MocapError(f"{src}: line {i + 1}: Frames: 0, the file holds no motion")
    text, i = _header(lines, i + 1, "Frame Time", src)
    where = f"{src}: line {i + 1}"
    dt = float(finite_floats([text], where)[0])
    if dt <= 0:
        raise MocapError(f"{where}: Frame Time {text[:20]!r} must be > 0 s")
    check_rate(1.0 / dt, f"{where}: Frame Time {text[:20]}")
    rows: list[list[float]] = []
    at: list[int] = []
    for j in range(i + 1, len(lines)):
        tok = lines[j].split()
        if not tok:
            continue
        if len(rows) == n_frames:
            raise MocapError(f"{src}: line {j + 1}: more frame lines than Frames: {n_frames}")
        if len(tok) != n_chan:
            raise MocapError(f"{src}: line {j + 1}: {len(tok)} values, expected {n_chan} channels")
        try:
            rows.append([float(t) for t in tok])
        except ValueError:
            raise MocapError(
                f"{src}: line {j + 1}: non-numeric value in {' '.join(tok)[:40]!r}"
            ) from None
        at.append(j + 1)
    if len(rows) < n_frames:
        raise MocapError(
            f"{src}: line {len(lines)}: file ends after {len(rows)} of {n_frames} frames "
            "(truncated?)"
        )
    return np.array(rows, dtype=float).reshape(n_frames, n_chan), dt, np.array(at)


def parse_bvh(lines: list[str], src: str) -> BvhFile:
    """Parse the lines of a BVH file (see the module docstring for what is checked)."""
    joints, motion_line = _hierarchy(lines, src)
    channels = tuple(f"{jt.name}.{c.capitalize()}" for jt in joints for c in jt.channels)
    values, dt, rows = _motion(lines, motion_line, len(channels), src)
    return BvhFile(joints, channels, values, dt, rows)
