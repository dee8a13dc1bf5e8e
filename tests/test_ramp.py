"""``step.ramp_scale``: the step model's stride-scale input follows the start-up's stride."""

from __future__ import annotations

import numpy as np
import pytest

from imitwalk.balance import STEP_CHANNELS, STEP_STATE, StepConfig, StepController


class _Spy:
    """A step model that predicts the state unchanged and records the scales it is shown."""

    def __init__(self):
        self.seen: list[np.ndarray] = []
        self.prev: list[float] = []

    def rollout_members(self, s, s_prev, seq, c_prev):
        self.seen.append(np.array(seq[0, :, -1]))
        self.prev.append(float(c_prev[-1]))
        return np.broadcast_to(s, (1, len(seq), seq.shape[1], len(s))).copy()


@pytest.mark.parametrize("ramp", [None, np.array([0.1, 0.5, 0.9])])
def test_start_up_steps_are_labelled_with_their_stride(ramp):
    spy = _Spy()
    cfg = StepConfig(horizon=2, candidates=8)
    ctrl = StepController(cfg, 100, 0.1, model=spy, scale=0.8, ramp=ramp)
    for k in range(6):
        ctrl.decide(np.zeros(len(STEP_STATE)), k)
    _, actions = ctrl.episode()
    assert actions.shape == (6, len(STEP_CHANNELS) + 1)
    want = np.full(6, 0.8) if ramp is None else 0.8 * np.array([0.1, 0.5, 0.9, 1, 1, 1])
    np.testing.assert_allclose(actions[:, -1], want)
    # the search (from step 1 on) sees the same labels: the previous step's, and the
    # horizon's from the step being decided on
    np.testing.assert_allclose(spy.prev, want[:5])
    for k, seen in enumerate(spy.seen, start=1):
        np.testing.assert_allclose(seen, [want[k], want[k + 1] if k + 1 < 6 else 0.8])


def test_startup_ramp_grows_to_a_steady_step(tiny_reference):
    from imitwalk.gait import GaitConfig, GaitModel
    from imitwalk.policy import startup_ramp, step_clock0

    ref, _ = tiny_reference
    gait = GaitModel(ref, [0.3, 0.4], GaitConfig())
    for scale in (0.3, 0.35, 0.4):
        ramp = startup_ramp(gait, scale)
        n_start = ref.starts.shape[1]
        # one value per step that begins in the start-up
        assert len(ramp) == np.ceil((n_start - step_clock0(gait)) / (gait.n_ticks / 2))
        assert np.all(np.diff(ramp) >= -1e-9) and np.all((ramp >= 0) & (ramp <= 1))
        assert ramp[0] < 0.2 and ramp[-1] == pytest.approx(1.0, abs=0.01)


@pytest.mark.parametrize("on", [False, True])
def test_the_option_reaches_the_step_controller(tiny_reference, robot, on):
    from imitwalk.config import apply_overrides
    from imitwalk.gait import GaitModel
    from imitwalk.learnconfig import preset
    from imitwalk.models import Models, build_policy
    from imitwalk.policy import startup_ramp

    ref, _ = tiny_reference
    cfg = apply_overrides(preset("extended"), [f"step.ramp_scale={str(on).lower()}"])
    gait = GaitModel(ref, [0.3, 0.4], cfg.gait)
    policy = build_policy(gait, 0.4, cfg, Models(), robot=robot)
    want = startup_ramp(gait, 0.4) if on else np.ones(0)
    np.testing.assert_allclose(policy.steps.ramp, want)
