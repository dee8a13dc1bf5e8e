"""The stepping gait walking: the controller, learning with resume, the run folder, the CLI."""

from __future__ import annotations

import itertools
import json

import numpy as np
import pytest

from tests.conftest import TINY_STEP, sets, strip_wall


@pytest.fixture(scope="module")
def gait(robot):
    from imitwalk.mocap import default_clip, load_motion
    from imitwalk.step.pipeline import gait_from_motion

    return gait_from_motion(load_motion(default_clip()), robot)


def test_the_nominal_robot_walks_the_style_from_its_sensors_alone(robot, gait):
    """Six seconds from standing: no fall, it travels, and the controller was handed
    nothing but the robot's observations (a plant that exposes nothing else)."""
    from imitwalk.sim.metrics import walk_metrics
    from imitwalk.sim.mujoco import MujocoPlant, run
    from imitwalk.step.controller import SteppingController
    from imitwalk.step.gains import StepGains

    seen = []

    class Blind:  # the controller sees the Observation only
        def __init__(self, ctrl):
            self.ctrl, self.q0 = ctrl, ctrl.q0

        def __call__(self, k, obs):
            seen.append(type(obs).__name__)
            return self.ctrl(k, obs)

    ctrl = SteppingController(robot, gait.style, StepGains(), gait.dt)
    ro = run(MujocoPlant(robot), Blind(ctrl), 600)
    m = walk_metrics(ro, gait.expected_distance(1.0, ro.seconds))
    assert not m.fell
    assert ctrl.steps >= 5
    assert m.progress_ratio > 0.5 and m.forward_distance_m > 0.2
    assert set(seen) == {"Observation"}


def test_the_clip_played_backward_walks_backward_from_the_sensors(robot, gait):
    """The style reversed in time, with the shipped backward gains, walks the nominal
    robot backward at the clip's whole stride for eight seconds, and is judged by its own
    (negative) distance."""
    from imitwalk.sim.metrics import walk_metrics
    from imitwalk.sim.mujoco import MujocoPlant, run
    from imitwalk.step.controller import SteppingController
    from imitwalk.step.gains import shipped_gains
    from imitwalk.step.style import reversed_in_time

    style = reversed_in_time(gait.style)
    ctrl = SteppingController(robot, style, shipped_gains(backward=True), gait.dt)
    ro = run(MujocoPlant(robot), ctrl, 800)
    m = walk_metrics(ro, style.speed * ro.seconds)
    assert not m.fell and ctrl.steps >= 8
    assert m.forward_distance_m < -0.5 and 0.6 < m.progress_ratio < 1.2


def test_learn_backward_writes_a_backward_run_that_resumes_as_one(tmp_path, capsys):
    from imitwalk.cli.main import main
    from imitwalk.step.gains import shipped_gains
    from imitwalk.step.gait import StepGait

    out = tmp_path / "back"
    assert main(["learn", "--backward", "--out", str(out), "--json", *sets(TINY_STEP)]) == 0
    capsys.readouterr()
    first = StepGait.load(out / "style.json").style
    assert first.step_length < 0 and first.backward
    # its default controller (and the search's start) is the shipped backward gains
    default = json.loads((out / "gains.json").read_text())["default"]
    assert default == shipped_gains(backward=True).to_dict() != shipped_gains().to_dict()
    # resumed (without --backward), the run walks its own style
    assert main(["learn", "--out", str(out), "--resume", "--json", *sets(TINY_STEP)]) == 0
    assert StepGait.load(out / "style.json").style.step_length == first.step_length


@pytest.mark.parametrize("deg", [-3.0, 3.0])
def test_the_soles_laid_onto_the_floor_carry_the_gait_across_a_slope(robot, gait, deg):
    """A floor tilted 3° across the walk fell the gait while its soles stayed level
    (10 of 10 ``eval`` robots); laid onto the slope the stance sole measures, the
    nominal robot walks 10 s."""
    from dataclasses import replace

    from imitwalk.sim.metrics import walk_metrics
    from imitwalk.sim.mujoco import MujocoPlant, run
    from imitwalk.sim.types import SimOptions
    from imitwalk.step.controller import SteppingController
    from imitwalk.step.gains import StepGains

    ctrl = SteppingController(robot, gait.style, StepGains(), gait.dt)
    plant = MujocoPlant(robot, replace(SimOptions(), cross_slope_deg=deg))
    ro = run(plant, ctrl, 1000)
    m = walk_metrics(ro, gait.expected_distance(1.0, ro.seconds))
    assert not m.fell and m.progress_ratio > 0.7


def test_expected_distance_grows_with_the_schedule(gait):
    d = [gait.expected_distance(1.0, t) for t in np.arange(0, 12, 0.5)]
    assert d[0] == 0.0 and all(b >= a for a, b in itertools.pairwise(d))
    steady = gait.expected_distance(1.0, 11.0) - gait.expected_distance(1.0, 9.0)
    assert steady == pytest.approx(2.0 * gait.style.speed, rel=1e-6)


def test_the_gait_saves_and_loads(gait, tmp_path):
    from imitwalk.errors import RunError
    from imitwalk.step.gait import StepGait

    back = StepGait.load(gait.save(tmp_path / "style.json"))
    assert back.to_dict() == gait.to_dict()
    (tmp_path / "bad.json").write_text("[1, 2]")
    with pytest.raises(RunError, match="not a stepping gait"):
        StepGait.load(tmp_path / "bad.json")


def test_learning_resumes_exactly(robot, gait, tmp_path):
    """Two generations straight, and one, interrupted, then resumed: the same gains."""
    from imitwalk.config import apply_overrides
    from imitwalk.sim.protocol import load_protocol
    from imitwalk.step.learn import StepLearnConfig
    from imitwalk.step.pipeline import learn_clip

    cfg = apply_overrides(StepLearnConfig(), [*TINY_STEP, "final_robots=0"])
    one = apply_overrides(cfg, ["generations=1"])
    proto = load_protocol(cfg.protocol)
    whole = learn_clip(gait, robot, cfg, tmp_path / "a", proto)
    learn_clip(gait, robot, one, tmp_path / "b", proto)
    # the interrupted run's settings said two generations: resume it with those
    cfg_b = json.loads((tmp_path / "b" / "config.json").read_text())
    cfg_b["learn"]["generations"] = 2
    (tmp_path / "b" / "config.json").write_text(json.dumps(cfg_b))
    import pickle

    state = pickle.loads((tmp_path / "b" / "cma.pkl").read_bytes())
    state["config"]["generations"] = 2
    (tmp_path / "b" / "cma.pkl").write_bytes(pickle.dumps(state))
    resumed = learn_clip(gait, robot, cfg, tmp_path / "b", proto, resume=True)
    assert resumed.step().gains == whole.step().gains
    assert strip_wall(resumed)["sim_seconds_used_for_learning"] == pytest.approx(
        whole.sim_seconds_used_for_learning
    )


def test_learn_and_evaluate_a_stepping_run_through_the_cli(tmp_path, capsys):
    from imitwalk.cli.main import main

    out = tmp_path / "run"
    assert main(["learn", "--out", str(out), "--json", *sets(TINY_STEP)]) == 0
    res = json.loads(capsys.readouterr().out)
    assert res["learner"] == "step" and res["variant"] == "step"
    assert set(json.loads((out / "gains.json").read_text())) == {"learned", "default"}
    argv = ["evaluate", str(out), "--seeds", "2", "--seconds", "4", "--json"]
    assert main(argv) == 0
    ev = json.loads(capsys.readouterr().out)
    assert set(ev["controllers"]) == {"learned", "default"}
    # resumed, it keeps its learner and its direction: other ones are refused in one line
    for flags, word in [(["--backward"], "walks forward"), (["--variant", "extended"], "'step'")]:
        assert main(["learn", "--out", str(out), "--resume", *flags, *sets(TINY_STEP)]) == 2
        err = capsys.readouterr().err.strip()
        assert err.startswith("error: ") and word in err and "\n" not in err
    # a damaged checkpoint is refused on --resume in one line, before any walk
    (out / "cma.pkl").write_bytes((out / "cma.pkl").read_bytes()[:40])
    assert main(["learn", "--out", str(out), "--resume", *sets(TINY_STEP)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) >= 1 and err[-1].startswith("error: ") and "cma.pkl" in err[-1]
    # a stepping run refuses the joint-space learner's flags, in one line
    assert main(["learn", "--out", str(tmp_path / "x"), "--turn", "10"]) == 2
    assert "--turn" in capsys.readouterr().err
    # ... and the joint-space learners refuse --backward
    argv = ["learn", "--out", str(tmp_path / "y"), "--variant", "extended", "--backward"]
    assert main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("error: --backward") and "\n" not in err
    assert not (tmp_path / "y").exists()


@pytest.mark.parametrize(
    ("setting", "message"),
    [
        ("population=2", "population=2 is out of range"),
        ("names=dcm,dmc", "unknown gain 'dmc'"),
        ("protocol=nope", "unknown protocol 'nope'"),
        ("robots=x", "expected int"),
    ],
)
def test_bad_learning_settings_are_refused_in_one_line_before_any_work(
    tmp_path, capsys, setting, message
):
    from imitwalk.cli.main import main

    out = tmp_path / "run"
    assert main(["learn", "--out", str(out), "--set", setting]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("error: ") and message in err and "\n" not in err
    assert not out.exists()


def test_a_broken_stepping_run_is_refused_in_one_line(tmp_path, capsys):
    from imitwalk.cli.main import main

    out = tmp_path / "run"
    assert main(["learn", "--out", str(out), *sets(TINY_STEP)]) == 0
    capsys.readouterr()
    (out / "gains.json").write_text('{"learned": {"dcm": "x"}}')
    assert main(["evaluate", str(out), "--seeds", "1", "--seconds", "1"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err[-1].startswith("error: ") and "gains.json" in err[-1]
    assert not any("Traceback" in line for line in err)


def test_a_stepping_run_names_the_robot_file_it_learned_on(gait, tmp_path):
    """``evaluate RUN`` without ``--robot`` finds an imported robot by the file its
    stepping gait records, not by the robot's name in ``config.json``."""
    from dataclasses import replace

    from imitwalk.cli.robot_args import run_robot
    from imitwalk.runs import RunDir

    replace(gait, provenance=gait.provenance.named("/x/op3.json", None)).save(
        tmp_path / "style.json"
    )
    assert run_robot(RunDir(tmp_path), {"robot": "op3"}) == ("/x/op3.json", None)


def test_a_gait_file_carries_its_format_and_a_newer_one_is_refused(gait, tmp_path):
    from imitwalk.errors import RunError
    from imitwalk.step.gait import GAIT_FORMAT, StepGait

    path = gait.save(tmp_path / "style.json")
    d = json.loads(path.read_text())
    assert d["format"] == GAIT_FORMAT
    del d["format"]  # a file written before versions reads as format 1
    path.write_text(json.dumps(d))
    assert StepGait.load(path).to_dict() == gait.to_dict()
    d["format"] = GAIT_FORMAT + 1
    path.write_text(json.dumps(d))
    with pytest.raises(RunError, match="newer imitwalk"):
        StepGait.load(path)
