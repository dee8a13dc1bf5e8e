"""What the stepping gait imitates: the human's walking style, scaled to the robot's legs.

A :class:`GaitStyle` keeps what imitation keeps of a clip (its
:class:`~imitwalk.retarget.template.GaitTemplate`): the cadence (the human's step time,
kept as it is), the stride and the swing foot's clearance (scaled by the robot's leg
over the human's), the double-support share, the swing foot's path shape (its forward
progress and lift over the swing), and the arms' and waist's swing over the gait
phase. The stepping controller (:mod:`imitwalk.step.controller`) walks these as its
nominal steps and changes them only where the measured state demands it.

What the robot adds is its own: the step width (its hips' spacing), the pelvis height
(the highest that keeps the knees bent through the longest step,
:func:`hip_height`), and the limits of its reach (:func:`reach_limits`).
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, replace
from typing import TYPE_CHECKING

import numpy as np

from imitwalk.errors import ConfigError
from imitwalk.retarget.params import LegGeometry

if TYPE_CHECKING:  # the template is read from mocap (SciPy); a style alone needs neither
    from imitwalk.retarget.template import GaitTemplate

__all__ = [
    "KNEE_MIN_DEG",
    "LIFT_MIN",
    "MAX_TURN",
    "GaitStyle",
    "hip_height",
    "reversed_in_time",
    "style_from_template",
    "with_stride",
]

#: The stance knee keeps at least this flexion at the nominal step [deg]: a position-
#: servoed knee near straight cannot lower or shift the hip, so nothing can balance.
KNEE_MIN_DEG = 20.0
#: A turning gait turns at most this much per cycle [rad] (45°, 0.785 of two steps' turn,
#: :data:`~imitwalk.step.schedule.MAX_STEP_YAW`; the rest is left to the heading's
#: feedback). Picked by trials on training robots (``eval`` seeds 100-119, 30 s,
#: ``walker_turn_left1`` and ``turn_right1``): none of 40 fell at 45°, 5 of 40 at 48°
#: and 3 of 40 at 51°. With all of two steps' turn fed forward (0.35 rad a step then;
#: ``walker_turn_right0``, 99° a loop) 10 eval robots turned 25-35° a cycle of 40° and
#: 2 fell.
MAX_TURN = np.pi / 4
#: The least swing clearance, a fraction of the leg (a tenth, as the joint-space gait's):
#: a clip's foot may skim the floor (CMU 07_04's lifts 1.4 cm on hoap2's scale), and at
#: 0.08 of the leg hoap2's swing foot scuffed the floor mid-swing on 07_04.
LIFT_MIN = 0.1


@dataclass(frozen=True)
class GaitStyle:
    """The nominal walk, for one robot.

    Attributes:
        step_time: one step, touchdown to touchdown [s] (half the human's cycle);
        double_support: its double-support time [s]; step_length: forward distance
            between successive feet [m] (negative: a backward walk,
            :func:`reversed_in_time`); step_width: lateral distance between the feet
            [m]; clearance: the swing foot's peak lift [m]; hip_height: hip centre above
            the soles [m]; swing_x, swing_z: ``(P,)`` the swing foot's forward progress
            (0 → 1) and lift (0 → 1 → 0) over the swing; upper: role → ``(P,)`` the arms'
            and waist's offsets from standing over the gait phase ψ ∈ [0, 1) (ψ = 0 at
            the left touchdown) [rad]; human: the clip's own figures (``period`` [s],
            ``stride`` [m], ``leg`` [m], ``speed`` [m/s]), its ``source`` and
            ``turn_deg``: its turn per cycle [deg]); geometry: the robot's leg measures;
            turn: the heading change per gait cycle [rad], + left (0: a straight walk):
            the clip's (:attr:`GaitTemplate.turn_deg
            <imitwalk.retarget.template.GaitTemplate.turn_deg>`), at most :data:`MAX_TURN`;
        stride_share: the share of the clip's (leg-scaled) stride walked: 1, or less where
            the robot's servos cannot carry the clip's swing (:mod:`imitwalk.step.pace`).
    """

    step_time: float
    double_support: float
    step_length: float
    step_width: float
    clearance: float
    hip_height: float
    swing_x: np.ndarray
    swing_z: np.ndarray
    upper: dict
    human: dict
    geometry: LegGeometry
    turn: float = 0.0
    stride_share: float = 1.0

    @property
    def pelvis_height(self) -> float:
        """The pelvis frame above the soles [m]."""
        return self.hip_height + self.geometry.hip_z

    @property
    def backward(self) -> bool:
        """Whether the walk goes backward (a negative step, :func:`reversed_in_time`)."""
        return self.step_length < 0

    @property
    def single_support(self) -> float:
        """Single-support time of a step [s]."""
        return self.step_time - self.double_support

    @property
    def speed(self) -> float:
        """Nominal forward speed [m/s]."""
        return self.step_length / self.step_time

    def upper_at(self, phase: float) -> dict[str, float]:
        """The arms' and waist's offsets [rad] at gait phase ``phase`` (wrapped to [0, 1))."""
        out = {}
        for role, prof in self.upper.items():
            x = (phase % 1.0) * len(prof)
            i = int(x)
            f = x - i
            out[role] = float((1.0 - f) * prof[i % len(prof)] + f * prof[(i + 1) % len(prof)])
        return out

    def to_dict(self) -> dict:
        """Plain-JSON dictionary (arrays as lists)."""
        d = asdict(self)
        d["swing_x"] = self.swing_x.tolist()
        d["swing_z"] = self.swing_z.tolist()
        d["upper"] = {k: np.asarray(v).tolist() for k, v in self.upper.items()}
        d["geometry"] = self.geometry.__dict__.copy()
        return d

    @classmethod
    def from_dict(cls, d: dict) -> GaitStyle:
        """Inverse of :meth:`to_dict` (a ``stride_share`` outside (0, 1]: ValueError)."""
        d = dict(d)
        share = float(d.get("stride_share", 1.0))
        if not 0.0 < share <= 1.0:
            raise ValueError(f"stride_share {share:g}: expected 0 < stride_share <= 1")
        d["swing_x"] = np.asarray(d["swing_x"], dtype=float)
        d["swing_z"] = np.asarray(d["swing_z"], dtype=float)
        d["upper"] = {k: np.asarray(v, dtype=float) for k, v in d["upper"].items()}
        d["geometry"] = LegGeometry(**d["geometry"])
        return cls(**d)


def hip_height(geom: LegGeometry, step_length: float, knee_min_deg: float = KNEE_MIN_DEG) -> float:
    """The highest hip centre above the soles [m] at which both legs reach the ground
    with the knee bent at least ``knee_min_deg`` when the feet are ``step_length`` [m]
    apart and the hips midway (thigh and shank taken as equal, so a knee bent by κ
    shortens the leg to ``leg·cos(κ/2)``).

    Raises:
        ConfigError: the legs cannot make the step at all (which limit says why).
    """
    reach = geom.leg * np.cos(np.radians(knee_min_deg) / 2)
    half = step_length / 2
    if half >= 0.9 * reach:
        raise ConfigError(
            f"a step of {step_length:.3f} m is beyond this robot's legs: with the knee bent "
            f"{knee_min_deg:g} deg each leg reaches {reach:.3f} m (leg {geom.leg:.3f} m); "
            "walk a shorter stride (--forward)"
        )
    return float(np.sqrt(reach**2 - half**2) + geom.ankle)


def style_from_template(
    template: GaitTemplate, geom: LegGeometry, scale: float = 1.0, forward: float = 1.0
) -> GaitStyle:
    """The clip's style on a robot with legs ``geom``, its stride × ``scale`` × ``forward``
    (``scale`` grows the whole gait's amplitude, arms included; ``forward`` the stride
    alone)."""
    if not 0.0 <= scale <= 1.5:
        raise ConfigError(f"scale {scale:g}: expected 0 <= scale <= 1.5")
    ratio = geom.leg / template.leg_length
    clip_turn = template.turn_deg
    step_time = template.period / 2
    ds = float(np.clip(template.double_support, 0.05, 0.3)) * template.period
    step_length = scale * forward * template.stride * ratio / 2
    clearance = max(template.lift * ratio, LIFT_MIN * geom.leg)
    shape_z = np.maximum(template.swing_z, np.sin(np.pi * np.linspace(0, 1, len(template.swing_z))))
    shape_z = shape_z / shape_z.max()
    centred = lambda a: np.asarray(a) - np.mean(a)  # noqa: E731
    upper = {
        "l_shoulder_pitch": -scale * centred(template.shoulder[:, 0]),
        "r_shoulder_pitch": -scale * centred(template.shoulder[:, 1]),
        "l_elbow": -scale * centred(template.elbow[:, 0]),
        "r_elbow": -scale * centred(template.elbow[:, 1]),
        "waist_yaw": scale * np.asarray(template.waist),
    }
    return GaitStyle(
        step_time=float(step_time),
        double_support=ds,
        step_length=float(step_length),
        step_width=float(2 * geom.hip_y),
        clearance=float(clearance),
        hip_height=hip_height(geom, max(abs(step_length), 1e-6)),
        swing_x=np.asarray(template.swing_x, dtype=float),
        swing_z=shape_z,
        upper=upper,
        human={
            "period": float(template.period),
            "stride": float(template.stride),
            "leg": float(template.leg_length),
            "speed": float(template.speed),
            "source": str(template.source),
            "turn_deg": clip_turn,
        },
        geometry=geom,
        turn=float(np.clip(np.radians(clip_turn), -MAX_TURN, MAX_TURN)),
    )


def with_stride(style: GaitStyle, share: float) -> GaitStyle:
    """``style`` walking ``share`` (0 < share <= 1) of the clip's stride, its hips as high
    as that step allows (:func:`hip_height`); cadence, clearance, swing shape and arms
    unchanged. ``share`` is of the clip's stride, not of ``style``'s."""
    if not 0.0 < share <= 1.0:
        raise ConfigError(f"stride share {share:g}: expected 0 < share <= 1")
    length = style.step_length / style.stride_share * share
    return replace(
        style,
        step_length=float(length),
        hip_height=hip_height(style.geometry, max(abs(length), 1e-6)),
        stride_share=float(share),
    )


def reversed_in_time(style: GaitStyle) -> GaitStyle:
    """``style`` played backward in time: a backward walk, the paper's "stepping backward"
    module learned from the same clip. Cadence, double support, stride, clearance and
    pelvis height are the clip's; the step is negative; the swing foot retraces its path
    (progress ``X'(σ) = 1 − X(1 − σ)``, lift ``Z'(σ) = Z(1 − σ)``); the arms and waist
    replay their profiles backward, phased so that ψ' = 0 is again a left touchdown
    (the forward walk's left lift-off, at ψ = ½ + the double support's share of the
    cycle: ``u'(ψ') = u(ψ_off − ψ')``). Reversing twice gives the style back (the arms'
    profiles to within their linear interpolation)."""
    swing_x = 1.0 - style.swing_x[::-1]
    swing_z = style.swing_z[::-1].copy()
    off = 0.5 + style.double_support / (2.0 * style.step_time)  # ψ of the left lift-off
    upper = {}
    for role, prof in style.upper.items():
        grid = np.arange(len(prof)) / len(prof)  # the ψ of each sample
        upper[role] = np.interp(off - grid, grid, prof, period=1.0)  # u(ψ_off − ψ')
    return replace(
        style,
        step_length=-style.step_length,
        swing_x=swing_x,
        swing_z=swing_z,
        upper=upper,
        turn=-style.turn,
    )
