"""ASF/AMC reader on the real CMU pair, and mismatched pairs."""

from __future__ import annotations

import shutil
from functools import cache
from pathlib import Path

import numpy as np
import pytest

from imitwalk.errors import MocapError
from imitwalk.mocap import leg_angles, load_motion
from imitwalk.mocap.amc import read_amc, read_asf

AMC = "cmu_asf_amc/test.amc"
ASF = "cmu_asf_amc/test.asf"


@cache
def _pair(folder: str):
    return load_motion(Path(folder) / AMC)


def test_pair_parses(shared_mocap):
    m = _pair(str(shared_mocap))
    assert (m.n_frames, m.fps, m.format) == (2751, 120.0, "amc")
    assert m.meta["skeleton"].endswith("test.asf")  # the single .asf beside the .amc
    assert m.data.shape == (2751, 6 + 56)  # root TX..RZ + the 28 bones' DOFs
    seg = m.meta["segments_m"]
    assert seg["lfemur"] == pytest.approx(7.1578 * 0.0254 / 0.45)  # ASF length 0.45
    assert all(0.3 < seg[b] < 0.6 for b in ("lfemur", "rfemur", "ltibia", "rtibia"))


def test_axis_convention_gives_knee_angle_of_tibia_dof(shared_mocap):
    """The tibia's rest direction equals the femur's and its only DOF is rx, so with
    G = G_parent C M C^-1 the knee angle is exactly |ltibia rx| in every frame."""
    m = _pair(str(shared_mocap))
    for s in "lr":
        _, knee = leg_angles(m, s)
        rx = m.data[:, m.channels.index(f"{s}tibia.rx")]
        np.testing.assert_allclose(np.degrees(knee), np.abs(rx), atol=1e-6)


def test_asf_units_and_hierarchy(shared_mocap):
    skel = read_asf(shared_mocap / ASF)
    assert len(skel.bones) == 31  # root + 30 bones
    assert skel.metres_per_unit == pytest.approx(0.0254 / 0.45)
    assert skel.bones["ltibia"].parent == "lfemur" and skel.bones["lfemur"].dof == (
        "rx",
        "ry",
        "rz",
    )
    assert skel.bones["root"].dof == ("tx", "ty", "tz", "rx", "ry", "rz")


def _copy_pair(shared: Path, tmp: Path, asf_edit) -> tuple[Path, Path]:
    amc = tmp / "clip.amc"
    shutil.copyfile(shared / AMC, amc)
    asf = tmp / "skel.asf"
    asf.write_text(asf_edit((shared / ASF).read_text()))
    return amc, asf


def _one_line(fn, match: str) -> None:
    with pytest.raises(MocapError, match=match) as info:
        fn()
    assert "\n" not in str(info.value)


def test_amc_bone_missing_from_asf(shared_mocap, tmp_path):
    amc, asf = _copy_pair(shared_mocap, tmp_path, lambda t: t.replace("ltibia", "lshin"))
    _one_line(lambda: read_amc(amc, asf), r"line \d+: bone 'ltibia' is not in the ASF")


def test_amc_dof_count_differs_from_asf(shared_mocap, tmp_path):
    def edit(text: str) -> str:
        head, tail = text.split("name ltibia", 1)
        return head + "name ltibia" + tail.replace("dof rx", "dof rx rz", 1)

    amc, asf = _copy_pair(shared_mocap, tmp_path, edit)
    _one_line(lambda: read_amc(amc, asf), r"bone 'ltibia' has 1 values, its ASF dof has 2")


def test_asf_bone_absent_from_amc(shared_mocap, tmp_path):
    def edit(text: str) -> str:
        head, tail = text.split("name lhipjoint", 1)
        return head + "name lhipjoint" + tail.replace("XYZ", "XYZ\n    dof rx", 1)

    amc, asf = _copy_pair(shared_mocap, tmp_path, edit)
    _one_line(lambda: read_amc(amc, asf), r"bone 'lhipjoint' of the ASF appears in 0 of 2751")


@pytest.mark.parametrize("n_asf", [0, 2])
def test_skeleton_must_be_given_unless_single_asf_beside(shared_mocap, tmp_path, n_asf):
    amc = tmp_path / "clip.amc"
    amc.symlink_to(shared_mocap / AMC)
    for i in range(n_asf):
        (tmp_path / f"s{i}.asf").symlink_to(shared_mocap / ASF)
    _one_line(
        lambda: load_motion(amc),
        rf"name its ASF with --skeleton \(skeleton= in Python\); {n_asf} .asf files",
    )
    assert load_motion(amc, skeleton=shared_mocap / ASF).n_frames == 2751
