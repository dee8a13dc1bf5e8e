"""A saved style's values read and checked: each refusal one line naming the field
(``ConfigError``), for :meth:`GaitStyle.from_dict
<imitwalk.step.style.GaitStyle.from_dict>` and :meth:`GaitStyle.check
<imitwalk.step.style.GaitStyle.check>`. Pure NumPy."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import MISSING, fields

import numpy as np

from imitwalk.errors import ConfigError
from imitwalk.retarget.params import LegGeometry

__all__ = [
    "as_array",
    "as_number",
    "check_geometry",
    "entry",
    "need",
    "profile",
    "read_geometry",
    "shown",
]


def shown(v: object) -> str:
    """``v`` as a message shows it: a number as ``%g``, anything else its short repr."""
    if isinstance(v, float | int | np.floating | np.integer) and not isinstance(v, bool):
        return f"{float(v):g}"
    text = repr(v)
    return text if len(text) <= 40 else text[:37] + "..."


def entry(d: dict, key: str) -> object:
    """``d[key]``, or a :class:`ConfigError` saying it is missing."""
    if key not in d:
        raise ConfigError(f"{key} is missing")
    return d[key]


def as_number(v: object, name: str) -> float:
    """``v`` as a float (a :class:`ConfigError` naming ``name`` if it is not a number;
    not-finite ones pass, for :func:`need` to say their range)."""
    if isinstance(v, bool) or not isinstance(v, int | float | np.floating | np.integer):
        raise ConfigError(f"{name} must be a number (got {shown(v)})")
    return float(v)


def as_array(v: object, name: str) -> np.ndarray:
    """``v`` as a float array (a :class:`ConfigError` naming ``name`` if it is not one)."""
    try:
        return np.asarray(v, dtype=float)
    except (TypeError, ValueError):
        raise ConfigError(f"{name} must be a list of numbers (got {shown(v)})") from None


def need(name: str, v: object, ok: Callable[[float], bool], what: str) -> None:
    """Refuse ``v`` unless it is a finite number for which ``ok`` holds (``what``: its
    range and unit, as the message says it)."""
    x = as_number(v, name)
    if not (np.isfinite(x) and ok(x)):
        raise ConfigError(f"{name} must be a finite number {what} (got {shown(x)})")


def profile(name: str, prof: object, least: int = 1) -> int:
    """Refuse a profile that is not a 1-D array of at least ``least`` finite numbers; its
    length."""
    a = np.asarray(prof)
    if a.ndim != 1 or a.dtype.kind not in "fiu" or len(a) < least or not np.isfinite(a).all():
        shape = f"{len(a)} samples" if a.ndim == 1 else f"shape {a.shape}"
        numbers = a.ndim == 1 and a.dtype.kind in "fiu"
        bad = " with a value that is not finite" if numbers and not np.isfinite(a).all() else ""
        need = "a non-empty list of" if least == 1 else f"a list of at least {least}"
        raise ConfigError(f"{name} must be {need} finite numbers (got {shape}{bad})")
    return len(a)


#: The robot's leg measures a style keeps (:class:`LegGeometry`), each with its range.
_GEOMETRY: dict[str, tuple[Callable[[float], bool], str]] = {
    "hip_y": (lambda v: v >= 0, ">= 0 [m]"),
    "hip_z": (lambda v: True, "[m]"),
    "leg": (lambda v: v > 0, "> 0 [m]"),
    "ankle": (lambda v: v >= 0, ">= 0 [m]"),
    "sole_x": (lambda v: True, "[m]"),
    "foot_length": (lambda v: v > 0, "> 0 [m]"),
    "hip_ahead": (lambda v: True, "[m]"),
    "foot_width": (lambda v: v >= 0, ">= 0 [m]"),
}


def check_geometry(g: LegGeometry) -> None:
    """Refuse leg measures no robot has: a length that is not finite or of the wrong sign."""
    for name, (ok, what) in _GEOMETRY.items():
        need(f"geometry.{name}", getattr(g, name), ok, what)


def read_geometry(d: object) -> LegGeometry:
    """The leg measures a style file holds (missing optional ones at their defaults)."""
    if not isinstance(d, dict):
        raise ConfigError(f"geometry must be an object of the leg's measures (got {shown(d)})")
    known = [f.name for f in fields(LegGeometry)]
    unknown = sorted(set(d) - set(known))
    if unknown:
        raise ConfigError(f"geometry.{unknown[0]} is not a leg measure; valid: {', '.join(known)}")
    kw = {}
    for f in fields(LegGeometry):
        if f.name in d:
            kw[f.name] = as_number(d[f.name], f"geometry.{f.name}")
        elif f.default is MISSING:
            raise ConfigError(f"geometry.{f.name} is missing")
    return LegGeometry(**kw)
