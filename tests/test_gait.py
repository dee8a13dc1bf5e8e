"""The gait representation: with the residual, the nominal action is the reference itself."""

from __future__ import annotations

import numpy as np
import pytest

from imitwalk.paper.gait import GaitConfig, GaitModel


@pytest.mark.parametrize("phase_source", ["time", "angle"])
def test_the_nominal_action_reproduces_the_reference_with_the_residual(
    tiny_reference, phase_source
):
    ref, _ = tiny_reference
    scales = (0.3, 0.4)
    exact = GaitModel(ref, scales, GaitConfig(3, phase_source, residual=True))
    truncated = GaitModel(ref, scales, GaitConfig(3, phase_source, residual=False))
    for s in scales:
        loop = ref.at_scale(s)[1]
        for i in range(0, len(loop), 7):
            a = exact.nominal_action(s, i)
            assert np.allclose(exact.joints(s, a), loop[i], atol=1e-9)
            # without it, the posture is the representation's reconstruction (k = 3)
            assert np.allclose(truncated.joints(s, a), loop[i] - exact.residuals[s][i])
        # the next cycle's phase gives the same posture
        a = exact.nominal_action(s, len(loop) + 3)
        assert np.allclose(exact.joints(s, a), loop[3], atol=1e-9)


def test_the_residual_is_continuous_between_ticks(tiny_reference):
    ref, _ = tiny_reference
    gm = GaitModel(ref, (0.4,), GaitConfig(3, "time", residual=True))
    nom = gm.nominal[0.4]
    n = len(nom)
    for i in (0, n // 2, n - 1):
        lo, hi = gm._residual_at(0.4, nom[i, 0]), gm._residual_at(0.4, nom[i, 0] + 1e-9)
        assert np.allclose(lo, hi, atol=1e-6)
    mid = gm._residual_at(0.4, 0.5 * (nom[4, 0] + nom[5, 0]))
    assert np.allclose(mid, 0.5 * (gm.residuals[0.4][4] + gm.residuals[0.4][5]), atol=1e-9)


def test_the_residual_follows_the_tick_where_the_phase_runs_backwards(tiny_reference):
    ref, _ = tiny_reference
    gm = GaitModel(ref, (0.4,), GaitConfig(3, "time", residual=True))
    res = gm.residuals[0.4]
    n = len(res)
    assert not gm._by_tick[0.4].any()  # a monotone phase: looked up by φ, as before
    # make φ run backwards over ticks 10-12 (as the time phase's fit can at full scale)
    nom = gm.nominal[0.4]
    nom[10:13, 0] = nom[9, 0] - 0.5 * (nom[10:13, 0] - nom[9, 0])
    gm._index_phase(0.4)
    assert gm._by_tick[0.4][10:13].all()
    wrong = [i for i in range(n) if not np.allclose(gm._residual_at(0.4, nom[i, 0]), res[i])]
    assert wrong  # by φ alone, some ticks find another tick's residual
    for cycle in range(3):
        for i in range(n):
            t = i + cycle * n
            phi = gm.nominal_action(0.4, t)[0]
            assert np.allclose(gm._residual_at(0.4, phi, t), res[i], atol=1e-9)
