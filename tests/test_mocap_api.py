"""load_motion / default_clip, and what every reader promises, on every real fixture."""

from __future__ import annotations

import hashlib
from dataclasses import replace
from functools import cache
from pathlib import Path

import numpy as np
import pybullet_data
import pytest

from imitwalk.errors import MocapError
from imitwalk.mocap import LOWER_BODY, default_clip, load_motion

ALL = {
    "07_04": "cmu_bvh/07_04.bvh",
    "07_06": "cmu_bvh/07_06.bvh",
    "amc": "cmu_asf_amc/test.amc",
    "c3d": "c3d/treadmill_events.c3d",
    "walk": "deepmimic/humanoid3d_walk.txt",
    "turn_left": "deepmimic/walker_turn_left0.txt",
    "turn_right": "deepmimic/walker_turn_right0.txt",
}


@cache
def _load(path: str):
    return load_motion(path)


def load(shared: Path, name: str):
    return _load(str(shared / ALL[name]))


# (file, frames, fps). BVH: the header says 450 / 418 frames; frame 0, the converter's
# T-pose, is dropped, so 449 / 417 frames remain.
KNOWN = [
    ("07_04", 449, 120.0),
    ("07_06", 417, 120.0),
    ("amc", 2751, 120.0),
    ("c3d", 1206, 100.0),
    ("walk", 39, 30.0),
    ("turn_left", 38, 30.0),
    ("turn_right", 38, 30.0),
]


@pytest.mark.parametrize(("name", "frames", "fps"), KNOWN)
def test_known_frame_counts_and_rates(shared_mocap, name, frames, fps):
    m = load(shared_mocap, name)
    assert m.n_frames == frames
    assert m.fps == pytest.approx(fps)
    assert m.data.shape == (frames, len(m.channels))
    assert m.format == {"07": "bvh", "am": "amc", "c3": "c3d"}.get(name[:2], "deepmimic")


@pytest.mark.parametrize("name", ALL)
def test_keypoints_finite_and_z_up(shared_mocap, name):
    m = load(shared_mocap, name)
    k = m.keypoints
    assert set(LOWER_BODY) <= set(k)
    assert all(v.shape == (m.n_frames, 3) and np.isfinite(v).all() for v in k.values())
    top = k["head"] if "head" in k else k["neck"]
    feet = np.maximum(k["l_ankle"][:, 2], k["r_ankle"][:, 2])
    assert np.all(top[:, 2] > k["pelvis"][:, 2])
    assert np.all(k["pelvis"][:, 2] > feet)
    assert 0.7 < np.median(k["pelvis"][:, 2]) < 1.2
    # the left hip is on the left of the feet's forward direction (no mirroring)
    fwd = (k["l_toe"] + k["r_toe"] - k["l_ankle"] - k["r_ankle"])[:, :2]
    left = (k["l_hip"] - k["r_hip"])[:, :2]
    assert np.median(fwd[:, 0] * left[:, 1] - fwd[:, 1] * left[:, 0]) > 0


@pytest.mark.parametrize("name", ALL)
def test_segment_lengths_plausible(shared_mocap, name):
    m = load(shared_mocap, name)
    k = m.keypoints
    for s in "lr":
        thigh = np.linalg.norm(k[f"{s}_knee"] - k[f"{s}_hip"], axis=1)
        shank = np.linalg.norm(k[f"{s}_ankle"] - k[f"{s}_knee"], axis=1)
        assert 0.3 < np.median(thigh) < 0.6 and 0.3 < np.median(shank) < 0.6
        if m.format != "c3d":  # rigid skeletons: constant bone lengths
            assert np.ptp(thigh) < 1e-6 and np.ptp(shank) < 1e-6


def test_default_clip_is_the_installed_pybullet_copy(shared_mocap):
    path = default_clip()
    assert path.is_file() and Path(pybullet_data.getDataPath()) in path.parents
    m = load_motion(path)
    assert (m.n_frames, m.fps, m.loop, m.meta["period_frames"]) == (39, 30.0, True, 38)
    pinned = shared_mocap / ALL["walk"]
    assert (
        hashlib.sha256(path.read_bytes()).digest() == hashlib.sha256(pinned.read_bytes()).digest()
    )


def test_grounded_puts_lowest_foot_keypoint_at_zero(shared_mocap):
    m = load(shared_mocap, "07_06")
    up = np.array([0.0, 0.0, 0.5])
    lifted = replace(m, keypoints={k: v + up for k, v in m.keypoints.items()})
    g = lifted.grounded()
    assert min(g.keypoints[k][:, 2].min() for k in LOWER_BODY[5:]) == pytest.approx(0, abs=1e-12)
    assert g.keypoint_array().shape == (m.n_frames, 17, 3)
    with pytest.raises(MocapError, match="unknown keypoint 'tail'; valid: "):
        g.keypoint_array(("tail",))


def one_line_error(fn, match: str) -> str:
    with pytest.raises(MocapError, match=match) as info:
        fn()
    msg = str(info.value)
    assert "\n" not in msg and msg.strip() == msg
    return msg


def test_unknown_extension_lists_valid_ones(tmp_path):
    path = tmp_path / "walk.fbx"
    path.write_text("x")
    msg = one_line_error(lambda: load_motion(path), "unknown mocap file extension '.fbx'")
    assert all(ext in msg for ext in (".bvh", ".amc", ".c3d", ".txt", ".json"))


@pytest.mark.parametrize("name", ["gone.bvh", "gone.amc", "gone.c3d", "gone.txt"])
def test_missing_file(tmp_path, name):
    one_line_error(lambda: load_motion(tmp_path / name), "mocap file not found")


def test_units_option_is_bvh_only(shared_mocap):
    one_line_error(lambda: load_motion(shared_mocap / ALL["walk"], units="cm"), "BVH files only")
