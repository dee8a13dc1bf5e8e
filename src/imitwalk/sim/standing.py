"""The standing test: hold the standing keyframe under position control."""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

from imitwalk.robots import Robot
from imitwalk.sim.metrics import tilt_deg
from imitwalk.sim.mujoco import MujocoPlant, SimOptions, playback

__all__ = ["StandResult", "stand_test"]


@dataclass(frozen=True)
class StandResult:
    """Outcome of :func:`stand_test`.

    Attributes:
        fell: the torso fell; seconds: simulated time [s];
        max_tilt_deg: largest torso tilt over the run [deg];
        final_tilt_deg: torso tilt at the end [deg];
        foot_force_sum_n: sum of all sole force sensors over the last second [N];
        weight_n: the robot's weight, mass × g [N];
        left_n, right_n: force under each sole over the last second [N];
        both_feet_in_contact: both soles carry load at the end;
        height_lost_m: how much lower the torso is at the end than at the start [m].
    """

    fell: bool
    seconds: float
    max_tilt_deg: float
    final_tilt_deg: float
    foot_force_sum_n: float
    weight_n: float
    left_n: float
    right_n: float
    both_feet_in_contact: bool
    height_lost_m: float = 0.0

    def to_dict(self) -> dict:
        """Plain-JSON dictionary."""
        return asdict(self)

    def refusal(self, robot: str) -> str:
        """One line saying that ``robot`` cannot stand: the height lost and the tilt."""
        return (
            f"robot {robot} cannot stand: after {self.seconds:g} s the torso lost "
            f"{self.height_lost_m:.3f} m of height and tilted {self.final_tilt_deg:.0f} deg"
        )


def _root(plant: MujocoPlant) -> int:
    m = plant.model
    return int(m.body_rootid[m.body(plant.robot.torso).id])


def stand_test(
    robot: Robot, seconds: float = 10.0, options: SimOptions | None = None
) -> StandResult:
    """Hold ``robot.stand`` for ``seconds`` and report tilt and sole forces."""
    plant = MujocoPlant(robot, options)
    steps = max(1, int(round(seconds / plant.control_dt)))
    ro = playback(plant, np.tile(robot.stand, (steps, 1)), stop_on_fall=False)
    tail = ro.foot_force[-max(1, int(round(1.0 / ro.control_dt))) :]
    per_side = tail.sum(axis=2).mean(axis=0)
    g = float(np.linalg.norm(plant.model.opt.gravity))
    tilt = tilt_deg(ro.torso_quat)
    return StandResult(
        fell=bool(ro.fell),
        seconds=float(ro.seconds),
        max_tilt_deg=float(tilt.max()),
        final_tilt_deg=float(tilt[-1]),
        foot_force_sum_n=float(per_side.sum()),
        weight_n=float(plant.model.body_subtreemass[_root(plant)] * g),
        left_n=float(per_side[0]),
        right_n=float(per_side[1]),
        both_feet_in_contact=bool((per_side > 0.05 * per_side.sum()).all()),
        height_lost_m=float(ro.torso_pos[0, 2] - ro.torso_pos[-1, 2]),
    )
