"""BVH reader: T-pose frame, unit/axis/channel-order/rig-name variants, malformed files."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from imitwalk.errors import MocapError
from imitwalk.mocap import load_motion
from imitwalk.mocap.bvh import UNITS, read_bvh

BVH_0704 = "cmu_bvh/07_04.bvh"
BVH_0706 = "cmu_bvh/07_06.bvh"
PERMS = ["XYZ", "XZY", "YXZ", "YZX", "ZXY", "ZYX"]
M_Z_UP = np.array([[1.0, 0, 0], [0, 0, -1], [0, 1, 0]])  # (x, y, z) -> (x, -z, y)


def test_tpose_frame_is_dropped_and_recorded(shared_mocap):
    m = read_bvh(shared_mocap / BVH_0704)
    assert m.n_frames == 449 and m.meta["skipped_frames"] == 1 and m.meta["tpose_detected"]
    full = read_bvh(shared_mocap / BVH_0704, skip_tpose=False)
    assert full.n_frames == 450  # as the header says
    np.testing.assert_array_equal(full.data[1:], m.data)
    assert (m.meta["units"], m.meta["units_guessed"], m.meta["up_axis"]) == ("cmu", True, "y")
    assert m.meta["joints"]["l_knee"] == "LeftLeg" and m.meta["joints"]["l_shoulder"] == "LeftArm"


def rewrite_bvh(text: str, frames: slice, orders: list[str], z_up: bool, prefix: str, scale: float):
    """Rewrite a cgspeed BVH (root 6 channels, others ZYX) with other conventions."""
    head, motion = text.split("MOTION")
    out, j = [], 0
    for line in head.splitlines():
        tok = line.split()
        if tok and tok[0] in ("ROOT", "JOINT"):
            line = f"{tok[0]} {prefix}{tok[1]}"
        elif tok and tok[0] == "OFFSET":
            v = np.array([float(t) for t in tok[1:]]) * scale
            v = M_Z_UP @ v if z_up else v
            line = "OFFSET " + " ".join(f"{x:.9g}" for x in v)
        elif tok and tok[0] == "CHANNELS":
            rot = " ".join(f"{a}rotation" for a in orders[j])
            line = (
                f"CHANNELS 6 Xposition Yposition Zposition {rot}" if j == 0 else f"CHANNELS 3 {rot}"
            )
            j += 1
        out.append(line)
    vals = np.array([r.split() for r in motion.strip().splitlines()[2:]], dtype=float)[frames]
    new = np.zeros_like(vals)
    pos = vals[:, :3] * scale
    new[:, :3] = pos @ M_Z_UP.T if z_up else pos
    for k in range(j):
        c = 3 + 3 * k
        r = Rotation.from_euler("ZYX", vals[:, c : c + 3], degrees=True).as_matrix()
        if z_up:
            r = M_Z_UP @ r @ M_Z_UP.T
        new[:, c : c + 3] = Rotation.from_matrix(r).as_euler(orders[k], degrees=True)
    body = "\n".join(" ".join(f"{x:.10g}" for x in row) for row in new)
    return "\n".join(out) + f"\nMOTION\nFrames: {len(new)}\nFrame Time: 0.0333333\n{body}\n"


@settings(max_examples=12, deadline=None)
@given(
    orders=st.lists(st.sampled_from(PERMS), min_size=31, max_size=31),
    z_up=st.booleans(),
    prefix=st.sampled_from(["", "mixamorig:"]),
    unit=st.sampled_from(sorted(UNITS)),
)
def test_variants_give_the_same_keypoints(
    shared_mocap, tmp_path_factory, orders, z_up, prefix, unit
):
    """Same motion, any rotation order per joint, y-up or z-up, Mixamo names, any unit."""
    text = (shared_mocap / BVH_0706).read_text()
    ref = read_bvh(shared_mocap / BVH_0706)
    path = tmp_path_factory.mktemp("bvh") / "variant.bvh"
    path.write_text(
        rewrite_bvh(text, slice(1, 31), orders, z_up, prefix, UNITS["cmu"] / UNITS[unit])
    )
    m = load_motion(path)
    assert m.meta["units"] == unit and m.meta["up_axis"] == ("z" if z_up else "y")
    assert (m.n_frames, m.fps, m.meta["skipped_frames"]) == (30, 30.0, 0)
    for key, v in m.keypoints.items():
        np.testing.assert_allclose(v, ref.keypoints[key][:30], atol=1e-6, err_msg=key)


@settings(max_examples=8, deadline=None)
@given(a=st.sampled_from(sorted(UNITS)), b=st.sampled_from(sorted(UNITS)))
def test_units_scale_exactly(shared_mocap, tmp_path_factory, a, b):
    """A file written in unit ``a``, read as ``a`` and as ``b``: the keypoints scale by
    exactly the ratio where the legs are still a human's (0.3-1.5 m); elsewhere the
    reading is refused, naming --units."""
    path = tmp_path_factory.mktemp("units") / "walk.bvh"
    text = (shared_mocap / BVH_0706).read_text()
    path.write_text(
        rewrite_bvh(text, slice(1, 31), ["ZYX"] * 31, False, "", UNITS["cmu"] / UNITS[a])
    )
    ma = read_bvh(path, units=a)
    assert not ma.meta["units_guessed"] and ma.meta["units"] == a
    leg = ma.meta["leg_length_m"] * UNITS[b] / UNITS[a]
    if not 0.3 <= leg <= 1.5:
        with pytest.raises(
            MocapError, match=rf"outside the human 0.3-1.5 m; pass --units \(read as {b}\)"
        ):
            read_bvh(path, units=b)
        return
    mb = read_bvh(path, units=b)
    for key in ma.keypoints:
        np.testing.assert_allclose(
            ma.keypoints[key] / UNITS[a], mb.keypoints[key] / UNITS[b], rtol=1e-12
        )


def test_position_channels_on_every_joint(shared_mocap, tmp_path):
    """Game rigs often give every joint 6 channels whose positions equal the OFFSETs."""
    text = (shared_mocap / BVH_0706).read_text()
    head, motion = text.split("MOTION")
    offsets, lines = [], []
    for line in head.splitlines():
        tok = line.split()
        if tok[:1] == ["OFFSET"]:
            offsets.append([float(t) for t in tok[1:]])
        if tok[:2] == ["CHANNELS", "3"]:
            line = "CHANNELS 6 Xposition Yposition Zposition Zrotation Yrotation Xrotation"
        lines.append(line)
    joint_offsets = [o for i, o in enumerate(offsets) if not _is_end_site(head, i)]
    vals = np.array([r.split() for r in motion.strip().splitlines()[2:]], dtype=float)[1:11]
    cols = [vals[:, :6]]
    for j in range(1, 31):
        cols += [np.tile(joint_offsets[j], (len(vals), 1)), vals[:, 3 + 3 * j : 6 + 3 * j]]
    body = "\n".join(" ".join(f"{x:.10g}" for x in row) for row in np.hstack(cols))
    path = tmp_path / "six.bvh"
    path.write_text("\n".join(lines) + f"\nMOTION\nFrames: 10\nFrame Time: .0083333\n{body}\n")
    m, ref = load_motion(path), read_bvh(shared_mocap / BVH_0706)
    for key, v in m.keypoints.items():
        np.testing.assert_allclose(v, ref.keypoints[key][:10], atol=1e-9, err_msg=key)


def _is_end_site(head: str, offset_index: int) -> bool:
    """Whether the ``offset_index``-th OFFSET of the hierarchy belongs to an End Site."""
    owners = [
        ln.split()[0]
        for ln in head.splitlines()
        if ln.split()[:1] in (["ROOT"], ["JOINT"], ["End"])
    ]
    return owners[offset_index] == "End"


# --- malformed files: one-line MocapError with the line number


def _bad(tmp_path: Path, text: str, match: str) -> str:
    path = tmp_path / "bad.bvh"
    path.write_text(text)
    with pytest.raises(MocapError, match=match) as info:
        load_motion(path)
    msg = str(info.value)
    assert "\n" not in msg
    return msg


@pytest.fixture
def lines(shared_mocap) -> list[str]:
    return (shared_mocap / BVH_0704).read_text().splitlines()


def test_truncated_motion(tmp_path, lines):
    _bad(
        tmp_path, "\n".join(lines[:300]), r"line 300: file ends after 113 of 450 frames"
    )  # lines 188-300


def test_truncated_before_motion(tmp_path, lines):
    _bad(tmp_path, "\n".join(lines[:120]), r"line 120: file ends without a MOTION section")


def test_missing_frame_time(tmp_path, lines):
    _bad(tmp_path, "\n".join(lines[:186]), r"line 187: expected 'Frame Time:'")


def test_wrong_value_count(tmp_path, lines):
    lines[250] = " ".join(lines[250].split()[:-1])
    _bad(tmp_path, "\n".join(lines), r"line 251: 95 values, expected 96 channels")


def test_non_numeric_value(tmp_path, lines):
    tok = lines[260].split()
    tok[7] = "1.2.3"
    lines[260] = " ".join(tok)
    _bad(tmp_path, "\n".join(lines), r"line 261: non-numeric value")


def test_rig_with_an_unknown_toe_name(shared_mocap, tmp_path, lines):
    """A toe joint no name table knows: the legs come from the skeleton's structure."""
    path = tmp_path / "tip.bvh"
    path.write_text("\n".join(lines).replace("JOINT LeftToeBase", "JOINT LeftFootTip"))
    m, ref = read_bvh(path), read_bvh(shared_mocap / BVH_0704)
    assert m.meta["roles"] == "structure" and m.meta["joints"]["l_toe"] == "LeftFootTip"
    for key, v in ref.keypoints.items():
        np.testing.assert_array_equal(m.keypoints[key], v, err_msg=key)


def test_unknown_unit(shared_mocap):
    with pytest.raises(MocapError, match=r"unknown BVH unit 'feet'; valid: cm, cmu, inch, m, mm$"):
        read_bvh(shared_mocap / BVH_0704, units="feet")
