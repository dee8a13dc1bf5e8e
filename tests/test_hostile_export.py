"""Hostile inputs to ``imitwalk export`` and :mod:`imitwalk.runtime` (round 3): an
``--out`` that is not an export (a user's folder with a ``manifest.json``, a symbolic
link, a file), a scale the run never learned, a manifest edited by hand, joint targets
beyond the published ranges, and sensor readings that are not real numbers, absurdly
large, or refused mid-walk."""

from __future__ import annotations

import json
import math
import os
import shutil
from decimal import Decimal

import numpy as np
import pytest

from imitwalk.errors import ConfigError, RunError, SensorError


def _cli(argv, capsys):
    from imitwalk.cli import main

    code = main(argv)
    out = capsys.readouterr()
    return code, out.out, out.err


def _one_line_error(code, err) -> str:
    """The message of a refused command: exit 2, one ``error:`` line and nothing else."""
    lines = err.strip().splitlines()
    assert code == 2 and len(lines) == 1 and lines[0].startswith("error: "), err
    return lines[0]


@pytest.fixture(scope="module")
def export(step_run, tmp_path_factory):
    """The tiny stepping run's learned controller, exported through the CLI."""
    from imitwalk.cli import main

    out = tmp_path_factory.mktemp("hostile_export") / "walk"
    assert main(["export", str(step_run), "--out", str(out)]) == 0
    return out


def _tree(folder):
    """Every file under ``folder`` with its bytes (links by their target)."""
    out = {}
    for root, dirs, files in os.walk(folder):
        for name in dirs + files:
            p = os.path.join(root, name)
            rel = os.path.relpath(p, folder)
            if os.path.islink(p):
                out[rel] = ("link", os.readlink(p))
            elif os.path.isfile(p):
                with open(p, "rb") as f:
                    out[rel] = f.read()
    return out


# -- 1. --out: only an earlier export is replaced -------------------------------------


def _users_folder(tmp_path, export, how: str):
    """A folder that is not an export, though it may look like one."""
    d = tmp_path / "userdir"
    if how == "foreign manifest":
        d.mkdir()
        (d / "manifest.json").write_text('{"name": "my-webapp"}')
        (d / "notes.txt").write_text("precious")
        (d / "sub").mkdir()
        (d / "sub" / "data.csv").write_text("x")
    elif how == "manifest not JSON":
        d.mkdir()
        (d / "manifest.json").write_text("name: my-webapp")
    elif how == "manifest of our kind, files unlisted":
        d.mkdir()
        (d / "manifest.json").write_text('{"format": 2, "kind": "imitwalk controller"}')
        (d / "notes.txt").write_text("precious")
    else:  # an earlier export the user put files into
        shutil.copytree(export, d)
        if how == "export plus a file":
            (d / "notes.txt").write_text("precious")
        else:
            (d / "sub").mkdir()
            (d / "sub" / "data.csv").write_text("x")
    return d


@pytest.mark.parametrize(
    "how",
    [
        "foreign manifest",
        "manifest not JSON",
        "manifest of our kind, files unlisted",
        "export plus a file",
        "export plus a folder",
    ],
)
def test_export_refuses_a_folder_that_is_not_an_export_and_deletes_nothing(
    step_run, export, tmp_path, capsys, how
):
    d = _users_folder(tmp_path, export, how)
    before = _tree(d)
    code, _, err = _cli(["export", str(step_run), "--out", str(d)], capsys)
    line = _one_line_error(code, err)
    assert "is not an export" in line and "nothing was replaced" in line
    assert _tree(d) == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["userdir"]  # no litter beside it


def test_the_api_refuses_it_too_before_building_anything(step_run, robot, tmp_path):
    from imitwalk.judge.export import export_run
    from imitwalk.judge.replay import load_run
    from imitwalk.runtime import write_bundle

    d = tmp_path / "userdir"
    d.mkdir()
    (d / "manifest.json").write_text('{"name": "my-webapp"}')
    with pytest.raises(ConfigError, match="not an export"):
        export_run(step_run, robot, d)
    with pytest.raises(ConfigError, match="not an export"):
        write_bundle(load_run(step_run).bundle("learned", robot), d)
    assert [p.name for p in tmp_path.iterdir()] == ["userdir"]
    assert [p.name for p in d.iterdir()] == ["manifest.json"]


def test_export_replaces_an_earlier_export_and_fills_an_empty_folder(
    step_run, export, tmp_path, capsys
):
    from imitwalk.runtime.bundle import is_export

    earlier = tmp_path / "earlier"
    shutil.copytree(export, earlier)
    empty = tmp_path / "empty"
    empty.mkdir()
    for out in (earlier, empty):
        code, _, err = _cli(
            ["export", str(step_run), "--out", str(out), "--controller", "default"], capsys
        )
        assert code == 0, err
        assert json.loads((out / "manifest.json").read_text())["source"]["controller"] == "default"
        assert is_export(out)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["earlier", "empty"]


# -- 2. --out a symbolic link: refused, the link and its target left as they were ------


@pytest.mark.parametrize("target", ["an export", "nothing"])
def test_export_refuses_a_symbolic_link(step_run, export, tmp_path, capsys, target):
    real = tmp_path / "export-v1"
    if target == "an export":
        shutil.copytree(export, real)
    link = tmp_path / "current"
    link.symlink_to(real.name)
    before = _tree(tmp_path)
    code, _, err = _cli(["export", str(step_run), "--out", str(link)], capsys)
    line = _one_line_error(code, err)
    assert "symbolic link" in line and "export-v1" in line
    assert link.is_symlink() and os.readlink(link) == "export-v1"
    assert _tree(tmp_path) == before  # no folder in the link's place, no .old-PID litter


# -- 6. --out a file; a scale the run did not learn ---------------------------------


def test_export_to_a_file_says_the_output_is_a_file(step_run, tmp_path, capsys):
    f = tmp_path / "walk.txt"
    f.write_text("mine")
    code, _, err = _cli(["export", str(step_run), "--out", str(f)], capsys)
    line = _one_line_error(code, err)
    assert "is a file, not an export folder" in line and "run folder" not in line
    assert f.read_text() == "mine"


@pytest.mark.parametrize("out", ["", ".", "sub/.."])
def test_export_refuses_an_out_that_names_no_folder(step_run, tmp_path, capsys, monkeypatch, out):
    """Even in an empty folder, where ``.`` would otherwise be the export."""
    monkeypatch.chdir(tmp_path)
    (tmp_path / "sub").mkdir()
    code, _, err = _cli(["export", str(step_run), "--out", out], capsys)
    assert "names no folder" in _one_line_error(code, err)
    assert [p.name for p in tmp_path.iterdir()] == ["sub"]


def test_export_refuses_a_scale_the_run_did_not_learn(step_run, tmp_path, capsys):
    from imitwalk.judge.replay import load_run

    passed = load_run(step_run).metrics.scales_passed
    assert 0.5 not in passed
    out = tmp_path / "half"
    code, _, err = _cli(["export", str(step_run), "--out", str(out), "--scale", "0.5"], capsys)
    line = _one_line_error(code, err)
    valid = ", ".join(f"{s:g}" for s in sorted(set(passed)))
    assert "--scale 0.5" in line and f"valid: {valid}" in line
    assert not out.exists()
    code, _, err = _cli(
        ["export", str(step_run), "--out", str(out), "--scale", f"{passed[-1]}"], capsys
    )
    assert code == 0, err


# -- 3. the manifest's fields, checked on load ------------------------------------------


def _edit(m: dict, how: str) -> None:
    j0 = m["joints"][0]
    edits = {
        "dt 0": lambda: m["control"].update(dt_s=0),
        "dt negative": lambda: m["control"].update(dt_s=-0.01),
        "dt NaN": lambda: m["control"].update(dt_s=math.nan),
        "dt inf": lambda: m["control"].update(dt_s=math.inf),
        "dt 1e9": lambda: m["control"].update(dt_s=1e9),
        "dt text": lambda: m["control"].update(dt_s="fast"),
        "dt true": lambda: m["control"].update(dt_s=True),
        "dt missing": lambda: m["control"].pop("dt_s"),
        "dt half rate": lambda: m["control"].update(dt_s=0.02),
        "rate disagrees": lambda: m["control"].update(rate_hz=500),
        "rate NaN": lambda: m["control"].update(rate_hz=math.nan),
        "control text": lambda: m.update(control="x"),
        "joints object": lambda: m.update(joints={"a": 1}),
        "joints empty": lambda: m.update(joints=[]),
        "joint text": lambda: m["joints"].__setitem__(0, "x"),
        "joint name number": lambda: j0.update(name=3),
        "mjcf joint renamed": lambda: j0.update(mjcf_joint="other"),
        "sign flipped": lambda: j0.update(sign=-j0["sign"]),
        "sign 2": lambda: j0.update(sign=2),
        "sign true": lambda: j0.update(sign=True),
        "sign text": lambda: j0.update(sign="+"),
        "unit deg": lambda: j0.update(unit="deg"),
        "stand NaN": lambda: j0.update(stand=math.nan),
        "stand moved": lambda: j0.update(stand=j0["stand"] + 0.1),
        "range empty": lambda: j0.update(range=[0, 0]),
        "range reversed": lambda: j0.update(range=j0["range"][::-1]),
        "range NaN": lambda: j0.update(range=[math.nan, 1.0]),
        "range short": lambda: j0.update(range=[0.0]),
        "range widened": lambda: j0.update(range=[j0["range"][0] - 1, j0["range"][1]]),
        "sensors list": lambda: m.update(sensors=[]),
        "sensors size text": lambda: m["sensors"].update(size="39"),
        "sensors size off": lambda: m["sensors"].update(size=m["sensors"]["size"] + 1),
        "blocks reordered": lambda: m["sensors"]["blocks"].reverse(),
        "block unit": lambda: m["sensors"]["blocks"][0].update(unit="deg/s"),
        "foot sensors renamed": lambda: m["sensors"]["blocks"][2].update(mjcf_sensors=["a"]),
        "robot renamed": lambda: m.update(robot="nao"),
        "robot number": lambda: m.update(robot=5),
        "source list": lambda: m.update(source=[1, 2]),
    }
    edits[how]()


_WORDS = {
    "dt": "dt_s",
    "rate": "rate_hz",
    "control": "control",
    "joints": "joints",
    "joint": "joints[0]",
    "mjcf": "mjcf_joint",
    "sign": "sign",
    "unit": "unit",
    "stand": "stand",
    "range": "range",
    "sensors": "sensors",
    "blocks": "sensors",
    "block": "sensors",
    "foot": "foot_force",
    "robot": "robot",
    "source": "source",
}

_EDITS = [
    "dt 0",
    "dt negative",
    "dt NaN",
    "dt inf",
    "dt 1e9",
    "dt text",
    "dt true",
    "dt missing",
    "dt half rate",
    "rate disagrees",
    "rate NaN",
    "control text",
    "joints object",
    "joints empty",
    "joint text",
    "joint name number",
    "mjcf joint renamed",
    "sign flipped",
    "sign 2",
    "sign true",
    "sign text",
    "unit deg",
    "stand NaN",
    "stand moved",
    "range empty",
    "range reversed",
    "range NaN",
    "range short",
    "range widened",
    "sensors list",
    "sensors size text",
    "sensors size off",
    "blocks reordered",
    "block unit",
    "foot sensors renamed",
    "robot renamed",
    "robot number",
    "source list",
]


@pytest.mark.parametrize("how", _EDITS)
def test_a_manifest_edited_by_hand_is_refused_in_one_line(export, tmp_path, how):
    from imitwalk.runtime import Controller

    bad = tmp_path / "bad"
    shutil.copytree(export, bad)
    path = bad / "manifest.json"
    m = json.loads(path.read_text())
    _edit(m, how)
    path.write_text(json.dumps(m))  # NaN and Infinity as json writes them
    with pytest.raises(RunError) as err:
        Controller.load(bad)
    msg = str(err.value)
    assert "\n" not in msg and _WORDS[how.split()[0]] in msg, msg


def test_an_export_another_mujoco_wrote_is_read_if_this_one_can(export, tmp_path, monkeypatch):
    """Another MuJoCo's export loads while this MuJoCo reads its model, and is refused in
    one line naming both versions once it does not."""
    import mujoco

    from imitwalk.robots import build
    from imitwalk.runtime import Controller

    other = tmp_path / "other"
    shutil.copytree(export, other)
    path = other / "manifest.json"
    m = json.loads(path.read_text())
    m["versions"]["mujoco"] = "3.1.0"
    path.write_text(json.dumps(m))
    Controller.load(other)

    def unreadable(_path):
        raise ValueError("Model and executable have different number of ints")

    monkeypatch.setattr(mujoco.MjModel, "from_binary_path", unreadable)
    monkeypatch.setattr(build, "_MODELS", {})
    with pytest.raises(RunError) as err:
        Controller.load(other)
    msg = str(err.value)
    assert "\n" not in msg and "MuJoCo 3.1.0" in msg and "install mujoco==3.1.0" in msg, msg


#: Values of every JSON type, and numbers a field should not take.
_JUNK = [None, True, "x", [], {}, -1, 0, 1e308, math.nan, [0.0, math.inf]]


def _leaves(m, at=()):
    """Every (path, value) of the manifest's fields, the first and last joint's only."""
    if isinstance(m, dict):
        for k, v in m.items():
            yield from _leaves(v, (*at, k))
    elif isinstance(m, list) and at == ("joints",):
        for i in (0, len(m) - 1):
            yield from _leaves(m[i], (*at, i))
    elif isinstance(m, list) and at == ("sensors", "blocks"):
        for i, b in enumerate(m):
            yield from _leaves(b, (*at, i))
    yield at, m


def test_any_junk_in_any_manifest_field_loads_or_is_a_run_error(export, tmp_path):
    """No field of the manifest, set to anything, reaches the user as another exception
    (ZeroDivisionError, AttributeError, TypeError...): the controller loads, and then
    walks to finite targets within the ranges, or the load is a one-line RunError."""
    from imitwalk.runtime import Controller

    m0 = json.loads((export / "manifest.json").read_text())
    leaves = [at for at, _ in _leaves(m0) if at and at[0] not in ("files", "format", "kind")]
    bad = tmp_path / "bad"
    shutil.copytree(export, bad)
    loaded = refused = 0
    for at in leaves:
        for junk in _JUNK:
            m = json.loads(json.dumps(m0))
            node = m
            for key in at[:-1]:
                node = node[key]
            node[at[-1]] = junk
            (bad / "manifest.json").write_text(json.dumps(m))
            try:
                ctl = Controller.load(bad)
            except RunError as exc:
                assert "\n" not in str(exc)
                refused += 1
                continue
            loaded += 1
            q = ctl.reset(_standing(ctl))
            assert np.isfinite(q).all() and ctl.dt == m0["control"]["dt_s"], (at, junk)
    assert loaded and refused


# -- 4. the targets stay within the ranges the manifest publishes --------------------


def _standing(ctl) -> np.ndarray:
    """The readings of the robot standing still on both feet ``(6 + 2k + n,)``."""
    s, k = ctl.sensors.slices(), ctl.sensors.sole_sensors
    v = np.zeros(ctl.sensors.size)
    v[s["accel"]] = [0.0, 0.0, 9.81]
    v[s["foot_force"]] = ctl.bundle.robot.total_mass * 9.81 / (2 * k)
    v[s["joints"]] = ctl.q0
    return v


@pytest.mark.parametrize("fault", ["upside down", "sideways", "joints far out"])
def test_targets_stay_within_the_manifests_ranges(export, fault):
    """Readings of a fallen or faulty robot (which drove the targets up to 0.87 rad past
    their ranges before): every target is within the manifest's range."""
    from imitwalk.runtime import Controller

    ctl = Controller.load(export)
    m = json.loads((export / "manifest.json").read_text())
    ranges = np.array([j["range"] for j in m["joints"]])
    assert np.array_equal(ctl.limits, ranges)
    s = ctl.sensors.slices()
    v = _standing(ctl)
    q = ctl.reset(v)
    if fault == "upside down":
        v[s["accel"]] = [0.0, 0.0, -9.81]
    elif fault == "sideways":
        v[s["accel"]] = [9.81, 0.0, 0.0]
    else:
        v[s["joints"]] = 100.0
    for _ in range(50):
        q = ctl.step(v)
        assert np.all((ranges[:, 0] <= q) & (q <= ranges[:, 1]))


def test_the_ranges_are_the_simulators_servo_ranges_and_its_plant_sends_the_targets_as_is(
    export, robot
):
    """The clamp is the one the simulator applies (the export's position servos' control
    ranges, in the joints' signs), so a simulated walk commands exactly the runtime's
    targets, tick for tick: clamping changes nothing the judge measured."""
    import mujoco

    from imitwalk.runtime import Controller
    from imitwalk.sim.mujoco import make_plant, run

    ctl = Controller.load(export)
    model = mujoco.MjModel.from_binary_path(str(export / "robot.mjb"))
    r = ctl.bundle.robot
    for name, sign, lim in zip(r.mj_joints, r.signs, ctl.limits, strict=True):
        j = model.joint(name).id
        (a,) = [a for a in range(model.nu) if model.actuator_trnid[a, 0] == j]
        assert model.actuator_ctrllimited[a]
        assert np.allclose(np.sort(model.actuator_ctrlrange[a] * sign), lim)
    sent = []

    def policy(k, obs):
        v = ctl.sensors.vector(obs)
        sent.append(ctl.reset(v) if k == 0 else ctl.step(v))
        return sent[-1]

    ro = run(make_plant(robot), policy, 100, q0=ctl.q0)
    assert np.array_equal(ro.q_cmd, np.array(sent[: len(ro.q_cmd)]))


def test_the_clamp_is_exactly_the_range(export, monkeypatch):
    """Targets beyond a range are sent as the range's end; those within, unchanged."""
    from imitwalk.runtime import Controller

    ctl = Controller.load(export)
    lo, hi = ctl.limits.T
    wild = np.where(np.arange(len(lo)) % 2 == 0, hi + 1.0, lo - 1.0)
    wild[0] = (lo[0] + hi[0]) / 2
    monkeypatch.setattr(ctl, "_policy", lambda k, obs: wild.copy())
    q = ctl.reset(_standing(ctl))
    want = np.where(np.arange(len(lo)) % 2 == 0, hi, lo)
    want[0] = wild[0]
    assert np.array_equal(q, want)


# -- 5. sensor readings: real numbers only, within a bound; a refused one is no tick --


def _bad_reading(ctl, how: str):
    v = _standing(ctl)
    n_joints0 = ctl.sensors.slices()["joints"].start
    if how == "complex array":
        return v.astype(complex) + 1j
    if how == "complex entry":
        out = list(v)
        out[1] = complex(0.0, 1.0)
        return out
    if how == "text array":
        return v.astype(str)
    if how == "text entry":
        out = list(v)
        out[n_joints0 + 3] = "0.5"
        return out
    if how == "bool array":
        return np.ones(ctl.sensors.size, dtype=bool)
    if how == "bool entry":
        out = list(v)
        out[n_joints0 + 3] = True
        return out
    if how == "None entry":
        out = np.array(list(v), dtype=object)
        out[4] = None
        return out
    if how == "Decimal entries":
        return [Decimal(str(x)) for x in v]
    if how == "huge foot force":
        v[ctl.sensors.slices()["foot_force"].start + 1] = 1e308
        return v
    if how == "huge int":
        out = list(v)
        out[0] = 10**400
        return out
    raise AssertionError(how)


@pytest.mark.parametrize(
    ("how", "word"),
    [
        ("complex array", "gyro[0]"),
        ("complex entry", "gyro[1]"),
        ("text array", "gyro[0]"),
        ("text entry", "joints[3]"),
        ("bool array", "gyro[0]"),
        ("bool entry", "joints[3]"),
        ("None entry", "accel[1]"),
        ("Decimal entries", "gyro[0]"),
        ("huge foot force", "foot_force[1]"),
        ("huge int", "gyro[0]"),
    ],
)
def test_a_reading_that_is_not_a_real_number_or_absurd_is_refused_in_one_line(
    export, how, word, recwarn
):
    from imitwalk.runtime import Controller

    ctl = Controller.load(export)
    ctl.reset(_standing(ctl))
    with pytest.raises(SensorError) as err:
        ctl.step(_bad_reading(ctl, how))
    msg = str(err.value)
    assert word in msg and "\n" not in msg, msg
    assert not [w for w in recwarn if issubclass(w.category, RuntimeWarning)]  # no overflow


def test_readings_of_any_real_type_are_taken(export):
    """Lists, tuples, float32, int and NumPy scalars all give the float64 vector's targets."""
    from imitwalk.runtime import Controller

    v = _standing(Controller.load(export))
    v[v == 0] = 1  # an int vector of the same readings
    v = np.round(v)
    outs = []
    for form in (
        v,
        list(v),
        tuple(v),
        v.astype(np.float32),
        v.astype(int),
        [np.float64(x) for x in v],
    ):
        ctl = Controller.load(export)
        outs.append(ctl.reset(form))
    assert all(np.array_equal(o, outs[0]) for o in outs)


def test_a_refused_reading_is_not_a_tick_and_changes_nothing(export):
    """20 good ticks, 5 refused ones, 10 good: the targets of an uninterrupted walk of
    30 good ticks, and the same tick count."""
    from imitwalk.runtime import Controller

    rng = np.random.default_rng(0)
    base = _standing(Controller.load(export))
    readings = [base + rng.normal(0, 0.01, base.size) for _ in range(31)]
    plain = Controller.load(export)
    want = [plain.reset(readings[0])] + [plain.step(r) for r in readings[1:]]
    ctl = Controller.load(export)
    got = [ctl.reset(readings[0])] + [ctl.step(r) for r in readings[1:21]]
    refused = [np.full(base.size, x) for x in (np.nan, np.inf, 1e308)] + ["x", None]
    for bad in refused:
        with pytest.raises(SensorError):
            ctl.step(bad)
    assert ctl._tick == 20
    got += [ctl.step(r) for r in readings[21:]]
    assert ctl._tick == plain._tick == 30
    assert all(np.array_equal(a, b) for a, b in zip(got, want, strict=True))


def test_a_refused_reset_leaves_the_controller_as_it_was(export):
    from imitwalk.runtime import Controller

    ctl = Controller.load(export)
    good = _standing(ctl)
    with pytest.raises(SensorError):
        ctl.reset(np.full(good.size, np.nan))
    with pytest.raises(SensorError, match="reset"):  # still not started
        ctl.step(good)
    ctl.reset(good)
    ctl.step(good)
    with pytest.raises(SensorError):
        ctl.reset([True] * good.size)
    assert ctl._tick == 1  # the walk goes on
