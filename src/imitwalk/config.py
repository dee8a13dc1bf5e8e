"""Settings: frozen dataclasses per stage, and dotted ``key=value`` overrides.

``apply_overrides(cfg, ["search.generations=2", "params.sway=0.8"])`` returns a copy
of ``cfg`` with those fields replaced, converting each value to the type of the
field it replaces. An unknown key raises :class:`~imitwalk.errors.ConfigError`
listing the valid ones.
"""

from __future__ import annotations

import dataclasses
import json
from typing import Any, cast

from imitwalk.errors import ConfigError, unknown_name

__all__ = ["apply_overrides", "from_dict", "to_dict"]


def _coerce(text: str, current: Any, key: str) -> Any:
    try:
        if isinstance(current, bool):
            if text.lower() in ("1", "true", "yes", "on"):
                return True
            if text.lower() in ("0", "false", "no", "off"):
                return False
            raise ValueError
        if isinstance(current, int) and not isinstance(current, bool):
            return int(text)
        if isinstance(current, float):
            return float(text)
        if isinstance(current, tuple):
            items = json.loads(text) if text.startswith("[") else text.split(",") if text else []
            kind = type(current[0]) if current else float
            return tuple(kind(x) for x in items)
        if current is None:
            return None if text.lower() == "none" else json.loads(text)
        return type(current)(text)
    except (ValueError, TypeError, json.JSONDecodeError):
        raise ConfigError(f"setting {key}={text!r}: expected {type(current).__name__}") from None


def _apply(obj: Any, items: list[tuple[list[str], str, str]]) -> Any:
    """``obj`` with ``items`` (path below ``obj``, value text, the whole key) applied,
    each field's group rebuilt once with all of its items."""
    if not dataclasses.is_dataclass(obj):
        path, _text, full = items[0]
        raise ConfigError(f"setting {full!r}: {path[0]!r} is not a group of settings")
    names = [f.name for f in dataclasses.fields(obj)]
    values: dict[str, Any] = {}
    groups: dict[str, list[tuple[list[str], str, str]]] = {}
    for path, text, full in items:
        if path[0] not in names:
            raise unknown_name(
                "setting", full, [_prefix(full, path[0]) + n for n in names], ConfigError
            )
        current = getattr(obj, path[0])
        if len(path) > 1:
            groups.setdefault(path[0], []).append((path[1:], text, full))
            continue
        if dataclasses.is_dataclass(current):
            raise ConfigError(f"setting {full!r} is a group; set one of its fields")
        if isinstance(current, str) and hasattr(obj, "CHOICES") and path[0] in obj.CHOICES:
            if text not in obj.CHOICES[path[0]]:
                raise unknown_name(f"value for {full}", text, obj.CHOICES[path[0]], ConfigError)
        values[path[0]] = _coerce(text, current, full)
    for name, sub in groups.items():
        values[name] = _apply(getattr(obj, name), sub)
    return dataclasses.replace(cast(Any, obj), **values)


def _prefix(full: str, last: str) -> str:
    head = full.rsplit(".", 1)[0] + "." if "." in full and not full.startswith(last) else ""
    return head


def apply_overrides(cfg: Any, overrides: list[str] | tuple[str, ...] | None) -> Any:
    """A copy of ``cfg`` with each ``"a.b.c=value"`` override applied (a later one of the
    same key wins). Every settings group is rebuilt once, with all of its overrides, so
    checks that tie fields together (elites ≤ population) see the final values whatever
    the order the overrides came in."""
    items = []
    for item in overrides or ():
        if "=" not in item:
            raise ConfigError(f"setting {item!r} must look like key=value")
        key, text = item.split("=", 1)
        items.append((key.strip().split("."), text.strip(), key.strip()))
    return _apply(cfg, items) if items else cfg


def schedule_scales(start: float, step: float, stop: float) -> tuple[float, ...]:
    """The scales of a schedule from ``start`` up to ``stop`` in ``step`` s (§6), the last
    one never past ``stop``."""
    n = max(int(round((stop - start) / step)) + 1, 1)
    return tuple(round(min(start + i * step, stop), 6) for i in range(n))


def to_dict(cfg: Any) -> dict:
    """Plain-JSON dictionary of a (nested) settings dataclass."""
    return json.loads(json.dumps(dataclasses.asdict(cfg), default=str))


def from_dict(cls: type, data: dict) -> Any:
    """Rebuild a (nested) settings dataclass from :func:`to_dict` output."""
    kwargs = {}
    hints = {f.name: f for f in dataclasses.fields(cls)}
    for name, value in data.items():
        if name not in hints:
            continue
        default = getattr(cls(), name) if _has_defaults(cls) else None
        if dataclasses.is_dataclass(default) and isinstance(value, dict):
            kwargs[name] = from_dict(type(default), value)
        elif isinstance(default, tuple) and isinstance(value, list):
            kwargs[name] = tuple(value)
        else:
            kwargs[name] = value
    return cls(**kwargs)


def _has_defaults(cls: type) -> bool:
    try:
        cls()
    except TypeError:
        return False
    return True
