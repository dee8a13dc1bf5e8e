"""The simulator layer: standing, the rollout record, and every robustness option."""

from __future__ import annotations

import json

import mujoco
import numpy as np
import pytest

from imitwalk.cli.main import main
from imitwalk.robots import load_robot
from imitwalk.sim.metrics import tilt_deg
from imitwalk.sim.mujoco import MujocoPlant, Plant, SimOptions, make_plant, playback
from imitwalk.sim.standing import stand_test
from imitwalk.sim.truth import body_truth


@pytest.fixture(scope="module")
def robot():
    return load_robot("hoap2")


def _hold(robot, seconds=1.0, **opts):
    plant = MujocoPlant(robot, SimOptions(**opts))
    steps = int(round(seconds / plant.control_dt))
    return plant, playback(plant, np.tile(robot.stand, (steps, 1)), stop_on_fall=False)


def test_plant_protocol(robot):
    assert isinstance(MujocoPlant(robot), Plant)


def test_stands_ten_seconds(robot):
    res = stand_test(robot, seconds=10.0)
    assert not res.fell
    assert res.max_tilt_deg < 5.0
    assert res.both_feet_in_contact
    assert res.foot_force_sum_n == pytest.approx(res.weight_n, rel=0.02)


def test_cli_stand_json(capsys):
    assert main(["robot", "stand", "hoap2", "--seconds", "2", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert {"fell", "max_tilt_deg", "foot_force_sum_n", "weight_n"} <= set(out)


def test_rollout_record(robot):
    plant, ro = _hold(robot, 0.5)
    n = len(ro.t)
    assert n == 50 and ro.control_dt == pytest.approx(0.01)
    assert ro.q.shape == ro.q_cmd.shape == (n, 25)
    assert ro.gyro.shape == ro.accel.shape == ro.torso_pos.shape == (n, 3)
    assert ro.torso_quat.shape == (n, 4) and ro.foot_force.shape == (n, 2, 4)
    assert ro.qpos.shape == (n, plant.model.nq)
    assert not ro.fell and ro.fall_time is None
    assert np.allclose(np.diff(ro.t), 0.01)
    assert np.abs(ro.q - ro.q_cmd).max() < 0.1
    assert ro.torque.shape == (n, 25) and ro.torque_limit.shape == (25,)
    legs = [robot.joint_names.index(j) for j in ("l_knee", "r_knee", "l_ankle_pitch")]
    assert np.allclose(ro.torque_limit[legs], 4.0)  # the HOAP-2 leg servos' 4 Nm
    assert (np.abs(ro.torque) <= ro.torque_limit + 1e-9).all()
    # standing, the knees carry the body: a real load, well under the limit
    assert 0.1 < np.abs(ro.torque[-1, legs[:2]]).min() < 4.0


def test_rates_are_configurable(robot):
    plant, ro = _hold(robot, 0.2, physics_hz=500.0, control_hz=50.0)
    assert plant.options.substeps == 10 and plant.model.opt.timestep == pytest.approx(0.002)
    assert len(ro.t) == 10


def test_fall_is_detected(robot):
    plant = MujocoPlant(robot, SimOptions(pushes=((0.1, 1.5, 0.0),)))
    ro = playback(plant, np.tile(robot.stand, (300, 1)))
    assert ro.fell and 0.1 < ro.fall_time < 3.0
    assert len(ro.t) < 300  # stopped at the fall
    assert tilt_deg(ro.torso_quat[-1])[0] > 45 or ro.torso_pos[-1, 2] < 0.5 * robot.torso_height


def test_push_changes_torso_velocity(robot):
    _, calm = _hold(robot, 0.5)
    _, pushed = _hold(robot, 0.5, pushes=((0.2, 0.0, 0.05),))
    vy = lambda ro: np.diff(ro.torso_pos[:, 1]) / ro.control_dt  # noqa: E731
    assert np.abs(vy(calm)).max() < 0.01
    assert np.abs(vy(pushed)[20:30]).max() > 0.02


@pytest.mark.parametrize("engine", ["mujoco", "bullet"])
def test_a_kick_changes_the_torso_velocity_by_the_drawn_amount(robot, engine):
    """A kick of Δv changes the torso's (and the whole robot's) velocity by Δv, within 5 %."""
    dv = np.array([0.12, -0.2])
    opts = SimOptions(pushes=((0.2, *dv),), control_hz=1000.0)  # sampled every 1 ms
    plant = make_plant(robot, opts, engine)
    plant.reset()
    velocity = []
    for _ in range(210):
        t0 = plant.torso_pose()[0]
        plant.command(robot.stand)
        plant.step()
        velocity.append(((plant.torso_pose()[0] - t0) / plant.control_dt)[:2])
    jumps = np.diff(velocity, axis=0)  # (209, 2) change from one 1 ms sample to the next
    k = int(np.argmax(np.linalg.norm(jumps, axis=1)))
    assert 195 <= k <= 205  # at 0.2 s
    change = jumps[k]
    assert np.allclose(change, dv, rtol=0.05, atol=0.05 * np.abs(dv).max())


def test_gyro_noise(robot):
    _, clean = _hold(robot, 1.0)
    _, noisy = _hold(robot, 1.0, gyro_noise=0.05, seed=3)
    diff = (noisy.gyro - clean.gyro)[10:]
    assert diff.std() == pytest.approx(0.05, rel=0.2)
    _, again = _hold(robot, 1.0, gyro_noise=0.05, seed=3)
    assert np.array_equal(again.gyro, noisy.gyro)


def test_servo_delay(robot):
    q_step = robot.stand.copy()
    j = robot.index("l_shoulder_pitch")
    q_step[j] -= 0.5
    targets = np.vstack([np.tile(robot.stand, (5, 1)), np.tile(q_step, (20, 1))])

    def moved_at(delay):
        ro = playback(MujocoPlant(robot, SimOptions(servo_delay=delay)), targets)
        return int(np.argmax(np.abs(ro.q[:, j] - robot.stand[j]) > 0.02))

    assert moved_at(0.02) - moved_at(0.0) == 2  # two control periods
    assert moved_at(0.005) - moved_at(0.0) in (0, 1)  # half of one: between them


def test_friction_and_mass_and_kp_options(robot):
    p = MujocoPlant(robot, SimOptions(friction=0.7))
    assert np.allclose(p.model.geom_friction[:, 0], 0.7)
    p = MujocoPlant(robot, SimOptions(friction_scale=0.5))
    assert np.allclose(p.model.geom_friction[:, 0], 0.5)
    base = MujocoPlant(robot).model
    p = MujocoPlant(robot, SimOptions(mass_scale=1.1))
    assert p.model.body_mass.sum() == pytest.approx(1.1 * base.body_mass.sum())
    p = MujocoPlant(robot, SimOptions(kp_scale=0.9, kp_jitter=0.1, seed=1))
    ratio = p.model.actuator_gainprm[:, 0] / base.actuator_gainprm[:, 0]
    assert ratio.min() >= 0.81 - 1e-9 and ratio.max() <= 0.99 + 1e-9 and ratio.std() > 0
    assert np.allclose(p.model.actuator_biasprm[:, 1], -p.model.actuator_gainprm[:, 0])


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_a_perturbed_robots_centre_of_mass_moves_with_it(robot, seed):
    """The truth's centre of mass is the perturbed bodies' (MuJoCo's ``subtree_com``
    divides by the compiled, nominal mass: 5 % off on a robot 5 % lighter)."""
    p = MujocoPlant(robot, SimOptions(mass_scale=0.9, mass_jitter=0.15, seed=seed))
    assert p.mass == pytest.approx(p.model.body_mass.sum())
    p.reset()
    before = body_truth(p).com
    p.data.qpos[0] += 2.0  # the whole robot carried 2 m along x
    mujoco.mj_forward(p.model, p.data)
    after = body_truth(p).com
    assert after - before == pytest.approx([2.0, 0.0, 0.0], abs=1e-9)
    weighted = np.average(p.data.xipos, axis=0, weights=p.model.body_mass)
    assert after == pytest.approx(weighted, abs=1e-12)


def test_heavier_robot_presses_harder(robot):
    _, light = _hold(robot, 1.0)
    _, heavy = _hold(robot, 1.0, mass_scale=1.1)
    f = lambda ro: ro.foot_force[-20:].sum(axis=(1, 2)).mean()  # noqa: E731
    assert f(heavy) == pytest.approx(1.1 * f(light), rel=0.02)


def test_slope_tilts_gravity_and_loads_the_feet_less(robot):
    p = MujocoPlant(robot, SimOptions(slope_deg=3.0))
    g = p.model.opt.gravity
    assert np.degrees(np.arctan2(-g[0], -g[2])) == pytest.approx(3.0)
    _, flat = _hold(robot, 1.0)
    _, slope = _hold(robot, 1.0, slope_deg=3.0)
    f = lambda ro: ro.foot_force[-20:].sum(axis=(1, 2)).mean()  # noqa: E731
    assert f(slope) == pytest.approx(f(flat) * np.cos(np.radians(3.0)), rel=0.01)


def test_initial_twist(robot):
    _, ro = _hold(robot, 0.05, init_twist=(0.0, 0.0, 0.0, 0.5, 0.0, 0.0))
    assert abs(ro.gyro[0, 0]) > 0.1


def test_a_policy_that_declares_its_start_posture_starts_there(robot):
    from imitwalk.sim.mujoco import run

    bent = robot.stand.copy()
    bent[robot.joint_names.index("l_knee")] += 0.2

    class Hold:
        q0 = bent

        def __call__(self, k, obs):
            return bent

    declared = run(MujocoPlant(robot), Hold(), 20)
    explicit = playback(MujocoPlant(robot), np.tile(bent, (20, 1)), q0=bent)
    assert np.array_equal(declared.q, explicit.q)
    standing = run(MujocoPlant(robot), lambda k, obs: bent, 20)  # no q0: standing
    assert not np.array_equal(standing.q, declared.q)
