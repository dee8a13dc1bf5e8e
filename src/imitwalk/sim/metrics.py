"""Walking metrics from a :class:`~imitwalk.sim.types.Rollout` (pure NumPy).

These read the simulator's ground-truth torso pose, so they are for *judging* a
run only; nothing here is ever fed back to a learner.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import asdict, dataclass
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from imitwalk.sim.types import Rollout

__all__ = [
    "GaitTiming",
    "WalkMetrics",
    "gait_timing",
    "summarise",
    "tilt_deg",
    "walk_metrics",
    "yaw_rad",
]


def tilt_deg(quat: np.ndarray) -> np.ndarray:
    """Angle between the body z axis and world z [deg] for ``(N, 4)`` (w, x, y, z) quaternions."""
    q = np.atleast_2d(quat)
    czz = 1.0 - 2.0 * (q[:, 1] ** 2 + q[:, 2] ** 2)
    return np.degrees(np.arccos(np.clip(czz, -1.0, 1.0)))


def yaw_rad(quat: np.ndarray) -> np.ndarray:
    """Heading of the body x axis about world z [rad], unwrapped, for ``(N, 4)`` quaternions."""
    q = np.atleast_2d(quat)
    w, x, y, z = q.T
    return np.unwrap(np.arctan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z)))


@dataclass(frozen=True)
class WalkMetrics:
    """How one run walked.

    Attributes:
        fell: the torso fell; fall_time_s: when [s] (``None`` if it did not).
        seconds: simulated time [s].
        forward_distance_m: torso travel along the initial heading [m] (along the
            commanded heading of the moment, for a turning reference).
        forward_speed_mps: that distance over the time walked [m/s].
        progress_ratio: forward distance ÷ the distance the reference commands over
            the duration it is judged on (``expected_distance``); for a reference that
            steps on the spot, the turn (or else the sidestep) made ÷ the one commanded
            over the whole ``track``. 1 is the commanded walk; 0 is no travel; it is
            negative for a robot that went backwards. Judged over the whole duration
            asked for (as ``evaluate`` does), a walk that falls after ``t`` seconds scores
            at most what it walked by then, and one that falls at once scores about 0
            (at most its standing height over the whole walk's distance) rather than its
            fall's few centimetres over the few millimetres commanded so far.
        lateral_drift_m: sideways torso travel beyond the commanded sidestep [m];
        yaw_drift_deg: heading change beyond the commanded turn [deg].
        gyro_rms: RMS of the torso angular velocity norm [rad/s].
        max_tilt_deg: largest torso tilt [deg].
        joint_rms_error_rad: RMS of measured minus reference joint angles [rad].
        torque_saturation: the largest, over the joints, fraction of ticks at which a
            servo gave at least 99 % of its torque limit (``None`` if not recorded);
            saturated_joint: that joint's name (``None`` if no servo saturated).
        commanded_turn_deg, commanded_side_m: the turn [deg] and sidestep [m] the
            reference commands over the run (0 for a straight walk).
    """

    fell: bool
    fall_time_s: float | None
    seconds: float
    forward_distance_m: float
    forward_speed_mps: float
    progress_ratio: float
    lateral_drift_m: float
    yaw_drift_deg: float
    gyro_rms: float
    max_tilt_deg: float
    joint_rms_error_rad: float
    torque_saturation: float | None = None
    saturated_joint: str | None = None
    commanded_turn_deg: float = 0.0
    commanded_side_m: float = 0.0

    def to_dict(self) -> dict:
        """Plain-JSON dictionary."""
        return asdict(self)


def walk_metrics(
    rollout: Rollout,
    expected_distance: float,
    q_ref: np.ndarray | None = None,
    track: np.ndarray | None = None,
) -> WalkMetrics:
    """Judge a rollout.

    Args:
        rollout: a :class:`~imitwalk.sim.types.Rollout`.
        expected_distance: distance the reference commands [m] (the denominator of
            ``progress_ratio``; negative for a backward walk): over the duration the walk
            is judged on, the rollout's own (a learner's or a search's walk, which may end
            early on purpose) or the whole duration asked for (``evaluate``: a fall then
            scores the share of the whole walk made).
        q_ref: ``(N, n)`` reference joint angles to compare the measured ones with;
            defaults to the commanded targets.
        track: ``(T, 3)`` the commanded forward and sideways travel [m] and heading
            [rad] per control tick (:meth:`~imitwalk.retarget.reference.Reference.track`);
            ``None``: straight ahead. Distances are measured along the commanded
            heading of each tick, and drifts are what is left beyond the command of
            the last tick walked; a ``track`` longer than the rollout (the whole judged
            duration) sets the turn or sidestep an on-the-spot ``progress_ratio`` is over.
    """
    pos, quat = rollout.torso_pos, rollout.torso_quat
    if len(pos) == 0:
        raise ValueError("empty rollout")
    yaw = yaw_rad(quat)
    head = yaw[0]
    cmd = np.zeros((len(pos), 3))
    if track is not None and len(track):
        track = np.asarray(track, dtype=float)
        cmd = track[np.minimum(np.arange(len(pos)), len(track) - 1)]
    h = head + 0.5 * (cmd[1:, 2] + cmd[:-1, 2])  # (T-1,) commanded heading over each tick
    d = np.diff(pos[:, :2], axis=0)
    fwd = float(np.sum(d[:, 0] * np.cos(h) + d[:, 1] * np.sin(h)))
    lat = float(np.sum(-d[:, 0] * np.sin(h) + d[:, 1] * np.cos(h)) - cmd[-1, 1])
    tail = max(1, int(round(1.0 / rollout.control_dt)))
    yaw_drift = float(np.degrees(np.mean(yaw[-tail:] - cmd[-tail:, 2]) - head))
    whole = track[-1] if track is not None and len(track) else cmd[-1]  # (3,) commanded
    if expected_distance != 0:  # negative: a backward walk
        progress = fwd / expected_distance
    elif abs(whole[2]) > 0:  # a turn on the spot: how much of the whole turn was made
        progress = _share(np.radians(yaw_drift), cmd[-1, 2], whole[2])
    elif abs(whole[1]) > 0:  # a sidestep on the spot
        progress = _share(lat, cmd[-1, 1], whole[1])
    else:
        progress = 0.0
    seconds = rollout.seconds
    ref = rollout.q_cmd if q_ref is None else q_ref[: len(rollout.q)]
    err = rollout.q - ref
    sat, joint = _saturation(rollout)
    return WalkMetrics(
        fell=bool(rollout.fell),
        fall_time_s=rollout.fall_time,
        seconds=float(seconds),
        forward_distance_m=fwd,
        forward_speed_mps=fwd / seconds if seconds > 0 else 0.0,
        progress_ratio=float(progress),
        lateral_drift_m=lat,
        yaw_drift_deg=yaw_drift,
        gyro_rms=float(np.sqrt(np.mean(np.sum(rollout.gyro**2, axis=1)))),
        max_tilt_deg=float(tilt_deg(quat).max()),
        joint_rms_error_rad=float(np.sqrt(np.mean(err**2))),
        torque_saturation=sat,
        saturated_joint=joint,
        commanded_turn_deg=float(np.degrees(cmd[-1, 2])),
        commanded_side_m=float(cmd[-1, 1]),
    )


def _share(beyond: float, now: float, whole: float) -> float:
    """The share of ``whole`` made: ``now`` (commanded so far) plus ``beyond`` (the drift
    past it), over ``whole`` (commanded over the judged duration; ``now`` if the same)."""
    return 1.0 + beyond / now if whole == now else (now + beyond) / whole


#: A servo is saturated when it gives at least this fraction of its torque limit.
SATURATED = 0.99


def _saturation(rollout: Rollout) -> tuple[float | None, str | None]:
    """The most saturated joint's fraction of saturated ticks, and its name."""
    tau, limit = getattr(rollout, "torque", None), getattr(rollout, "torque_limit", None)
    if tau is None or limit is None or len(tau) == 0:
        return None, None
    frac = (np.abs(tau) >= SATURATED * limit).mean(axis=0)
    j = int(np.argmax(frac))
    if frac[j] == 0.0:
        return 0.0, None
    names = rollout.joint_names
    return float(frac[j]), (names[j] if j < len(names) else str(j))


def summarise(values: Sequence[float]) -> dict:
    """``{"mean", "min", "max"}`` of per-seed figures (NaN-free floats)."""
    a = np.asarray([v for v in values if v is not None], dtype=float)
    if a.size == 0:
        return {"mean": None, "min": None, "max": None}
    return {"mean": float(a.mean()), "min": float(a.min()), "max": float(a.max())}


#: A sole lifted for less than this [s] and back down is a bounce at lift-off, not a step.
BOUNCE_S = 0.05


@dataclass(frozen=True)
class GaitTiming:
    """How a walk stepped, from its sole forces alone (what the robot's own sensors say,
    not the controller's plan).

    Attributes:
        touchdowns: each foot's touchdown times [s], ``{"l": (...), "r": (...)}``;
        scuffs: touches of a sole lifted for less than a swing but more than a bounce
            (:data:`BOUNCE_S`): a toe catching the floor;
        steps: touchdowns counted over the span measured; cadence_spm: steps per minute;
        cycle_s: the mean time between two touchdowns of the same foot [s];
        stride_m: the torso's forward travel per cycle over that span [m] (``None`` if
        fewer than two cycles were measured).
    """

    touchdowns: dict
    scuffs: int
    steps: int
    cadence_spm: float | None
    cycle_s: float | None
    stride_m: float | None

    def to_dict(self) -> dict:
        """Plain-JSON dictionary."""
        d = asdict(self)
        d["touchdowns"] = {k: list(v) for k, v in self.touchdowns.items()}
        return d


def gait_timing(
    rollout: Rollout,
    weight_n: float,
    after_s: float = 0.0,
    load: float = 0.1,
    lifted_s: float = 0.08,
) -> GaitTiming:
    """The touchdowns of a rollout: a sole takes more than ``load`` of ``weight_n`` [N]
    after it carried almost nothing (under a quarter of that) for at least ``lifted_s``
    [s] (a swing; a shorter lift is a scuff, counted apart); cadence and stride are
    measured over the touchdowns after ``after_s`` [s] (say, once the start-up is
    over), up to the fall if it fell."""
    f = np.asarray(rollout.foot_force, dtype=float).sum(axis=2)  # (N, 2)
    t = np.asarray(rollout.t, dtype=float)
    end = rollout.fall_time if rollout.fell and rollout.fall_time is not None else np.inf
    events: dict[str, tuple[float, ...]] = {}
    scuffs = 0
    for j, side in enumerate("lr"):
        found, lifted_at = [], None
        for i in range(len(t)):
            if f[i, j] < 0.25 * load * weight_n:
                lifted_at = t[i] if lifted_at is None else lifted_at
            elif f[i, j] > load * weight_n:
                if lifted_at is not None and after_s <= t[i] < end:
                    if t[i] - lifted_at >= lifted_s:
                        found.append(float(t[i]))
                    elif t[i] - lifted_at >= BOUNCE_S:
                        scuffs += 1
                lifted_at = None
        events[side] = tuple(found)
    times = sorted(events["l"] + events["r"])
    if len(times) < 3:
        return GaitTiming(events, scuffs, len(times), None, None, None)
    span = times[-1] - times[0]
    cadence = 60.0 * (len(times) - 1) / span if span > 0 else None
    cycles = [np.diff(events[s]) for s in "lr" if len(events[s]) > 1]
    cycle = float(np.mean(np.concatenate(cycles))) if cycles else None
    stride = None
    if cycle is not None and span >= 2 * cycle:
        i0, i1 = np.searchsorted(t, [times[0], times[-1]])
        i1 = min(i1, len(t) - 1)
        travel = float(np.linalg.norm(rollout.torso_pos[i1, :2] - rollout.torso_pos[i0, :2]))
        stride = travel * cycle / span
    return GaitTiming(events, scuffs, len(times), cadence, cycle, stride)
