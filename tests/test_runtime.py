"""The exported controller (``imitwalk export``, :mod:`imitwalk.runtime`): through the
runtime alone (a sensor vector in, joint targets out) it walks the judge's robots as
``evaluate`` does, on MuJoCo and on Bullet; what it imports and calls; bad exports, bad
sensor vectors and bad export commands."""

from __future__ import annotations

import json
import shutil
import subprocess
import sys

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from imitwalk.errors import ConfigError, RunError, SensorError


def _cli(argv, capsys):
    from imitwalk.cli import main

    code = main(argv)
    out = capsys.readouterr()
    return code, out.out, out.err


@pytest.fixture(scope="module")
def export(step_run, tmp_path_factory):
    """The tiny stepping run's learned controller, exported through the CLI."""
    from imitwalk.cli import main

    out = tmp_path_factory.mktemp("export") / "walk"
    assert main(["export", str(step_run), "--out", str(out)]) == 0
    return out


def _through_runtime(export, step_run, robot, protocol: str, seeds: int, seconds: float):
    """Each of the protocol's first ``seeds`` robots walked by the exported controller,
    handed nothing but the sensor vector: ``[(fell, fall time, distance)]``. The run
    folder only sets up the plant and the metrics, as the judge does."""
    from imitwalk.judge.replay import load_run
    from imitwalk.runtime import Controller
    from imitwalk.sim.metrics import walk_metrics
    from imitwalk.sim.mujoco import make_plant, run
    from imitwalk.sim.protocol import load_protocol

    proto = load_protocol(protocol)
    gait = load_run(step_run).step_gait
    out = []
    for seed in range(seeds):
        draw = proto.draw(seed, robot, seconds=seconds)
        ctl = Controller.load(export)
        plant = make_plant(robot, gait.sim_options(draw.options), proto.engine)

        def policy(k, obs, ctl=ctl):
            v = ctl.sensors.vector(obs)  # all the controller sees
            return ctl.reset(v) if k == 0 else ctl.step(v)

        ro = run(plant, policy, round(seconds / gait.dt), q0=ctl.q0)
        m = walk_metrics(
            ro,
            gait.expected_distance(1.0, seconds),
            gait.trajectory(1.0, seconds),
            gait.track(1.0, seconds),
        )
        out.append((m.fell, m.fall_time_s, m.forward_distance_m))
    return out


def _judged(step_run, robot, protocol: str, seeds: int, seconds: float):
    from imitwalk.judge.verdict import judge_protocol
    from imitwalk.sim.protocol import load_protocol

    v = judge_protocol(
        str(step_run), robot, load_protocol(protocol), seeds, seconds, ("learned",), workers=1
    )
    rows = v.controllers["learned"].per_seed
    return [(r.fell, r.fall_time_s, r.forward_distance_m) for r in rows]


@pytest.mark.parametrize(("protocol", "seeds", "seconds"), [("eval", 3, 4.0), ("bullet", 2, 3.0)])
def test_the_runtime_walks_the_judges_robots_as_evaluate_does(
    export, step_run, robot, protocol, seeds, seconds
):
    """MuJoCo: the same falls and distances, exactly; Bullet: the same falls."""
    mine = _through_runtime(export, step_run, robot, protocol, seeds, seconds)
    judged = _judged(step_run, robot, protocol, seeds, seconds)
    assert mine == judged


@pytest.mark.slow
@pytest.mark.parametrize("protocol", ["eval", "bullet"])
def test_ten_robots_walk_through_the_runtime_as_evaluate_judges_them(
    export, step_run, robot, protocol
):
    mine = _through_runtime(export, step_run, robot, protocol, 10, 20.0)
    assert mine == _judged(step_run, robot, protocol, 10, 20.0)


#: Run in a fresh interpreter: load an export, run it a second of ticks with every
#: physics entry point of MuJoCo replaced by one that fails, print what was imported.
_PROBE = """
import json, sys
import mujoco
def _never(*args, **kwargs):
    raise AssertionError("the runtime called MuJoCo's physics")
for name in ("mj_step", "mj_step1", "mj_step2", "mj_forward", "mj_inverse"):
    setattr(mujoco, name, _never)
import numpy as np
from imitwalk.runtime import Controller
ctl = Controller.load(sys.argv[1])
k = ctl.sensors.sole_sensors
weight = ctl.bundle.robot.total_mass * 9.81
v = np.concatenate([np.zeros(3), [0.0, 0.0, 9.81], np.full(2 * k, weight / (2 * k)), ctl.q0])
q = ctl.reset(v)
for _ in range(100):
    q = ctl.step(v)
assert q.shape == (len(ctl.joint_names),) and np.all(np.isfinite(q))
print(json.dumps(sorted(sys.modules)))
"""

#: What a robot's computer need not have, and the parts of imitwalk a controller never uses.
NEVER = (
    "scipy",
    "pybullet",
    "mink",
    "matplotlib",
    "sklearn",
    "torch",
    "gymnasium",
    "stable_baselines3",
    "imitwalk.mocap",
    "imitwalk.judge",
    "imitwalk.evidence",
    "imitwalk.envs",
    "imitwalk.cli",
    "imitwalk.sim.mujoco",
    "imitwalk.sim.bullet",
    "imitwalk.retarget.template",
)


def test_a_loaded_controller_imports_only_numpy_and_mujoco_and_never_steps_physics(export):
    out = subprocess.run(
        [sys.executable, "-c", _PROBE, str(export)], capture_output=True, text=True, check=False
    )
    assert out.returncode == 0, out.stderr[-2000:]
    modules = json.loads(out.stdout)
    pulled = [m for m in modules if any(m == n or m.startswith(n + ".") for n in NEVER)]
    assert pulled == []


def test_the_manifest_says_what_a_robot_needs(export, robot):
    m = json.loads((export / "manifest.json").read_text())
    assert m["format"] == 2 and m["controller"] == "stepping"
    assert [j["name"] for j in m["joints"]] == list(robot.joint_names)
    assert m["control"]["rate_hz"] == pytest.approx(100.0)
    blocks = {b["name"]: b for b in m["sensors"]["blocks"]}
    assert list(blocks) == ["gyro", "accel", "foot_force", "joints"]
    assert blocks["foot_force"]["mjcf_sensors"] == [*robot.foot_force["l"], *robot.foot_force["r"]]
    assert m["sensors"]["size"] == sum(b["size"] for b in blocks.values())
    assert m["source"]["controller"] == "learned" and m["versions"]["mujoco"]
    assert sorted(m["files"]) == ["gains.json", "robot.json", "robot.mjb", "style.json"]


def _damage(folder, how: str) -> str:
    """Damage an export copy; the word its error message must contain."""
    m_path = folder / "manifest.json"
    if how == "truncated model":
        data = (folder / "robot.mjb").read_bytes()
        (folder / "robot.mjb").write_bytes(data[: len(data) // 2])
        return "robot.mjb"
    if how == "tampered gains":
        g = json.loads((folder / "gains.json").read_text())
        g[next(iter(g))] += 0.01
        (folder / "gains.json").write_text(json.dumps(g))
        return "gains.json"
    if how == "missing style":
        (folder / "style.json").unlink()
        return "style.json"
    m = json.loads(m_path.read_text())
    if how == "newer format":
        from imitwalk.runtime.bundle import BUNDLE_FORMAT

        m["format"] = BUNDLE_FORMAT + 1
        word = f"format {BUNDLE_FORMAT + 1}"
    elif how == "another kind":
        m["kind"] = "something else"
        word = "kind"
    elif how == "no format":
        del m["format"]
        word = "format"
    else:
        m_path.write_text(m_path.read_text()[:100])
        return "manifest.json"
    m_path.write_text(json.dumps(m))
    return word


@pytest.mark.parametrize(
    "how",
    [
        "truncated model",
        "tampered gains",
        "missing style",
        "newer format",
        "another kind",
        "no format",
        "truncated manifest",
    ],
)
def test_a_damaged_export_is_refused_in_one_line(export, tmp_path, how):
    from imitwalk.runtime import Controller

    bad = tmp_path / "bad"
    shutil.copytree(export, bad)
    word = _damage(bad, how)
    with pytest.raises(RunError) as err:
        Controller.load(bad)
    msg = str(err.value)
    assert word in msg and "\n" not in msg


def test_a_format_1_export_walks_its_whole_stride(export, tmp_path):
    """An export of 0.7.0 (format 1: its style has no ``stride_share``) still loads."""
    import hashlib

    from imitwalk.runtime.bundle import read_bundle

    old = tmp_path / "old"
    shutil.copytree(export, old)
    style = json.loads((old / "style.json").read_text())
    del style["stride_share"]
    (old / "style.json").write_text(json.dumps(style))
    m = json.loads((old / "manifest.json").read_text())
    m["format"] = 1
    m["files"]["style.json"] = hashlib.sha256((old / "style.json").read_bytes()).hexdigest()
    (old / "manifest.json").write_text(json.dumps(m))
    assert read_bundle(old).style.stride_share == 1.0


@pytest.mark.parametrize(
    ("sensors", "word"),
    [
        ("short", "a vector of"),
        ("matrix", "shape"),
        ("nan", "gyro[1]"),
        ("inf", "joints[0]"),
        ("text", "a vector of"),
    ],
)
def test_a_bad_sensor_vector_is_refused_in_one_line(export, sensors, word):
    from imitwalk.runtime import Controller

    ctl = Controller.load(export)
    n = ctl.sensors.size
    good = np.concatenate([np.zeros(n - len(ctl.q0)), ctl.q0])
    good[5] = 9.81
    ctl.reset(good)
    bad = {
        "short": good[:-1],
        "matrix": good.reshape(1, -1),
        "nan": np.where(np.arange(n) == 1, np.nan, good),
        "inf": np.where(np.arange(n) == n - len(ctl.q0), np.inf, good),
        "text": "sensors",
    }[sensors]
    with pytest.raises(SensorError) as err:
        ctl.step(bad)
    assert word in str(err.value) and "\n" not in str(err.value)


def test_step_before_reset_is_refused(export):
    from imitwalk.runtime import Controller

    ctl = Controller.load(export)
    with pytest.raises(SensorError, match="reset"):
        ctl.step(np.zeros(ctl.sensors.size))


@settings(max_examples=40, deadline=None)
@given(
    k=st.integers(1, 6),
    n=st.integers(1, 30),
    seed=st.integers(0, 2**32 - 1),
    bad=st.sampled_from([None, np.nan, np.inf, -np.inf]),
)
def test_the_sensor_vector_round_trips_and_names_a_bad_entry(k, n, seed, bad):
    from imitwalk.runtime import SensorLayout

    lay = SensorLayout(k, n)
    rng = np.random.default_rng(seed)
    v = rng.normal(size=lay.size) * 100
    obs = lay.observation(v, 0.5)
    assert obs.foot_force.shape == (2, k) and obs.joints.shape == (n,)
    assert np.array_equal(lay.vector(obs), v)
    if bad is not None:
        i = int(rng.integers(lay.size))
        v[i] = bad
        with pytest.raises(SensorError) as err:
            lay.observation(v)
        block = next(name for name, sl in lay.slices().items() if sl.start <= i < sl.stop)
        assert f"{block}[{i - lay.slices()[block].start}]" in str(err.value)


def test_export_replaces_an_earlier_export_atomically(step_run, robot, tmp_path, monkeypatch):
    from imitwalk.judge.export import export_run
    from imitwalk.runtime import bundle

    out = tmp_path / "walk"
    export_run(step_run, robot, out)
    before = {p.name: p.read_bytes() for p in out.iterdir()}
    export_run(step_run, robot, out, controller="default")  # replaces it
    assert json.loads((out / "manifest.json").read_text())["source"]["controller"] == "default"

    def broken(b, folder):
        (folder / "robot.json").write_text("{")
        raise OSError("disk full")

    export_run(step_run, robot, out)
    before = {p.name: p.read_bytes() for p in out.iterdir()}
    monkeypatch.setattr(bundle, "_write_parts", broken)
    with pytest.raises(OSError):
        export_run(step_run, robot, out, controller="default")
    assert {p.name: p.read_bytes() for p in out.iterdir()} == before  # the old one, whole
    assert [p.name for p in tmp_path.iterdir()] == ["walk"]  # nothing half-written beside it


def test_bad_export_commands_exit_2_with_one_line(step_run, tick_run, tmp_path, capsys):
    cases = [
        (["export", str(tick_run), "--out", str(tmp_path / "a")], "learners: step, rl"),
        (
            ["export", str(step_run), "--out", str(tmp_path / "b"), "--controller", "x"],
            "valid: default, learned",
        ),
        (["export", str(step_run), "--out", str(tmp_path / "c"), "--scale", "0"], "--scale"),
        (["export", str(tmp_path / "none"), "--out", str(tmp_path / "d")], "not found"),
        (["export", str(step_run), "--out", str(step_run)], "not an export"),
    ]
    for argv, word in cases:
        code, _, err = _cli(argv, capsys)
        lines = err.strip().splitlines()
        assert code == 2 and word in lines[-1] and lines[-1].startswith("error: "), (argv, err)
    assert sorted(p.name for p in tmp_path.iterdir()) == []


def test_a_bundle_refuses_parts_that_do_not_make_its_kind(robot):
    from imitwalk.runtime import Bundle

    with pytest.raises(ConfigError, match="valid: rl-joints, rl-residual, stepping"):
        Bundle("walker", robot, 0.01)
    with pytest.raises(ConfigError, match=r"style\.json, gains\.json"):
        Bundle("stepping", robot, 0.01)
