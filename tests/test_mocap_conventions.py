"""Mocap as it comes: one CMU walk, written in other files' conventions, reads the same.

Rest poses along any axis, y-up / z-up / any-up files, 6 channels on every joint, a
static top joint, 24-120 fps, cm and m, other rigs' joint names, no names at all; and
the bad files that must be refused in one line.
"""

from __future__ import annotations

import json
import subprocess
import sys
from dataclasses import replace
from functools import cache
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from imitwalk.cli.main import main
from imitwalk.errors import MocapError
from imitwalk.mocap import LOWER_BODY, load_motion
from imitwalk.mocap._common import UP_AXES, UP_TO_Z_UP
from imitwalk.mocap.bvh import UNITS, read_bvh
from imitwalk.retarget.template import extract_template
from tests.helpers.bvh_writer import M_Z_UP, load_rig, write_bvh

SRC = "cmu_bvh/07_06.bvh"
CMU = UNITS["cmu"]
AXIS = {"x": [1, 0, 0], "y": [0, 1, 0], "z": [0, 0, 1], "-x": [-1, 0, 0], "-y": [0, -1, 0]}
AXIS["-z"] = [0, 0, -1]
PERMS = ["XYZ", "XZY", "YXZ", "YZX", "ZXY", "ZYX"]


@cache
def _reference(folder: str):
    return read_bvh(Path(folder) / SRC)


@cache
def _rig(folder: str, start: int = 1, stop: int | None = 121):
    return load_rig(Path(folder) / SRC, slice(start, stop))


def rest_along(axis: str) -> np.ndarray:
    """A rotation that lays the (y-up) rest pose along ``axis``."""
    r, _ = Rotation.align_vectors([AXIS[axis]], [[0, 1, 0]])
    return r.as_matrix()


def world_for(up: str) -> np.ndarray:
    """The axes of a file whose up axis is ``up``, from the y-up source's."""
    return UP_TO_Z_UP[up].T @ M_Z_UP


def assert_same(m, ref, step: int = 1, atol: float = 1e-3, names=None) -> None:
    """Every keypoint of ``m`` within ``atol`` [m] of frames 1, 1 + step, ... of ``ref``."""
    for key in names or m.keypoints:
        want = ref.keypoints[key][:120][::step]
        np.testing.assert_allclose(m.keypoints[key], want, rtol=0, atol=atol, err_msg=key)


@pytest.mark.parametrize("rest", sorted(AXIS))
@pytest.mark.parametrize("up", ["y", "z"])
@pytest.mark.parametrize(("fps", "unit"), [(30, "cm"), (120, "cm"), (30, "m"), (120, "m")])
def test_rest_pose_along_any_axis_gives_the_same_keypoints(
    shared_mocap, tmp_path, rest, up, fps, unit
):
    """Rest pose along +-x, +-y, +-z; y-up and z-up; 6 channels on every joint; 30 and
    120 fps; cm and m; at 30 fps also a static top joint with the pelvis below it."""
    step = 120 // fps
    path = write_bvh(
        tmp_path / "v.bvh",
        _rig(str(shared_mocap)),
        rest=rest_along(rest),
        world=world_for(up),
        scale=CMU / UNITS[unit],
        step=step,
        six=True,
        static_top=fps == 30,
    )
    m = load_motion(path)
    assert (m.meta["units"], m.meta["up_axis"], m.fps) == (unit, up, float(fps))
    assert m.meta["units_guessed"] and m.meta["up_guessed"] and m.meta["roles"] == "names"
    assert_same(m, _reference(str(shared_mocap)), step)


@settings(max_examples=25, deadline=None)
@given(
    quat=st.lists(st.floats(-1, 1), min_size=4, max_size=4).filter(
        lambda q: np.linalg.norm(q) > 0.1
    ),
    up=st.sampled_from(UP_AXES),
    unit=st.sampled_from(sorted(UNITS)),
    step=st.sampled_from([1, 2, 4, 5]),  # 120, 60, 30, 24 fps
    six=st.booleans(),
    static_top=st.booleans(),
    orders=st.lists(st.sampled_from(PERMS), min_size=31, max_size=31),
)
def test_any_rest_rotation_gives_the_same_keypoints(
    shared_mocap, tmp_path_factory, quat, up, unit, step, six, static_top, orders
):
    rest = Rotation.from_quat(quat).as_matrix()
    path = write_bvh(
        tmp_path_factory.mktemp("rot") / "v.bvh",
        _rig(str(shared_mocap)),
        rest=rest,
        world=world_for(up),
        scale=CMU / UNITS[unit],
        step=step,
        orders=orders,
        six=six,
        static_top=static_top,
    )
    m = load_motion(path)
    assert (m.meta["units"], m.meta["up_axis"], m.fps) == (unit, up, 120.0 / step)
    assert_same(m, _reference(str(shared_mocap)), step)


def test_the_same_reference_from_a_rewritten_file(shared_mocap, tmp_path):
    """The whole walk, rest pose along +x, z up, 6 channels, cm, static top joint: the same
    keypoints give the same gait template, from which the reference is built."""
    path = write_bvh(
        tmp_path / "v.bvh",
        _rig(str(shared_mocap), 1, None),
        rest=rest_along("x"),
        world=world_for("z"),
        scale=CMU / UNITS["cm"],
        six=True,
        static_top=True,
    )
    ref, m = _reference(str(shared_mocap)), load_motion(path)
    for key, v in m.keypoints.items():
        np.testing.assert_allclose(v, ref.keypoints[key], rtol=0, atol=1e-6, err_msg=key)
    a, b = extract_template(ref), extract_template(m)
    assert a.cycles == b.cycles and a.meta["cycles_report"] == b.meta["cycles_report"]
    for f in ("period", "stride", "leg_length", "stance", "swing_x", "swing_z", "shoulder"):
        np.testing.assert_allclose(getattr(b, f), getattr(a, f), rtol=0, atol=1e-6, err_msg=f)


CMU_NAMES = {
    "Hips": "{pelvis}",
    "LeftUpLeg": "{hip_l}",
    "LeftLeg": "{knee_l}",
    "LeftFoot": "{foot_l}",
    "LeftToeBase": "{toe_l}",
    "LeftShoulder": "{clav_l}",
    "LeftArm": "{arm_l}",
    "LeftForeArm": "{fore_l}",
    "LeftHand": "{hand_l}",
}
RIGS = {  # a rig's naming convention: part -> name, "{s}" the side in its own spelling
    "bandai": (
        "L",
        "R",
        dict(
            pelvis="Hips",
            hip="UpperLeg_{s}",
            knee="LowerLeg_{s}",
            foot="Foot_{s}",
            toe="Toes_{s}",
            clav="Shoulder_{s}",
            arm="UpperArm_{s}",
            fore="LowerArm_{s}",
            hand="Hand_{s}",
        ),
    ),
    "lafan1": (
        "Left",
        "Right",
        dict(
            pelvis="Hips",
            hip="{s}UpLeg",
            knee="{s}Leg",
            foot="{s}Foot",
            toe="{s}Toe",
            clav="{s}Shoulder",
            arm="{s}Arm",
            fore="{s}ForeArm",
            hand="{s}Hand",
        ),
    ),
    "l_prefix": (
        "l",
        "r",
        dict(
            pelvis="pelvis",
            hip="{s}_thigh",
            knee="{s}_shin",
            foot="{s}_foot",
            toe="{s}_toes",
            clav="{s}_clavicle",
            arm="{s}_upperarm",
            fore="{s}_forearm",
            hand="{s}_hand",
        ),
    ),
    "blender": (
        "L",
        "R",
        dict(
            pelvis="hips",
            hip="thigh.{s}",
            knee="shin.{s}",
            foot="foot.{s}",
            toe="toe.{s}",
            clav="shoulder.{s}",
            arm="upper_arm.{s}",
            fore="forearm.{s}",
            hand="hand.{s}",
        ),
    ),
    "unreal": (
        "l",
        "r",
        dict(
            pelvis="pelvis",
            hip="thigh_{s}",
            knee="calf_{s}",
            foot="foot_{s}",
            toe="ball_{s}",
            clav="clavicle_{s}",
            arm="upperarm_{s}",
            fore="lowerarm_{s}",
            hand="hand_{s}",
        ),
    ),
    "mixamo": (
        "Left",
        "Right",
        dict(
            pelvis="mixamorig:Hips",
            hip="mixamorig:{s}UpLeg",
            knee="mixamorig:{s}Leg",
            foot="mixamorig:{s}Foot",
            toe="mixamorig:{s}ToeBase",
            clav="mixamorig:{s}Shoulder",
            arm="mixamorig:{s}Arm",
            fore="mixamorig:{s}ForeArm",
            hand="mixamorig:{s}Hand",
        ),
    ),
}


def rig_names(rig: str, prefix: str = "") -> dict[str, str]:
    left, right, parts = RIGS[rig]
    out = {}
    for cmu, pattern in CMU_NAMES.items():
        part = pattern.strip("{}").split("_")[0]
        for side, word in (("Left", left), ("Right", right)):
            if cmu == "Hips" and side == "Right":
                continue
            name = cmu.replace("Left", side)
            out[name] = prefix + parts[part].format(s=word)
    return out


@pytest.mark.parametrize("rig", sorted(RIGS))
def test_other_rigs_names(shared_mocap, tmp_path, rig):
    """CMU, Bandai-Namco style (``UpperLeg_L``, static top joint, rest pose along +x,
    6 channels, 30 fps, cm, y up: the clips the issue was filed on), LAFAN1, ``l_*``,
    Blender, Unreal and Mixamo names give the joints they name."""
    names = rig_names(rig)
    path = write_bvh(
        tmp_path / "v.bvh",
        _rig(str(shared_mocap)),
        rest=rest_along("x"),
        scale=CMU / UNITS["cm"],
        step=4,
        six=True,
        static_top=rig == "bandai",
        names=names,
    )
    m = load_motion(path)
    assert m.meta["roles"] == "names" and m.meta["missing_keypoints"] == ()
    assert m.meta["joints"]["l_knee"] == names["LeftLeg"]
    assert m.meta["joints"]["r_shoulder"] == names["RightArm"]
    assert_same(m, _reference(str(shared_mocap)), 4)


def test_a_prefix_every_joint_shares_is_ignored(shared_mocap, tmp_path):
    rig = _rig(str(shared_mocap))
    names = {n: f"Character1_{n}" for n in rig.names}
    m = load_motion(write_bvh(tmp_path / "v.bvh", rig, step=4, names=names))
    assert m.meta["joints"]["l_ankle"] == "Character1_LeftFoot"
    assert_same(m, _reference(str(shared_mocap)), 4)


def _silent(rig) -> dict[str, str]:
    return {n: f"Bone{i:03d}" for i, n in enumerate(rig.names)}


def test_silent_names_fall_back_on_the_structure(shared_mocap, tmp_path):
    """Names that say nothing: the legs are the two mirror-image chains below the pelvis,
    sided by the direction of travel; the upper body is absent and listed."""
    rig = _rig(str(shared_mocap))
    path = write_bvh(
        tmp_path / "v.bvh", rig, rest=rest_along("-z"), step=2, six=True, names=_silent(rig)
    )
    m = load_motion(path)
    assert m.meta["roles"] == "structure" and set(m.keypoints) == set(LOWER_BODY)
    assert len(m.meta["missing_keypoints"]) == 8
    assert m.meta["joints"]["l_knee"] == _silent(rig)["LeftLeg"]
    assert_same(m, _reference(str(shared_mocap)), 2)


def test_joint_names_file_maps_by_hand(shared_mocap, tmp_path):
    rig = _rig(str(shared_mocap))
    silent = _silent(rig)
    cmu = {"pelvis": "Hips", "neck": "Neck", "head": "Head"}
    for s, side in (("l", "Left"), ("r", "Right")):
        for key, joint in (
            ("hip", "UpLeg"),
            ("knee", "Leg"),
            ("ankle", "Foot"),
            ("toe", "ToeBase"),
            ("shoulder", "Arm"),
            ("elbow", "ForeArm"),
            ("wrist", "Hand"),
        ):
            cmu[f"{s}_{key}"] = side + joint
    mapping = tmp_path / "names.json"
    mapping.write_text(json.dumps({k: silent[v] for k, v in cmu.items()}))
    path = write_bvh(tmp_path / "v.bvh", rig, step=4, names=silent)
    m = load_motion(path, joint_names=mapping)
    assert m.meta["missing_keypoints"] == () and m.meta["joints"]["head"] == silent["Head"]
    assert_same(m, _reference(str(shared_mocap)), 4)
    mapping.write_text(json.dumps({"l_kneee": "Bone003"}))
    with pytest.raises(MocapError, match=r"unknown keypoint in names.json 'l_kneee'; valid: "):
        load_motion(path, joint_names=mapping)
    mapping.write_text(json.dumps({"l_knee": "Femur"}))
    with pytest.raises(MocapError, match=r"unknown joint of .*'Femur'; valid: Bone000, "):
        load_motion(path, joint_names=mapping)


def test_up_and_units_overrides(shared_mocap, tmp_path):
    ref = _reference(str(shared_mocap))
    path = write_bvh(tmp_path / "v.bvh", _rig(str(shared_mocap)), world=world_for("-x"), step=4)
    m = load_motion(path, up="-x", units="cmu")
    assert not m.meta["up_guessed"] and not m.meta["units_guessed"]
    assert_same(m, ref, 4)
    with pytest.raises(MocapError, match=r"outside the human 0.3-1.5 m; pass --units \(read as cm"):
        load_motion(path, units="cm")
    with pytest.raises(MocapError, match=r"unknown up axis 'w'; valid: "):
        load_motion(path, up="w")


# --- bad input: one line, exit status 2 on the CLI, no traceback, no output


def _standing_tilted(shared_mocap: Path, path: Path) -> Path:
    """Frame 100 held for 0.5 s, in a file whose up axis is (1, 1, 1) / sqrt(3)."""
    rig = _rig(str(shared_mocap), 100, 101)
    rig = replace(rig, rot=np.repeat(rig.rot, 60, axis=0), root=np.repeat(rig.root, 60, axis=0))
    tilt, _ = Rotation.align_vectors([[1, 1, 1]], [[0, 1, 0]])
    return write_bvh(path, rig, world=tilt.as_matrix())


def _no_legs(path: Path) -> Path:
    chain = ["Body", "Neck", "Head"]
    lines = [
        "HIERARCHY",
        "ROOT Body",
        "{",
        "OFFSET 0 0 0",
        "CHANNELS 6 Xposition Yposition Zposition Zrotation Yrotation Xrotation",
    ]
    for name in chain[1:]:
        lines += [f"JOINT {name}", "{", "OFFSET 0 10 0", "CHANNELS 3 Zrotation Yrotation Xrotation"]
    lines += ["End Site", "{", "OFFSET 0 5 0", "}"] + ["}"] * len(chain)
    lines += ["MOTION", "Frames: 2", "Frame Time: 0.0333333"] + ["0 " * 12] * 2
    path.write_text("\n".join(lines) + "\n")
    return path


def _edited(shared_mocap: Path, path: Path, edit) -> Path:
    path.write_text(edit((shared_mocap / SRC).read_text()))
    return path


def _zero_offsets(text: str) -> str:
    return "\n".join(
        "OFFSET 0 0 0" if ln.split()[:1] == ["OFFSET"] else ln for ln in text.splitlines()
    )


BAD = {
    "no legs": (lambda s, p: _no_legs(p), r"cannot find the legs: .*joints: Body, Neck, Head; "),
    "zero-length bones": (lambda s, p: _edited(s, p, _zero_offsets), r"legs have zero length"),
    "0 frames": (
        lambda s, p: _edited(s, p, lambda t: t.replace("Frames: 418", "Frames: 0")),
        r"line \d+: Frames: 0, the file holds no motion",
    ),
    "Frame Time 0": (
        lambda s, p: _edited(s, p, lambda t: t.replace("Frame Time: .0083333", "Frame Time: 0")),
        r"line \d+: Frame Time '0' must be > 0 s",
    ),
    "every axis ambiguous": (
        _standing_tilted,
        r"cannot tell the up axis: the head is above the feet along .* alike.*; pass --up=x\|y",
    ),
}


@pytest.mark.parametrize("case", sorted(BAD))
def test_bad_bvh_one_line_error(shared_mocap, tmp_path, capsys, case):
    make, match = BAD[case]
    bad = make(shared_mocap, tmp_path / "bad.bvh")
    with pytest.raises(MocapError, match=match) as info:
        load_motion(bad)
    assert "\n" not in str(info.value)
    out = tmp_path / "o.npz"
    assert main(["retarget", str(bad), "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("error: ") and not out.exists()


def test_bad_bvh_through_a_real_process(shared_mocap, tmp_path):
    bad = _standing_tilted(shared_mocap, tmp_path / "bad.bvh")
    out = tmp_path / "o.npz"
    cmd = [sys.executable, "-m", "imitwalk", "retarget", str(bad), "--out", str(out)]
    res = subprocess.run(cmd, capture_output=True, text=True, timeout=300)
    assert res.returncode == 2 and "Traceback" not in res.stderr
    assert res.stderr.strip().count("\n") == 0 and res.stderr.startswith("error: ")
    assert not out.exists()


@pytest.mark.parametrize("command", ["retarget", "learn"])
def test_cli_mocap_flags(shared_mocap, tmp_path, command):
    """``--up``, ``--units`` and ``--joint-names`` reach the reader from both commands."""
    from imitwalk.cli.main import build_parser
    from imitwalk.cli.retarget_commands import clip_motion

    rig = _rig(str(shared_mocap))
    silent = _silent(rig)
    path = write_bvh(tmp_path / "v.bvh", rig, world=world_for("-x"), step=4, names=silent)
    mapping = tmp_path / "names.json"
    mapping.write_text(json.dumps({"head": silent["Head"], "neck": silent["Neck"]}))
    argv = [command, str(path), "--up=-x", "--units", "cmu", "--joint-names", str(mapping)]
    m = clip_motion(build_parser().parse_args([*argv, "--out", str(tmp_path / "o")]), robot=None)
    assert (m.meta["up_axis"], m.meta["units"]) == ("-x", "cmu") and not m.meta["up_guessed"]
    assert m.meta["joints"]["head"] == silent["Head"] and m.meta["roles"] == "structure"
    assert_same(m, _reference(str(shared_mocap)), 4, names=(*LOWER_BODY, "head", "neck"))
