"""The second physics engine: the robot's URDF export and the Bullet plant."""

from __future__ import annotations

import json
from dataclasses import replace

import mujoco
import numpy as np
import pybullet as pb
import pytest

from imitwalk.balance.tickconfig import TickLearnConfig
from imitwalk.cli.main import main
from imitwalk.errors import ConfigError, RobotError
from imitwalk.paper.learnconfig import LearnConfig
from imitwalk.retarget.search import SearchConfig
from imitwalk.robots import BUILTIN, load_robot
from imitwalk.robots.urdf import to_urdf, urdf_file
from imitwalk.sim.bullet import BulletPlant
from imitwalk.sim.mujoco import MujocoPlant, make_plant, playback, run
from imitwalk.sim.perturb import perturbed
from imitwalk.sim.types import jitter_draws
from tests.test_other_robot import _other_robot


def test_urdf_carries_masses_and_frames(robot):
    """Loaded in Bullet at the standing pose, every link's centre of mass is MuJoCo's
    (to 0.1 mm) and the total mass is the robot's."""
    path, u = urdf_file(robot)
    m = robot.compile()
    d = mujoco.MjData(m)
    d.qpos[:] = robot.stand_qpos
    mujoco.mj_forward(m, d)
    c = pb.connect(pb.DIRECT)
    try:
        body = pb.loadURDF(str(path), flags=pb.URDF_USE_INERTIA_FROM_FILE, physicsClientId=c)
        w, x, y, z = robot.stand_qpos[3:7]
        ipos, iorn = pb.getDynamicsInfo(body, -1, physicsClientId=c)[3:5]  # Bullet places the
        pos, orn = pb.multiplyTransforms(robot.stand_qpos[:3], [x, y, z, w], ipos, iorn)  # CoM
        pb.resetBasePositionAndOrientation(body, pos, orn, physicsClientId=c)
        total = pb.getDynamicsInfo(body, -1, physicsClientId=c)[0]
        for i in range(pb.getNumJoints(body, physicsClientId=c)):
            info = pb.getJointInfo(body, i, physicsClientId=c)
            pb.resetJointState(
                body, i, d.qpos[m.joint(info[1].decode()).qposadr[0]], physicsClientId=c
            )
        for i in range(pb.getNumJoints(body, physicsClientId=c)):
            name = pb.getJointInfo(body, i, physicsClientId=c)[12].decode()
            com = pb.getLinkState(body, i, computeForwardKinematics=1, physicsClientId=c)[0]
            np.testing.assert_allclose(com, d.xipos[m.body(name).id], atol=1e-4, err_msg=name)
            total += pb.getDynamicsInfo(body, i, physicsClientId=c)[0]
    finally:
        pb.disconnect(c)
    assert total == pytest.approx(robot.total_mass, rel=1e-6)
    assert u.base == "pelvis" and len(u.joint_links) == robot.dof


def test_bullet_robot_stands_and_senses(robot):
    """Standing for 2 s: upright, the soles carry the weight, the accelerometer reads
    gravity and the gyro about nothing, as on MuJoCo."""
    ro = run(BulletPlant(robot), lambda k, obs: robot.stand, 200)
    assert not ro.fell
    weight = robot.total_mass * 9.81
    assert ro.foot_force[-1].sum() == pytest.approx(weight, rel=0.1)
    np.testing.assert_allclose(ro.accel[-1], [0.0, 0.0, 9.81], atol=0.3)
    assert np.abs(ro.gyro[-1]).max() < 0.02
    mj = run(MujocoPlant(robot), lambda k, obs: robot.stand, 200)
    assert ro.torso_pos[-1][2] == pytest.approx(mj.torso_pos[-1][2], abs=0.005)
    np.testing.assert_allclose(ro.q[-1], mj.q[-1], atol=1e-3)  # the same static stiffness


def test_other_robot_stands_on_bullet(tmp_path):
    """A joint map's signs and a flipped knee axis carry over to the URDF."""
    bot = _other_robot(tmp_path)
    ro = run(make_plant(bot, None, "bullet"), lambda k, obs: bot.stand, 100)
    assert not ro.fell
    np.testing.assert_allclose(ro.q[-1], bot.stand, atol=0.05)


def test_same_seed_same_robot(robot):
    """A perturbed seed has the same masses and servo gains on both engines."""
    opts = perturbed(3, None)
    bp, mp = BulletPlant(robot, opts), MujocoPlant(robot, opts)
    _, kps = jitter_draws(opts, mp.model.nbody, robot.joint_names)
    np.testing.assert_allclose(bp.servo.kp, robot.kp * kps)
    links = sum(
        pb.getDynamicsInfo(bp.body, i, physicsClientId=bp.client)[0]
        for i in range(-1, pb.getNumJoints(bp.body, physicsClientId=bp.client))
    )
    assert links == pytest.approx(mp.model.body_mass.sum(), rel=1e-6)


def test_reference_walks_on_bullet(tiny_reference, robot):
    """The small-scale reference plays on Bullet for 4 s without a fall, and moves forward."""
    ref, _ = tiny_reference
    q = ref.trajectory(0.3, 4.0)
    ro = playback(make_plant(robot, None, "bullet"), q, q0=q[0])
    assert not ro.fell
    assert ro.torso_pos[-1][0] > ro.torso_pos[0][0]


def test_unknown_engine_lists_choices(robot):
    with pytest.raises(ConfigError, match="unknown engine 'ode'; valid: bullet, mujoco"):
        make_plant(robot, None, "ode")


def test_urdf_needs_hinges(robot, tmp_path):
    """Only hinges are exported (a slide joint here): a clear error, not a wrong model."""
    xml = (BUILTIN["hoap2"].parent / "hoap2.xml").read_text()
    hinge = '<joint name="neck_pitch" axis="0 1 0" range="-0.2618 1.0472"'
    xml = xml.replace(hinge, '<joint name="neck_pitch" type="slide" axis="0 0 1" range="0 0.01"')
    assert 'type="slide"' in xml
    (tmp_path / "slide.xml").write_text(xml)
    with pytest.raises(RobotError, match="'neck_pitch' is not a hinge"):
        to_urdf(replace(robot, mjcf=tmp_path / "slide.xml"))


def test_cli_playback_on_bullet(tiny_reference, capsys):
    _, path = tiny_reference
    argv = ["playback", str(path), "--scale", "0.3", "--seconds", "2", "--models", "2"]
    assert main([*argv, "--engine", "bullet", "--workers", "1", "--json"]) == 0
    res = json.loads(capsys.readouterr().out)
    assert res["engine"] == "bullet" and res["models"] == 2
    assert not any(r["fell"] for r in res["runs"])


def test_engine_settings_are_checked():
    """A learning run or a reference search on an unknown engine is refused up front."""
    with pytest.raises(ConfigError, match="unknown engine 'physx'; valid: bullet, mujoco"):
        LearnConfig(engine="physx")
    with pytest.raises(ConfigError, match="valid: bullet, mujoco"):
        SearchConfig(engine="physx")
    assert LearnConfig(engine="bullet").engine == "bullet"
    with pytest.raises(ConfigError, match="engine 'physx'; valid: ") as err:
        TickLearnConfig(engine="physx")
    assert sorted(str(err.value).split("valid: ")[1].split(", ")) == ["bullet", "mujoco"]
    assert TickLearnConfig(engine="bullet").engine == "bullet"


def test_servos_without_a_force_limit(tmp_path):
    """An MJCF whose servos have no force range gets unlimited Bullet servos (not zero)."""
    xml = (BUILTIN["hoap2"].parent / "hoap2.xml").read_text().replace(' forcerange="-4 4"', "")
    (tmp_path / "free.xml").write_text(xml)
    bot = load_robot(tmp_path / "free.xml", BUILTIN["hoap2"])
    plant = BulletPlant(bot)
    legs = [bot.index(j) for j in ("l_knee", "r_knee", "l_hip_pitch")]
    assert np.all(np.isinf(plant.torque_limits()[legs]))
    assert not run(plant, lambda k, obs: bot.stand, 100).fell
