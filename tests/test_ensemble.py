"""The bootstrap ensemble of step models and the search that trusts only what all agree on."""

from __future__ import annotations

import numpy as np
import pytest

from imitwalk.balance import STEP_CHANNELS, STEP_STATE, StepConfig, StepController
from imitwalk.ensemble import ModelEnsemble
from imitwalk.errors import ConfigError
from imitwalk.predictor import SensoryMotorModel

PARAMS = {"angle_action": False, "linear": True, "n_centers": 4}
C_MAX = np.asarray(StepConfig().c_max)


def _episodes(rng, gain: float, noise: float, n: int = 16):
    """Steps where next pitch = pitch + gain × lean + noise; other dims are noise."""
    eps = []
    for _ in range(n):
        a = np.c_[rng.uniform(-1, 1, (30, len(STEP_CHANNELS))) * C_MAX, np.ones(30)]
        s = rng.normal(0, noise, (30, len(STEP_STATE)))
        for k in range(29):
            s[k + 1, 1] = s[k, 1] + gain * a[k, 4] + rng.normal(0, noise)
        eps.append((s, a))
    return eps


def test_an_ensemble_of_one_is_the_model_on_all_the_data():
    eps = _episodes(np.random.default_rng(0), 5.0, 0.01)
    one = ModelEnsemble(n_members=1, random_state=3, ridge=1e-3, **PARAMS).fit(eps)
    model = SensoryMotorModel(random_state=3, ridge=1e-3, **PARAMS).fit(eps)
    s, a = eps[0]
    seq = a[None, 2:4]
    assert np.allclose(one.rollout(s[1], s[0], seq, a[1]), model.rollout(s[1], s[0], seq, a[1]))
    assert one.evaluate(eps).overall_ratio == pytest.approx(model.evaluate(eps).overall_ratio)


def test_members_differ_and_their_mean_is_the_rollout():
    eps = _episodes(np.random.default_rng(1), 5.0, 0.02)
    ens = ModelEnsemble(n_members=4, random_state=0, ridge=1e-3, **PARAMS).fit(eps)
    s, a = eps[0]
    seq = a[None, 2:4]
    members = ens.rollout_members(s[1], s[0], seq, a[1])
    assert members.shape == (4, 1, 2, len(STEP_STATE))
    assert np.ptp(members, axis=0).max() > 0.0
    assert np.allclose(members.mean(axis=0), ens.rollout(s[1], s[0], seq, a[1]))


def _decide(model, pitches, margin: float = 0.0, gain: float = 1.0) -> np.ndarray:
    """Channel decisions ``(K, 5)`` for steps starting at the given torso pitches."""
    cfg = StepConfig(
        weights=(0, 1, 0, 0, 0, 0, 0, 0),
        effort=0.0,
        horizon=1,
        candidates=400,
        margin=margin,
        gain=gain,
    )
    ctrl = StepController(cfg, 100, 0.1, model=model)
    out = []
    for k, p in enumerate(pitches):
        state = np.zeros(len(STEP_STATE))
        state[1] = p
        out.append(ctrl.decide(state, k))
    return np.array(out)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_where_all_members_agree_the_ensemble_acts_as_one_model(seed):
    eps = _episodes(np.random.default_rng(seed), 5.0, 0.0)
    ens = ModelEnsemble(n_members=5, ridge=1e-6, **PARAMS).fit(eps)
    c = _decide(ens, [0.0, -0.03])[-1]  # leaning back: lean forward by 6 mm to level out
    assert c[4] == pytest.approx(0.006, abs=0.0015)
    # a clear predicted gain clears a margin; a level torso (nothing to gain) does not act
    assert _decide(ens, [0.0, -0.03], margin=0.5)[-1][4] == pytest.approx(c[4])
    assert not np.any(_decide(ens, [0.0, 0.0, 0.0], margin=0.5)[1:])
    # the gain scales what the search chose; 0 turns the corrections off
    assert np.allclose(_decide(ens, [0.0, -0.03], gain=0.5)[-1], 0.5 * c)
    assert not np.any(_decide(ens, [0.0, -0.03, 0.02], gain=0.0))


@pytest.mark.parametrize(("seed", "margin"), [(0, 0.0), (1, 0.0), (2, 0.0), (0, 0.1), (1, 0.3)])
def test_no_member_expects_the_chosen_channels_to_do_worse_than_none(seed, margin):
    """Every member predicts the chosen channels gain at least ``margin`` of the zero
    channels' mean predicted cost (0: at least do no worse)."""
    rng = np.random.default_rng(seed)
    noise = _episodes(rng, 0.0, 0.03, n=6)  # the channels do nothing; few, noisy steps
    ens = ModelEnsemble(n_members=5, ridge=1e-2, **PARAMS).fit(noise)
    cfg = StepConfig(
        weights=(0, 1, 0, 0, 0, 0, 0, 0), effort=0.0, horizon=2, candidates=100, margin=margin
    )
    ctrl = StepController(cfg, 100, 0.1, model=ens)
    for k, p in enumerate(rng.normal(0.0, 0.03, 12)):
        state = np.zeros(len(STEP_STATE))
        state[1] = p
        c = ctrl.decide(state, k)
        if k < 1:
            continue
        seq = np.zeros((2, 2, len(STEP_CHANNELS) + 1))
        seq[:, :, -1] = 1.0
        seq[0, 0, :-1] = c
        s_prev, c_prev = ctrl.states[-2], np.r_[ctrl.actions[-2], 1.0]
        pred = ens.rollout_members(ctrl.states[-1], s_prev, seq, c_prev)  # (E, 2, H, ds)
        cost = (pred[..., 1] ** 2).sum(axis=-1)  # (E, 2): chosen, zero
        assert np.all(cost[:, 0] <= cost[:, 1] + 1e-12)
        if np.any(c):
            assert np.all(cost[:, 0] - cost[:, 1] <= -margin * cost[:, 1].mean() + 1e-12)


@pytest.mark.parametrize("margin", [-0.1, 1.0, 2.0])
def test_a_margin_outside_0_1_is_refused_with_its_range(margin):
    with pytest.raises(ConfigError, match="0 <= margin < 1"):
        StepConfig(margin=margin)


@pytest.mark.parametrize("gain", [-0.5, 2.5])
def test_a_gain_outside_0_2_is_refused_with_its_range(gain):
    with pytest.raises(ConfigError, match="0 <= gain <= 2"):
        StepConfig(gain=gain)
