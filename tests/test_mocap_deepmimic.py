"""DeepMimic reader: the character's offsets, heights, loops, malformed files."""

from __future__ import annotations

import json
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pybullet_data
import pytest

from imitwalk.errors import MocapError
from imitwalk.mocap import load_motion
from imitwalk.mocap.deepmimic import OFFSETS, SCALE

CLIPS = ["humanoid3d_walk.txt", "walker_turn_left0.txt", "walker_turn_right0.txt"]


def test_offsets_match_installed_character():
    urdf = Path(pybullet_data.getDataPath()) / "humanoid" / "humanoid.urdf"
    root = ET.fromstring(urdf.read_bytes().rstrip(b"\0"))  # the shipped file ends in a NUL
    joints = {j.get("name"): j for j in root.iter("joint")}
    for name, (parent, offset) in OFFSETS.items():
        assert joints[name].find("parent").get("link") == parent
        xyz = [float(v) for v in joints[name].find("origin").get("xyz").split()]
        np.testing.assert_allclose(xyz, offset, atol=1e-6)
    env = Path(pybullet_data.__file__).parent.parent / "pybullet_envs/deep_mimic/env"
    assert f"globalScaling={SCALE}" in (env / "humanoid_stable_pd.py").read_text().replace(" ", "")


@pytest.mark.parametrize("clip", CLIPS)
def test_clip_geometry(shared_mocap, clip):
    m = load_motion(shared_mocap / "deepmimic" / clip)
    assert m.loop and m.meta["period_frames"] == m.n_frames - 1 and m.data.shape[1] == 44
    k = m.keypoints
    assert 0.84 < k["pelvis"][:, 2].min() and k["pelvis"][:, 2].max() < 0.89  # README: ~0.85 m
    np.testing.assert_allclose(k["pelvis"], m.data[:, [1, 3, 2]] * [1, -1, 1])  # y-up -> z-up
    toe_low = min(k["l_toe"][:, 2].min(), k["r_toe"][:, 2].min())
    assert -0.02 < toe_low < 0.03  # the sole reaches the ground
    assert np.all(k["pelvis"][-1, 0] - k["pelvis"][0, 0] > 0.5)  # walks along +x


def _bad(tmp_path: Path, doc, match: str) -> None:
    path = tmp_path / "bad.txt"
    path.write_text(doc if isinstance(doc, str) else json.dumps(doc))
    with pytest.raises(MocapError, match=match) as info:
        load_motion(path)
    assert "\n" not in str(info.value)


def test_malformed(shared_mocap, tmp_path):
    doc = json.loads((shared_mocap / "deepmimic" / CLIPS[0]).read_text())
    _bad(tmp_path, '{"Loop": "wrap", "Frames": [[0.03, 1', "not DeepMimic JSON")
    _bad(tmp_path, {"Loop": "wrap"}, "no 'Frames' list")
    doc["Frames"][5] = doc["Frames"][5][:40]
    _bad(tmp_path, doc, "frame 5 has 40 values, expected 44")
