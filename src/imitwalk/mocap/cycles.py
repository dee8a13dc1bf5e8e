"""Foot contacts, heel strikes and whole gait cycles from keypoints.

A foot is in contact when it is low and not moving forward relative to the pelvis along
the walking direction (:func:`foot_contacts`). Relative to the pelvis, a stance foot
always moves backwards, overground or on a treadmill (where the pelvis barely translates
and the belt carries the foot back), so no ground speed is needed. Heel strike is the
onset of contact: the foot's most forward point relative to the pelvis (the event of
Zeni et al. 2008, Gait Posture 27:710). The walking direction is the horizontal normal
of the hip line, per frame, so turning walks work too.

If contacts give no whole cycle, the thigh angle's periodicity (autocorrelation) is the
fallback: cycles then run from one maximum hip flexion to the next.
"""

from __future__ import annotations

import math
from itertools import pairwise

import numpy as np
from scipy.ndimage import minimum_filter1d
from scipy.signal import find_peaks

from imitwalk.errors import MocapError, unknown_name
from imitwalk.mocap.filters import lowpass, period_frames
from imitwalk.mocap.motion import Motion

__all__ = [
    "cycle_period",
    "find_cycles",
    "foot_contacts",
    "heading",
    "heel_strikes",
    "leg_angles",
]

FEET = ("l", "r")
MIN_PERIOD_S, MAX_PERIOD_S = 0.4, 3.0  # accepted stride durations [s]
_MIN_RUN_S = 0.05  # contact / swing runs shorter than this are merged [s]


def _check_foot(foot: str) -> None:
    if foot not in FEET:
        raise unknown_name("foot", foot, FEET, MocapError)


def _smooth(x: np.ndarray, motion: Motion, hz: float = 6.0) -> np.ndarray:
    period = period_frames(motion) if motion.loop else None
    if motion.n_frames < 4:
        return x
    return lowpass(x, motion.fps, min(hz, 0.4 * motion.fps), period=period)


def heading(motion: Motion) -> np.ndarray:
    """``(T, 3)`` unit horizontal walking direction: ``(l_hip - r_hip) x z``, smoothed (1 Hz)."""
    left = motion.keypoints["l_hip"] - motion.keypoints["r_hip"]
    fwd = np.cross(left, [0.0, 0.0, 1.0])
    fwd[:, 2] = 0.0
    fwd = _smooth(fwd, motion, 1.0)
    return fwd / np.linalg.norm(fwd, axis=1, keepdims=True)


def _leg_length(motion: Motion) -> float:
    k = motion.keypoints
    thigh = np.linalg.norm(k["l_knee"] - k["l_hip"], axis=1)
    shank = np.linalg.norm(k["l_ankle"] - k["l_knee"], axis=1)
    return float(np.median(thigh + shank))


def _relative_ap(motion: Motion, name: str, fwd: np.ndarray) -> np.ndarray:
    """``(T,)`` position [m] of keypoint ``name`` ahead of the pelvis along ``fwd``."""
    return np.sum((motion.keypoints[name] - motion.keypoints["pelvis"]) * fwd, axis=1)


def _clean_runs(mask: np.ndarray, min_len: int) -> np.ndarray:
    """Merge inner runs (of either value) shorter than ``min_len`` frames into their
    neighbours, shortest first.

    Only a run with a neighbour on both sides is flipped: flipping it joins it with both,
    so each pass removes two runs and the loop ends after at most ``len(mask) // 2``
    passes. The first and last runs (and a mask of one run, or an empty one) are kept.
    """
    mask = np.array(mask, dtype=bool)  # a copy
    while True:
        edges = np.flatnonzero(np.diff(mask.astype(np.int8))) + 1
        bounds = np.concatenate([[0], edges, [len(mask)]])
        lengths = np.diff(bounds)
        short = [i for i in range(1, len(lengths) - 1) if lengths[i] < min_len]
        if not short:
            return mask
        i = min(short, key=lambda j: lengths[j])
        mask[bounds[i] : bounds[i + 1]] = ~mask[bounds[i]]


def foot_contacts(motion: Motion) -> dict[str, np.ndarray]:
    """Foot-contact masks ``{"l": (T,) bool, "r": (T,) bool}``.

    Contact: the ankle or the toe is low (the heel lands first, the toe leaves last) and
    the mid-foot does not move forward relative to the pelvis faster than
    ``0.12 * leg length`` per second. "Low": the height above its own lowest point within
    +-0.75 s (so a sloping floor does not matter) is at most 3 cm or 35 % of that
    height's 95th percentile, whichever is more. Runs shorter than 50 ms are merged into
    their neighbours. Masks are ``(T,)`` bool; the retargeting stage reuses them.
    """
    fwd = heading(motion)
    leg = _leg_length(motion)
    k = motion.keypoints
    window = 2 * round(0.75 * motion.fps) + 1  # local ground: the lowest point within +-0.75 s
    out = {}
    for f in FEET:
        mid = (k[f"{f}_ankle"] + k[f"{f}_toe"]) / 2
        rel = _smooth(np.sum((mid - k["pelvis"]) * fwd, axis=1), motion)
        vel = _gradient(rel, motion) * motion.fps  # (T,) [m/s]
        low = np.zeros(motion.n_frames, dtype=bool)
        for part in ("ankle", "toe"):
            z = k[f"{f}_{part}"][:, 2]
            h = z - minimum_filter1d(z, window, mode="wrap" if motion.loop else "nearest")
            low |= h <= max(0.03, 0.35 * np.percentile(h, 95))
        mask = low & (vel <= 0.12 * leg)
        out[f] = _clean_runs(mask, max(1, round(_MIN_RUN_S * motion.fps)))
    return out


def _gradient(x: np.ndarray, motion: Motion) -> np.ndarray:
    if len(x) < 2:
        return np.zeros_like(x)
    if motion.loop:  # x is periodic (relative to the pelvis): wrap around the ends
        p = period_frames(motion)
        ext = np.concatenate([x[p - 1 : p], x, x[len(x) - p : len(x) - p + 1]])
        return np.gradient(ext)[1:-1]
    return np.gradient(x)


def heel_strikes(motion: Motion, foot: str = "l") -> np.ndarray:
    """Frame indices of heel strikes (contact onsets after a swing) of ``foot``."""
    _check_foot(foot)
    return _onsets(foot_contacts(motion)[foot], motion)


def _onsets(c: np.ndarray, motion: Motion) -> np.ndarray:
    if motion.loop:  # a contact starting at frame 0 of a loop is a strike if the loop ends in swing
        p = period_frames(motion)
        onsets = np.flatnonzero(c & ~np.concatenate([c[p - 1 : p], c[:-1]]))
        return onsets[onsets < p]  # frame p is frame 0 of the next loop
    return np.flatnonzero(c & ~np.concatenate([[True], c[:-1]]))


def leg_angles(motion: Motion, side: str = "l") -> tuple[np.ndarray, np.ndarray]:
    """Sagittal thigh angle and knee flexion of one leg, ``(T,)`` each [rad].

    The thigh angle is the hip-knee vector's inclination from the downward vertical in
    the walking direction (positive forward: hip flexion); knee flexion is 0 when the
    leg is straight.
    """
    _check_foot(side)
    k = motion.keypoints
    thigh = k[f"{side}_knee"] - k[f"{side}_hip"]
    shank = k[f"{side}_ankle"] - k[f"{side}_knee"]
    fwd = heading(motion)
    hip = np.arctan2(np.sum(thigh * fwd, axis=1), -thigh[:, 2])
    cos = (
        np.sum(thigh * shank, axis=1)
        / np.linalg.norm(thigh, axis=1)
        / np.linalg.norm(shank, axis=1)
    )
    return hip, np.arccos(np.clip(cos, -1.0, 1.0))


def _autocorr_period(x: np.ndarray, fps: float) -> tuple[float, float]:
    """(period [frames], correlation) of the first autocorrelation peak >= 0.5 at 0.4-3 s."""
    x = x - x.mean()
    n = len(x)
    acf = np.correlate(x, x, "full")[n - 1 :] / (n - np.arange(n))  # unbiased
    if acf[0] <= 0:
        return 0.0, 0.0
    acf = acf / acf[0]
    lo, hi = int(MIN_PERIOD_S * fps), min(int(MAX_PERIOD_S * fps), int(0.75 * n))
    peaks, _ = find_peaks(acf[: hi + 1])
    peaks = peaks[(peaks >= lo) & (acf[peaks] >= 0.5)]
    if len(peaks) == 0:
        return 0.0, 0.0
    return float(peaks[0]), float(acf[peaks[0]])  # the first strong peak: not a multiple


def _cycles_from_periodicity(motion: Motion, foot: str) -> list[tuple[int, int]]:
    hip, _ = leg_angles(motion, foot)
    if np.ptp(np.percentile(hip, [5, 95])) < np.radians(15):
        return []
    if motion.loop:
        return [(0, period_frames(motion))]
    period, corr = _autocorr_period(hip, motion.fps)
    if corr < 0.5:
        return []
    peaks, _ = find_peaks(_smooth(hip, motion), distance=max(1, int(0.7 * period)))
    return [(int(a), int(b)) for a, b in pairwise(peaks) if 0.7 * period <= b - a <= 1.3 * period]


def _min_frames(fps: float) -> int:
    """Fewest frames that can hold one gait cycle at ``fps`` [Hz]: ``MIN_PERIOD_S`` (0.4 s),
    and at least 8."""
    return max(8, math.ceil(MIN_PERIOD_S * fps - 1e-9))


def _check_length(motion: Motion) -> None:
    """MocapError (one line: frames, seconds, the minimum) if ``motion`` is shorter than
    one gait cycle can be."""
    n, need = motion.n_frames, _min_frames(motion.fps)
    if n >= need:
        return
    dropped = " (after dropping the T-pose frame 0)" if motion.meta.get("skipped_frames") else ""
    raise MocapError(
        f"no walking cycle found in {motion.source}: only {n} frame{'' if n == 1 else 's'}"
        f"{dropped} = {n / motion.fps:.3g} s at {motion.fps:g} fps, need >= {need} frames "
        f"(one gait cycle lasts >= {MIN_PERIOD_S:g} s)"
    )


def find_cycles(motion: Motion, foot: str = "l") -> list[tuple[int, int]]:
    """Whole gait cycles of ``foot``: ``(start, end)`` frame pairs, end exclusive.

    Each runs from a heel strike to the next heel strike of the same foot, lasts 0.4-3 s,
    holds one heel strike of the other foot, and the foot travels at least 10 % of the leg
    length relative to the pelvis. A looping clip with one strike of each foot
    per loop is one cycle ``[(0, period_frames)]``. Falls back to hip periodicity.

    Raises:
        MocapError: ``"no walking cycle found in ..."`` if there is none, or if the clip
            is shorter than one cycle can be (0.4 s and 8 frames; the message says so).
    """
    _check_foot(foot)
    src = motion.source
    _check_length(motion)
    fwd = heading(motion)
    reach = _leg_length(motion) * 0.1
    contacts = foot_contacts(motion)
    strikes = {f: _onsets(contacts[f], motion) for f in FEET}
    other = strikes["r" if foot == "l" else "l"]
    hs = strikes[foot]
    if motion.loop and len(hs) == 1 and len(other) == 1:
        return [(0, period_frames(motion))]
    rel = _relative_ap(motion, f"{foot}_ankle", fwd)
    cycles = []
    for a, b in pairwise(hs):
        ok_time = MIN_PERIOD_S <= (b - a) / motion.fps <= MAX_PERIOD_S
        ok_other = np.count_nonzero((other > a) & (other < b)) == 1
        if ok_time and ok_other and np.ptp(rel[a:b]) >= reach:
            cycles.append((int(a), int(b)))
    if not cycles:
        cycles = _cycles_from_periodicity(motion, foot)
    if not cycles:
        raise MocapError(
            f"no walking cycle found in {src}: {len(hs)} heel strikes of foot {foot!r} "
            "and no periodic hip motion"
        )
    return cycles


def cycle_period(motion: Motion) -> float:
    """Median gait-cycle duration [s] over both feet."""
    lengths = []
    for f in FEET:
        try:
            lengths += [b - a for a, b in find_cycles(motion, f)]
        except MocapError:
            continue
    if not lengths:
        find_cycles(motion, "l")  # raises the explanatory error
    return float(np.median(lengths)) / motion.fps
