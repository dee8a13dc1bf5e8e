"""The plausibility bounds every reader holds its :class:`Motion` to, stated once here.

A clip is refused with a one-line :class:`~imitwalk.errors.MocapError` unless:

* its frame rate is within :data:`FPS_RANGE` (1-1000 fps);
* each leg (hip -> knee -> ankle, median over the frames) is :data:`LEG_RANGE_M` long
  (0.3-1.5 m) once the units are resolved;
* every keypoint is finite, within :data:`MAX_COORD_M` of the origin and within
  :data:`MAX_REACH_LEGS` leg lengths of the pelvis in every frame;
* every ``data`` column that moves a keypoint is finite.

A ``data`` column with non-finite values that moves no keypoint (a finger, a spare
per-frame ``dt``) is dropped, with a :class:`~imitwalk.errors.MocapWarning` naming it,
and listed in ``meta["dropped_channels"]``. C3D is the exception: there NaN is the
format's own mark of an invalid sample (a gap), kept in ``data`` as read.
"""

from __future__ import annotations

import warnings
from collections.abc import Sequence

import numpy as np

from imitwalk.errors import MocapError, MocapWarning
from imitwalk.mocap.motion import Motion

__all__ = [
    "FPS_RANGE",
    "LEG_RANGE_M",
    "MAX_COORD_M",
    "MAX_REACH_LEGS",
    "check_leg",
    "check_motion",
    "check_rate",
    "drop_channels",
    "leg_lengths",
]

#: Accepted frame rates [Hz].
FPS_RANGE: tuple[float, float] = (1.0, 1000.0)
#: Accepted human leg length, hip to knee to ankle [m].
LEG_RANGE_M: tuple[float, float] = (0.3, 1.5)
#: Largest accepted keypoint coordinate [m] (a capture volume is far smaller).
MAX_COORD_M = 1000.0
#: Largest accepted distance of a keypoint from the pelvis in any frame [leg lengths].
MAX_REACH_LEGS = 3.0


def check_rate(fps: float, where: str) -> float:
    """``fps`` [Hz] as a float if finite and within :data:`FPS_RANGE`, else MocapError."""
    lo, hi = FPS_RANGE
    if not (np.isfinite(fps) and lo <= fps <= hi):
        raise MocapError(f"{where}: frame rate {fps:.6g} fps is outside {lo:g}-{hi:g} fps")
    return float(fps)


def check_leg(length: float, src: str, units_hint: str = "", side: str = "left") -> float:
    """``length`` [m] of a leg if within :data:`LEG_RANGE_M`, else MocapError (with the hint)."""
    lo, hi = LEG_RANGE_M
    if not lo <= length <= hi:
        hint = f"; {units_hint}" if units_hint else ""
        raise MocapError(
            f"{src}: the {side} leg (hip-knee-ankle) is {length:.3g} m long, outside the "
            f"human {lo:g}-{hi:g} m{hint}"
        )
    return length


def leg_lengths(keypoints: dict[str, np.ndarray]) -> dict[str, float]:
    """``{"l": m, "r": m}``: hip -> knee -> ankle length of each leg, median over frames."""
    out = {}
    for s in "lr":
        hip, knee, ankle = (keypoints[f"{s}_{j}"] for j in ("hip", "knee", "ankle"))
        length = np.linalg.norm(knee - hip, axis=1) + np.linalg.norm(ankle - knee, axis=1)
        out[s] = float(np.median(length))
    return out


def drop_channels(
    data: np.ndarray, channels: Sequence[str], used: np.ndarray, source: str
) -> tuple[np.ndarray, tuple[str, ...], tuple[str, ...]]:
    """Drop the non-finite columns of ``data`` ``(T, D)`` that move no keypoint.

    Args:
        used: ``(D,)`` bool, True for the columns that move a keypoint; a non-finite
            value in one of them is a MocapError naming the column (its caller names the
            line where it can: see the readers).

    Returns:
        the kept ``data``, its channel names and the names of the dropped ones.
    """
    bad = ~np.all(np.isfinite(data), axis=0)
    if np.any(bad & used):
        name = channels[int(np.flatnonzero(bad & used)[0])]
        raise MocapError(f"{source}: channel {name} has non-finite values")
    if not bad.any():
        return data, tuple(channels), ()
    dropped = tuple(c for c, b in zip(channels, bad, strict=True) if b)
    warnings.warn(
        f"{source}: dropped {len(dropped)} channel(s) with non-finite values that move no "
        f"keypoint: {', '.join(dropped)}",
        MocapWarning,
        stacklevel=3,
    )
    kept = tuple(c for c, b in zip(channels, bad, strict=True) if not b)
    return np.ascontiguousarray(data[:, ~bad]), kept, dropped


def check_motion(motion: Motion, units_hint: str = "") -> Motion:
    """Hold ``motion`` to the bounds of this module (see the module docstring).

    Args:
        units_hint: appended to a leg-length error, e.g. ``"pass --units"``.

    Returns:
        ``motion`` itself (the readers drop non-finite columns before, with
        :func:`drop_channels`).

    Raises:
        MocapError: one line naming the file, the figure and the bound.
    """
    src = motion.source
    check_rate(motion.fps, src)
    if motion.data.ndim != 2 or motion.data.shape[1] != len(motion.channels):
        raise MocapError(
            f"{src}: data of shape {motion.data.shape} for {len(motion.channels)} channels"
        )
    if motion.format != "c3d" and not np.all(np.isfinite(motion.data)):
        raise MocapError(f"{src}: non-finite values in data")
    if motion.format == "c3d" and np.any(np.isinf(motion.data)):
        raise MocapError(f"{src}: infinite values in data")
    k = motion.keypoints
    for name, v in k.items():
        if v.shape != (motion.n_frames, 3) or not np.all(np.isfinite(v)):
            raise MocapError(f"{src}: keypoint {name} is not a finite ({motion.n_frames}, 3) array")
    legs = leg_lengths(k)
    for side, length in legs.items():
        check_leg(length, src, units_hint, "left" if side == "l" else "right")
    for name, v in k.items():
        if np.max(np.abs(v)) > MAX_COORD_M:
            raise MocapError(
                f"{src}: keypoint {name} reaches {np.max(np.abs(v)):.3g} m from the origin "
                f"(more than {MAX_COORD_M:g} m)"
            )
    reach = MAX_REACH_LEGS * max(legs.values())
    for name, v in k.items():
        far = float(np.max(np.linalg.norm(v - k["pelvis"], axis=1)))
        if far > reach:
            frame = int(np.argmax(np.linalg.norm(v - k["pelvis"], axis=1)))
            raise MocapError(
                f"{src}: keypoint {name} is {far:.3g} m from the pelvis in frame {frame} "
                f"(more than {MAX_REACH_LEGS:g} leg lengths, {reach:.3g} m)"
            )
    return motion
