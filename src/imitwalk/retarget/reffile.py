"""What a reference ``.npz`` must hold to be read back (:meth:`Reference.load`), checked.

:meth:`~imitwalk.retarget.reference.Reference.save` writes the arrays of a
:class:`~imitwalk.retarget.reference.Reference` and its other fields as JSON metadata
(``meta_json``). A file is refused in one line naming it and what is wrong unless it is
an ``.npz`` archive (:func:`~imitwalk.readback.read_npz`) holding:

* metadata that is a JSON object of a ``format`` this imitwalk reads (up to
  :data:`REFERENCE_FORMAT`; none: a reference written before versions, format 1), with
  ``robot``, ``joint_names`` (``n`` strings), ``mapping``, ``dt`` and ``period``
  (finite, above 0) [s], any optional field of its type, a ``command`` that
  :class:`~imitwalk.retarget.command.GaitCommand` takes, ``params`` that
  :class:`~imitwalk.retarget.params.GaitParams` takes (numbers), and ``settings`` whose
  clip and robot entries are of their types;
* the arrays in :data:`ARRAYS`, numbers, with the shapes the trajectories need:
  ``scales (S,)`` finite and increasing, ``loops (S, N, n)`` and ``starts (S, M, n)``
  finite [rad], ``strides (S,)``, ``start_travel (S, M)``, ``phase (N,)``,
  ``stance (N, 2)``.
"""

from __future__ import annotations

import json
import math
from dataclasses import fields
from pathlib import Path
from typing import Any

import numpy as np

from imitwalk.errors import ConfigError, RunError
from imitwalk.readback import check_fields, check_format, read_npz
from imitwalk.retarget.command import LIMITS, GaitCommand
from imitwalk.retarget.params import GaitParams

__all__ = ["ARRAYS", "REFERENCE_FORMAT", "read_reference_file"]

#: The reference format :meth:`~imitwalk.retarget.reference.Reference.save` writes, and
#: the newest this imitwalk reads.
REFERENCE_FORMAT = 1
#: What a reference file is, as messages name it.
WHAT = "a reference .npz written by imitwalk retarget"
#: The arrays every reference holds.
ARRAYS = ("scales", "loops", "starts", "strides", "start_travel", "phase", "stance", "residual_mm")
_META = {"robot": str, "joint_names": list, "mapping": str, "dt": float, "period": float}
_OPTIONAL = {
    "clipped": list,
    "source": str,
    **dict.fromkeys(("checks", "params", "search", "settings", "command", "scale_params"), dict),
}
_MOCAP = (".bvh", ".amc", ".asf", ".c3d")
#: The types of a stored ``settings`` object's entries (each may be absent).
_SETTINGS: dict[str, type | tuple[type, ...]] = {
    "search": bool,
    "motion_format": str,
    "motion_fps": float,
    "filled": list,
    "robot": (str, type(None)),
    "joint_map": (str, type(None)),
}


def read_reference_file(path: str | Path) -> tuple[dict[str, Any], dict[str, np.ndarray]]:
    """The checked metadata and arrays of the reference file at ``path``.

    Raises:
        RunError: one line naming the file and what is wrong (see the module doc).
    """
    if Path(path).suffix.lower() in _MOCAP:
        raise RunError(
            f"{path} is a mocap file, not a reference: make one with "
            f"imitwalk retarget {path} --out REF.npz"
        )
    arrays = read_npz(path, WHAT, RunError, (*ARRAYS, "meta_json"))
    try:
        meta = json.loads(str(arrays.pop("meta_json")))
    except (ValueError, RecursionError):
        raise RunError(f"{path}: its metadata is not valid JSON; expected {WHAT}") from None
    if isinstance(meta, dict):
        check_format(meta, REFERENCE_FORMAT, f"{path} metadata", RunError)
    check_fields(meta, _META, f"{path} metadata", RunError, _OPTIONAL)
    if meta.pop("scale_params", None):
        raise RunError(
            f"{path}: its parameters differ per stride (search_config.refine_per_scale, "
            "removed in imitwalk 0.5); make it again with imitwalk retarget CLIP --out REF.npz"
        )
    if not all(isinstance(j, str) for j in meta["joint_names"]):
        raise RunError(f"{path} metadata: joint_names are not all strings")
    for key in ("dt", "period"):
        if not (math.isfinite(meta[key]) and meta[key] > 0):
            raise RunError(f"{path} metadata: {key} is {meta[key]}; expected a time above 0 s")
    meta["joint_names"] = tuple(meta["joint_names"])
    _check_command(meta.get("command") or {}, f"{path} metadata")
    _check_params(meta.get("params") or {}, f"{path} metadata")
    check_fields(meta.get("settings") or {}, {}, f"{path} metadata settings", RunError, _SETTINGS)
    _check_arrays(arrays, len(meta["joint_names"]), str(path))
    return meta, arrays


def _check_command(command: dict, where: str) -> None:
    """Refuse a stored gait command that :class:`GaitCommand` would not build."""
    unknown = sorted(set(command) - set(LIMITS))
    if unknown:
        raise RunError(f"{where}: unknown command field(s) {', '.join(unknown)}")
    check_fields(command, {}, f"{where} command", RunError, dict.fromkeys(LIMITS, float))
    try:
        GaitCommand.from_dict(command)
    except ConfigError as exc:
        raise RunError(f"{where}: its command is out of range: {exc}") from None


def _check_params(params: dict, where: str) -> None:
    """Refuse stored reference parameters that :class:`GaitParams` would not build."""
    names = [f.name for f in fields(GaitParams)]
    if unknown := sorted(set(params) - set(names)):
        raise RunError(
            f"{where}: unknown parameter(s) {', '.join(unknown)}; valid: {', '.join(names)}"
        )
    check_fields(
        params,
        {},
        f"{where} params",
        RunError,
        {**dict.fromkeys(names, float), "lift": (float, type(None))},
    )
    for k, v in params.items():
        if v is not None and not math.isfinite(v):
            raise RunError(f"{where}: params {k} is {v}; expected a finite number")


def _check_arrays(arrays: dict[str, np.ndarray], n: int, where: str) -> None:
    """Refuse arrays that are not numbers, or whose shapes do not agree with ``n`` joints
    and ``S`` scales (see the module doc)."""
    for key in ARRAYS:
        a = arrays[key]
        if not (np.issubdtype(a.dtype, np.number) or a.dtype == bool):
            raise RunError(f"{where}: {key} holds {a.dtype}, not numbers")
    scales, loops, starts = arrays["scales"], arrays["loops"], arrays["starts"]
    s = scales.shape
    if (
        len(s) != 1
        or s[0] == 0
        or loops.ndim != 3
        or starts.ndim != 3
        or loops.shape[::2] != (s[0], n)
        or starts.shape[::2] != (s[0], n)
        or loops.shape[1] == 0
    ):
        raise RunError(
            f"{where}: scales {s}, loops {loops.shape} and starts {starts.shape} do not fit "
            f"{n} joints: expected (S,), (S, N, {n}), (S, M, {n})"
        )
    m, t = starts.shape[1], loops.shape[1]
    shapes = {"strides": (s[0],), "start_travel": (s[0], m), "phase": (t,), "stance": (t, 2)}
    for key, shape in shapes.items():
        if arrays[key].shape != shape:
            raise RunError(f"{where}: {key} has the shape {arrays[key].shape}; expected {shape}")
    for key in ("scales", "loops", "starts", "strides", "start_travel"):
        if not np.isfinite(arrays[key]).all():
            raise RunError(f"{where}: {key} is not finite")
    if not (np.diff(scales) > 0).all():
        raise RunError(f"{where}: scales {scales.tolist()} are not increasing")
