"""C3D reader (Vicon Plug-in-Gait marker set), via the ``c3d`` package.

Keypoints, in the file's lab axes (z-up; y-up labs are mapped by (x, y, z) -> (x, -z, y)):

* Plug-in-Gait model outputs, when the file has them (preferred): ``pelvis = PELO``
  (mid-point of the hip centres), hips ``LFEP/RFEP`` (femur proximal point = hip
  centre), knees ``LFEO/RFEO``, ankles ``LTIO/RTIO``.
* otherwise from markers: hip centres by the Harrington et al. (2007, J Biomech 40:595)
  regression in the pelvis frame (origin mid-ASIS, x anterior, y up, z right; PW =
  inter-ASIS width, PD = mid-ASIS to mid-PSIS (or SACR) depth, mm)::

      x = -0.24 PD - 9.9,  y = -0.30 PW - 10.9,  z = +-(0.33 PW + 7.3)

  knees / ankles at the mid-point of the lateral and medial markers, or without a medial
  marker by the Plug-in-Gait chord rule: the centre C lies half the joint width plus a
  marker radius medial of the lateral marker J, in the plane of J, the wand marker (THI,
  TIB) and the proximal centre P, with P-C perpendicular to J-C. Joint widths come from
  ``PROCESSING:{L,R}{KNEE,ANKLE}WIDTH`` [mm] (defaults 100 / 70 mm, marker 14 mm).
* toes: ``LTOE/RTOE``; optional: neck = mid(C7, CLAV), head = centroid of LFHD RFHD LBHD
  RBHD, shoulders LSHO, elbows LELB, wrists mid(LWRA, LWRB).

Invalid samples (negative residual or all-zero) are NaN; gaps up to ``max_gap`` [s] are
filled (:func:`imitwalk.mocap.gaps.fill_gaps`) and noted in ``Motion.filled``.
"""

from __future__ import annotations

from collections.abc import Callable
from functools import partial
from pathlib import Path

import numpy as np

from imitwalk.errors import MocapError, unknown_name
from imitwalk.mocap._common import UP_AXES, check_keypoints, z_up
from imitwalk.mocap.bounds import check_leg, check_motion
from imitwalk.mocap.c3d_file import POINT_UNITS, C3dTrial, read_trial
from imitwalk.mocap.gaps import GapTooLong, fill_gaps
from imitwalk.mocap.motion import KEYPOINTS, LOWER_BODY, Motion
from imitwalk.mocap.orient import decide_up

__all__ = ["MARKER_ALIASES", "POINT_UNITS", "read_c3d"]

#: Plug-in-Gait role (left side; right is the same with "R") -> accepted labels.
MARKER_ALIASES: dict[str, tuple[str, ...]] = {
    "ASI": ("ASI", "ASIS", "FWT"),  # FWT/BWT: front/back waist of the CMU 41-marker set
    "PSI": ("PSI", "PSIS", "BWT"),
    "THI": ("THI", "LTHI"),
    "KNE": ("KNE", "LEK", "KNEE", "LFE"),
    "KNM": ("KNM", "MEK", "MKNE", "MFE", "KNEM"),
    "TIB": ("TIB", "LSHA", "SHA", "SHN"),
    "ANK": ("ANK", "LM", "LMAL", "ANKLE"),
    "MED": ("MED", "MM", "MMAL", "ANKM"),
    "TOE": ("TOE", "MT2", "TOE2"),
    "SHO": ("SHO",),
    "ELB": ("ELB",),
    "WRA": ("WRA",),
    "WRB": ("WRB",),
    "FHD": ("FHD",),
    "BHD": ("BHD",),
}
_CENTRAL = {"SACR": ("SACR", "SACRUM"), "C7": ("C7",), "CLAV": ("CLAV", "JN", "IJ")}
_PIG = ("PELO", "LFEP", "RFEP", "LFEO", "RFEO", "LTIO", "RTIO")
_MARKER_RADIUS_MM = 7.0


def _chord(joint: np.ndarray, wand: np.ndarray, prox: np.ndarray, offset: float) -> np.ndarray:
    """Joint centre ``offset`` medial of the lateral marker ``joint`` (all ``(T, 3)``)."""
    a = prox - joint
    length = np.linalg.norm(a, axis=1, keepdims=True)
    a = a / length
    w = wand - joint
    w = w - np.sum(w * a, axis=1, keepdims=True) * a
    medial = -w / np.linalg.norm(w, axis=1, keepdims=True)
    cos = np.clip(offset / length, -1.0, 1.0)
    return joint + offset * (cos * a + np.sqrt(1.0 - cos**2) * medial)


def _hip_centres(
    lasi: np.ndarray, rasi: np.ndarray, back: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Harrington (2007) hip centres [mm] from ASIS markers and mid-PSIS/SACR (``(T, 3)``)."""
    origin = (lasi + rasi) / 2
    z = rasi - lasi
    pw = np.linalg.norm(z, axis=1, keepdims=True)
    z = z / pw
    x = origin - back
    pd = np.linalg.norm(x, axis=1, keepdims=True)
    x = x - np.sum(x * z, axis=1, keepdims=True) * z
    x = x / np.linalg.norm(x, axis=1, keepdims=True)
    y = np.cross(z, x)
    out = []
    for sign in (-1.0, 1.0):  # left, right
        loc = (-0.24 * pd - 9.9, -0.30 * pw - 10.9, sign * (0.33 * pw + 7.3))
        out.append(origin + loc[0] * x + loc[1] * y + loc[2] * z)
    return out[0], out[1]


class _Markers:
    """A trial's marker trajectories by Plug-in-Gait role, each gap-filled once [mm]."""

    def __init__(self, trial: C3dTrial, src: str, max_gap: float) -> None:
        """Index ``trial``'s labels; gaps up to ``max_gap`` [s] will be filled."""
        self.src = src
        self.xyz, self.fps = trial.xyz, trial.fps
        self.to_mm = POINT_UNITS[trial.units] * 1000.0
        # lookup by upper-case label without a "Subject:" prefix; the first of duplicates wins
        labels = trial.labels
        self.index = {
            lab.rsplit(":", 1)[-1].upper(): i for i, lab in reversed(list(enumerate(labels)))
        }
        self.max_frames = int(round(max_gap * trial.fps))
        self.filled: list[str] = []
        self._cache: dict[str, np.ndarray] = {}

    def get(self, role: str) -> np.ndarray:
        """Filled ``(T, 3)`` trajectory [mm] of a role such as ``LKNE`` or ``C7``."""
        if role not in self._cache:
            if role in _CENTRAL:
                names = _CENTRAL[role]
            elif role[1:] in MARKER_ALIASES:
                names = tuple(role[0] + a for a in MARKER_ALIASES[role[1:]])
            else:
                names = (role,)
            label = next((n for n in names if n in self.index), None)
            if label is None:
                raise MocapError(
                    f"{self.src}: required marker {role} not found (tried {', '.join(names)})"
                )
            column = self.xyz[:, self.index[label]] * self.to_mm
            try:
                self._cache[role], notes = fill_gaps(column, self.max_frames, label, self.fps)
            except GapTooLong as exc:
                raise GapTooLong(f"{self.src}: {exc}") from None
            self.filled.extend(notes)
        return self._cache[role]

    def has(self, role: str) -> bool:
        """Whether the trial has a usable marker for ``role`` (fills it on the way)."""
        try:
            self.get(role)
        except MocapError:
            return False
        return True

    def mean(self, *roles: str) -> np.ndarray:
        """The mean ``(T, 3)`` trajectory [mm] of these roles' markers (summed in order)."""
        total = self.get(roles[0])
        for role in roles[1:]:
            total = total + self.get(role)
        return total / len(roles)


def _model_output_keypoints(marker: _Markers) -> dict[str, np.ndarray]:
    """Pelvis, hips, knees and ankles ``(T, 3)`` [mm] from the Plug-in-Gait model outputs."""
    kp: dict[str, np.ndarray] = {}
    kp["pelvis"] = marker.get("PELO")
    for s in "LR":
        kp[f"{s.lower()}_hip"], kp[f"{s.lower()}_knee"] = (
            marker.get(f"{s}FEP"),
            marker.get(f"{s}FEO"),
        )
        kp[f"{s.lower()}_ankle"] = marker.get(f"{s}TIO")
    return kp


def _marker_keypoints(marker: _Markers, widths: dict[str, float]) -> dict[str, np.ndarray]:
    """Pelvis, hips (Harrington 2007), knees and ankles ``(T, 3)`` [mm] from the markers;
    ``widths``: the trial's joint widths [mm]."""
    kp: dict[str, np.ndarray] = {}
    has = marker.has
    back = marker.get("SACR") if has("SACR") else (marker.get("LPSI") + marker.get("RPSI")) / 2
    kp["l_hip"], kp["r_hip"] = _hip_centres(marker.get("LASI"), marker.get("RASI"), back)
    kp["pelvis"] = (kp["l_hip"] + kp["r_hip"]) / 2
    for s in "LR":
        k = s.lower()
        knee_off = widths.get(f"{s}KNEEWIDTH", 100.0) / 2 + _MARKER_RADIUS_MM
        ankle_off = widths.get(f"{s}ANKLEWIDTH", 70.0) / 2 + _MARKER_RADIUS_MM
        lat = marker.get(f"{s}KNE")
        kp[f"{k}_knee"] = (
            (lat + marker.get(f"{s}KNM")) / 2
            if has(f"{s}KNM")
            else _chord(lat, marker.get(f"{s}THI"), kp[f"{k}_hip"], knee_off)
        )
        lat = marker.get(f"{s}ANK")
        kp[f"{k}_ankle"] = (
            (lat + marker.get(f"{s}MED")) / 2
            if has(f"{s}MED")
            else _chord(lat, marker.get(f"{s}TIB"), kp[f"{k}_knee"], ankle_off)
        )
    return kp


def _optional_keypoints(marker: _Markers) -> tuple[dict[str, np.ndarray], tuple[str, ...]]:
    """The upper-body keypoints ``(T, 3)`` [mm] the trial has, and the names of those it
    lacks."""
    optional: dict[str, Callable[[], np.ndarray]] = {
        "neck": partial(marker.mean, "C7", "CLAV"),
        "head": partial(marker.mean, "LFHD", "RFHD", "LBHD", "RBHD"),
    }
    for s in "LR":
        optional[f"{s.lower()}_shoulder"] = partial(marker.get, f"{s}SHO")
        optional[f"{s.lower()}_elbow"] = partial(marker.get, f"{s}ELB")
        optional[f"{s.lower()}_wrist"] = partial(marker.mean, f"{s}WRA", f"{s}WRB")
    found: dict[str, np.ndarray] = {}
    missing = []
    for key, make in optional.items():
        try:
            found[key] = make()
        except MocapError:
            missing.append(key)
    return found, tuple(missing)


def _guess_up(kp: dict[str, np.ndarray], src: str) -> str:
    """The lab's up axis, told from the motion of the keypoints ``(T, 3)`` [mm]."""
    feet = np.stack([kp[k] for k in ("l_ankle", "r_ankle", "l_toe", "r_toe")], axis=1)
    leg = np.nanmedian(np.linalg.norm(kp["l_knee"] - kp["l_hip"], axis=1))
    leg += np.nanmedian(np.linalg.norm(kp["l_ankle"] - kp["l_knee"], axis=1))  # [mm]
    check_leg(float(leg) / 1000.0, src, "check POINT:UNITS")
    top = kp.get("neck", kp["pelvis"])
    up, _ = decide_up(top, feet, float(leg), src)
    return up


def read_c3d(
    path: str | Path,
    *,
    max_gap: float = 0.1,
    use_model_outputs: bool = True,
    up: str | None = None,
) -> Motion:
    """Read a C3D trial.

    Args:
        path: the ``.c3d`` file (checked by :func:`~imitwalk.mocap.c3d_file.read_trial`).
        max_gap: longest gap [s] of a marker that is filled by interpolation.
        use_model_outputs: use Plug-in-Gait joint centres when the file has them.
        up: the lab's up axis (``x y z -x -y -z``); None tells it from the motion.

    Returns:
        a :class:`Motion`: ``data`` ``(T, 3 N)`` every POINT label (markers and model
        outputs) in the file's units, NaN where invalid; ``keypoints`` ``(T, 3)`` [m] z
        up; ``meta``: ``units``, ``hip_method``, ``missing_keypoints``, ``events``
        (context, label, time [s], frame index), ``first_frame``.
    """
    src = str(path)
    if up is not None and up not in UP_AXES:
        raise unknown_name("up axis", up, UP_AXES, MocapError)
    trial = read_trial(path)
    xyz, labels, fps, units = trial.xyz, trial.labels, trial.fps, trial.units
    marker = _Markers(trial, src, max_gap)
    use_pig = use_model_outputs and all(p in marker.index for p in _PIG)
    if use_pig:
        kp = _model_output_keypoints(marker)
    else:
        kp = _marker_keypoints(marker, trial.widths)
    kp["l_toe"], kp["r_toe"] = marker.get("LTOE"), marker.get("RTOE")
    optional, missing = _optional_keypoints(marker)
    kp.update(optional)
    guessed = up is None
    if up is None:
        up = _guess_up(kp, src)
    keypoints = check_keypoints(
        {k: z_up(kp[k] / 1000.0, up) for k in KEYPOINTS if k in kp}, src, len(xyz), LOWER_BODY
    )
    channels = tuple(f"{lab}.{c}" for lab in labels for c in "xyz")
    meta = {
        "units": units,
        "up_axis": up,
        "up_guessed": guessed,
        "hip_method": "plug-in-gait outputs" if use_pig else "harrington2007",
        "missing_keypoints": missing,
        "events": list(trial.events),
        "first_frame": trial.first_frame,
    }
    data = xyz.reshape(len(xyz), -1)
    filled = tuple(marker.filled)
    motion = Motion(fps, channels, data, keypoints, src, "c3d", filled=filled, meta=meta)
    return check_motion(motion, "check POINT:UNITS")
