"""What the C3D reader takes from a file, via the ``c3d`` package, checked.

* The file must open, have a POINT group with ``POINT:LABELS`` naming every point, a
  frame rate within :data:`~imitwalk.mocap.bounds.FPS_RANGE`, a known ``POINT:UNITS``,
  and every frame its header promises (a truncated data section is refused).
* A sample is invalid (NaN) if its residual is negative, it is all zero, or it is not a
  finite number within :data:`WILD_M` of the origin; the last two are named in a
  :class:`~imitwalk.errors.MocapWarning`.
* ``EVENT:TIMES`` must be ``(2, n)`` (minutes, seconds) with labels to match; events
  with a non-finite time are dropped, and a malformed EVENT group is ignored, each with
  a warning.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field
from pathlib import Path
from typing import NamedTuple

import c3d
import numpy as np

from imitwalk.errors import MocapError, MocapWarning, unknown_name
from imitwalk.mocap._common import snap_rate
from imitwalk.mocap.bounds import check_rate

__all__ = ["POINT_UNITS", "C3dTrial", "read_trial"]

#: POINT:UNITS -> metres per unit.
POINT_UNITS = {"mm": 0.001, "cm": 0.01, "m": 1.0}
#: A sample farther than this from the origin is no coordinate at all, but a corrupt
#: number (3e38, say) [m]; it is marked invalid. (A whole file in the wrong unit is left
#: to the leg-length bound, which names POINT:UNITS.)
WILD_M = 1e6
_WIDTHS = ("LKNEEWIDTH", "RKNEEWIDTH", "LANKLEWIDTH", "RANKLEWIDTH")


@dataclass(frozen=True)
class C3dTrial:
    """A C3D file's points and the parameters the reader uses.

    Attributes:
        xyz: ``(T, N, 3)`` point coordinates [file units], NaN where invalid.
        labels: the ``N`` POINT labels; fps: point rate [Hz]; units: POINT:UNITS.
        first_frame: the trial's first frame number.
        events: (context, label, time [s], frame index) of each event, by time.
        widths: ``PROCESSING:{L,R}{KNEE,ANKLE}WIDTH`` [mm] the file gives validly.
    """

    xyz: np.ndarray
    labels: tuple[str, ...]
    fps: float
    units: str
    first_frame: int
    events: tuple[tuple[str, str, float, int], ...] = ()
    widths: dict[str, float] = field(default_factory=dict)


def _warn(message: str) -> None:
    warnings.warn(message, MocapWarning, stacklevel=4)


def _events(reader: c3d.Reader, fps: float, first: int, src: str) -> tuple:
    group = reader.get("EVENT")
    if group is None or group.get("TIMES") is None or group.get("LABELS") is None:
        return ()
    try:
        times = np.asarray(group.get("TIMES").float_array, dtype=float)
        labels = [str(s).strip() for s in np.atleast_1d(group.get("LABELS").string_array)]
        ctx_p = group.get("CONTEXTS")
        contexts = [str(s).strip() for s in np.atleast_1d(ctx_p.string_array)] if ctx_p else []
    except Exception as exc:  # the c3d package raises TypeError/ValueError/... on bad params
        _warn(f"{src}: ignored the EVENT group: {exc}".replace("\n", " "))
        return ()
    contexts = contexts or [""] * len(labels)
    if times.ndim != 2 or times.shape[1] != 2 or len(labels) != len(times):
        _warn(
            f"{src}: ignored the EVENT group: EVENT:TIMES of shape {times.shape} for "
            f"{len(labels)} labels, expected (2, {len(labels)}) (minutes, seconds)"
        )
        return ()
    t = 60.0 * times[:, 0] + times[:, 1]
    ok = np.isfinite(t) & (np.abs(t) < 1e7)
    if not ok.all():
        _warn(f"{src}: dropped {np.count_nonzero(~ok)} event(s) whose EVENT:TIMES is not finite")
    out = [
        (ctx, label, float(tt), int(round(tt * fps)) + 1 - first)
        for tt, label, ctx, good in zip(t, labels, contexts, ok, strict=False)
        if good
    ]
    return tuple(sorted(out, key=lambda e: e[2]))


def _widths(reader: c3d.Reader, src: str) -> dict[str, float]:
    out = {}
    for key in _WIDTHS:
        p = reader.get(f"PROCESSING:{key}")
        if p is None or p.total_bytes < 4:
            continue
        try:
            value = float(p.float_value)
        except Exception:  # a malformed parameter
            value = float("nan")
        if np.isfinite(value) and 0 < value < 1000:
            out[key] = value
        else:
            _warn(f"{src}: ignored PROCESSING:{key} {value:g} (expected 0-1000 mm)")
    return out


class _Raw(NamedTuple):
    """What the c3d package gives: the reader, labels, frame count promised, frames read
    (each ``(N, 4)``), point rate [Hz] and POINT:UNITS."""

    reader: c3d.Reader
    labels: tuple[str, ...]
    expected: int
    frames: list[np.ndarray]
    rate: float
    units: str


#: The C3D header's size, and the size of a parameter or data block [bytes].
_BLOCK = 512
#: A parameter section's processor types (byte 4 of its header).
_PROCESSORS = {84: "Intel", 85: "DEC", 86: "MIPS"}


def why_unreadable(p: Path) -> str:
    """What is wrong with the header or the parameter section of a file the ``c3d``
    package could not open, from its bytes (in words, without the package's text)."""
    size = p.stat().st_size
    with p.open("rb") as fh:
        head = fh.read(_BLOCK)
        if size < _BLOCK:
            return f"truncated header: the file is {size} bytes, a C3D header is {_BLOCK}"
        if head[1] != 0x50:
            return f"not a C3D file: byte 2 of its header is {head[1]}, not the C3D mark 80"
        start = (head[0] - 1) * _BLOCK
        fh.seek(max(start, 0))
        params = fh.read(4)
    if start < _BLOCK or len(params) < 4:
        return f"truncated parameter section: it should begin at byte {start}; the file is {size}"
    end = start + params[2] * _BLOCK
    if size < end:
        return (
            f"truncated parameter section: its {params[2]} blocks end at byte {end}; "
            f"the file is {size} bytes"
        )
    if params[3] not in _PROCESSORS:
        return f"corrupt parameter section: processor type {params[3]}, expected " + ", ".join(
            f"{k} ({v})" for k, v in _PROCESSORS.items()
        )
    return "corrupt parameter section: a group or parameter in it cannot be read"


def _open(p: Path) -> _Raw:
    with p.open("rb") as handle, warnings.catch_warnings():
        warnings.filterwarnings("ignore", category=UserWarning, module="c3d")
        try:
            reader = c3d.Reader(handle)
        except Exception:  # the c3d package raises bare ValueError/struct.error/...
            raise MocapError(f"{p}: {why_unreadable(p)}") from None
        if reader.get("POINT") is None:
            raise MocapError(f"{p}: no POINT group (expected the marker data)")
        if reader.get("POINT:LABELS") is None:
            raise MocapError(f"{p}: no POINT:LABELS parameter (expected the marker names)")
        labels = []
        for key in ("LABELS", *(f"LABELS{i}" for i in range(2, 10))):  # > 255 points: LABELS2...
            if reader.get(f"POINT:{key}") is not None:
                labels += [
                    str(s).strip()
                    for s in np.atleast_1d(reader.get(f"POINT:{key}").string_array).ravel()
                ]
        expected = int(reader.frame_count)
        frames: list[np.ndarray] = []
        try:
            frames.extend(pts[:, :4].copy() for _, pts, _ in reader.read_frames(copy=True))
        except Exception:
            raise MocapError(
                f"{p}: corrupt or truncated data section: it cannot be read after "
                f"{len(frames)} of {expected} frames"
            ) from None
        units_p = reader.get("POINT:UNITS")
        units = str(units_p.string_value).strip().lower() if units_p else "mm"
        return _Raw(reader, tuple(labels), expected, frames, float(reader.point_rate), units)


def read_trial(path: str | Path) -> C3dTrial:
    """Read and check a C3D file (see the module docstring)."""
    p = Path(path)
    if not p.is_file():
        raise MocapError(f"mocap file not found: {p}")
    try:
        reader, labels, expected, frames, rate, units = _open(p)
    except MocapError:
        raise
    except Exception:  # a parameter the package cannot read (labels, rate, units)
        raise MocapError(f"{p}: {why_unreadable(p)}") from None
    if not frames:
        raise MocapError(f"{p}: C3D file has no frames")
    if len(frames) < expected:
        raise MocapError(
            f"{p}: the data section ends after {len(frames)} of {expected} frames (truncated?)"
        )
    pts = np.array(frames, dtype=float)  # (T, N, 4): x, y, z, residual
    if pts.shape[1] != len(labels):
        _warn(f"{p}: POINT:LABELS names {len(labels)} points, the data has {pts.shape[1]}")
        extra = [f"POINT{i + 1}" for i in range(len(labels), pts.shape[1])]
        labels = (*labels, *extra)[: pts.shape[1]]
    if units not in POINT_UNITS:
        raise unknown_name("C3D POINT:UNITS", units, POINT_UNITS, MocapError)
    fps = snap_rate(check_rate(rate, f"{p}: POINT:RATE"))
    xyz = pts[:, :, :3]
    sane = np.all(np.isfinite(xyz) & (np.abs(xyz) <= WILD_M / POINT_UNITS[units]), axis=2)
    wild = ~sane & ~(pts[:, :, 3] < 0)  # not already marked invalid by its residual
    if wild.any():
        names = sorted({labels[i] for i in np.flatnonzero(wild.any(axis=0))})
        _warn(
            f"{p}: {np.count_nonzero(wild)} sample(s) not finite or beyond {WILD_M:g} m "
            f"marked invalid, in {', '.join(names)}"
        )
    bad = ~sane | ~(pts[:, :, 3] >= 0) | np.all(xyz == 0, axis=2)
    xyz = np.where(bad[:, :, None], np.nan, xyz)
    try:
        first = int(reader.first_frame)
        events = _events(reader, fps, first, str(p))
        widths = _widths(reader, str(p))
    except Exception:  # a parameter the package cannot read
        raise MocapError(f"{p}: {why_unreadable(p)}") from None
    return C3dTrial(xyz, labels, fps, units, first, events, widths)
