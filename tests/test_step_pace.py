"""The stride a robot's servos carry: their top speed, the swing's, and the trials' choice."""

from __future__ import annotations

import json

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as hs

from imitwalk.cli.main import main
from imitwalk.errors import ConfigError, RunError
from imitwalk.robots import load_robot


@pytest.fixture(scope="module")
def maps(shared_robots, tmp_path_factory):
    """``{name: joint map path}`` of Menagerie's OP3 and G1, imported once."""
    out = {}
    for name, xml in (("op3", "robotis_op3/op3.xml"), ("g1", "unitree_g1/g1.xml")):
        path = tmp_path_factory.mktemp(name) / f"{name}.json"
        assert main(["robot", "import", str(shared_robots / xml), "--out", str(path)]) == 0
        out[name] = path
    return out


@pytest.fixture(scope="module")
def imported(maps):
    """``{name: Robot}`` of OP3 and G1."""
    return {n: load_robot(p) for n, p in maps.items()}


@pytest.fixture(scope="module")
def styles(robot, imported):
    """``{name: GaitStyle}``: the default clip's style on hoap2, OP3 and G1."""
    from imitwalk.mocap import default_clip
    from imitwalk.retarget.motionfiles import load_clip
    from imitwalk.step.pipeline import gait_from_motion

    robots = {"hoap2": robot, **imported}
    return {n: gait_from_motion(load_clip(default_clip(), r), r).style for n, r in robots.items()}


def test_a_servos_top_speed_is_its_torque_over_its_joints_damping(robot, imported):
    from imitwalk.step.pace import top_speeds

    knee = robot.index("l_knee")
    assert top_speeds(robot)[knee] == pytest.approx(4.0 / 0.1)  # hoap2's MJCF
    op3 = imported["op3"]
    assert top_speeds(op3)[op3.index("l_knee")] == pytest.approx(5.0 / 1.084, rel=1e-3)
    g1 = imported["g1"]  # Menagerie's G1 gives its joints no damping: no top speed
    assert np.isinf(top_speeds(g1)[g1.index("l_knee")])


def test_op3s_servos_are_slower_than_the_human_swing_and_hoap2s_are_not(robot, imported, styles):
    from imitwalk.step.pace import servo_ratio, swing_speeds

    assert servo_ratio(robot, styles["hoap2"]) < 1.0
    assert servo_ratio(imported["op3"], styles["op3"]) > 2.0
    assert servo_ratio(imported["g1"], styles["g1"]) == 0.0
    # the swinging (right) leg moves faster than the standing one
    sw = swing_speeds(robot, styles["hoap2"])
    assert sw[robot.index("r_knee")] > 2 * sw[robot.index("l_knee")]
    assert sw[robot.index("r_hip_pitch")] > sw[robot.index("l_hip_pitch")]


def test_a_robot_whose_servos_follow_the_swing_walks_the_clips_stride_untried(robot, styles):
    from imitwalk.step.pace import choose_stride

    class NoRobots:  # any trial would draw a robot
        def draw(self, *args, **kwargs):
            raise AssertionError("no trial should walk")

    style, choice = choose_stride(robot, styles["hoap2"], NoRobots(), 15.0)  # type: ignore[arg-type]
    assert style is styles["hoap2"]
    assert choice.share == 1.0 and choice.trials == {} and choice.sim_seconds == 0.0


@pytest.mark.parametrize(
    ("falls", "kept"),
    [
        ((8, 8, 2, 0), 0.35),  # no robot fell at 0.35: the shorter ones are not tried
        ((8, 3, 3, 3, 5, 4), 0.7),
        ((1, 1, 0), 0.5),
        ((4, 4, 4, 4, 4, 4), 1.0),
    ],
)
def test_the_trials_keep_the_longest_stride_with_the_fewest_falls(
    imported, styles, monkeypatch, falls, kept
):
    """The choice alone (the walks stubbed: ``falls[i]`` of the ``i``-th stride's robots
    fall)."""
    from imitwalk.sim.protocol import load_protocol
    from imitwalk.step import pace
    from imitwalk.step.episode import StepScore

    strides = []

    def walks(fn, jobs):
        assert len(jobs) == pace.PACE_ROBOTS and len({j.style.step_length for j in jobs}) == 1
        fell = falls[len(strides)]
        strides.append(jobs[0].style.stride_share)
        return [
            StepScore(j.seed, i < fell, 1.0 if i < fell else None, 3.0, 1, 0, 0)
            for i, j in enumerate(jobs)
        ]

    monkeypatch.setattr(pace, "run_parallel", walks)
    said = []
    style, choice = pace.choose_stride(
        imported["op3"], styles["op3"], load_protocol("eval"), 3.0, progress=said.append
    )
    assert strides == list(pace.STRIDES[: len(falls)])  # longest first
    assert choice.share == kept and style.stride_share == kept
    assert choice.trials == {f"{s:g}": f for s, f in zip(pace.STRIDES, falls, strict=False)}
    assert choice.robots == pace.PACE_ROBOTS
    assert choice.sim_seconds == pytest.approx(3.0 * pace.PACE_ROBOTS * len(falls))
    assert style.step_length == pytest.approx(kept * styles["op3"].step_length)
    assert f"kept {kept:g}" in said[0]


@settings(max_examples=25, deadline=None)
@given(a=hs.floats(0.05, 1.0), b=hs.floats(0.05, 1.0))
def test_a_stride_share_is_of_the_clips_stride(styles, a, b):
    from imitwalk.step.style import with_stride

    st = styles["hoap2"]
    once, twice = with_stride(st, b), with_stride(with_stride(st, a), b)
    assert twice.step_length == pytest.approx(once.step_length)
    assert once.step_length == pytest.approx(b * st.step_length)
    assert once.step_time == st.step_time and once.clearance == st.clearance
    # a shorter step lets the hips stand higher
    if b < 1.0:
        assert once.hip_height >= st.hip_height


@pytest.mark.parametrize("share", [0.0, -0.5, 1.2, float("nan")])
def test_a_stride_share_out_of_range_is_refused(styles, share):
    from imitwalk.step.style import with_stride

    with pytest.raises(ConfigError, match="expected 0 < share <= 1"):
        with_stride(styles["hoap2"], share)


def test_a_paced_gait_saves_its_share_and_an_older_file_walks_the_whole_stride(
    robot, styles, tmp_path
):
    from imitwalk.step.gait import StepGait
    from imitwalk.step.style import with_stride

    gait = StepGait(style=with_stride(styles["hoap2"], 0.35), robot=robot.name)
    back = StepGait.load(gait.save(tmp_path / "style.json"))
    assert back.style.stride_share == 0.35
    assert back.style.step_length == pytest.approx(gait.style.step_length)
    d = json.loads((tmp_path / "style.json").read_text())
    d["format"] = 1
    del d["style"]["stride_share"]
    (tmp_path / "old.json").write_text(json.dumps(d))
    assert StepGait.load(tmp_path / "old.json").style.stride_share == 1.0
    d["format"], d["style"]["stride_share"] = 2, 1.5
    (tmp_path / "bad.json").write_text(json.dumps(d))
    with pytest.raises(RunError, match="expected 0 < stride_share <= 1") as err:
        StepGait.load(tmp_path / "bad.json")
    assert "\n" not in str(err.value)


@pytest.mark.slow
def test_op3_learns_a_stride_its_servos_carry_and_walks_it(maps, tmp_path, capsys):
    """The whole product path on OP3 with the defaults: ``learn`` tries shorter strides,
    keeps one, and the nominal robot walks it 20 s without falling."""
    out = tmp_path / "run"
    capsys.readouterr()
    assert main(["learn", "--robot", str(maps["op3"]), "--out", str(out)]) == 0
    assert "pace: the swing asks" in capsys.readouterr().err
    pace = json.loads((out / "config.json").read_text())["pace"]
    assert pace["ratio"] > 1.0 and pace["share"] < 1.0
    argv = ["evaluate", str(out), "--seeds", "1", "--seconds", "20", "--json"]
    assert main([*argv, "--controllers", "learned"]) == 0
    res = json.loads(capsys.readouterr().out)["controllers"]["learned"]
    assert res["falls"] == 0 and res["progress_ratio_min"] > 0.8
