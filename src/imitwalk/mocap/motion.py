"""The one record every mocap reader produces.

Conventions (all readers):

* world frame: right-handed, metres, **z up**; the ground is near z = 0 when the
  source says where it is (readers do not move it; :func:`Motion.grounded` shifts the
  lowest foot keypoint over the clip to z = 0 for sources that do not).
* ``keypoints``: ``(T, 3)`` arrays [m] named by :data:`KEYPOINTS`, world frame, finite.
  The walking direction is left as recorded (no re-orientation): the retargeting
  stage works out the heading.
* required keypoints: the lower body, :data:`LOWER_BODY` (pelvis, hips, knees, ankles,
  toes), from every reader; a file that cannot give them raises ``MocapError``.
  ASF/AMC and DeepMimic give all of :data:`KEYPOINTS`. For BVH and C3D the trunk, head
  and arm keypoints are optional: those the rig does not name (or whose markers the file
  lacks) are absent from ``keypoints`` and listed in ``meta["missing_keypoints"]``.
* bounds: every reader holds its Motion to :mod:`imitwalk.mocap.bounds` (frame rate,
  leg length, finite keypoints near the pelvis, finite ``data``).
* keypoint meaning: joint centres. ``pelvis`` is the root of a skeleton (for CMU rigs
  ~10 cm above the hip centres, for DeepMimic at hip height) and the mid-point of the
  hip centres for C3D; ``l_toe``/``r_toe`` is the ball of the foot (toe joint of a
  skeleton, toe marker of C3D, sole under the ball for DeepMimic); ``neck`` is the base
  of the neck; ``head`` is the head joint (C3D: centroid of the head markers).
* ``data``: the per-frame values as read (BVH/AMC channels in degrees or the
  file's units, C3D marker coordinates in the file's units with invalid samples
  as NaN, DeepMimic frame vectors), ``(T, D)``, with ``channels`` naming the ``D`` columns.
  Columns with non-finite values that move no keypoint are dropped (with a warning) and
  named in ``meta["dropped_channels"]``; elsewhere ``data`` is finite.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from imitwalk.errors import MocapError, unknown_name

__all__ = ["KEYPOINTS", "LOWER_BODY", "Motion"]

#: Body keypoint names, in this order (:data:`LOWER_BODY` are the ones every reader gives).
KEYPOINTS: tuple[str, ...] = (
    "pelvis",
    "l_hip",
    "r_hip",
    "l_knee",
    "r_knee",
    "l_ankle",
    "r_ankle",
    "l_toe",
    "r_toe",
    "l_shoulder",
    "r_shoulder",
    "l_elbow",
    "r_elbow",
    "l_wrist",
    "r_wrist",
    "neck",
    "head",
)

#: Keypoints every reader must provide (the rest may be absent for C3D).
LOWER_BODY: tuple[str, ...] = KEYPOINTS[:9]


@dataclass(frozen=True)
class Motion:
    """A motion clip.

    Attributes:
        fps: frame rate [Hz].
        channels: names of the columns of ``data`` (joint channels or markers).
        data: ``(T, D)`` per-frame values as read from the file.
        keypoints: name -> ``(T, 3)`` positions [m], world frame, z up.
        source: path of the file read.
        format: one of ``"bvh"``, ``"amc"``, ``"c3d"``, ``"deepmimic"``.
        filled: human-readable notes on gaps that were filled (empty if none).
        loop: True if the clip is a closed loop (DeepMimic ``"Loop": "wrap"``).
        meta: reader-specific facts (units, skipped frames, events, ...);
            ``meta["period_frames"]`` of a loop is its period in frames.
    """

    fps: float
    channels: tuple[str, ...]
    data: np.ndarray
    keypoints: dict[str, np.ndarray]
    source: str
    format: str
    filled: tuple[str, ...] = ()
    loop: bool = False
    meta: dict = field(default_factory=dict)

    @property
    def n_frames(self) -> int:
        """Number of frames ``T``."""
        return int(self.data.shape[0])

    @property
    def dt(self) -> float:
        """Frame period [s]."""
        return 1.0 / self.fps

    @property
    def duration(self) -> float:
        """Clip length [s] (``T / fps``)."""
        return self.n_frames / self.fps

    def keypoint_array(self, names: tuple[str, ...] | None = None) -> np.ndarray:
        """Stack keypoints into a ``(T, len(names), 3)`` array [m].

        ``names=None`` takes every keypoint present, in :data:`KEYPOINTS` order.
        """
        if names is None:
            names = tuple(n for n in KEYPOINTS if n in self.keypoints)
        absent = [n for n in names if n not in self.keypoints]
        if absent:
            raise unknown_name("keypoint", absent[0], self.keypoints, MocapError)
        return np.stack([self.keypoints[n] for n in names], axis=1)

    def grounded(self) -> Motion:
        """A copy with every keypoint shifted in z so the lowest foot keypoint is at z = 0."""
        feet = [self.keypoints[n][:, 2] for n in LOWER_BODY[5:] if n in self.keypoints]
        dz = float(min(f.min() for f in feet))
        shifted = {n: p - np.array([0.0, 0.0, dz]) for n, p in self.keypoints.items()}
        return replace(self, keypoints=shifted, meta={**self.meta, "ground_shift_m": -dz})
