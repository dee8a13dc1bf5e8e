"""The walkable reference's parameters and the robot's leg measures (plain records).

:class:`GaitParams` are the few numbers the reference search tunes
(:mod:`imitwalk.retarget.search`); :class:`LegGeometry` is what
:func:`imitwalk.retarget.ik.leg_geometry` measures on the robot's model. The plan
(:mod:`imitwalk.retarget.plan`) reads both.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, replace

__all__ = ["LIFT", "REFERENCE_LEG", "GaitParams", "LegGeometry", "leg_scaled"]

#: The leg (hip to ankle) [m] that every length in the reference's tables is written
#: for: the default lift below, the search ranges (:data:`imitwalk.retarget.search.BOUNDS`),
#: and the least gap between the feet. They were set on hoap2,
#: whose leg this is; a robot with another leg has them scaled by its own over this one
#: (:func:`leg_scaled`), so a robot three times as tall lifts its feet three times as high.
REFERENCE_LEG = 0.2
#: The default swing-foot clearance at :data:`REFERENCE_LEG` [m] (a tenth of the leg).
LIFT = 0.02


def leg_scaled(x: float, leg: float | None) -> float:
    """A length ``x`` [m] written for :data:`REFERENCE_LEG`, for a robot whose leg is
    ``leg`` [m] (``None``: as written); rounded to the micrometre, so that a leg of
    :data:`REFERENCE_LEG` gives back ``x`` exactly."""
    return x if leg is None else round(x * leg / REFERENCE_LEG, 6) + 0.0


@dataclass(frozen=True)
class GaitParams:
    """The reference's few parameters, found by trials in simulation (``search.py``).

    Attributes:
        sway: lateral CoM amplitude ÷ the lateral offset of the feet (about 0.9 worked).
        height: hip height ÷ the straight-leg hip height (knee stays bent below 1).
        lift: swing foot clearance at its peak [m]; ``None``: :data:`LIFT` scaled to the
            robot's leg (:meth:`for_leg`), a tenth of it.
        ds: double-support fraction of the cycle, per transition (about 0.1 worked).
        lean: centre of mass ahead of the feet's midpoint [m]; a compliant robot sags
            backwards under its own weight, so a few millimetres may be needed.
        width: extra lateral offset of each foot beyond its hip [m].
    """

    sway: float = 0.9
    height: float = 0.9
    lift: float | None = None
    ds: float = 0.1
    lean: float = 0.0
    width: float = 0.0

    def to_dict(self) -> dict:
        """Plain dictionary."""
        return asdict(self)

    def for_leg(self, leg: float | None) -> GaitParams:
        """These parameters with a ``None`` lift set for a leg of ``leg`` [m] (``None``:
        :data:`REFERENCE_LEG`)."""
        return self if self.lift is not None else replace(self, lift=leg_scaled(LIFT, leg))


@dataclass(frozen=True)
class LegGeometry:
    """The robot's leg measures, from its model.

    Attributes:
        hip_y: lateral offset of each hip centre from the pelvis centre [m].
        hip_z: hip centre below the pelvis frame [m] (positive down).
        leg: hip centre to ankle with the leg straight [m].
        ankle: ankle to sole [m].
        sole_x: sole centre ahead of the ankle [m].
        foot_length: sole length [m].
        hip_ahead: hips ahead of the centre of mass when standing [m].
        foot_width: sole width [m] (a sidestep widens the stance to keep the feet apart).
    """

    hip_y: float
    hip_z: float
    leg: float
    ankle: float
    sole_x: float
    foot_length: float
    hip_ahead: float = 0.0
    foot_width: float = 0.0

    @property
    def hip_height(self) -> float:
        """Hip centre above the sole with the leg straight [m]."""
        return self.leg + self.ankle
