"""The stand check: hold the standing posture under position control and judge it.

One rule, used by ``imitwalk robot import``, ``imitwalk robot stand`` and ``imitwalk
learn``: a robot *stands* when, over the whole hold,

* its torso never tilts more than :data:`TILT_LIMIT_DEG` from upright (world z);
* its torso ends no more than :data:`HEIGHT_LOST_LIMIT` of its standing height lower
  than it started (knees that give way);
* and at the end it is no longer tipping: its tilt changed by less than
  :data:`TIPPING_LIMIT_DEG_PER_S` over the last :data:`TIPPING_WINDOW_S`.

The simulator's own fall (``fell``: 45° or half the height, :class:`~imitwalk.sim.types.SimOptions`)
ends a walk; it is far too late for a stand, which is why ``fell`` is reported but not
used here. ``robot import`` and ``learn`` hold :data:`CHECK_SECONDS`; ``robot stand`` holds
``--seconds`` (10 by default), so a robot near a limit is judged on more evidence there:
``robot stand --seconds 2`` repeats the import's check exactly.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

from imitwalk.errors import RobotError
from imitwalk.robots import Robot
from imitwalk.robots.spec import LEG_ROLES
from imitwalk.sim.metrics import tilt_deg
from imitwalk.sim.mujoco import MujocoPlant, SimOptions, playback

__all__ = [
    "CHECK_SECONDS",
    "HEIGHT_LOST_LIMIT",
    "TILT_LIMIT_DEG",
    "TIPPING_LIMIT_DEG_PER_S",
    "TIPPING_WINDOW_S",
    "StandResult",
    "require_standing",
    "stand_test",
]

#: ``robot import`` and ``learn`` hold the standing posture this long [s].
CHECK_SECONDS = 2.0
#: A standing torso tilts at most this far from upright [deg] (hoap2 1.3°, OP3 2.0°, G1 0.2°).
TILT_LIMIT_DEG = 20.0
#: A standing torso loses at most this fraction of its standing height (hoap2: 0.4 %).
HEIGHT_LOST_LIMIT = 0.10
#: A robot still tipping faster than this at the end of the hold has not stood [deg/s].
TIPPING_LIMIT_DEG_PER_S = 2.0
#: The tipping rate is measured over the last this long of the hold [s].
TIPPING_WINDOW_S = 0.5


@dataclass(frozen=True)
class StandResult:
    """Outcome of :func:`stand_test`.

    Attributes:
        stands: the robot stood by the rule of this module (tilt, height, tipping).
        fell: the simulator's fall (45° of tilt or half the torso height), far past
            ``stands``; seconds: simulated time [s];
        max_tilt_deg: largest torso tilt from upright over the run [deg];
        final_tilt_deg: torso tilt at the end [deg];
        tipping_deg_per_s: how fast the tilt grew over the last :data:`TIPPING_WINDOW_S`
            [deg/s] (negative: righting itself);
        foot_force_sum_n: sum of all sole force sensors over the last second [N];
        weight_n: the robot's weight, mass × g [N];
        left_n, right_n: force under each sole over the last second [N];
        both_feet_in_contact: both soles carry load at the end;
        height_lost_m: how much lower the torso is at the end than at the start [m];
        height_lost_limit_m: :data:`HEIGHT_LOST_LIMIT` × the standing torso height [m];
        tilt_limit_deg: :data:`TILT_LIMIT_DEG` [deg];
        leg_kp_nm_per_rad: the weakest leg servo's stiffness [Nm/rad] (for the advice).
    """

    stands: bool
    fell: bool
    seconds: float
    max_tilt_deg: float
    final_tilt_deg: float
    tipping_deg_per_s: float
    foot_force_sum_n: float
    weight_n: float
    left_n: float
    right_n: float
    both_feet_in_contact: bool
    height_lost_m: float
    height_lost_limit_m: float
    tilt_limit_deg: float = TILT_LIMIT_DEG
    leg_kp_nm_per_rad: float = float("nan")

    def to_dict(self) -> dict:
        """Plain-JSON dictionary."""
        return asdict(self)

    def why(self) -> str:
        """What was measured, against the limits, e.g. ``torso tilted 30 deg (limit 20)``."""
        out = []
        if self.max_tilt_deg > self.tilt_limit_deg:
            out.append(f"torso tilted {self.max_tilt_deg:.0f} deg (limit {self.tilt_limit_deg:g})")
        if self.height_lost_m > self.height_lost_limit_m:
            out.append(
                f"torso sank {self.height_lost_m:.3f} m (limit {self.height_lost_limit_m:.3f} m)"
            )
        if self.tipping_deg_per_s > TIPPING_LIMIT_DEG_PER_S:
            out.append(
                f"still tipping at {self.tipping_deg_per_s:.1f} deg/s at {self.final_tilt_deg:.0f} "
                f"deg (limit {TIPPING_LIMIT_DEG_PER_S:g} deg/s)"
            )
        return "; ".join(out) or f"torso tilted {self.max_tilt_deg:.1f} deg"

    def line(self) -> str:
        """One line: whether it stood, its largest tilt and the height it lost."""
        verdict = "stands" if self.stands else "does NOT stand"
        return (
            f"{verdict} {self.seconds:g} s: tilt up to {self.max_tilt_deg:.1f} deg "
            f"(limit {self.tilt_limit_deg:g}), height lost {self.height_lost_m * 1000:.1f} mm"
        )

    def refusal(self, robot: str) -> str:
        """One line saying that ``robot`` cannot stand, what was measured and what to change,
        by the joint map's keys."""
        return (
            f"robot {robot} cannot stand: after {self.seconds:g} s its {self.why()}; "
            f'stiffen the leg servos with the joint map\'s "servos": '
            f'{{"legs": {{"kp": ...}}}} (now {self.leg_kp_nm_per_rad:.3g} Nm/rad), or fix its '
            'standing posture ("stand_keyframe" or "stand") or its "soles"'
        )


def stand_test(
    robot: Robot, seconds: float = 10.0, options: SimOptions | None = None
) -> StandResult:
    """Hold ``robot.stand`` for ``seconds`` [s]; report tilt, height, sole forces and the
    verdict ``stands`` (the rule in the module docstring)."""
    plant = MujocoPlant(robot, options)
    steps = max(1, int(round(seconds / plant.control_dt)))
    ro = playback(plant, np.tile(robot.stand, (steps, 1)), stop_on_fall=False)
    tail = ro.foot_force[-max(1, int(round(1.0 / ro.control_dt))) :]
    per_side = tail.sum(axis=2).mean(axis=0)
    g = float(np.linalg.norm(plant.model.opt.gravity))
    tilt = tilt_deg(ro.torso_quat)  # (N,)
    window = min(len(tilt) - 1, max(1, int(round(TIPPING_WINDOW_S / ro.control_dt))))
    tipping = float(tilt[-1] - tilt[-1 - window]) / (window * ro.control_dt) if window else 0.0
    lost = float(ro.torso_pos[0, 2] - ro.torso_pos[-1, 2])
    lost_limit = HEIGHT_LOST_LIMIT * float(robot.torso_height)
    legs = robot.indices([r for r in LEG_ROLES if r in robot.joint_names])
    stands = (
        not ro.fell
        and float(tilt.max()) <= TILT_LIMIT_DEG
        and lost <= lost_limit
        and tipping <= TIPPING_LIMIT_DEG_PER_S
    )
    return StandResult(
        stands=bool(stands),
        fell=bool(ro.fell),
        seconds=float(ro.seconds),
        max_tilt_deg=float(tilt.max()),
        final_tilt_deg=float(tilt[-1]),
        tipping_deg_per_s=tipping,
        foot_force_sum_n=float(per_side.sum()),
        weight_n=plant.mass * g,
        left_n=float(per_side[0]),
        right_n=float(per_side[1]),
        both_feet_in_contact=bool((per_side > 0.05 * per_side.sum()).all()),
        height_lost_m=lost,
        height_lost_limit_m=lost_limit,
        leg_kp_nm_per_rad=float(np.min(robot.kp[legs])) if len(legs) else float("nan"),
    )


def require_standing(robot: Robot, label: str, seconds: float = CHECK_SECONDS) -> StandResult:
    """:func:`stand_test` for ``seconds`` [s]; the result if ``robot`` stands.

    Raises:
        RobotError: it does not: one line with what was measured and the joint-map keys
            to change (``label`` names the robot, e.g. its joint map's path).
    """
    res = stand_test(robot, seconds=seconds)
    if not res.stands:
        raise RobotError(res.refusal(label))
    return res
