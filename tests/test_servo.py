"""The implicit servo of the Bullet plant, on a one-joint model (pure NumPy)."""

import numpy as np

from imitwalk.sim.servo import StablePD


def _simulate(torque_fn, inertia: float, load: float, dt: float, steps: int) -> np.ndarray:
    """A joint of inertia ``inertia`` [kg m²] under a constant load torque [Nm],
    semi-implicit Euler; returns its angle at every step."""
    q = qd = 0.0
    out = []
    for _ in range(steps):
        tau = torque_fn(q, qd)
        qd += dt * (tau + load) / inertia
        q += dt * qd
        out.append(q)
    return np.array(out)


def test_stable_where_explicit_pd_diverges_and_keeps_static_stiffness():
    kp, kd, inertia, dt, load, target = 2.0, 0.1, 6e-6, 2e-4, -0.01, 0.2
    assert kd * dt / inertia > 2.0  # an explicit PD is unstable here
    servo = StablePD(np.array([kp]), np.array([kd]), np.array([5.0]), dt)
    mjj = np.array([inertia])

    def implicit(q, qd):
        return float(servo.torque(np.array([target]), np.array([q]), np.array([qd]), mjj)[0])

    def explicit(q, qd):
        return kp * (target - q) - kd * qd

    q_imp = _simulate(implicit, inertia, load, dt, 4000)
    with np.errstate(over="ignore", invalid="ignore"):
        q_exp = _simulate(explicit, inertia, load, dt, 400)
    assert not np.all(np.isfinite(q_exp)) or np.abs(q_exp).max() > 1e3
    assert np.all(np.isfinite(q_imp)) and np.abs(q_imp).max() < 1.0
    # at rest the servo balances the load with kp · error: the static stiffness is kp
    np.testing.assert_allclose(q_imp[-1], target + load / kp, atol=1e-6)


def test_torque_is_clipped_and_reset_forgets():
    servo = StablePD(np.array([40.0, 40.0]), np.array([0.1, 0.1]), np.array([1.0, 2.0]), 2e-4)
    tau = servo.torque(np.array([1.0, -1.0]), np.zeros(2), np.zeros(2), np.array([1e-3, 1e-3]))
    np.testing.assert_array_equal(tau, [1.0, -2.0])
    servo.reset()
    np.testing.assert_array_equal(servo.tau, 0.0)
