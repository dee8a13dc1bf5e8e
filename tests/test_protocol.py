"""Robustness protocols: shipped files, validation, and that every drawn range is real."""

from __future__ import annotations

import json

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from imitwalk.cli.main import main
from imitwalk.errors import ConfigError
from imitwalk.robots import load_robot
from imitwalk.sim.mujoco import MujocoPlant, SimOptions, make_plant
from imitwalk.sim.perturb import perturbed
from imitwalk.sim.protocol import FACTORS, PROTOCOLS, load_protocol


@pytest.fixture(scope="module")
def robot():
    return load_robot("hoap2")


def test_the_shipped_protocols_load_and_name_their_sources():
    assert {"eval", "hard", "bullet"} <= set(PROTOCOLS)
    for name in PROTOCOLS:
        p = load_protocol(name)
        assert p.name == name and p.version >= 1
        for factor, spec in p.factors.items():
            assert factor in FACTORS and spec["source"].strip()


def test_eval_draws_the_robots_figures_were_judged_on_before(robot):
    p = load_protocol("eval")
    for seed in range(40):
        assert p.draw(seed, robot).options == perturbed(seed, disturbance=seed != 0)
    assert load_protocol("bullet").engine == "bullet"
    assert load_protocol("bullet").draw(7, robot).options == p.draw(7, robot).options


def test_servo_draws_evals_robots_with_hards_servo_spread(robot):
    servo, ev = load_protocol("servo"), load_protocol("eval")
    assert servo.factors["servo"]["spread"] == load_protocol("hard").factors["servo"]["spread"]
    for seed in range(8):
        o, e = servo.draw(seed, robot).options, ev.draw(seed, robot).options
        same = ("friction", "mass_jitter", "init_twist")
        assert [getattr(o, k) for k in same] == [getattr(e, k) for k in same]
        assert o.kp_jitter == (0.2 if seed else e.kp_jitter)


def test_slope_draws_servos_robots_on_hards_slopes(robot):
    slope, servo = load_protocol("slope"), load_protocol("servo")
    hard = load_protocol("hard").factors["slope"]
    assert [slope.factors["slope"][k] for k in ("min_deg", "max_deg")] == [-3.0, 3.0]
    assert [hard[k] for k in ("min_deg", "max_deg")] == [-3.0, 3.0]
    for seed in range(8):
        o, s = slope.draw(seed, robot).options, servo.draw(seed, robot).options
        same = ("friction", "mass_jitter", "init_twist", "kp_jitter")
        assert [getattr(o, k) for k in same] == [getattr(s, k) for k in same]
        if seed == 0:  # the nominal robot stands on a flat floor
            assert o.slope_deg == 0.0
        else:
            assert -3.0 <= o.slope_deg <= 3.0 and o.slope_deg != 0.0


def test_hard_draws_cover_their_ranges(robot):
    p = load_protocol("hard")
    draws = [p.draw(s, robot, seconds=30.0) for s in range(40)]
    opts = [d.options for d in draws]
    friction = np.array([o.friction for o in opts])
    assert friction.min() >= 0.4 and friction.max() <= 1.5 and np.ptp(friction) > 0.7
    slope = np.array([o.slope_deg for o in opts])
    assert np.abs(slope).max() <= 3.0 and slope.min() < -1.5 < 1.5 < slope.max()
    delay = np.array([o.servo_delay for o in opts])
    assert delay.min() >= 0.0 and delay.max() <= 0.01 and np.ptp(delay) > 0.005
    shift = np.array([o.com_shift for o in opts])
    c = 0.025 * robot.height / 1.3
    assert np.abs(shift[:, :2]).max() <= c + 1e-12 and np.abs(shift[:, :2]).max() > 0.7 * c
    assert all(o.mass_jitter == 0.15 and o.kp_jitter == 0.20 for o in opts)
    assert all(o.gyro_noise == 0.05 and o.accel_noise == 0.2 for o in opts)
    top = 0.5 * np.sqrt(robot.height / 1.3)  # Froude-scaled: 0.31 m/s for hoap2
    for o in opts:
        t = np.array([k[0] for k in o.pushes])
        gaps = np.diff(np.r_[0.0, t])
        assert 3.0 - 1e-9 <= gaps.min() and gaps.max() <= 6.0 + 1e-9 and t.max() < 30.0
        speed = np.hypot(*np.array([k[1:] for k in o.pushes]).T)
        assert speed.max() <= top + 1e-12
    speeds = np.concatenate([np.hypot(*np.array([k[1:] for k in o.pushes]).T) for o in opts])
    assert speeds.max() > 0.9 * top
    for d in draws:  # every drawn factor has a percentile; the furthest is one of them
        assert set(d.deviation) <= set(FACTORS) and d.furthest in d.deviation
        assert all(0.0 <= v <= 1.0 for v in d.deviation.values())
    assert p.draw(3, robot) == p.draw(3, robot)  # a seed is one robot


def test_the_draws_reach_the_simulators(robot):
    """Friction, masses, servo stiffness and the torso's centre of mass are applied in
    MuJoCo; friction and the shift in Bullet too."""
    o = load_protocol("hard").draw(5, robot).options
    m = MujocoPlant(robot, o).model
    base = MujocoPlant(robot, SimOptions()).model
    assert np.allclose(m.geom_friction[:, 0], o.friction)
    assert not np.allclose(m.body_mass, base.body_mass)
    assert not np.allclose(m.actuator_gainprm[:, 0], base.actuator_gainprm[:, 0])
    torso = m.body(robot.torso).id
    assert np.allclose(m.body_ipos[torso] - base.body_ipos[torso], o.com_shift)
    import pybullet as pb

    b = make_plant(robot, o, "bullet")
    link = b._link_of_body[torso]
    mu = pb.getDynamicsInfo(b.body, link, physicsClientId=b.client)[1]
    assert mu == pytest.approx(o.friction)


def _write(tmp_path, data) -> str:
    path = tmp_path / "p.json"
    path.write_text(json.dumps(data))
    return str(path)


def _hard(**factors) -> dict:
    data = load_protocol("hard").to_dict()
    data["factors"] = {**data["factors"], **factors}
    return data


PUSH = {"every_min_s": 3, "every_max_s": 6, "max_speed": 0.5, "at_height_m": 1.3, "source": "x"}


@pytest.mark.parametrize(
    "change, message",
    [
        ({"nosuch": 1}, r"unknown key in protocol .*'nosuch'; valid: description"),
        (
            {"factors": {"windy": {"source": "x"}}},
            r"unknown factor in protocol .*'windy'; valid: .*friction",
        ),
        (
            {"factors": {"friction": {"min": 1.2, "max": 0.5, "nominal": 1, "source": "x"}}},
            r"friction: min 1.2 is above max 0.5",
        ),
        (
            {"factors": {"pushes": {**PUSH, "max_speed": -0.5}}},
            r"pushes.max_speed is negative",
        ),
        ({"factors": {"mass": {"spread": 0.1}}}, r"factor 'mass' lacks 'source'"),
        ({"factors": {"mass": {"spread": "big", "source": "x"}}}, r"mass.spread must be a finite"),
    ],
)
def test_bad_protocol_files_get_one_line(tmp_path, change, message):
    data = {"name": "mine", "factors": {}}
    data.update(change)
    with pytest.raises(ConfigError, match=message) as info:
        load_protocol(_write(tmp_path, data))
    assert "\n" not in str(info.value)


def test_an_unknown_protocol_lists_the_shipped_ones():
    with pytest.raises(
        ConfigError, match=r"unknown protocol 'harder'; valid: bullet, cross, eval, hard"
    ):
        load_protocol("harder")


def test_a_users_protocol_file_works_as_a_shipped_one(tmp_path, robot):
    path = _write(tmp_path, _hard())
    assert load_protocol(path).draw(4, robot) == load_protocol("hard").draw(4, robot)


@pytest.mark.parametrize(
    "protocol, expect",
    [("nosuch", "unknown protocol 'nosuch'"), ("bad.json", "protocol file not found")],
)
def test_cli_bad_protocol_exits_2(tmp_path, capsys, protocol, expect):
    run = tmp_path / "run"
    run.mkdir()
    (run / "config.json").write_text('{"learn": {}, "robot": "hoap2"}')
    assert main(["evaluate", str(run), "--protocol", protocol]) == 2
    err = capsys.readouterr().err
    assert expect in err and "Traceback" not in err and len(err.strip().splitlines()) == 1


#: The options each factor of a protocol sets (the rest stay as drawn without it).
FIELDS = {
    "friction": ("friction",),
    "mass": ("mass_jitter",),
    "servo": ("kp_jitter",),
    "torso_com": ("com_shift",),
    "gyro_noise": ("gyro_noise",),
    "accel_noise": ("accel_noise",),
    "servo_delay": ("servo_delay",),
    "slope": ("slope_deg",),
    "cross_slope": ("cross_slope_deg",),
    "pushes": ("pushes",),
    "initial_twist": ("init_twist",),
}


@settings(max_examples=15, deadline=None)
@given(seed=st.integers(1, 10**6), name=st.sampled_from(["eval", "hard"]))
def test_a_factor_left_out_is_nominal_and_every_other_is_drawn_as_before(robot, seed, name):
    """What ``evaluate --explain-falls`` relies on: ``only`` without one factor draws
    the same robot but for that factor, which is at nominal."""
    from dataclasses import fields

    protocol = load_protocol(name)
    full = protocol.draw(seed, robot, seconds=12.0).options
    nominal = SimOptions()
    for factor in protocol.factors:
        rest = [f for f in protocol.factors if f != factor]
        less = protocol.only(rest).draw(seed, robot, seconds=12.0).options
        for f in fields(SimOptions):
            want = getattr(nominal if f.name in FIELDS[factor] else full, f.name)
            assert getattr(less, f.name) == want, (factor, f.name)


@settings(max_examples=30, deadline=None)
@given(*[st.floats(-10, 10).filter(lambda x: x == 0 or abs(x) > 1e-9)] * 2)
def test_gravity_tilts_both_ways_and_is_unchanged_without_a_cross_slope(sx, sy):
    """The floor is the plane z = 0 and gravity leans: a floor rising along +x (or +y)
    pulls the robot back along -x (or -y) (slopes below 1e-9 deg are left out: their
    component rounds to zero)."""
    from imitwalk.sim.types import gravity

    g = gravity(SimOptions(slope_deg=sx, cross_slope_deg=sy))
    assert np.isclose(np.linalg.norm(g), 9.81) and g[2] < 0
    assert np.sign(g[0]) == -np.sign(sx) and np.sign(g[1]) == -np.sign(sy)
    th, ph = np.deg2rad(sx), np.deg2rad(sy)
    assert np.array_equal(
        gravity(SimOptions(slope_deg=sx)), 9.81 * np.array([-np.sin(th), 0.0, -np.cos(th)])
    )
    across = gravity(SimOptions(cross_slope_deg=sy))
    assert np.allclose(across, 9.81 * np.array([0.0, -np.sin(ph), -np.cos(ph)]))


def test_cross_draws_evals_robots_on_floors_sloped_across(robot):
    cross, ev = load_protocol("cross"), load_protocol("eval")
    for seed in range(1, 8):
        o, e = cross.draw(seed, robot).options, ev.draw(seed, robot).options
        assert -3.0 <= o.cross_slope_deg <= 3.0 and o.cross_slope_deg != 0.0
        assert o.slope_deg == 0.0 and o.friction == e.friction
    assert cross.draw(0, robot).options.cross_slope_deg == 0.0
