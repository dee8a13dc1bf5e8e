"""One error base class for everything imitwalk refuses, with a few subclasses.

Every message is a single line that says what is wrong and, where a name was
looked up, lists the valid choices. The CLI prints ``error: <message>`` and
exits with status 2; it never shows a traceback for these.
"""

from __future__ import annotations

from collections.abc import Iterable

__all__ = [
    "ConfigError",
    "ImitwalkError",
    "MocapError",
    "MocapWarning",
    "RetargetError",
    "RobotError",
    "RunError",
    "unknown_name",
]


class ImitwalkError(Exception):
    """Base class of every error imitwalk raises on purpose."""


class MocapError(ImitwalkError):
    """A motion-capture file cannot be read or holds no usable motion."""


class MocapWarning(UserWarning):
    """A mocap file was read, but something in it was dropped or repaired (named in the message)."""


class RobotError(ImitwalkError):
    """A robot model or its joint map is invalid, or a joint/sensor name is unknown."""


class RetargetError(ImitwalkError):
    """Retargeting could not produce a usable robot trajectory."""


class ConfigError(ImitwalkError):
    """A setting is unknown or has an invalid value."""


class RunError(ImitwalkError):
    """A run directory (or an exported controller) is missing, incomplete or incompatible."""


class SensorError(ImitwalkError):
    """A sensor vector handed to an exported controller has the wrong length, or a value
    that is not a finite real number within the runtime's bound on a reading."""


def unknown_name(
    kind: str, name: str, valid: Iterable[str], cls: type[ImitwalkError] = RobotError
) -> ImitwalkError:
    """Build an error for an unknown name that lists the valid choices.

    >>> str(unknown_name("joint", "kneee", ["knee", "hip"]))
    "unknown joint 'kneee'; valid: hip, knee"
    """
    choices = ", ".join(sorted(valid))
    return cls(f"unknown {kind} {name!r}; valid: {choices}")
