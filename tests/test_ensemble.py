"""The bootstrap ensemble of step models and the search that trusts only what all agree on."""

from __future__ import annotations

import numpy as np
import pytest

from imitwalk.balance import STEP_CHANNELS, STEP_STATE, StepConfig, StepController
from imitwalk.ensemble import ModelEnsemble
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


def _decide(model, pitches) -> np.ndarray:
    """Channel decisions ``(K, 5)`` for steps starting at the given torso pitches."""
    cfg = StepConfig(weights=(0, 1, 0, 0, 0, 0, 0, 0), effort=0.0, horizon=1, candidates=400)
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


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_no_member_expects_the_chosen_channels_to_do_worse_than_none(seed):
    rng = np.random.default_rng(seed)
    noise = _episodes(rng, 0.0, 0.03, n=6)  # the channels do nothing; few, noisy steps
    ens = ModelEnsemble(n_members=5, ridge=1e-2, **PARAMS).fit(noise)
    cfg = StepConfig(weights=(0, 1, 0, 0, 0, 0, 0, 0), effort=0.0, horizon=2, candidates=100)
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
