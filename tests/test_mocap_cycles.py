"""Gait cycles, contacts, walking speed, periodicity and smoothing on the real walks."""

from __future__ import annotations

from dataclasses import replace
from functools import cache
from itertools import pairwise
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.signal import detrend, find_peaks

from imitwalk.errors import MocapError
from imitwalk.mocap import (
    cycle_period,
    find_cycles,
    foot_contacts,
    heel_strikes,
    leg_angles,
    load_motion,
    smooth,
)

WALKS = {
    "walk": "deepmimic/humanoid3d_walk.txt",
    "turn_left": "deepmimic/walker_turn_left0.txt",
    "turn_right": "deepmimic/walker_turn_right0.txt",
    "07_04": "cmu_bvh/07_04.bvh",
    "07_06": "cmu_bvh/07_06.bvh",
    "treadmill": "c3d/treadmill_events.c3d",
}
LONG = ["07_04", "07_06", "treadmill"]  # several cycles, not loops


@cache
def _load(path: str):
    return load_motion(path)


def load(shared: Path, name: str):
    return _load(str(shared / WALKS[name]))


@pytest.mark.parametrize("name", WALKS)
def test_find_cycles_whole_cycles_with_plausible_period(shared_mocap, name):
    m = load(shared_mocap, name)
    for foot in "lr":
        cycles = find_cycles(m, foot)
        assert len(cycles) >= 1
        for a, b in cycles:
            assert 0 <= a < b <= m.n_frames
            assert 0.8 <= (b - a) / m.fps <= 1.6
    assert 0.8 <= cycle_period(m) <= 1.6
    if m.loop:  # a DeepMimic loop of one stride is one cycle covering the loop
        assert find_cycles(m) == [(0, m.meta["period_frames"])]


@pytest.mark.parametrize("name", WALKS)
def test_walking_speed_plausible(shared_mocap, name):
    m = load(shared_mocap, name)
    pelvis = m.keypoints["pelvis"]
    end = m.meta.get("period_frames", m.n_frames - 1)
    pelvis_speed = np.linalg.norm(pelvis[end, :2] - pelvis[0, :2]) / (end / m.fps)
    # speed of the stance feet relative to the pelvis: the walking speed over ground,
    # and the belt speed on a treadmill
    contacts = foot_contacts(m)
    rel = []
    for f in "lr":
        mid = (m.keypoints[f"{f}_ankle"] + m.keypoints[f"{f}_toe"]) / 2 - pelvis
        v = np.linalg.norm(np.gradient(mid[:, :2], axis=0), axis=1) * m.fps
        rel.append(v[contacts[f]])
    foot_speed = float(np.median(np.concatenate(rel)))
    assert 0.5 < foot_speed < 2.0
    if name == "treadmill":
        assert pelvis_speed < 0.05  # the subject stays on the belt
    else:
        assert 0.5 < pelvis_speed < 2.0
        assert foot_speed == pytest.approx(pelvis_speed, rel=0.25)


def _first_acf_peak(x: np.ndarray, fps: float) -> tuple[float, float]:
    """Lag [s] and value of the first autocorrelation peak >= 0.5 after 0.4 s."""
    x = x - x.mean()
    n = len(x)
    acf = np.correlate(x, x, "full")[n - 1 :] / (n - np.arange(n))
    acf /= acf[0]
    peaks, _ = find_peaks(acf[: int(0.75 * n)])
    peaks = peaks[(peaks >= 0.4 * fps) & (acf[peaks] >= 0.5)]
    return peaks[0] / fps, float(acf[peaks[0]])


@pytest.mark.parametrize("name", LONG)
def test_hip_and_knee_angles_periodic_at_cycle_period(shared_mocap, name):
    m = load(shared_mocap, name)
    period = cycle_period(m)
    for side in "lr":
        for angle in leg_angles(m, side):
            lag, value = _first_acf_peak(angle, m.fps)
            assert lag == pytest.approx(period, rel=0.1)
            assert value > 0.8


@pytest.mark.parametrize("name", ["walk", "turn_left", "turn_right"])
def test_loop_angles_one_oscillation_per_loop(shared_mocap, name):
    m = load(shared_mocap, name)
    p = m.meta["period_frames"]
    for side in "lr":
        hip, knee = leg_angles(m, side)
        assert np.degrees(abs(hip[p] - hip[0])) < 10  # the loop closes
        assert np.degrees(np.ptp(hip)) > 25
        wrapped = np.concatenate([knee[:p]] * 3)
        swing, _ = find_peaks(wrapped, height=np.radians(50))
        assert np.count_nonzero((swing >= p) & (swing < 2 * p)) == 1  # one swing per loop


def test_treadmill_events_match_vicon(shared_mocap):
    m = load(shared_mocap, "treadmill")
    contacts = foot_contacts(m)
    for side in ("Left", "Right"):
        f = side[0].lower()
        events = sorted((e[3], e[1]) for e in m.meta["events"] if e[0] == side)
        strikes = [i for i, label in events if label == "Foot Strike"]
        ours = heel_strikes(m, f)
        assert len(ours) == len(strikes)
        assert np.all(np.abs(ours - strikes) <= 4)  # 40 ms at 100 Hz
        ref = np.zeros(m.n_frames, bool)
        covered = np.zeros(m.n_frames, bool)
        for (a, label), (b, _) in pairwise(events):
            ref[a:b], covered[a:b] = label == "Foot Strike", True
        assert np.mean(ref[covered] == contacts[f][covered]) > 0.95


@pytest.mark.parametrize("name", WALKS)
def test_contact_masks(shared_mocap, name):
    m = load(shared_mocap, name)
    contacts = foot_contacts(m)
    for f in "lr":
        c = contacts[f]
        assert c.shape == (m.n_frames,) and c.dtype == bool
        assert 0.5 < c.mean() < 0.75  # stance is ~60 % of a walking cycle
    assert np.all(contacts["l"] | contacts["r"])  # walking: never both feet off


def _no_cycle(m) -> str:
    with pytest.raises(MocapError, match="no walking cycle found in ") as info:
        find_cycles(m)
    assert "\n" not in str(info.value)
    return str(info.value)


def test_standing_still_has_no_cycle(shared_mocap):
    m = load(shared_mocap, "07_06")
    frozen = {k: np.repeat(v[100:101], 360, axis=0) for k, v in m.keypoints.items()}
    _no_cycle(replace(m, data=np.repeat(m.data[100:101], 360, axis=0), keypoints=frozen))


def test_few_frames_have_no_cycle(shared_mocap):
    m = load(shared_mocap, "07_06")
    short = replace(m, data=m.data[:6], keypoints={k: v[:6] for k, v in m.keypoints.items()})
    assert "only 6 frames" in _no_cycle(short)


def test_hip_periodicity_fallback(shared_mocap):
    """Feet that stay on the ground and never move relative to the pelvis give no heel
    strikes; the swinging thighs still give the cycles."""
    m = load(shared_mocap, "treadmill")
    k = dict(m.keypoints)
    for part in ("l_ankle", "r_ankle", "l_toe", "r_toe"):
        k[part] = k["pelvis"] + (k[part] - k["pelvis"]).mean(axis=0)
        k[part][:, 2] = m.keypoints[part][:, 2].min()
    stiff = replace(m, keypoints=k)
    assert len(heel_strikes(stiff, "l")) == 0
    cycles = find_cycles(stiff, "l")
    assert len(cycles) >= 5
    assert np.median([b - a for a, b in cycles]) / m.fps == pytest.approx(cycle_period(m), rel=0.05)


def test_unknown_foot(shared_mocap):
    with pytest.raises(MocapError, match=r"unknown foot 'left'; valid: l, r"):
        find_cycles(load(shared_mocap, "walk"), "left")


# --- smoothing


def _hf_power(x: np.ndarray, fps: float, above_hz: float) -> float:
    """Power of ``(T, 3)`` noise-like x above ``above_hz``, less a linear trend."""
    spec = np.abs(np.fft.rfft(detrend(x, axis=0), axis=0)) ** 2
    return float(spec[np.fft.rfftfreq(len(x), 1 / fps) > above_hz].sum())


@settings(max_examples=15, deadline=None)
@given(
    cutoff=st.floats(2.0, 12.0),
    noise=st.floats(0.001, 0.02),
    seed=st.integers(0, 2**16),
    name=st.sampled_from(["07_06", "treadmill"]),
)
def test_smooth_keeps_shape_and_removes_high_frequencies(shared_mocap, cutoff, noise, seed, name):
    m = load(shared_mocap, name)
    rng = np.random.default_rng(seed)
    added = {k: rng.normal(0, noise, v.shape) for k, v in m.keypoints.items()}
    out = smooth(replace(m, keypoints={k: v + added[k] for k, v in m.keypoints.items()}), cutoff)
    base = smooth(m, cutoff)
    assert out.keypoints.keys() == m.keypoints.keys() and out.meta["smoothed_hz"] == cutoff
    for key, v in out.keypoints.items():
        assert v.shape == m.keypoints[key].shape and np.isfinite(v).all()
        left = v - base.keypoints[key]  # the filter is linear: what is left of the noise
        assert _hf_power(left, m.fps, 2 * cutoff) < 0.05 * _hf_power(added[key], m.fps, 2 * cutoff)
        if cutoff >= 6.0:  # walking kinematics lie below ~6 Hz: the motion itself is kept
            assert np.sqrt(np.mean((base.keypoints[key] - m.keypoints[key]) ** 2)) < 0.005


def test_smooth_loop_is_periodic(shared_mocap):
    """A loop is smoothed as the endless walk DeepMimic plays: like the middle copy of the
    clip repeated three times, each copy advanced by the root offset per loop."""
    m = load(shared_mocap, "walk")
    p = m.meta["period_frames"]
    advance = m.keypoints["pelvis"][p] - m.keypoints["pelvis"][0]
    tiled = {
        k: np.concatenate([v[:p] + c * advance for c in range(3)]) for k, v in m.keypoints.items()
    }
    long = replace(m, loop=False, data=np.tile(m.data[:p], (3, 1)), keypoints=tiled, meta={})
    ref, out = smooth(long, 4.0), smooth(m, 4.0)
    for key, v in out.keypoints.items():
        np.testing.assert_allclose(v[:p], ref.keypoints[key][p : 2 * p] - advance, atol=1e-6)
        np.testing.assert_allclose(v[p] - v[0], advance, atol=1e-9)  # closes with the offset


def test_smooth_rejects_cutoff_above_nyquist(shared_mocap):
    with pytest.raises(MocapError, match=r"cutoff 20.0 Hz must be in \(0, 15\) Hz at 30 fps"):
        smooth(load(shared_mocap, "walk"), 20.0)
