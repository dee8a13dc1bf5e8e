"""Where the next foot lands and when: step location and timing adaptation (pure NumPy).

Re-solved at every control tick from the measured DCM, after Khadiv, Herzog, Moosavian
and Righetti, "Walking control based on step timing adaptation" (T-RO 2020), with the
stance foot's ZMP as a third choice: the next footstep ``u``, the time left to
touchdown ``Δ`` and a constant shift ``δ`` of the ZMP within the stance sole for the
rest of the step are chosen to minimise

    w_zmp |δ (e^{ωΔ} − 1)|² + w_step |u − u_nom|² + w_offset |ξ(Δ) − u − b_nom|²
        + w_time (T − T_nom)²,

where the DCM at touchdown follows from the DCM now in closed form
(:func:`~imitwalk.step.lipm.dcm_after`: ``ξ(Δ) = ξ_nom(Δ) + δ (1 − e^{ωΔ})``), ``b_nom`` is
the nominal DCM offset at touchdown (:class:`~imitwalk.step.lipm.NominalGait`), ``u`` is
boxed by the leg's reach, the feet kept apart and how far the swing foot can still
travel in ``Δ``, and ``δ`` by the sole. The ZMP shift is charged by what it moves the
DCM at touchdown, so that a DCM error is shared between the ankles and the step in the
ratio of their weights whatever the step's length, until the ZMP reaches the sole's
edge. Khadiv et al. fix the ZMP at the sole's centre and write the time as
``τ = e^{ωΔ}`` to keep a quadratic program; a slow walk on a small robot (``e^{ωT}``
near 20 on hoap2) needs the ankles' share, or every millimetre of DCM error at lift-off
moves the step by centimetres. Here the time is searched on a grid
and, for each time, the two-variable box-constrained quadratic per axis is solved by
exact coordinate descent (a few sweeps, vectorised over the grid).

Everything is in the stance foot's frame: origin at its sole centre, x along its
heading, y to its left.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from imitwalk.step.lipm import NominalGait, dcm_after

__all__ = ["StepChoice", "StepLimits", "StepWeights", "plan_step"]


@dataclass(frozen=True)
class StepLimits:
    """Where and when a step may land, relative to the stance foot.

    Attributes:
        forward, backward: the farthest landing ahead of and behind the stance foot [m]
            (both ≥ 0); inner, outer: the least and largest lateral distance between the
            feet [m] (the feet never cross); ss_min, ss_max: the shortest and longest
            single support [s]; swing_speed: the swing foot's top horizontal speed [m/s].
    """

    forward: float
    backward: float
    inner: float
    outer: float
    ss_min: float
    ss_max: float
    swing_speed: float


@dataclass(frozen=True)
class StepWeights:
    """The cost's weights (see the module doc): ``step``, ``offset``, ``zmp`` [1/m²] and
    ``time`` [1/s²]. Only their ratios matter."""

    step: float
    offset: float
    time: float
    zmp: float


@dataclass(frozen=True)
class StepChoice:
    """The planner's answer at one tick.

    Attributes:
        landing: ``(2,)`` where the swing foot lands [m]; remaining: time to its
        touchdown [s]; ss: the whole single support this gives [s]; xi_end: ``(2,)``
        the DCM predicted at touchdown [m]; offset_error: ``(2,)`` that DCM's offset from
        the landing point less the nominal offset [m]; zmp_shift: ``(2,)`` the ZMP's
        shift within the sole for the rest of the step [m].
    """

    landing: np.ndarray
    remaining: float
    ss: float
    xi_end: np.ndarray
    offset_error: np.ndarray
    zmp_shift: np.ndarray


def _clip(x: np.ndarray, lo: float | np.ndarray, hi: float | np.ndarray) -> np.ndarray:
    """``np.clip(x, lo, hi)``, the same numbers at a fifth of its call overhead."""
    return np.minimum(np.maximum(x, lo), hi)


def plan_step(
    xi: np.ndarray,
    side: float,
    gait: NominalGait,
    limits: StepLimits,
    weights: StepWeights,
    *,
    elapsed: float,
    zmp_now: np.ndarray,
    swing_at: np.ndarray,
    nominal_step: np.ndarray,
    offset: np.ndarray,
    zmp_box: tuple[np.ndarray, np.ndarray],
    grid: int = 24,
    sweeps: int = 6,
) -> StepChoice:
    """The next footstep and its timing.

    Args:
        xi: ``(2,)`` the measured DCM [m]; side: the stance foot's side (+1 left, −1
            right); gait: the nominal walk (its ZMP points and timing).
        limits, weights: the constraints and the cost.
        elapsed: time spent in single support [s].
        zmp_now: ``(2,)`` the planned ZMP now [m]; swing_at: ``(2,)`` the swing foot
            now [m]; nominal_step: ``(2,)`` the nominal landing [m]; offset: ``(2,)`` the
            nominal DCM offset at touchdown, relative to the landing foot [m].
        zmp_box: ``((2,), (2,))`` the least and largest ZMP shift that keeps the ZMP
            plan within the sole for the rest of the step [m].
        grid: single-support durations tried; sweeps: coordinate-descent sweeps.
    """
    _, _, toe = gait.zmp_points(side)
    lo = max(limits.ss_min - elapsed, 0.01)
    hi = max(limits.ss_max - elapsed, lo)
    left = np.linspace(lo, hi, grid)  # (G,) time to touchdown
    xi_end = dcm_after(xi, zmp_now, toe, left, gait.omega)  # (G, 2)
    ss = elapsed + left
    # the box: the leg's reach, no crossing, and what the swing foot can still travel
    lateral = -side  # the swing foot lands on the other side
    y_lo, y_hi = (limits.inner, limits.outer) if lateral > 0 else (-limits.outer, -limits.inner)
    reach = limits.swing_speed * left[:, None]
    box_lo = np.maximum(np.array([-limits.backward, y_lo]), swing_at - reach)
    box_hi = np.minimum(np.array([limits.forward, y_hi]), swing_at + reach)
    box_hi = np.maximum(box_hi, box_lo)
    ws, wo, wz = weights.step, weights.offset, weights.zmp
    gain = 1.0 - np.exp(gait.omega * left)[:, None]  # (G, 1): dξ(Δ)/dδ
    z_lo, z_hi = zmp_box
    delta = np.zeros_like(xi_end)
    u = _clip(nominal_step, box_lo, box_hi)
    for _ in range(sweeps):  # exact minimisation over each variable in turn
        rest = xi_end - u - offset  # the offset error without the ZMP shift
        delta = _clip(-wo * rest / ((wz + wo) * gain), z_lo, z_hi)
        reach_end = xi_end + gain * delta
        u = _clip((ws * nominal_step + wo * (reach_end - offset)) / (ws + wo), box_lo, box_hi)
    end = xi_end + gain * delta
    err = end - u - offset
    cost = (
        wz * np.sum((gain * delta) ** 2, axis=1)
        + ws * np.sum((u - nominal_step) ** 2, axis=1)
        + wo * np.sum(err**2, axis=1)
        + weights.time * (ss - gait.ss) ** 2
    )
    k = int(np.argmin(cost))
    return StepChoice(
        u[k].copy(), float(left[k]), float(ss[k]), end[k].copy(), err[k].copy(), delta[k].copy()
    )
