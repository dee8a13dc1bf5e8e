"""A stepping run's files are checked when read (hostile input, the style round): every
field of ``style.json`` (the :class:`~imitwalk.step.style.GaitStyle` and the
:class:`~imitwalk.step.gait.StepGait`'s own), ``gains.json``'s entries and
``config.json``'s learner. Each refusal is one line naming the file and the field; the
CLI exits with status 2 before any walk. The run's files are written directly (no
learning, no physics).
"""

from __future__ import annotations

import json
import shutil
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from imitwalk.errors import ConfigError, RunError

NAN, INF = float("nan"), float("inf")


@pytest.fixture(scope="module")
def gait():
    """The default clip's stepping gait on hoap2 (a straight, forward walk)."""
    from imitwalk.mocap import default_clip, load_motion
    from imitwalk.robots import load_robot
    from imitwalk.step.pipeline import gait_from_motion

    return gait_from_motion(load_motion(default_clip()), load_robot("hoap2"))


def _write_run(folder: Path, gait) -> Path:
    """A finished stepping run's files for ``gait``, as ``learn`` writes them (the shipped
    gains as both the learned and the default ones)."""
    from imitwalk.runs import LearnSummary, RunDir, StepOutcome
    from imitwalk.step.gains import shipped_gains

    rd = RunDir(folder)
    folder.mkdir(parents=True)
    gains = shipped_gains(gait.style.backward).to_dict()
    rd.write_json("config.json", {"learner": "step", "learn": {}, "robot": "hoap2"})
    gait.save(rd.file("style.json"))
    rd.write_json("gains.json", {"learned": gains, "default": gains})
    summary = LearnSummary(
        learner="step",
        scale_reached=1.0,
        scales_passed=[1.0],
        iterations=1,
        sim_seconds_used_for_learning=1.0,
        wall_seconds_for_learning=1.0,
        config={},
        outcome=StepOutcome(gains=gains, final={}),
    )
    rd.write_json("metrics.json", summary.to_dict())
    return folder


@pytest.fixture(scope="module")
def run(gait, tmp_path_factory) -> Path:
    """A stepping run's folder, not to be changed (:func:`_copy` one to corrupt it)."""
    return _write_run(tmp_path_factory.mktemp("steprun") / "run", gait)


def _copy(run: Path, tmp_path: Path) -> Path:
    out = tmp_path / "run"
    shutil.copytree(run, out)
    return out


def _edit(path: Path, keys: tuple[str, ...], value) -> None:
    """Set ``keys`` (a path into the JSON document at ``path``) to ``value``."""
    d = json.loads(path.read_text())
    node = d
    for k in keys[:-1]:
        node = node[k]
    node[keys[-1]] = value
    path.write_text(json.dumps(d))


#: (the path into style.json, the value written, the field the message names).
CORRUPT = [
    (("style", "step_time"), NAN, "style.step_time"),
    (("style", "step_time"), 0.0, "style.step_time"),
    (("style", "step_time"), -0.6, "style.step_time"),
    (("style", "step_time"), "0.6", "style.step_time"),
    (("dt",), 0.0, "dt"),
    (("dt",), NAN, "dt"),
    (("dt",), 5.0, "dt"),
    (("style", "double_support"), 0.0, "style.double_support"),
    (("style", "double_support"), 5.0, "style.double_support"),
    (("style", "hip_height"), INF, "style.hip_height"),
    (("style", "hip_height"), 0.0, "style.hip_height"),
    (("style", "hip_height"), 5.0, "style.hip_height"),
    (("style", "turn"), 100.0, "style.turn"),
    (("style", "turn"), -NAN, "style.turn"),
    (("style", "step_length"), -5.0, "style.step_length"),
    (("style", "step_length"), 5.0, "style.step_length"),
    (("style", "step_length"), 0.0, "style.step_length"),
    (("style", "step_length"), INF, "style.step_length"),
    (("style", "step_width"), 0.0, "style.step_width"),
    (("style", "clearance"), -0.01, "style.clearance"),
    (("style", "clearance"), NAN, "style.clearance"),
    (("style", "stride_share"), 1.5, "style.stride_share"),
    (("style", "swing_x"), [], "style.swing_x"),
    (("style", "swing_x"), [0.0, NAN, 1.0], "style.swing_x"),
    (("style", "swing_x"), "fast", "style.swing_x"),
    (("style", "swing_z"), [0.0, 1.0, 0.0], "style.swing_x and swing_z"),
    (("style", "upper", "l_elbow"), [], "style.upper.l_elbow"),
    (("style", "upper", "waist_yaw"), [0.1, INF], "style.upper.waist_yaw"),
    (("style", "upper"), [], "style.upper"),
    (("style", "geometry", "leg"), 0.0, "style.geometry.leg"),
    (("style", "geometry", "foot_length"), NAN, "style.geometry.foot_length"),
    (("style", "geometry", "knee"), 0.1, "style.geometry.knee"),
    (("style", "human", "period"), 0.0, "style.human.period"),
    (("style", "human", "turn_deg"), INF, "style.human.turn_deg"),
    (("style", "bogus"), 1.0, "style.bogus"),
]


@pytest.mark.parametrize(("keys", "value", "field"), CORRUPT, ids=lambda v: str(v))
def test_a_corrupted_style_field_is_refused_in_one_line_naming_it(
    run, tmp_path, keys, value, field
):
    from imitwalk.judge.replay import load_run
    from imitwalk.step.gait import StepGait

    out = _copy(run, tmp_path)
    _edit(out / "style.json", keys, value)
    for read in (lambda: load_run(out), lambda: StepGait.load(out / "style.json")):
        with pytest.raises(RunError) as err:
            read()
        msg = str(err.value)
        assert "\n" not in msg
        assert msg.startswith(f"{out / 'style.json'}: {field} "), msg


def test_a_missing_style_field_is_named(run, tmp_path):
    from imitwalk.step.gait import StepGait

    out = _copy(run, tmp_path)
    d = json.loads((out / "style.json").read_text())
    del d["style"]["step_time"]
    (out / "style.json").write_text(json.dumps(d))
    with pytest.raises(RunError, match=r"style\.json: style\.step_time is missing$"):
        StepGait.load(out / "style.json")


def test_real_styles_pass_forward_backward_and_turning(gait, run, tmp_path):
    """The checks refuse nothing a clip makes: a forward and a backward run load, a
    turning style turns its clip's way forward and the other way backward (and a step
    the other way round is refused), and a style at any scale is a style."""
    from imitwalk.judge.replay import load_run
    from imitwalk.step.style import MAX_TURN, reversed_in_time

    assert load_run(run).step_gait.to_dict() == gait.to_dict()
    back = replace(gait, style=reversed_in_time(gait.style))
    lr = load_run(_write_run(tmp_path / "back", back))
    assert lr.step_gait.style.backward and lr.step_gait.style.step_length < 0
    human = {**gait.style.human, "turn_deg": 99.0}
    turning = replace(gait.style, turn=MAX_TURN, human=human)
    assert reversed_in_time(turning).turn == -MAX_TURN
    with pytest.raises(ConfigError, match=r"turn .* disagree with the clip's turn"):
        replace(turning, step_length=-turning.step_length)
    for scale in (0.0, 0.5, 1.5):
        assert gait.at_scale(scale).step_length == pytest.approx(scale * gait.style.step_length)


def test_a_style_or_gait_made_in_code_is_checked(gait):
    from imitwalk.step.gait import StepGait

    with pytest.raises(ConfigError, match=r"^step_time must be a finite number > 0 \[s\]"):
        replace(gait.style, step_time=NAN)
    with pytest.raises(ConfigError, match=r"^swing_z must be"):
        replace(gait.style, swing_z=np.array([]))
    with pytest.raises(ConfigError, match=r"^dt must be"):
        StepGait(style=gait.style, robot="hoap2", dt=0.0)


def test_gains_without_an_entry_say_which_and_what_the_file_holds(run, tmp_path):
    from imitwalk.judge.replay import load_run

    out = _copy(run, tmp_path)
    gains = json.loads((out / "gains.json").read_text())
    (out / "gains.json").write_text(json.dumps({"default": gains["default"]}))
    with pytest.raises(RunError) as err:
        load_run(out)
    msg = str(err.value)
    assert "\n" not in msg and "gains.json lacks 'learned'" in msg
    assert "holds 'learned' and 'default'" in msg
    (out / "gains.json").write_text(json.dumps({**gains, "learned": {"dcm": 99.0}}))
    with pytest.raises(RunError, match=r"gains\.json: 'learned': gain dcm=99"):
        load_run(out)
    (out / "gains.json").write_text("[1, 2]")
    with pytest.raises(RunError, match=r"gains\.json holds a list, not an object"):
        load_run(out)


def test_an_unknown_learner_is_refused_listing_the_learners(run, tmp_path):
    from imitwalk.judge.replay import load_run

    out = _copy(run, tmp_path)
    config = json.loads((out / "config.json").read_text())
    for learner in ("bogus", 3, None):
        (out / "config.json").write_text(json.dumps({**config, "learner": learner}))
        with pytest.raises(RunError) as err:
            load_run(out)
        msg = str(err.value)
        assert "\n" not in msg and msg.startswith(f"{out / 'config.json'}: unknown learner ")
        assert msg.endswith("valid: faithful, rl, step, tick")
    # a run written before learners were named is read as the paper's, as it was
    del config["learner"]
    (out / "config.json").write_text(json.dumps(config))
    with pytest.raises(RunError) as err:
        load_run(out)
    assert "unknown learner" not in str(err.value)
    (out / "config.json").write_text(json.dumps({**config, "learner": "step", "learn": [1]}))
    with pytest.raises(RunError, match=r"config\.json: learn must be an object"):
        load_run(out)


@pytest.mark.parametrize(
    ("file", "keys", "value", "field"),
    [
        ("style.json", ("style", "step_time"), NAN, "style.step_time"),
        ("config.json", ("learner",), "bogus", "unknown learner 'bogus'"),
    ],
)
def test_evaluate_refuses_a_corrupted_run_with_status_2(
    run, tmp_path, capsys, file, keys, value, field
):
    from imitwalk.cli.main import main

    out = _copy(run, tmp_path)
    _edit(out / file, keys, value)
    assert main(["evaluate", str(out), "--seeds", "1", "--seconds", "1"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) >= 1 and err[-1].startswith("error: ") and "Traceback" not in "\n".join(err)
    assert file in err[-1] and field in err[-1], err[-1]
    assert sorted(p.name for p in out.iterdir()) == sorted(p.name for p in run.iterdir())
