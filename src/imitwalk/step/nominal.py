"""The nominal walk a stepping controller aims at, and what bounds its steps (pure NumPy).

:class:`NominalWalk` turns a style and the gains into the planner's model
(:mod:`imitwalk.step.planner`): the periodic pendulum walk of each step of the start-up
and after it (:class:`~imitwalk.step.lipm.NominalGait`: the style's stride, width and
timing; the ZMP rolling heel to toe by ``zmp_roll`` of the half sole (toe to heel in
a backward walk, :func:`~imitwalk.step.style.reversed_in_time`) and set ``zmp_out``
of the half sole outside the centre line), its DCM offsets at touchdown, the steps'
limits and the planner's weights.

The limits come from the robot's legs (:class:`~imitwalk.retarget.params.LegGeometry`):
a step reaches at most as far as both legs, nearly straight, reach from hips midway
between the feet at the walking height (half that against the walk's direction); the
feet stay a tenth of a sole's width apart at least, and at most 0.4 of a leg wider than
the style's width; a single support lasts ``ss_min`` to 1.5 times the style's; the swing
foot moves at most four times its nominal speed.
"""

from __future__ import annotations

import numpy as np

from imitwalk.step.gains import StepGains
from imitwalk.step.lipm import NominalGait
from imitwalk.step.odometry import rot2
from imitwalk.step.planner import StepLimits, StepWeights
from imitwalk.step.schedule import START_STEPS, stride_at
from imitwalk.step.style import GaitStyle

__all__ = ["NominalWalk", "turning_step"]


class NominalWalk:
    """The planner's model of one controller's walk (see the module doc).

    Args:
        style: the walk; gains: the controller's gains; omega: the pendulum's frequency
        [1/s]; pelvis_z: the pelvis's walking height over the soles [m].

    Attributes:
        limits: :class:`~imitwalk.step.planner.StepLimits`; weights: the planner's
        :class:`~imitwalk.step.planner.StepWeights`.
    """

    def __init__(self, style: GaitStyle, gains: StepGains, omega: float, pelvis_z: float):
        self.style, self.gains, self.omega = style, gains, omega
        geom = style.geometry
        self.half = np.array([geom.foot_length, geom.foot_width]) / 2
        hip = pelvis_z - geom.hip_z - geom.ankle  # the hips over the ankles [m]
        reach = geom.leg * 0.99
        far = 2 * np.sqrt(max(reach**2 - hip**2, 0.0))  # both legs reaching, hips midway
        ahead, behind = (0.5 * far, far) if style.backward else (far, 0.5 * far)
        length = abs(style.step_length)
        self.limits = StepLimits(
            forward=max(ahead, style.step_length),
            backward=max(behind, -style.step_length),
            inner=geom.foot_width + 0.1 * geom.foot_width,
            outer=style.step_width + 0.4 * geom.leg,
            ss_min=gains.ss_min * style.single_support,
            ss_max=1.5 * style.single_support,
            swing_speed=4.0 * max(length, style.step_width) / style.single_support + 0.2,
        )
        self.weights = StepWeights(
            10.0**gains.step_weight, 1.0, 10.0**gains.time_weight, 10.0**gains.zmp_weight
        )
        self._gaits: dict[tuple[int, float], NominalGait] = {}
        self._offsets: dict[tuple[int, float, float], np.ndarray] = {}

    def gait(self, step: int, stride: float = 1.0) -> NominalGait:
        """The periodic walk step ``step`` (counted from 1) is aimed at: the stride grows
        over :data:`~imitwalk.step.schedule.START_STEPS` steps to ``stride`` [0, 1] of
        the style's (rounded to a twentieth: the walks are cached)."""
        stride = round(stride * 20) / 20
        k = (min(step, START_STEPS), stride)
        if k not in self._gaits:
            st, g = self.style, self.gains
            # the ZMP rolls the way the walk goes: heel to toe, or toe to heel backward
            roll = g.zmp_roll * self.half[0] * (-1.0 if st.backward else 1.0)
            self._gaits[k] = NominalGait(
                step=stride * stride_at(k[0], st.step_length),
                width=st.step_width,
                ss=st.single_support,
                ds=st.double_support,
                heel=roll,
                toe=roll,
                inward=-g.zmp_out * self.half[1],
                omega=self.omega,
            )
        return self._gaits[k]

    def offset(self, step: int, side: float, stride: float = 1.0) -> np.ndarray:
        """``(2,)`` the nominal DCM offset at touchdown [m] of step ``step``'s foot landing
        on ``side`` (+1 left, −1 right), at ``stride`` of the style's."""
        stride = round(stride * 20) / 20
        key = (min(step, START_STEPS), side, stride)
        if key not in self._offsets:
            self._offsets[key] = self.gait(step, stride).offset(side)
        return self._offsets[key]


def turning_step(
    step: float, width: float, side: float, turn: float, offset: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """A step of a walk that turns ``turn`` [rad] a step, in the stance foot's frame: where
    the swing foot lands ``(2,)`` [m] and the nominal DCM offset ``(2,)`` [m] turned with
    it. The walking frame moves ``step`` [m] along the chord of its arc (half the turn)
    and turns by ``turn``; each foot sits ``width / 2`` [m] beside it. ``side``: the stance
    foot's (+1 left); ``offset``: the straight walk's (:meth:`NominalWalk.offset`)."""
    half = 0.5 * width * side
    land = rot2(0.5 * turn) @ np.array([step, 0.0]) + rot2(turn) @ np.array([0.0, -half])
    return land - np.array([0.0, half]), rot2(turn) @ offset
