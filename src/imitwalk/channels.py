"""Named balance channels and measured features of the per-tick controller (pure NumPy).

A *channel* is an offset [rad] added to the reference's joint targets on one or more
of the legs' balance joints; a *feature* is one of the robot's own measurements, as the
state estimator (:mod:`imitwalk.estimator`) gives it. The per-tick controller
(:mod:`imitwalk.feedback`) maps features to channels; everything crossing that map is
named, so a gain reads as "``gyro_y`` → ``ankle_pitch``", never as an index.
"""

from __future__ import annotations

import numpy as np

from imitwalk.errors import ConfigError, unknown_name

__all__ = ["CHANNELS", "FEATURES", "channel_matrix", "check_names"]

#: Channel → the joint roles it moves, each by the channel's value (radians).
#: ``ankle_pitch`` / ``ankle_roll`` / ``hip_yaw`` move both legs' joints together; the
#: ``l_`` / ``r_`` channels one leg's.
CHANNELS: dict[str, tuple[str, ...]] = {
    "ankle_pitch": ("l_ankle_pitch", "r_ankle_pitch"),
    "ankle_roll": ("l_ankle_roll", "r_ankle_roll"),
    "hip_yaw": ("l_hip_yaw", "r_hip_yaw"),
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

#: What the controller may feed back, all from the robot's own sensors: the torso gyro
#: [rad/s]; roll and pitch of the torso [rad] from the gyro and accelerometer; heading
#: [rad], the integrated yaw rate less the reference's own commanded turn.
FEATURES: tuple[str, ...] = ("gyro_x", "gyro_y", "gyro_z", "roll", "pitch", "heading")


def check_names(kind: str, names, valid) -> tuple[str, ...]:
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


def channel_matrix(joint_names: tuple[str, ...], channels: tuple[str, ...]) -> np.ndarray:
    """``(n, m)`` the joint offsets [rad] of one radian on each channel.

    Raises:
        ConfigError: an unknown channel, or one whose joints the robot lacks (listing
            the robot's joints).
    """
    check_names("channel", channels, CHANNELS)
    out = np.zeros((len(joint_names), len(channels)))
    for c, name in enumerate(channels):
        for role in CHANNELS[name]:
            if role not in joint_names:
                raise unknown_name(f"joint for channel {name!r}", role, joint_names, ConfigError)
            out[joint_names.index(role), c] = 1.0
    return out
