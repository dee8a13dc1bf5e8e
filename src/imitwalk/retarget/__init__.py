"""Mocap → robot joint angles.

Two mappings: ``"walkable"`` (the default) solves a task-space gait plan by IK on the
robot itself, with its few parameters found by trials in simulation; ``"paper"`` is
the paper's own mapping (§2), IK on a human-sized copy of the robot's skeleton.

The package's names load on first use (PEP 562), so that a NumPy stage that only needs
the :class:`Reference` record (the gait, the learner's settings, the policy) imports
it without the IK and MuJoCo. :func:`retarget` itself lives in
:mod:`imitwalk.retarget.pipeline`.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

__all__ = [
    "MAPPINGS",
    "GaitCommand",
    "GaitParams",
    "GaitTemplate",
    "Reference",
    "RetargetConfig",
    "RetargetResult",
    "SearchConfig",
    "extract_template",
    "retarget",
]

#: Where each public name lives (a submodule of this package). ``__all__`` above lists the
#: same names as a literal, which static tools need; ``test_imports`` checks they agree.
_HOME = {
    "MAPPINGS": "pipeline",
    "GaitCommand": "command",
    "GaitParams": "params",
    "GaitTemplate": "template",
    "Reference": "reference",
    "RetargetConfig": "pipeline",
    "RetargetResult": "pipeline",
    "SearchConfig": "search",
    "extract_template": "template",
    "retarget": "pipeline",
}

if TYPE_CHECKING:  # for type checkers and editors; at run time, __getattr__ below
    from imitwalk.retarget.command import GaitCommand
    from imitwalk.retarget.params import GaitParams
    from imitwalk.retarget.pipeline import MAPPINGS, RetargetConfig, RetargetResult, retarget
    from imitwalk.retarget.reference import Reference
    from imitwalk.retarget.search import SearchConfig
    from imitwalk.retarget.template import GaitTemplate, extract_template


def __getattr__(name: str) -> Any:
    if name not in _HOME:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    value = getattr(importlib.import_module(f"{__name__}.{_HOME[name]}"), name)
    globals()[name] = value  # later lookups skip this function
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))
