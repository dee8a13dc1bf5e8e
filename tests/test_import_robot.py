"""Bring your own robot (issue 33): ROBOTIS OP3 and Unitree G1 as Menagerie ships them.

The files are read from ``../shared/robots`` (never written to); the package ships
neither.
"""

from __future__ import annotations

import hashlib
import json
import shutil

import numpy as np
import pytest

from imitwalk.cli.main import main
from imitwalk.robots import load_robot
from imitwalk.robots.servos import KP_PER_MGL
from imitwalk.robots.spec import LEG_ROLES


@pytest.fixture(scope="module")
def drafted(shared_robots, tmp_path_factory):
    """``{name: (joint map path, joint map, stderr lines)}`` of both robots, imported once."""
    out = {}
    folder = tmp_path_factory.mktemp("maps")
    for name, xml in (("op3", "robotis_op3/op3.xml"), ("g1", "unitree_g1/g1.xml")):
        path = folder / f"{name}.json"
        argv = ["robot", "import", str(shared_robots / xml), "--out", str(path), "--json"]
        out[name] = (path, argv)
    return out


def _import(drafted, name, capsys):
    path, argv = drafted[name]
    if not path.exists():
        assert main(argv) == 0
    capsys.readouterr()
    return path, json.loads(path.read_text())


def test_op3_roles_signs_and_what_it_lacks(drafted, capsys, shared_robots):
    xml = shared_robots / "robotis_op3" / "op3.xml"
    before = hashlib.sha256(xml.read_bytes()).hexdigest()
    path, argv = drafted["op3"]
    assert main(argv) == 0
    captured = capsys.readouterr()
    err = captured.err
    assert json.loads(captured.out)["stands"] and "warning" not in err
    assert hashlib.sha256(xml.read_bytes()).hexdigest() == before  # never edited
    assert "guessed l_hip_yaw: l_hip_yaw (sign -1" in err and "could not guess l_elbow" in err
    assert "an IMU (gyro, accelerometer) is added" in err and "4 touch sensors" in err
    jm = json.loads(path.read_text())
    j = jm["joints"]
    assert j["l_knee"] == "l_knee" and j["r_knee"] == {"joint": "r_knee", "sign": -1}
    assert j["l_ankle_pitch"] == {"joint": "l_ank_pitch", "sign": -1}
    assert j["neck_pitch"] == {"joint": "head_tilt", "sign": -1} and "waist_yaw" not in j
    assert jm["torso"] == "body_link" and "gyro" not in jm and "stand_keyframe" not in jm
    assert jm["soles"]["l"]["body"] == "l_ank_roll_link"
    assert jm["stand"]["l_knee"] == pytest.approx(np.radians(30), abs=0.01)
    r = load_robot(path)
    assert r.dof == 18 and set(LEG_ROLES) <= set(r.joint_names)
    assert all(len(r.foot_force[s]) == 4 for s in "lr") and r.accelerometer
    assert 3.0 < r.total_mass < 3.3 and 0.45 < r.height < 0.55
    assert np.all(r.stand[r.indices(["l_knee", "r_knee"])] > 0.4)  # canonical: flexed
    assert not r.additions.empty and load_robot("hoap2").additions.empty


def test_g1_uses_its_keyframe_and_its_imu(drafted, capsys):
    path, argv = drafted["g1"]
    assert main(argv) == 0
    assert json.loads(capsys.readouterr().out)["stands"]  # with no joint-map edits
    path, jm = _import(drafted, "g1", capsys)
    assert jm["stand_keyframe"] == "stand" and "stand" not in jm
    assert jm["gyro"] == "imu-torso-angular-velocity" and jm["torso"] == "torso_link"
    assert jm["joints"]["waist_yaw"] == "waist_yaw_joint" and "l_hand" in jm["joints"]
    r = load_robot(path)
    assert r.dof == 23 and 32 < r.total_mass < 34.5 and 1.2 < r.height < 1.4
    legs = r.indices([x for x in r.joint_names if x[2:5] in ("hip", "kne", "ank")])
    assert np.isfinite(r.torque_limit).all() and r.torque_limit[legs].min() >= 50.0


@pytest.mark.parametrize("name", ["op3", "g1"])
def test_imported_robots_stand_ten_seconds(drafted, capsys, name):
    path, _ = _import(drafted, name, capsys)
    assert main(["robot", "stand", str(path), "--seconds", "10", "--json"]) == 0
    res = json.loads(capsys.readouterr().out)
    assert res["stands"] and not res["fell"] and res["max_tilt_deg"] < 5.0
    assert res["both_feet_in_contact"]
    assert res["foot_force_sum_n"] == pytest.approx(res["weight_n"], rel=0.02)
    assert main(["robot", "info", str(path), "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["dof"] == load_robot(path).dof


def test_a_robot_folder_loads_from_any_working_directory(shared_robots, tmp_path, monkeypatch):
    shutil.copytree(shared_robots / "robotis_op3", tmp_path / "robot")
    monkeypatch.chdir(tmp_path / "robot")
    assert main(["robot", "import", "op3.xml", "--out", "op3.json"]) == 0
    assert json.loads((tmp_path / "robot" / "op3.json").read_text())["mjcf"] == "op3.xml"
    (tmp_path / "elsewhere").mkdir()
    monkeypatch.chdir(tmp_path / "elsewhere")
    assert main(["robot", "info", "../robot/op3.json"]) == 0
    assert load_robot("../robot/op3.json").compile().nmesh > 0


def _op3_variant(shared_robots, tmp_path, edit) -> str:
    src = shared_robots / "robotis_op3"
    xml = (src / "op3.xml").read_text().replace('meshdir="assets"', f'meshdir="{src / "assets"}"')
    (tmp_path / "op3.xml").write_text(edit(xml))
    return str(tmp_path / "op3.xml")


def test_motor_actuators_get_position_servos(shared_robots, tmp_path, capsys):
    motors = lambda x: x.replace('<position kp="21.1"', '<motor gear="1"').replace(  # noqa: E731
        "<position ", '<motor ctrlrange="-4 4" '
    )
    xml = _op3_variant(shared_robots, tmp_path, motors)
    assert main(["robot", "import", xml, "--out", str(tmp_path / "m.json")]) == 0
    assert "position servos are added" in capsys.readouterr().err
    r = load_robot(tmp_path / "m.json")
    leg = r.index("l_knee")
    m = r.compile()
    a = next(i for i in range(m.nu) if m.actuator_trnid[i, 0] == m.joint("l_knee").id)
    assert m.actuator_biasprm[a, 1] == pytest.approx(-r.kp[leg])  # a position servo now
    assert r.kp[leg] == pytest.approx(KP_PER_MGL * r.total_mass * 9.81 * 0.22, rel=0.02)
    assert r.torque_limit[leg] == pytest.approx(4.0)  # the motor's ctrlrange x gear


def _cli_refuses(argv, capsys, *parts):
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.startswith("error: ") and err.count("\n") == 1, err
    for p in parts:
        assert p in err, err


def test_bad_robots_are_refused_in_one_line(shared_robots, tmp_path, capsys, drafted):
    out = str(tmp_path / "x.json")
    nofree = _op3_variant(shared_robots, tmp_path, lambda x: x.replace("<freejoint/>", ""))
    _cli_refuses(["robot", "import", nofree, "--out", out], capsys, "no floating base")
    legless = tmp_path / "legless.xml"
    legless.write_text(
        '<mujoco><worldbody><body name="trunk"><freejoint/><geom size="0.1"/>'
        '<body name="arm"><joint name="a" axis="0 1 0"/><geom size="0.05" pos="0 0 -0.2"/>'
        "</body></body></worldbody></mujoco>"
    )
    _cli_refuses(
        ["robot", "import", str(legless), "--out", out], capsys, "no legs found", "trunk, arm"
    )
    assert not (tmp_path / "x.json").exists()
    # a robot that cannot stand is drafted all the same (test_stand_check.py), then refused
    weak = _op3_variant(shared_robots, tmp_path, lambda x: x.replace('kp="21.1"', 'kp="0.05"'))
    assert main(["robot", "import", weak, "--out", out]) == 0
    assert "warning: robot " in capsys.readouterr().err
    _cli_refuses(["robot", "stand", out], capsys, "cannot stand", "sank", "tilted", '"servos"')
    path, _ = _import(drafted, "op3", capsys)
    jm = json.loads(path.read_text())
    jm["joints"]["l_knee"] = "left_knee"
    (tmp_path / "bad.json").write_text(
        json.dumps({**jm, "mjcf": str(shared_robots / "robotis_op3/op3.xml")})
    )
    _cli_refuses(
        ["robot", "info", str(tmp_path / "bad.json")], capsys, "unknown joint 'left_knee'", "l_knee"
    )


def test_imported_robots_stand_on_bullet(drafted, capsys):
    from imitwalk.sim.mujoco import make_plant, run

    for name in ("op3", "g1"):
        path, _ = _import(drafted, name, capsys)
        r = load_robot(path)
        ro = run(make_plant(r, None, "bullet"), lambda k, obs, r=r: r.stand, 50)
        assert not ro.fell and np.isfinite(ro.torso_pos).all()


def test_op3_reference_adapts_to_its_legs(drafted, capsys):
    from imitwalk.mocap import default_clip, load_motion
    from imitwalk.retarget import RetargetConfig, retarget
    from imitwalk.retarget.ik import leg_geometry
    from imitwalk.retarget.search import bounds
    from imitwalk.sim.mujoco import MujocoPlant, playback

    path, _ = _import(drafted, "op3", capsys)
    r = load_robot(path)
    geom = leg_geometry(r)
    assert geom.leg == pytest.approx(0.22, abs=0.005) and geom.hip_y == pytest.approx(0.054)
    cfg = RetargetConfig(search=False, scales=(0.5,))
    ref = retarget(load_motion(default_clip()), r, cfg).reference
    assert ref.params.lift == pytest.approx(0.1 * geom.leg, abs=1e-6)
    assert bounds(geom.leg)["lift"] == pytest.approx((0.075 * geom.leg, 0.225 * geom.leg), abs=1e-6)
    assert ref.residual_mm.max() < 5.0 and ref.checks["feet_alternate"]
    q = ref.trajectory(0.5, 2.0)
    ro = playback(MujocoPlant(r), q, q0=q[0])
    assert np.isfinite(ro.torso_pos).all() and len(ro.t) > 100


def test_hoap2_keeps_its_tables_exactly(robot):
    """The lengths are written for hoap2's leg: scaled to it, they come back bit for bit."""
    from imitwalk.retarget import GaitParams
    from imitwalk.retarget.ik import leg_geometry
    from imitwalk.retarget.params import LIFT, REFERENCE_LEG
    from imitwalk.retarget.search import BOUNDS, bounds

    leg = leg_geometry(robot).leg
    assert leg == pytest.approx(REFERENCE_LEG)
    assert bounds(leg) == BOUNDS and GaitParams().for_leg(leg).lift == LIFT == 0.02
    assert bounds(0.6)["lift"] == (0.045, 0.135) and bounds(0.6)["sway"] == BOUNDS["sway"]


def test_a_sidestep_is_held_to_the_robot_s_leg():
    from imitwalk.errors import ConfigError
    from imitwalk.retarget.command import GaitCommand, check_side

    check_side(GaitCommand(side_m=0.05), 0.2)  # hoap2's limit, as before
    with pytest.raises(ConfigError, match=r"expected -0.05 <= --side <= 0.05 \(scaled"):
        check_side(GaitCommand(side_m=0.06), 0.2)
    check_side(GaitCommand(side_m=0.15), 0.6)  # a leg three times as long


def test_a_run_finds_its_robot_file(tiny_reference, tmp_path):
    """evaluate and report load the robot a run's reference records (a file), not its name."""
    from dataclasses import replace

    from imitwalk.cli.robot_args import run_robot
    from imitwalk.runs import RunDir

    ref, _ = tiny_reference  # shared: a copy with other settings
    made = ref.provenance.named("/robots/op3.json", None)
    replace(ref, provenance=made).save(tmp_path / "reference.npz")
    (tmp_path / "config.json").write_text(json.dumps({"robot": "op3"}))
    assert run_robot(RunDir(tmp_path), {"robot": "op3"}) == ("/robots/op3.json", None)


def test_importing_hoap2_gives_back_its_own_joint_map(tmp_path, capsys):
    """The drafted map of hoap2.xml is the hand-written hoap2.json (roles, signs, sensors in
    front-left, front-right, rear-left, rear-right order, soles, torso, keyframe)."""
    from imitwalk.robots import BUILTIN

    out = tmp_path / "hoap2.json"
    xml = BUILTIN["hoap2"].parent / "hoap2.xml"
    assert main(["robot", "import", str(xml), "--out", str(out)]) == 0
    capsys.readouterr()
    drafted, own = json.loads(out.read_text()), json.loads(BUILTIN["hoap2"].read_text())
    assert drafted.pop("mjcf").endswith("hoap2.xml") and own.pop("mjcf") == "hoap2.xml"
    assert drafted == own


def test_bullet_says_what_the_robots_rotors_are(drafted, capsys):
    from imitwalk.robots.urdf import rotor_note, rotor_ratio

    # OP3's rotors carry most of what its leg joints do; Bullet has none
    assert rotor_ratio(load_robot(_import(drafted, "op3", capsys)[0])) > 30.0
    assert rotor_ratio(load_robot(_import(drafted, "g1", capsys)[0])) < 1.0
    note = rotor_note(load_robot("hoap2"))
    assert "\n" not in note and "hoap2's leg rotors are 3.5 x" in note


def test_g1_starts_the_stepping_gait_without_a_spin_or_a_false_tilt(drafted, capsys):
    """Set down onto the floor, G1's first half second under the stepping gait: its arms
    swing in (set at once, their kp-500 servos yawed the torso at 5 rad/s) and its tilt
    averages the landing's jolt in (taken from the first reading, it was 34° off)."""
    from scipy.spatial.transform import Rotation

    from imitwalk.mocap import default_clip, load_motion
    from imitwalk.sim.mujoco import MujocoPlant
    from imitwalk.step.controller import SteppingController
    from imitwalk.step.gains import StepGains
    from imitwalk.step.pipeline import gait_from_motion

    path, _ = _import(drafted, "g1", capsys)
    robot = load_robot(path)
    style = gait_from_motion(load_motion(default_clip()), robot).style
    ctrl = SteppingController(robot, style, StepGains(), 0.01)
    plant = MujocoPlant(robot)
    obs = plant.reset()
    spin, tilt_err = 0.0, 0.0
    for k in range(50):
        plant.command(ctrl(k, obs))
        obs = plant.step()
        spin = max(spin, abs(float(obs.gyro[2])))
        if k >= 1:  # the controller's tilt against the torso's true one (the test's, not its)
            quat = plant.data.xquat[plant.model.body(robot.torso).id]
            true = Rotation.from_quat(quat[[1, 2, 3, 0]]).as_euler("xyz")
            t = ctrl.est._last_tilt
            tilt_err = max(tilt_err, abs(t.roll - true[0]), abs(t.pitch - true[1]))
    assert spin < 1.0  # [rad/s]
    assert np.degrees(tilt_err) < 8.0


def test_an_existing_joint_map_is_kept_unless_forced(tmp_path, capsys):
    """``robot import`` never overwrites a joint map the user may have edited: it refuses
    in one line (exit 2) and writes nothing; ``--force`` replaces it."""
    from imitwalk.robots import BUILTIN

    out = tmp_path / "mine.json"
    out.write_text('{"edited": true}\n')
    xml = str(BUILTIN["hoap2"].parent / "hoap2.xml")
    assert main(["robot", "import", xml, "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "exists" in err[0] and "--force" in err[0]
    assert out.read_text() == '{"edited": true}\n'
    assert main(["robot", "import", xml, "--out", str(out), "--force"]) == 0
    assert json.loads(out.read_text())["name"] == "hoap2"
