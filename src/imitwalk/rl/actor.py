"""A trained policy as a controller ``(tick, observation) -> joint targets``.

:class:`ActorSpec` is everything the policy needs besides its network: the observation
layout, the action box, the clock of the reference it was trained against, the posture
it starts from and, for a residual policy, the stepping gait it adds to. It is saved as
``actor.json`` beside the network (``policy.npz``). :class:`PolicyActor` plays it on
any plant, the same computation the environment (:mod:`imitwalk.envs.walk`) trained it
in: encode the observation, evaluate the network, map its output from [−1, 1] onto the
box, clip, add the stepping gait's command in residual mode.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from imitwalk import readback
from imitwalk.errors import RunError
from imitwalk.fileio import atomic_write
from imitwalk.rl.network import MLP
from imitwalk.rl.observation import ObservationLayout, clock_phase
from imitwalk.sim.types import Observation

__all__ = ["ACTOR_FORMAT", "ActorSpec", "PolicyActor"]

#: The format version of ``actor.json`` written here (and the newest read).
ACTOR_FORMAT = 1


@dataclass(frozen=True)
class ActorSpec:
    """What a policy needs besides its network (see the module doc).

    Attributes:
        layout: the observation; low, high: ``(n,)`` the action box [rad]; q0: ``(n,)``
        the posture a walk starts from [rad]; start_ticks, loop_ticks, phase0: the
        reference's clock (``joints`` mode's phase; a residual policy sees the stepping
        gait's own).
    """

    layout: ObservationLayout
    low: np.ndarray
    high: np.ndarray
    q0: np.ndarray
    start_ticks: int
    loop_ticks: int
    phase0: float

    def to_dict(self) -> dict:
        """Plain-JSON dictionary (with its ``format``)."""
        lay = self.layout
        return {
            readback.FORMAT_KEY: ACTOR_FORMAT,
            "action": lay.action,
            "stand": lay.stand.tolist(),
            "weight": lay.weight,
            "sole_sensors": lay.sole_sensors,
            "previous": lay.previous,
            "low": self.low.tolist(),
            "high": self.high.tolist(),
            "q0": self.q0.tolist(),
            "clock": {
                "start_ticks": self.start_ticks,
                "loop_ticks": self.loop_ticks,
                "phase0": self.phase0,
            },
            "blocks": [list(b) for b in lay.blocks],
        }

    def save(self, path: str | Path) -> Path:
        """Write ``path`` (JSON) atomically."""
        text = json.dumps(self.to_dict(), indent=1)
        return atomic_write(path, lambda tmp: tmp.write_text(text + "\n"))

    @classmethod
    def load(cls, path: str | Path) -> ActorSpec:
        """Read what :meth:`save` wrote (a one-line :class:`RunError` if it cannot)."""
        what = "a policy's spec (actor.json of an 'imitwalk rl' run)"
        keys = ("action", "stand", "weight", "sole_sensors", "previous", "low", "high", "q0")
        d = readback.read_json(path, what, RunError, required=(*keys, "clock"))
        readback.check_format(d, ACTOR_FORMAT, str(path), RunError)
        try:
            low, high = np.asarray(d["low"], float), np.asarray(d["high"], float)
            layout = ObservationLayout(
                stand=np.asarray(d["stand"], float),
                weight=float(d["weight"]),
                sole_sensors=int(d["sole_sensors"]),
                action=str(d["action"]),
                action_center=(high + low) / 2,
                action_scale=(high - low) / 2,
                previous=bool(d["previous"]),
            )
            c = d["clock"]
            spec = cls(
                layout,
                low,
                high,
                np.asarray(d["q0"], float),
                int(c["start_ticks"]),
                int(c["loop_ticks"]),
                float(c["phase0"]),
            )
        except (ValueError, KeyError, TypeError) as exc:
            raise RunError(f"{path} is not {what}: {type(exc).__name__}: {exc}") from None
        n = len(spec.layout.stand)
        if not (len(low) == len(high) == len(spec.q0) == n) or np.any(high <= low):
            raise RunError(f"{path}: the action box and postures must be {n} joints, low < high")
        return spec


class PolicyActor:
    """Plays ``net`` under ``spec`` (see the module doc).

    Args:
        spec: the policy's spec; net: its network (``layout.size`` in, ``n`` out);
        base: the stepping controller a residual policy adds to (``None`` in ``joints``
        mode).
    """

    def __init__(
        self,
        spec: ActorSpec,
        net: MLP,
        base: Any = None,  # a step.controller.SteppingController (rl may not import step)
    ):
        if (spec.layout.action == "residual") != (base is not None):
            raise RunError("a residual policy needs its stepping gait, a joints policy none")
        if net.sizes != (spec.layout.size, len(spec.q0)):
            raise RunError(
                f"the network maps {net.sizes[0]} → {net.sizes[1]}, the policy's spec "
                f"{spec.layout.size} → {len(spec.q0)}"
            )
        self.spec, self.net, self.base = spec, net, base
        self.q0 = base.q0 if base is not None else spec.q0
        self.previous = spec.layout.action_center.copy()

    def __call__(self, k: int, obs: Observation) -> np.ndarray:
        s = self.spec
        if k == 0:
            self.previous = s.layout.action_center.copy()
        base = self.base(k, obs) if self.base is not None else None
        if base is not None:
            phase = self.base.phase
        else:
            phase = clock_phase(k, s.start_ticks, s.loop_ticks, s.phase0)
        x = s.layout.encode(obs, phase, self.previous, base)
        u = np.clip(self.net(x), -1.0, 1.0)
        a = np.clip(s.layout.action_center + u * s.layout.action_scale, s.low, s.high)
        self.previous = a
        return a + base if base is not None else a
