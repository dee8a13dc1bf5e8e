"""The linear inverted pendulum and its divergent component of motion (pure NumPy).

The centre of mass ``c`` (horizontal, ``(2,)`` [m]) of a robot walking at a constant
height ``z_c`` moves as ``c̈ = ω² (c − p)`` with ``ω = sqrt(g / z_c)`` and ``p`` the zero
moment point (ZMP, the centre of pressure on flat ground). Its divergent component of
motion (DCM, the instantaneous capture point) ``ξ = c + ċ / ω`` obeys the first-order
``ξ̇ = ω (ξ − p)``: the DCM runs away from the ZMP, and the centre of mass follows the
DCM, ``ċ = ω (ξ − c)`` (Englsberger, Ott & Albu-Schäffer, T-RO 2015, eqs. 5–9).

Every ZMP path used here is piecewise linear in time, for which the DCM has a closed
form: with ``p(s) = p₀ + ṗ s`` over ``[0, h]``,

    ξ(h) = p(h) + ṗ / ω + (ξ(0) − p₀ − ṗ / ω) e^{ω h}.

:class:`NominalGait` is the periodic walk of a step length, width and timing, with the
ZMP rolling from heel to toe in single support and across to the next foot in double
support; its DCM at each touchdown, relative to the foot that lands, is the offset the
footstep planner aims the next step at (:mod:`imitwalk.step.planner`; Khadiv et al.,
T-RO 2020, "b" in their eq. 12).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["GRAVITY", "NominalGait", "dcm_after", "lipm_step", "omega_of"]

#: Standard gravity [m/s²].
GRAVITY = 9.81


def omega_of(com_height: float) -> float:
    """The pendulum's natural frequency ``ω = sqrt(g / z_c)`` [1/s] for a centre of mass
    ``com_height`` [m] above the ground."""
    if not com_height > 0:
        raise ValueError(f"centre-of-mass height {com_height!r}: expected > 0 m")
    return float(np.sqrt(GRAVITY / com_height))


def dcm_after(
    xi: np.ndarray,
    p_from: np.ndarray,
    p_to: np.ndarray,
    duration: float | np.ndarray,
    omega: float,
) -> np.ndarray:
    """The DCM after ``duration`` [s] while the ZMP moves linearly from ``p_from`` to
    ``p_to`` (closed form, see the module doc).

    Args:
        xi: ``(..., 2)`` the DCM now [m]; p_from, p_to: ``(..., 2)`` the ZMP now and at the
            end [m]; duration: ``(...)`` or scalar, > 0 [s]; omega: [1/s].

    Returns:
        ``(..., 2)`` the DCM at the end [m].
    """
    h = np.asarray(duration, dtype=float)[..., None]
    slope = (np.asarray(p_to) - np.asarray(p_from)) / np.maximum(h, 1e-9) / omega  # ṗ/ω
    return p_to + slope + (xi - p_from - slope) * np.exp(omega * h)


def dcm_before(
    xi_end: np.ndarray,
    p_from: np.ndarray,
    p_to: np.ndarray,
    duration: float | np.ndarray,
    omega: float,
) -> np.ndarray:
    """The DCM at the start of a linear ZMP segment that ends at ``xi_end``: the inverse
    of :func:`dcm_after` (the backward recursion of the DCM plan)."""
    h = np.asarray(duration, dtype=float)[..., None]
    slope = (np.asarray(p_to) - np.asarray(p_from)) / np.maximum(h, 1e-9) / omega
    return p_from + slope + (xi_end - p_to - slope) * np.exp(-omega * h)


def lipm_step(
    c: np.ndarray, v: np.ndarray, p: np.ndarray, dt: float, omega: float
) -> tuple[np.ndarray, np.ndarray]:
    """The centre of mass after ``dt`` [s] with the ZMP held at ``p`` (exact).

    Args:
        c, v: ``(2,)`` position [m] and velocity [m/s]; p: ``(2,)`` ZMP [m].

    Returns:
        ``(c, v)`` after ``dt``.
    """
    ch, sh = np.cosh(omega * dt), np.sinh(omega * dt)
    d = c - p
    return p + d * ch + v * sh / omega, d * omega * sh + v * ch


@dataclass(frozen=True)
class NominalGait:
    """The periodic walk the footstep planner adapts (relative to the stance foot).

    Each step starts at a touchdown: for ``ds`` [s] the ZMP moves from the previous
    foot's toe point to the new stance foot's heel point (double support), then for
    ``ss`` [s] from that heel point to its toe point (single support). The feet are
    ``step`` [m] apart along the walk and ``width`` [m] across it.

    Attributes:
        step: forward distance between successive feet [m]; width: lateral distance
            between them [m]; ss, ds: single- and double-support time [s];
        heel, toe: the ZMP's heel and toe points behind and ahead of the sole centre [m]
            (both ≥ 0); inward: the ZMP sits this far inside the sole centre [m];
        omega: [1/s].
    """

    step: float
    width: float
    ss: float
    ds: float
    heel: float
    toe: float
    inward: float
    omega: float

    def zmp_points(self, side: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The previous foot's toe point, this foot's heel and toe points ``(2,)`` [m],
        relative to this stance foot, for a stance foot on ``side`` (+1 left, −1 right)."""
        inner = -side * self.inward  # towards the body's midline
        prev_toe = np.array([-self.step + self.toe, -side * self.width - inner])
        heel = np.array([-self.heel, inner])
        toe = np.array([self.toe, inner])
        return prev_toe, heel, toe

    def dcm_at_touchdown(self, side: float) -> np.ndarray:
        """``(2,)`` the periodic DCM at the start of a step [m], relative to the foot that
        lands (on ``side``): the backward recursion over steps ahead, each segment in
        closed form, started at the far end from the ZMP (its weight is ``e^{−ω·6T}``)."""
        xi = None
        steps = 6
        # walk back from `steps` steps ahead; step k's foot sits at k × (step, ±width)
        for k in range(steps, -1, -1):
            s = side if k % 2 == 0 else -side
            origin = np.array([k * self.step, 0.0 if k % 2 == 0 else -side * self.width])
            prev_toe, heel, toe = (origin + z for z in self.zmp_points(s))
            if xi is None:
                xi = toe.copy()
            xi = dcm_before(xi, heel, toe, self.ss, self.omega)
            xi = dcm_before(xi, prev_toe, heel, max(self.ds, 1e-3), self.omega)
        assert xi is not None
        return xi

    def offset(self, side: float) -> np.ndarray:
        """``(2,)`` the DCM at touchdown relative to the landing foot on ``side`` [m]: what
        the planner aims each step at (Khadiv et al.'s nominal DCM offset)."""
        return self.dcm_at_touchdown(side)
