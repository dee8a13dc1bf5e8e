"""imitwalk: a humanoid robot learns to walk by imitating human motion capture.

An implementation, and extension, of Chalodhorn, Grimes, Grochow & Rao,
*Learning to Walk through Imitation*, IJCAI 2007, on a HOAP-2-class humanoid
simulated in MuJoCo.

The flat API loads each stage when it is first used (``import imitwalk`` does not import
MuJoCo)::

    import imitwalk as iw

    robot = iw.load_robot("hoap2")
    summary = iw.learn(iw.default_clip(), robot, "RUN")  # what `imitwalk learn` does
    judged = iw.evaluate_run("RUN", robot, iw.load_protocol("eval"), seeds=40)  # a ProtocolVerdict

``iw.retarget`` is always the function :func:`imitwalk.retarget.pipeline.retarget`, never
the subpackage of the same name; reach the subpackage by ``from imitwalk.retarget import
...`` or ``importlib.import_module("imitwalk.retarget")`` (``import imitwalk.retarget as
m`` reads the attribute, and so gives the function).
"""

from __future__ import annotations

import importlib
import os
from typing import Any

# Offscreen rendering on the CPU: MuJoCo reads MUJOCO_GL when it is first imported.
os.environ.setdefault("MUJOCO_GL", "egl")

from imitwalk.errors import (
    ConfigError,
    ImitwalkError,
    MocapError,
    RetargetError,
    RobotError,
    RunError,
    SensorError,
)

__version__ = "0.12.1"

#: The flat API: name -> the module that defines it, or (module, its name there); each is
#: imported on first use.
_LAZY: dict[str, str | tuple[str, str]] = {
    "load_motion": "imitwalk.mocap",
    "default_clip": "imitwalk.mocap",
    "Motion": "imitwalk.mocap",
    "load_robot": "imitwalk.robots",
    "Robot": "imitwalk.robots",
    "retarget": ("imitwalk.retarget.pipeline", "retarget"),
    "RetargetConfig": "imitwalk.retarget",
    "Reference": "imitwalk.retarget",
    "learn": "imitwalk.step.pipeline",
    "gait_from_motion": "imitwalk.step.pipeline",
    "StepGait": "imitwalk.step.gait",
    "StepGains": "imitwalk.step.gains",
    "StepLearnConfig": "imitwalk.step.learn",
    "SteppingController": "imitwalk.step.controller",
    "TickLearnConfig": "imitwalk.balance.tickconfig",
    "learn_tick": "imitwalk.balance.ticklearn",
    "learn_clip": "imitwalk.learning.refchoice",
    "learn_joint_space": "imitwalk.learning.jointspace",
    "load_run": "imitwalk.judge.replay",
    "evaluate_run": ("imitwalk.judge.verdict", "judge_protocol"),
    "Plant": "imitwalk.sim.mujoco",
    "SimOptions": "imitwalk.sim.types",
    "make_plant": "imitwalk.sim.mujoco",
    "run": "imitwalk.sim.mujoco",
    "load_laws": "imitwalk.balance.tickstore",
    "load_protocol": "imitwalk.sim.protocol",
    "judge_protocol": "imitwalk.judge.verdict",
    "judge_controllers": "imitwalk.judge.verdict",
    "RunController": "imitwalk.judge.verdict",
    "push_recovery": "imitwalk.judge.pushes",
    "LearnSummary": "imitwalk.runs",
    "ProtocolVerdict": "imitwalk.judge.records",
    "PushVerdict": "imitwalk.judge.records",
    "write_report": "imitwalk.evidence.report",
    "WalkConfig": "imitwalk.envs.setup",
    "WalkEnv": "imitwalk.envs.walk",
    "PPOConfig": "imitwalk.envs.ppo",
    "train_ppo": ("imitwalk.envs.ppo", "train"),
    "PolicyActor": "imitwalk.rl.actor",
}


# The subpackage ``imitwalk.retarget`` (NumPy only until one of its names is used) shares
# its name with the function ``retarget``. Python binds a subpackage as an attribute of
# its parent once, on the subpackage's first import, which would hide the function from
# then on. So import it now and drop that binding: the name then resolves through
# ``__getattr__`` to the function, whatever is imported later and in what order.
importlib.import_module("imitwalk.retarget")
globals().pop("retarget", None)


def __getattr__(name: str) -> Any:
    if name in _LAZY:
        where = _LAZY[name]
        module, attr = where if isinstance(where, tuple) else (where, name)
        value = getattr(importlib.import_module(module), attr)
        globals()[name] = value
        return value
    raise AttributeError(f"module 'imitwalk' has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_LAZY))


__all__ = [
    *_LAZY,
    "ConfigError",
    "ImitwalkError",
    "MocapError",
    "RetargetError",
    "RobotError",
    "RunError",
    "SensorError",
    "__version__",
]
