"""A robot other than hoap2, given as MJCF + joint map, goes through the same pipeline."""

from __future__ import annotations

import json
import re

import numpy as np

from imitwalk.mocap import default_clip, load_motion
from imitwalk.retarget import GaitParams, RetargetConfig, retarget
from imitwalk.robots import BUILTIN, load_robot
from imitwalk.sim.mujoco import MujocoPlant, playback

HOAP2 = BUILTIN["hoap2"].parent


def _other_robot(tmp_path):
    """hoap2 with longer shanks, other joint names, and the knees' axes flipped."""
    xml = (HOAP2 / "hoap2.xml").read_text()
    xml = xml.replace(
        '<body name="l_ankle" pos="0 0 -0.1">', '<body name="l_ankle" pos="0 0 -0.12">'
    )
    xml = xml.replace(
        '<body name="r_ankle" pos="0 0 -0.1">', '<body name="r_ankle" pos="0 0 -0.12">'
    )
    for side in "lr":  # knee about -y: positive angles now extend; the map's sign says so
        xml = xml.replace(
            f'<joint name="{side}_knee" axis="0 1 0" range="-0.01745 2.2689"/>',
            f'<joint name="{side}_knee" axis="0 -1 0" range="-2.2689 0.01745"/>',
        )
    xml = re.sub(r'name="([lr])_(hip_pitch|knee)"', r'name="\1_\2_j"', xml)
    xml = re.sub(r'joint="([lr])_(hip_pitch|knee)"', r'joint="\1_\2_j"', xml)
    # the standing keyframe's knee angles flip sign with the axis
    xml = xml.replace("0 0 -0.2946 0.6909 -0.3963 0", "0 0 -0.2946 -0.6909 -0.3963 0")
    jmap = json.loads((HOAP2 / "hoap2.json").read_text())
    jmap.pop("mjcf")
    jmap["name"] = "longshank"
    for side in "lr":
        jmap["joints"][f"{side}_hip_pitch"] = f"{side}_hip_pitch_j"
        jmap["joints"][f"{side}_knee"] = {"joint": f"{side}_knee_j", "sign": -1}
    (tmp_path / "bot.xml").write_text(xml)
    (tmp_path / "bot.json").write_text(json.dumps(jmap))
    return load_robot(tmp_path / "bot.xml", tmp_path / "bot.json")


def test_other_robot_retargets_and_plays(tmp_path):
    robot = _other_robot(tmp_path)
    assert robot.name == "longshank" and robot.dof == 25
    k = robot.index("l_knee")
    assert robot.stand[k] > 0.5  # canonical knee flexion is positive whatever the MJCF axis
    cfg = RetargetConfig(search=False, scales=(0.5,), params=GaitParams(sway=0.9, ds=0.1))
    res = retarget(load_motion(default_clip()), robot, cfg)
    ref = res.reference
    assert ref.robot == "longshank" and ref.residual_mm.max() < 5.0
    c = ref.checks
    assert c["stance_tilt_deg_max"] < 3.0 and c["swing_clearance_mm_min"] >= 15.0
    assert c["feet_alternate"] and c["steps_forward"]
    assert np.all(ref.loops[..., k] > 0.1)  # the knee stays bent, in canonical signs
    q = ref.trajectory(0.5, 3.0)
    ro = playback(MujocoPlant(robot), q, q0=q[0])
    assert len(ro.t) > 50 and np.isfinite(ro.torso_pos).all()
