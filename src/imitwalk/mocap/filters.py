"""Zero-phase low-pass filtering of keypoint trajectories."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
from scipy.signal import butter, sosfiltfilt

from imitwalk.errors import MocapError
from imitwalk.mocap.motion import Motion

__all__ = ["lowpass", "period_frames", "smooth"]


def period_frames(motion: Motion) -> int:
    """Frames in one loop of a looping clip (``meta["period_frames"]``, else ``T``)."""
    return int(motion.meta.get("period_frames", motion.n_frames))


def lowpass(
    x: np.ndarray,
    fps: float,
    cutoff_hz: float,
    *,
    order: int = 2,
    period: int | None = None,
    drift: np.ndarray | None = None,
) -> np.ndarray:
    """Zero-phase Butterworth low-pass along axis 0 (``scipy.signal.sosfiltfilt``).

    Args:
        x: ``(T, ...)`` samples at ``fps`` [Hz].
        cutoff_hz: -3 dB cut-off of each pass [Hz], below ``fps / 2``.
        order: order of the filter run forwards and backwards (doubled in effect).
        period: for a loop, its period in frames (``<= T``): frames ``[0, period)`` are
            filtered as one period of a periodic signal (wrapped around instead of odd
            reflection at the ends); frames from ``period`` on repeat the loop.
        drift: ``x.shape[1:]`` change per loop (e.g. the root advancing), removed as a
            linear ramp before filtering and added back; default none.

    Returns:
        the filtered ``(T, ...)`` array.
    """
    x = np.asarray(x, dtype=float)
    if not 0 < cutoff_hz < fps / 2:
        raise MocapError(f"cutoff {cutoff_hz} Hz must be in (0, {fps / 2:g}) Hz at {fps:g} fps")
    if len(x) < 2:
        return x.copy()
    sos = butter(order, cutoff_hz, btype="low", fs=fps, output="sos")
    pad = min(len(x) - 1, 3 * (2 * len(sos) + 1))
    if period is None:
        return sosfiltfilt(sos, x, axis=0, padlen=pad)
    n = len(x)
    drift = np.zeros_like(x[0]) if drift is None else np.broadcast_to(drift, x[0].shape)
    ramp = np.arange(n).reshape((n,) + (1,) * (x.ndim - 1)) / period
    flat = x - ramp * drift  # (T, ...) periodic part
    one = flat[:period]
    reps = int(np.ceil(max(pad, int(fps / cutoff_hz) * 3) / period)) + 1
    tiled = np.concatenate([one] * (2 * reps + 1), axis=0)
    out = sosfiltfilt(sos, tiled, axis=0, padlen=0)[reps * period : reps * period + n]
    return out + ramp * drift


def smooth(motion: Motion, cutoff_hz: float = 6.0, *, order: int = 2) -> Motion:
    """Low-pass every keypoint with a zero-phase Butterworth filter.

    Args:
        motion: the clip; a looping clip (``motion.loop``) is filtered as periodic, less
            the pelvis advance per loop, as DeepMimic plays it (its closing frame becomes
            the smoothed first frame plus that advance).
        cutoff_hz: cut-off frequency [Hz] (6 Hz is usual for walking kinematics).
        order: filter order per pass (``order=2`` run both ways: 4th-order zero-phase).

    Returns:
        a copy with smoothed ``keypoints`` (same shapes); ``data`` is unchanged and
        ``meta["smoothed_hz"]`` records the cut-off.
    """
    period = period_frames(motion) if motion.loop else None
    names = list(motion.keypoints)
    stacked = np.stack([motion.keypoints[k] for k in names], axis=1)  # (T, K, 3)
    drift = None
    if period is not None and period < motion.n_frames:  # DeepMimic: the root offset per loop
        drift = motion.keypoints["pelvis"][period] - motion.keypoints["pelvis"][0]
    out = lowpass(stacked, motion.fps, cutoff_hz, order=order, period=period, drift=drift)
    keypoints = {k: out[:, i] for i, k in enumerate(names)}
    return replace(motion, keypoints=keypoints, meta={**motion.meta, "smoothed_hz": cutoff_hz})
