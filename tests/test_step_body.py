"""The stepping gait's robot-side parts: style, gains, kinematics, estimator (real robot)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from imitwalk.errors import ConfigError
from imitwalk.step.gains import BOUNDS, StepGains
from imitwalk.step.kinematics import BodyModel, FootPose, floor_mat, rot_z
from imitwalk.step.style import GaitStyle, hip_height, reversed_in_time, style_from_template


@pytest.fixture(scope="module")
def template():
    from imitwalk.mocap import default_clip, load_motion
    from imitwalk.retarget.template import extract_template

    return extract_template(load_motion(default_clip()))


@pytest.fixture(scope="module")
def geom(robot):
    from imitwalk.retarget.ik import leg_geometry

    return leg_geometry(robot)


def test_the_style_keeps_the_cadence_and_scales_the_stride(template, geom):
    st = style_from_template(template, geom, 1.0)
    assert st.step_time == pytest.approx(template.period / 2)
    assert 2 * st.step_length == pytest.approx(template.stride * geom.leg / template.leg_length)
    half = style_from_template(template, geom, 0.5)
    assert half.step_length == pytest.approx(st.step_length / 2)
    assert half.step_time == st.step_time
    back = GaitStyle.from_dict(st.to_dict())
    assert back.step_length == st.step_length and np.array_equal(back.swing_x, st.swing_x)
    assert back.geometry == st.geometry


@pytest.mark.parametrize("scale", [0.5, 1.0])
def test_the_style_reversed_in_time_walks_the_same_steps_backward(template, geom, scale):
    """The clip played backward: the same cadence, double support, clearance and hips,
    the step negated, the swing retracing its path (its progress still 0 → 1, non-
    decreasing), the turn negated; reversed twice, the style comes back."""
    st = style_from_template(template, geom, scale)
    back = reversed_in_time(st)
    assert back.step_length == -st.step_length and back.speed == -st.speed
    for name in ("step_time", "double_support", "clearance", "hip_height", "step_width"):
        assert getattr(back, name) == getattr(st, name)
    assert back.swing_x[0] == pytest.approx(0.0) and back.swing_x[-1] == pytest.approx(1.0)
    assert np.all(np.diff(back.swing_x) >= -1e-12)
    assert np.allclose(back.swing_z, st.swing_z[::-1])
    twice = reversed_in_time(back)
    assert np.allclose(twice.swing_x, st.swing_x) and np.allclose(twice.swing_z, st.swing_z)
    for role, prof in st.upper.items():  # to within the profiles' linear interpolation
        step = np.max(np.abs(np.diff(np.r_[prof, prof[0]])))
        assert np.max(np.abs(twice.upper[role] - prof)) <= step + 1e-9
        assert np.ptp(back.upper[role]) == pytest.approx(np.ptp(prof), abs=step)


def test_the_style_reversed_lifts_off_where_the_forward_walk_touched_down(template, geom):
    """ψ' = 0 (a left touchdown of the backward walk) is the forward walk's left
    lift-off: the arms there are the forward profile's at ψ = ½ + the double support's
    share of the cycle."""
    st = style_from_template(template, geom, 1.0)
    back = reversed_in_time(st)
    off = 0.5 + st.double_support / (2 * st.step_time)
    fwd = st.upper_at(off)
    for role, value in back.upper_at(0.0).items():
        assert value == pytest.approx(fwd[role])
    later = st.upper_at(off - 0.1)  # a tenth of a cycle on backward is a tenth earlier
    for role, value in back.upper_at(0.1).items():
        assert value == pytest.approx(later[role], abs=0.02)


def test_a_backward_walk_plans_its_steps_behind_with_the_zmp_rolling_toe_to_heel(template, geom):
    from imitwalk.step.nominal import NominalWalk

    st = style_from_template(template, geom, 1.0)
    fwd = NominalWalk(st, StepGains(), 4.0, st.pelvis_height)
    back = NominalWalk(reversed_in_time(st), StepGains(), 4.0, st.pelvis_height)
    assert back.limits.backward == pytest.approx(fwd.limits.forward)
    assert back.limits.forward == pytest.approx(fwd.limits.backward)
    assert back.limits.swing_speed == pytest.approx(fwd.limits.swing_speed)
    g, b = fwd.gait(5), back.gait(5)
    assert b.step == pytest.approx(-g.step) and g.step > 0
    _, heel_f, toe_f = g.zmp_points(1.0)
    _, heel_b, toe_b = b.zmp_points(1.0)
    assert toe_f[0] > heel_f[0] and toe_b[0] < heel_b[0]  # the ZMP rolls the way it walks
    assert back.offset(5, 1.0)[0] == pytest.approx(-fwd.offset(5, 1.0)[0])


def test_a_step_beyond_the_legs_is_refused_naming_the_limit(geom):
    with pytest.raises(ConfigError, match=r"beyond this robot's legs.*--forward"):
        hip_height(geom, 2.0 * geom.leg)


def test_gains_out_of_range_or_unknown_are_refused_with_the_valid_ones():
    with pytest.raises(ConfigError, match=r"expected 1 <= dcm <= 6"):
        StepGains(dcm=9.0)
    with pytest.raises(ConfigError, match="valid gains: dcm, ankle"):
        StepGains.from_dict({"dmc": 1.0})
    g = StepGains()
    names = tuple(BOUNDS)
    back = g.with_vector(names, g.vector(names)).to_dict()
    assert back == pytest.approx(g.to_dict())


def test_the_leg_ik_reaches_its_targets(robot):
    body = BodyModel(robot)
    body.set(robot.stand)
    feet = {}
    for s, dx, dz, yaw in (("l", 0.03, 0.02, 0.1), ("r", -0.04, 0.0, -0.05)):
        feet[s] = FootPose(body.sole_pos(s) + np.array([dx, 0.0, dz]), yaw)
    q = robot.stand.copy()
    for _ in range(4):
        q = body.solve_legs(q, feet, rot_z(0.0), iterations=3)
    body.set(q)
    for s, f in feet.items():
        assert np.linalg.norm(body.sole_pos(s) - f.pos) < 1e-5
        assert body.sole_yaw(s) == pytest.approx(f.yaw, abs=1e-4)
    assert np.all(q >= robot.limits[:, 0] - 1e-9) and np.all(q <= robot.limits[:, 1] + 1e-9)


@settings(max_examples=40, deadline=None)
@given(st.floats(-0.2, 0.2, allow_nan=False), st.floats(-0.2, 0.2, allow_nan=False))
def test_the_floors_tilt_lays_a_level_sole_onto_the_floor(sx, sy):
    """A level sole's normal turned by :func:`floor_mat` is the floor's normal, and a
    line along the sole's x stays in the vertical plane x-z (the yaw is left alone)."""
    m = floor_mat(np.array([sx, sy]))
    normal = np.array([-sx, -sy, 1.0]) / np.sqrt(1 + sx * sx + sy * sy)
    assert np.allclose(m @ np.array([0.0, 0.0, 1.0]), normal, atol=1e-12)
    assert np.allclose(m @ m.T, np.eye(3), atol=1e-12) and np.linalg.det(m) > 0
    assert abs((m @ np.array([1.0, 0.0, 0.0]))[1]) < 1e-12


def test_the_leg_ik_lays_both_soles_onto_a_tilted_floor(robot):
    body = BodyModel(robot)
    body.set(robot.stand)
    feet = {s: FootPose(body.sole_pos(s), 0.0) for s in "lr"}
    tilt = floor_mat(np.array([0.0, np.tan(np.radians(4.0))]))
    q = robot.stand.copy()
    for _ in range(4):
        q = body.solve_legs(q, feet, rot_z(0.0), iterations=3, floor=tilt)
    body.set(q)
    for s in "lr":
        normal = body.sole_mat(s) @ body._flat[s].T[:, 2]
        assert np.degrees(np.arccos(normal @ tilt[:, 2])) < 0.05


def test_static_torques_hold_the_standing_robot(robot):
    """Torques from the model, with the weight shared by the soles under the centre of
    mass, equal what holds the standing robot in MuJoCo (its servos at rest)."""
    body = BodyModel(robot)
    body.set(robot.stand)
    com, l, r = body.com(), body.sole_pos("l"), body.sole_pos("r")
    w = float(np.clip((com[1] - r[1]) / (l[1] - r[1]), 0, 1))
    point = lambda p: np.array([com[0], p[1], p[2]])  # noqa: E731
    tau = body.static_torques({"l": (w, point(l)), "r": (1 - w, point(r))})
    legs = np.concatenate([body.legs["l"], body.legs["r"]])
    # the robot standing still in MuJoCo: the leg servos' torques once it has settled
    from imitwalk.sim.mujoco import MujocoPlant

    plant = MujocoPlant(robot)
    plant.reset()
    for _ in range(200):
        plant.command(robot.stand)
        plant.step()
    held = plant.torques()
    assert np.abs(tau[legs] - held[legs]).max() < 0.15  # [Nm], against 4 Nm servos


def test_the_estimator_sees_a_robot_standing_still(robot):
    from imitwalk.sim.mujoco import MujocoPlant
    from imitwalk.step.estimator import BodyEstimator
    from imitwalk.step.lipm import omega_of

    body = BodyModel(robot)
    est = BodyEstimator(body, 0.01, omega_of(0.23))
    plant = MujocoPlant(robot)
    obs = plant.reset()
    for _ in range(100):
        e = est.update(obs, np.zeros(2))
        plant.command(robot.stand)
        obs = plant.step()
    # the right sole is the stance frame's origin, the left one its width to the left
    assert e.swing.pos[1] == pytest.approx(2 * 0.039, abs=2e-3)
    assert abs(e.swing.pos[0]) < 2e-3 and abs(e.swing.yaw) < 1e-2
    assert e.com[1] == pytest.approx(0.039, abs=5e-3)
    assert np.linalg.norm(e.com_vel) < 0.01
    assert np.allclose(e.dcm, e.com[:2], atol=5e-3)
    assert e.cop is not None and e.cop[1] == pytest.approx(e.com[1], abs=1e-2)


def test_the_estimator_reads_a_floor_sloped_across_from_the_stance_sole(robot):
    """Standing on a floor rising 4° to the left, the settled slope across converges on
    the floor's (its tilt from the IMU and the encoders only), and none along."""
    from dataclasses import replace

    from imitwalk.sim.mujoco import MujocoPlant
    from imitwalk.sim.types import SimOptions
    from imitwalk.step.estimator import SETTLED_TAU, BodyEstimator
    from imitwalk.step.lipm import omega_of

    body = BodyModel(robot)
    est = BodyEstimator(body, 0.01, omega_of(0.23))
    plant = MujocoPlant(robot, replace(SimOptions(), cross_slope_deg=4.0))
    obs = plant.reset()
    for _ in range(int(4 * SETTLED_TAU / 0.01)):
        e = est.update(obs, np.zeros(2))
        plant.command(robot.stand)
        obs = plant.step()
    assert e.settled_slope[1] == pytest.approx(np.tan(np.radians(4.0)), abs=0.015)
    assert abs(e.settled_slope[0]) < 0.015


@settings(max_examples=30, deadline=None)
@given(
    roll=st.floats(-0.3, 0.3),
    pitch=st.floats(-0.3, 0.3),
    jolt=st.floats(-60.0, 60.0),
)
def test_the_attitude_starts_level_and_averages_its_readings_in(roll, pitch, jolt):
    """With a prior, one jolted reading (a landing) moves the tilt by at most its share
    dt / (prior + dt); steady readings of a tilt are then averaged in, and after a few
    time constants the tilt is theirs (a complementary filter, the gyro at rest)."""
    from imitwalk.balance.estimator import StateEstimator
    from imitwalk.step.estimator import TILT_PRIOR

    dt, g = 0.01, 9.81
    est = StateEstimator(dt, 0.5, prior=TILT_PRIOR)
    est.update(np.zeros(3), np.zeros(3), np.zeros((2, 4)))  # free fall: nothing learnt
    assert est.roll == est.pitch == 0.0
    est.update(np.zeros(3), np.array([jolt, 0.0, g]), np.zeros((2, 4)))
    share = dt / (TILT_PRIOR + dt)
    assert abs(est.pitch) <= share * abs(np.arctan2(-jolt, g)) + 1e-12
    # gravity as an accelerometer tilted by (roll, pitch) reads it
    a = g * np.array([-np.sin(pitch), np.sin(roll) * np.cos(pitch), np.cos(roll) * np.cos(pitch)])
    for _ in range(300):
        est.update(np.zeros(3), a, np.zeros((2, 4)))
    assert est.roll == pytest.approx(roll, abs=0.01)
    assert est.pitch == pytest.approx(pitch, abs=0.01)


def test_the_first_joint_targets_carry_no_velocity_feedforward(robot):
    """The jump from the measured posture to the walking one is not a velocity: the
    first targets are the posture solved plus the static feedforward alone."""
    from imitwalk.mocap import default_clip, load_motion
    from imitwalk.step.gains import StepGains
    from imitwalk.step.joints import JointSolver
    from imitwalk.step.pipeline import gait_from_motion

    style = gait_from_motion(load_motion(default_clip()), robot).style
    gains = StepGains(feedforward=1.0)
    solver = JointSolver(robot, style, gains, 0.01)
    far = robot.stand.copy()
    far[robot.index("l_knee")] += 0.3  # measured: a knee 17° off the walking posture
    solver.reset(far)
    other = FootPose(np.array([0.0, style.step_width, 0.0]), 0.0)
    z = style.pelvis_height
    out = solver.solve("r", np.array([0.0, style.step_width / 2]), z, other, 0.0, {}, np.zeros(2))
    assert np.abs(solver.q - far).max() > 0.05  # the posture moved ...
    static = solver.ik.static_torques({}) / solver.kp
    assert np.allclose(out, solver.q + static)  # ... and no velocity was fed forward
    # the second tick's targets do carry the velocity of their motion
    out2 = solver.solve("r", np.array([0.01, style.step_width / 2]), z, other, 0.0, {}, np.zeros(2))
    vel = solver.ik.kv * (solver.q - solver.q_prev) / 0.01 / solver.kp
    assert np.allclose(out2, solver.q + vel + solver.ik.static_torques({}) / solver.kp)


def test_the_arms_swing_in_from_standing(robot):
    """At the first tick the arms and waist hold their standing angles: the style's
    swing is ramped in over the start's double support, not set at once."""
    from imitwalk.mocap import default_clip, load_motion
    from imitwalk.sim.mujoco import MujocoPlant
    from imitwalk.step.controller import SteppingController
    from imitwalk.step.gains import StepGains
    from imitwalk.step.pipeline import gait_from_motion

    style = gait_from_motion(load_motion(default_clip()), robot).style
    ctrl = SteppingController(robot, style, StepGains(), 0.01)
    plant = MujocoPlant(robot)
    obs = plant.reset()
    upper = [robot.index(r) for r in style.upper if r in robot.joint_names]
    assert upper
    swing = max(abs(v).max() for v in style.upper.values())
    assert swing > 0.05  # the style does swing its arms
    q = ctrl(0, obs)  # the targets; the posture solved (no feedforward) is ctrl.joints.q
    assert np.allclose(ctrl.joints.q[upper], robot.stand[upper])
    for k in range(1, 200):
        plant.command(q)
        obs = plant.step()
        q = ctrl(k, obs)
        if ctrl.single:
            break
    assert ctrl.single  # lifted off: the swing is in full
    offsets = style.upper_at(ctrl.phase)
    solved = ctrl.joints.q
    assert all(
        solved[robot.index(r)] == pytest.approx(robot.stand[robot.index(r)] + offsets[r])
        for r in style.upper
        if r in robot.joint_names
    )
