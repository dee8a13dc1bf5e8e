"""A protocol file's checks: every key, factor and range, one line per fault (pure Python).

:func:`checked` validates a parsed file for :func:`imitwalk.sim.protocol.load_protocol`;
:data:`FACTORS` lists the factors a protocol may draw and the keys of each (their meaning
is in :mod:`imitwalk.sim.protocol`).
"""

from __future__ import annotations

import math

from imitwalk.errors import ConfigError, unknown_name
from imitwalk.sim.types import ENGINES

__all__ = ["FACTORS", "checked", "fail"]

#: Every factor a protocol may draw, with the keys it takes (``source`` is always allowed
#: and always required: where the range comes from).
FACTORS: dict[str, tuple[str, ...]] = {
    "friction": ("min", "max", "nominal"),
    "mass": ("spread",),
    "servo": ("spread",),
    "torso_com": ("max_m", "at_height_m"),
    "gyro_noise": ("sigma",),
    "accel_noise": ("sigma",),
    "servo_delay": ("min_s", "max_s"),
    "slope": ("min_deg", "max_deg"),
    "cross_slope": ("min_deg", "max_deg"),
    "pushes": ("every_min_s", "every_max_s", "max_speed", "at_height_m"),
    "initial_twist": ("linear", "angular"),
}
_TOP = ("name", "version", "description", "engine", "nominal_first", "factors")
#: (low, high) key pairs that must be ordered.
_ORDERED = (("min", "max"), ("min_s", "max_s"), ("min_deg", "max_deg"))


def fail(where: str, what: str) -> ConfigError:
    return ConfigError(f"protocol {where}: {what}")


def checked(data: object, where: str) -> dict:
    """``data`` (a parsed protocol file from ``where``) validated: the fields of a
    :class:`~imitwalk.sim.protocol.Protocol`, factors as floats.

    Raises:
        ConfigError: one line naming what is wrong (listing the valid keys or factors).
    """
    if not isinstance(data, dict):
        raise fail(where, "expected a JSON object")
    for key in data:
        if key not in _TOP:
            raise unknown_name(f"key in protocol {where}", key, _TOP, ConfigError)
    for key in ("name", "factors"):
        if key not in data:
            raise fail(where, f"has no {key!r}")
    engine = data.get("engine", "mujoco")
    if engine not in ENGINES:
        raise unknown_name(f"engine in protocol {where}", str(engine), ENGINES, ConfigError)
    factors = data["factors"]
    if not isinstance(factors, dict):
        raise fail(where, "'factors' must be an object of factor -> range")
    out = {}
    for name, spec in factors.items():
        if name not in FACTORS:
            raise unknown_name(f"factor in protocol {where}", name, FACTORS, ConfigError)
        if not isinstance(spec, dict):
            raise fail(where, f"factor {name!r} must be an object")
        keys = (*FACTORS[name], "source")
        for key in spec:
            if key not in keys:
                raise unknown_name(f"key of factor {name!r} in {where}", key, keys, ConfigError)
        for key in keys:
            if key not in spec:
                raise fail(where, f"factor {name!r} lacks {key!r}")
        vals = {k: v for k, v in spec.items() if k != "source"}
        for key, v in vals.items():
            if isinstance(v, bool) or not isinstance(v, int | float) or not math.isfinite(v):
                raise fail(where, f"{name}.{key} must be a finite number, got {v!r}")
            if v < 0 and key not in ("min_deg", "max_deg"):
                raise fail(where, f"{name}.{key} is negative ({v})")
        for lo, hi in _ORDERED:
            if lo in vals and vals[lo] > vals[hi]:
                raise fail(where, f"{name}: {lo} {vals[lo]} is above {hi} {vals[hi]}")
        if name == "pushes" and vals["every_min_s"] <= 0:
            raise fail(where, "pushes.every_min_s must be above 0")
        if name in ("mass", "servo") and vals["spread"] >= 1:
            raise fail(where, f"{name}.spread must be below 1, got {vals['spread']}")
        for key in ("at_height_m",):
            if key in vals and vals[key] <= 0:
                raise fail(where, f"{name}.{key} must be above 0")
        out[name] = {**{k: float(v) for k, v in vals.items()}, "source": str(spec["source"])}
    version = data.get("version", 1)
    if isinstance(version, bool) or not isinstance(version, int) or version < 1:
        raise fail(where, f"version must be a whole number >= 1, got {version!r}")
    return {
        "name": str(data["name"]),
        "version": version,
        "description": str(data.get("description", "")),
        "engine": engine,
        "nominal_first": bool(data.get("nominal_first", False)),
        "factors": out,
    }
