"""Gap filling for marker trajectories (runs of NaN samples)."""

from __future__ import annotations

import numpy as np
from scipy.interpolate import PchipInterpolator

from imitwalk.errors import MocapError

__all__ = ["GapTooLong", "fill_gaps", "nan_runs"]


class GapTooLong(MocapError):
    """A trajectory has a gap longer than allowed, or no valid sample at all."""


def nan_runs(valid: np.ndarray) -> list[tuple[int, int]]:
    """``(start, end)`` index pairs (end exclusive) of the runs where ``valid`` is False."""
    bad = np.concatenate([[False], ~np.asarray(valid, dtype=bool), [False]])
    edges = np.flatnonzero(np.diff(bad.astype(np.int8)))
    return [(int(a), int(b)) for a, b in zip(edges[::2], edges[1::2], strict=True)]


def fill_gaps(
    x: np.ndarray, max_frames: int, name: str, fps: float
) -> tuple[np.ndarray, tuple[str, ...]]:
    """Fill NaN gaps of a ``(T, 3)`` trajectory.

    Interior gaps of at most ``max_frames`` frames are filled by shape-preserving cubic
    (PCHIP) interpolation through all valid samples; gaps of that length at either end
    hold the nearest valid sample.

    Returns:
        the filled ``(T, 3)`` copy and one note per filled gap.

    Raises:
        GapTooLong: naming ``name``, if a gap is longer or no sample is valid.
    """
    valid = np.all(np.isfinite(x), axis=1)
    n = len(x)
    if not valid.any():
        raise GapTooLong(f"marker {name} has no valid sample in {n} frames")
    runs = nan_runs(valid)
    for a, b in runs:
        if b - a > max_frames:
            raise GapTooLong(
                f"marker {name} is missing in frames {a}-{b - 1} ({(b - a) / fps:.3g} s), "
                f"longer than the {max_frames / fps:.3g} s that may be filled"
            )
    if not runs:
        return x, ()
    out = x.copy()
    idx = np.flatnonzero(valid)
    if len(idx) >= 2:
        interp = PchipInterpolator(idx, x[idx], axis=0, extrapolate=False)
    notes = []
    for a, b in runs:
        if a == 0 or b == n or len(idx) < 2:
            out[a:b] = x[idx[0]] if a == 0 else x[idx[-1]]
            how = "held"
        else:
            out[a:b] = interp(np.arange(a, b))
            how = "interpolated"
        notes.append(f"{name}: frames {a}-{b - 1} ({b - a} frames, {(b - a) / fps:.3g} s) {how}")
    return out, tuple(notes)
