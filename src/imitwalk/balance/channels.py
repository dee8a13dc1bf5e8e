"""Named balance channels and measured features of the per-tick controller (pure NumPy).

A *channel* is an offset [rad] added to the reference's joint targets on one or more
of the legs' balance joints; a *feature* is one of the robot's own measurements, as the
state estimator (:mod:`imitwalk.balance.estimator`) gives it. One channel depends on the gait's
phase: ``turn`` steers. A steady turn of ``u`` per step turns each stance foot, planted,
by −u relative to the pelvis over its stance (hip yaw +u/2 → −u/2) and brings each swing
foot round by +u before it lands (−u/2 → +u/2, smoothly), so that the walk turns by u
every step; the reference's stance schedule says which leg does which. The per-tick controller
(:mod:`imitwalk.balance.feedback`) maps features to channels; everything crossing that map is
named, so a gain reads as "``gyro_y`` → ``ankle_pitch``", never as an index.
"""

from __future__ import annotations

from collections.abc import Collection, Iterable

import numpy as np

from imitwalk.errors import ConfigError, unknown_name

__all__ = ["CHANNELS", "FEATURES", "PHASED", "channel_matrix", "check_names", "turn_pattern"]

#: Channel → the joint roles it moves, each by the channel's value (radians).
#: ``ankle_pitch`` / ``ankle_roll`` / ``hip_yaw`` / ``hip_pitch`` move both legs' joints
#: together; the ``l_`` / ``r_`` channels one leg's.
CHANNELS: dict[str, tuple[str, ...]] = {
    "ankle_pitch": ("l_ankle_pitch", "r_ankle_pitch"),
    "ankle_roll": ("l_ankle_roll", "r_ankle_roll"),
    "hip_yaw": ("l_hip_yaw", "r_hip_yaw"),
    "hip_pitch": ("l_hip_pitch", "r_hip_pitch"),
    "turn": ("l_hip_yaw", "r_hip_yaw"),
    "hip_roll": ("l_hip_roll", "r_hip_roll"),
    "l_ankle_pitch": ("l_ankle_pitch",),
    "r_ankle_pitch": ("r_ankle_pitch",),
    "l_ankle_roll": ("l_ankle_roll",),
    "r_ankle_roll": ("r_ankle_roll",),
    "l_hip_roll": ("l_hip_roll",),
    "r_hip_roll": ("r_hip_roll",),
    "l_hip_pitch": ("l_hip_pitch",),
    "r_hip_pitch": ("r_hip_pitch",),
}

#: The channels whose joint offsets follow the gait's phase (:func:`turn_pattern`).
PHASED = ("turn",)

#: What the controller may feed back, all from the robot's own sensors: the torso gyro
#: [rad/s]; roll and pitch of the torso [rad] from the gyro and accelerometer; heading
#: [rad], the integrated yaw rate less the reference's own commanded turn.
FEATURES: tuple[str, ...] = ("gyro_x", "gyro_y", "gyro_z", "roll", "pitch", "heading")


def check_names(kind: str, names: Iterable[str], valid: Collection[str]) -> tuple[str, ...]:
    """``names`` as a tuple, each one in ``valid`` and none twice.

    Raises:
        ConfigError: an unknown name (listing the valid ones), a repeat, or no names.
    """
    names = tuple(names)
    if not names:
        raise ConfigError(f"no {kind}s given; valid: {', '.join(valid)}")
    for n in names:
        if n not in valid:
            raise unknown_name(kind, n, valid, ConfigError)
    if len(set(names)) != len(names):
        raise ConfigError(f"{kind}s {', '.join(names)}: a name is given twice")
    return names


def turn_pattern(stance: np.ndarray) -> np.ndarray:
    """``(N, 2)`` each leg's hip-yaw offset per loop tick for a turn of 1 rad per step:
    +½ → −½ linearly over the leg's stance, −½ → +½ (smoothstep) over its swing.

    Args:
        stance: ``(N, 2)`` bool, left and right foot on the floor at each loop tick.
    """
    stance = np.asarray(stance, dtype=bool)
    n = len(stance)
    out = np.zeros((n, 2))
    for leg in range(2):
        on = stance[:, leg]
        if on.all() or not on.any():
            continue  # never swings (or never stands): nothing to steer with
        start = int(np.flatnonzero(on & ~np.roll(on, 1))[0])  # a stance begins here
        k = 0
        while k < n:
            state = on[(start + k) % n]
            run = 1
            while k + run < n and on[(start + k + run) % n] == state:
                run += 1
            u = (np.arange(run) + 1.0) / run  # progress through this stance or swing
            idx = (start + k + np.arange(run)) % n
            out[idx, leg] = 0.5 - u if state else -0.5 + u * u * (3.0 - 2.0 * u)
            k += run
    return out


def channel_matrix(
    joint_names: tuple[str, ...], channels: tuple[str, ...], stance: np.ndarray | None = None
) -> np.ndarray:
    """``(P, n, m)`` the joint offsets [rad] of one radian on each channel, per loop tick
    (P = N with a phased channel, given the reference's ``(N, 2)`` stance schedule;
    else P = 1).

    Raises:
        ConfigError: an unknown channel, one whose joints the robot lacks (listing the
            robot's joints), or a phased channel without a stance schedule.
    """
    check_names("channel", channels, CHANNELS)
    phased = [c for c in channels if c in PHASED]
    if phased and stance is None:
        raise ConfigError(f"channel {phased[0]!r} follows the gait: it needs the stance schedule")
    pattern = turn_pattern(stance) if phased and stance is not None else np.ones((1, 2))
    out = np.zeros((len(pattern), len(joint_names), len(channels)))
    for c, name in enumerate(channels):
        for leg, role in enumerate(CHANNELS[name]):
            if role not in joint_names:
                raise unknown_name(f"joint for channel {name!r}", role, joint_names, ConfigError)
            out[:, joint_names.index(role), c] = pattern[:, leg] if name in PHASED else 1.0
    return out
