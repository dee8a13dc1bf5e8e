"""Commanded gaits: turning, sidestepping, stepping on the spot and walking on a slope."""

from __future__ import annotations

import json
from types import SimpleNamespace

import numpy as np
import pytest

from imitwalk.cli.main import main
from imitwalk.errors import ConfigError
from imitwalk.mocap import default_clip, load_motion
from imitwalk.retarget import GaitCommand, GaitParams, RetargetConfig, extract_template, retarget
from imitwalk.retarget.command import advance
from imitwalk.retarget.ik import leg_geometry
from imitwalk.retarget.plan import plan_walk
from imitwalk.retarget.reference import Reference
from imitwalk.retarget.walkable import build_walkable
from imitwalk.sim.metrics import walk_metrics


@pytest.fixture(scope="module")
def template():
    return extract_template(load_motion(default_clip()))


@pytest.fixture(scope="module")
def geom(robot):
    return leg_geometry(robot)


def _plan(template, geom, cmd, scale=0.8, cycles=3):
    return plan_walk(
        template, geom, GaitParams(), scale, 0.01, cycles=cycles, start=True, command=cmd
    )


def _n(plan):
    return round(plan.period / plan.dt)


@pytest.mark.parametrize("turn", [-12.0, 8.0])
def test_a_turning_plan_yaws_by_the_command_every_cycle(template, geom, turn):
    scale = 0.8
    plan = _plan(template, geom, GaitCommand(turn_deg=turn), scale)
    n, m = _n(plan), len(plan.phase) - 3 * _n(plan)
    want = np.radians(turn * scale)
    assert plan.motion[2] == pytest.approx(want)
    heading = plan.path[:, 2]
    np.testing.assert_allclose(heading[m + n :: n][:2] - heading[m:-n:n][:2], want, rtol=1e-9)
    # a stance foot stays put, position and heading, and lands turned to the frame
    for j, sole in enumerate((plan.l_sole, plan.r_sole)):
        st = plan.stance[:, j]
        runs = np.flatnonzero(np.diff(st.astype(int)) == 1) + 1  # first tick of each stance
        for a in runs:
            b = a + np.argmin(st[a:]) if not st[a:].all() else len(st)
            assert np.ptp(sole[a:b, :2], axis=0).max() < 1e-12
            assert np.ptp(plan.yaw[a:b, j]) < 1e-12
            assert abs(plan.yaw[a, j] - heading[a]) < abs(want)  # within a cycle's turn
    # the feet turn with the walk: their heading ends near the pelvis's, not at 0
    assert abs(plan.yaw[-1].mean() - heading[-1]) < abs(want)
    assert abs(heading[-1]) > 3 * abs(want)


def test_the_straight_command_is_the_straight_plan(template, geom):
    a = plan_walk(template, geom, GaitParams(), 0.7, 0.01, cycles=2, start=True)
    b = _plan(template, geom, GaitCommand(), 0.7, cycles=2)
    for key in ("l_sole", "r_sole", "com", "pelvis_z", "yaw", "path"):
        np.testing.assert_array_equal(getattr(a, key), getattr(b, key))
    assert not np.any(b.yaw) and b.pitch == 0.0 and b.motion[0] == pytest.approx(b.stride)


def test_a_sidestep_moves_the_feet_sideways_and_keeps_them_apart(template, geom):
    from imitwalk.retarget.plan import FOOT_GAP

    assert geom.foot_width == pytest.approx(0.065)  # the HOAP-2 model's sole
    for side, scale in ((0.04, 0.5), (0.05, 1.0), (-0.03, 0.8)):
        plan = _plan(template, geom, GaitCommand(side_m=side, forward=0.0), scale)
        n = _n(plan)
        assert plan.motion[1] == pytest.approx(side * scale) and plan.motion[0] == 0.0
        assert plan.l_sole[-1, 1] - plan.l_sole[-1 - n, 1] == pytest.approx(side * scale)
        gap = plan.l_sole[:, 1] - plan.r_sole[:, 1] - geom.foot_width  # between the edges
        assert gap.min() >= FOOT_GAP - 1e-9
        assert np.ptp(plan.l_sole[:, 0]) < 1e-12  # no forward stride
    # a small sidestep keeps the stance the straight walk has
    plan = _plan(template, geom, GaitCommand(side_m=0.01, forward=0.0), 0.5)
    assert plan.l_sole[0, 1] - plan.r_sole[0, 1] == pytest.approx(2 * geom.hip_y)


def test_a_slope_pitches_the_pelvis_and_moves_the_centre_of_mass_uphill(template, geom):
    flat = _plan(template, geom, GaitCommand(), 0.6)
    up = _plan(template, geom, GaitCommand(slope_deg=4.0), 0.6)
    assert up.pitch == pytest.approx(np.radians(4.0))
    shift = up.com[:, 0] - flat.com[:, 0]
    np.testing.assert_allclose(shift, up.pelvis_z[0] * np.tan(np.radians(4.0)), rtol=1e-9)
    np.testing.assert_array_equal(up.l_sole, flat.l_sole)


def test_advance_moves_a_loop_row_as_the_plan_does(template, geom):
    plan = _plan(template, geom, GaitCommand(turn_deg=10.0, side_m=0.01), 0.9, cycles=3)
    n = _n(plan)
    m = len(plan.phase) - 2 * n  # the first cycle whose every foothold is a steady one
    keys = ("l_sole", "r_sole", "com", "yaw", "path")
    for r in (0, 17, n - 1):
        row = {k: getattr(plan, k)[m + r] for k in keys}
        moved = advance(row, plan.path[m], plan.motion, 1)
        for k in keys:
            np.testing.assert_allclose(moved[k], getattr(plan, k)[m + n + r], atol=1e-9)
        twice = advance(row, plan.path[m], plan.motion, 2)
        back = advance(twice, plan.path[m], -plan.motion, 0)
        np.testing.assert_allclose(back["path"], twice["path"])


def test_commands_out_of_range_are_one_line_errors():
    with pytest.raises(
        ConfigError, match=r"--turn 90 \(setting command\.turn_deg\): expected -30 <= --turn <= 30"
    ):
        GaitCommand(turn_deg=90)
    with pytest.raises(ConfigError, match="forward"):
        GaitCommand(forward=-1)
    with pytest.raises(ConfigError, match="mapping=walkable"):
        cfg = RetargetConfig(mapping="paper", search=False, command=GaitCommand(turn_deg=5))
        retarget(load_motion(default_clip()), None, cfg)


@pytest.fixture(scope="module")
def turning(robot, template):
    cmd = GaitCommand(turn_deg=10.0)
    return build_walkable(template, robot, GaitParams(), [0.5, 1.0], 0.01, command=cmd).reference


def test_a_turning_reference_is_solved_and_saved(turning, tmp_path):
    assert turning.residual_mm.max() < 1.0  # the IK reaches the turned soles
    path = turning.save(tmp_path / "turn.npz")
    back = Reference.load(path)
    assert back.command == GaitCommand(turn_deg=10.0)
    np.testing.assert_array_equal(back.motion, turning.motion)
    tr = back.track(0.5, 20.0)
    per_cycle = back.motion_at(0.5)[2]
    assert per_cycle == pytest.approx(np.radians(5.0))
    n = back.loops.shape[1]
    assert tr[-1, 2] - tr[-1 - n, 2] == pytest.approx(per_cycle)
    assert back.summary()["command"]["turn_deg"] == 10.0


def test_a_reference_from_before_commands_reads_as_straight(tiny_reference):
    ref, _ = tiny_reference
    old = Reference(
        **{
            **ref.__dict__,
            "plan": {k: v for k, v in ref.plan.items() if k not in ("yaw", "path")},
            "motion": np.zeros((0, 5)),
            "command": GaitCommand(),
        }
    )
    plan = old.plan_at(0.35)
    assert not plan["yaw"].any() and plan["path"][:, 3].max() > 0
    assert old.motion_at(0.3)[0] == pytest.approx(ref.strides[0])
    np.testing.assert_allclose(old.track(0.3, 10.0), ref.track(0.3, 10.0), atol=1e-9)


def test_metrics_measure_a_turn_against_its_command():
    dt, w, v = 0.01, 0.3, 0.1  # a torso that follows a 0.3 rad/s, 0.1 m/s arc exactly
    t = np.arange(1000) * dt
    th = w * t
    pos = np.stack([v / w * np.sin(th), v / w * (1 - np.cos(th)), 0 * t], axis=1)
    quat = np.stack([np.cos(th / 2), 0 * t, 0 * t, np.sin(th / 2)], axis=1)
    ro = SimpleNamespace(
        torso_pos=pos,
        torso_quat=quat,
        control_dt=dt,
        seconds=t[-1] + dt,
        fell=False,
        fall_time=None,
        gyro=np.zeros((len(t), 3)),
        q=np.zeros((len(t), 2)),
        q_cmd=np.zeros((len(t), 2)),
    )
    track = np.stack([v * t, 0 * t, th], axis=1)
    m = walk_metrics(ro, v * t[-1], track=track)
    assert abs(m.yaw_drift_deg) < 1e-6 and abs(m.lateral_drift_m) < 1e-3
    assert m.progress_ratio == pytest.approx(1.0, abs=1e-3)
    assert m.commanded_turn_deg == pytest.approx(np.degrees(th[-1]))
    straight = walk_metrics(ro, v * t[-1])  # judged as a straight walk it drifts
    assert straight.yaw_drift_deg == pytest.approx(np.degrees(th[-100:].mean()), rel=1e-6)


def test_a_turning_reference_turns_on_the_robot(robot, turning):
    from imitwalk.retarget.playback import play_reference

    runs = play_reference(turning, robot, 0.5, 10.0, seeds=[0, 1], workers=1)
    for r in runs:
        m = r.metrics
        assert not m.fell and m.commanded_turn_deg > 25.0
        turned = m.commanded_turn_deg + m.yaw_drift_deg
        assert turned > 0.5 * m.commanded_turn_deg  # it turns, most of the way
        assert m.progress_ratio > 0.5


def test_a_slope_reference_is_played_on_its_slope(robot, template):
    cmd = GaitCommand(slope_deg=3.0)
    ref = build_walkable(template, robot, GaitParams(), [0.5], 0.01, command=cmd).reference
    assert ref.sim_options().slope_deg == 3.0
    from imitwalk.sim.types import SimOptions

    assert ref.sim_options(SimOptions(slope_deg=-3.0)).slope_deg == 0.0  # added to a cell's


def test_cli_retarget_turn_and_bad_commands(tmp_path, capsys):
    out = tmp_path / "turn.npz"
    argv = ["retarget", "--out", str(out), "--no-search", "--set", "scales=[0.5]"]
    assert main([*argv, "--turn", "8", "--forward", "0.5", "--json"]) == 0
    capsys.readouterr()
    assert Reference.load(out).command == GaitCommand(turn_deg=8.0, forward=0.5)
    assert (
        main(["playback", str(out), "--scale", "0.5", "--seconds", "2", "--models", "1", "--json"])
        == 0
    )
    res = json.loads(capsys.readouterr().out)
    assert res["runs"][0]["commanded_turn_deg"] > 0
    bad = tmp_path / "bad.npz"
    assert main(["retarget", "--out", str(bad), "--no-search", "--turn", "45"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err[-1].startswith("error: ") and "--turn 45" in err[-1] and not bad.exists()
    assert (
        main(["learn", "--reference", str(out), "--out", str(tmp_path / "r"), "--slope", "2"]) == 2
    )
    err = capsys.readouterr().err.strip().splitlines()
    assert "--slope" in err[-1] and "Traceback" not in "\n".join(err)


def test_the_command_in_words_and_on_the_ground(turning):
    assert GaitCommand().describe() == "straight ahead on level ground"
    words = GaitCommand(turn_deg=10, side_m=0.02, forward=0.5, slope_deg=-3).describe()
    assert words == (
        "turn 10° and sidestep 0.02 m per cycle at scale 1; stride × 0.5; on a -3° slope"
    )
    xy = turning.ground_path(1.0, 20.0)
    tr = turning.track(1.0, 20.0)
    length = np.sum(np.linalg.norm(np.diff(xy, axis=0), axis=1))
    assert length == pytest.approx(tr[-1, 0], rel=1e-3)  # the arc is as long as the travel
    assert xy[-1, 1] > 0.1  # a left turn bends the path to +y


def test_the_learner_sees_heading_beyond_the_commanded_turn(robot, turning):
    from imitwalk.balance.channels import FEATURES
    from imitwalk.balance.feedback import FeedbackLaw, TickPolicy
    from imitwalk.sim.types import Observation

    law = FeedbackLaw.zero(("hip_yaw",), ("heading",), 0.1)
    policy = TickPolicy(turning, 1.0, (law,), robot.joint_names, 30.0)
    tr = turning.track(1.0, 30.0)
    n_loop = turning.loops.shape[1]
    for k in (0, 150, policy.start + 3, policy.start + 5 * n_loop + 7):
        assert policy.heading_ref[k] == pytest.approx(tr[k, 2], abs=1e-9)
    half = TickPolicy(turning, 0.5, (law,), robot.joint_names, 30.0)  # half the scale: half turn
    assert half.heading_ref[2000] == pytest.approx(turning.track(0.5, 30.0)[2000, 2])
    assert half.heading_ref[2000] == pytest.approx(tr[2000, 2] / 2, rel=0.05)
    # a robot whose gyro turns it exactly as commanded has no heading error; one that
    # does not turn at all sees the whole commanded turn as its error
    dt, h = turning.dt, FEATURES.index("heading")
    rate = np.diff(tr[:, 2], prepend=0.0) / dt  # (T,) yaw rate that integrates to the track
    for gz, expected in ((rate, np.zeros(len(tr))), (0.0 * rate, -tr[:, 2])):
        p = TickPolicy(turning, 1.0, (law,), robot.joint_names, 30.0)
        for k in range(len(tr)):
            obs = Observation(
                k * dt,
                np.array([0, 0, gz[k]]),
                np.array([0, 0, 9.81]),
                np.zeros((2, 4)),
                np.zeros(len(robot.joint_names)),
            )
            p(k, obs)
        np.testing.assert_allclose(p.episode().features[:, h], expected, atol=1e-9)
    assert tr[-1, 2] > np.radians(100)  # it does turn: ~10° per cycle for 30 s


@pytest.mark.slow
def test_learn_and_evaluate_a_turning_walk(tmp_path, robot, template):
    """The whole loop on a turning reference: learned, evaluated against its own path."""
    from imitwalk.balance.tickconfig import TickLearnConfig
    from imitwalk.balance.ticklearn import learn_tick
    from imitwalk.config import apply_overrides
    from imitwalk.judge.verdict import RunController
    from imitwalk.sim.protocol import load_protocol
    from tests.conftest import TICK

    cmd = GaitCommand(turn_deg=12.0)
    ref = build_walkable(template, robot, GaitParams(), [0.3, 0.4], 0.01, command=cmd).reference
    cfg = apply_overrides(TickLearnConfig(), [*TICK, "start=0.3", "step=0.1", "stop=0.4"])
    summary = learn_tick(ref, robot, cfg, tmp_path / "run")
    assert summary.scale_reached is not None
    protocol = load_protocol("eval")
    for mode in ("learned", "feedback", "open_loop"):
        for seed in (0, 1):
            d = protocol.draw(seed, robot, seconds=10.0)
            run = RunController(str(tmp_path / "run"), mode)
            r = run.walk(robot, d.options, 10.0, protocol.engine)
            assert r.commanded_turn_deg > 20.0  # ~4.8° per cycle for 10 s
            if not r.fell:  # it follows the turn: what is left is a drift, not the turn
                assert abs(r.yaw_drift_deg) < r.commanded_turn_deg / 2


@pytest.mark.parametrize("mapping", ["walkable", "paper"])
@pytest.mark.parametrize("search", [True, False])
def test_a_config_searches_only_the_walkable_mapping(mapping, search):
    cfg = RetargetConfig(mapping=mapping, search=search)
    assert cfg.searches == (search and mapping == "walkable")
