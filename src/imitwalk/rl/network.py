"""A trained policy's network in NumPy: the deterministic action of a PPO actor.

Stable-Baselines3's ``MlpPolicy`` computes its mean action as ``action_net(pi(x))``,
``pi`` a stack of linear layers each followed by the activation (tanh by default).
:class:`MLP` holds those layers' weights and evaluates them with NumPy, so a trained
policy is judged, replayed and exported without PyTorch. The trainer copies them out of
a trained model (:func:`imitwalk.envs.sb3net.from_sb3`).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from imitwalk import readback
from imitwalk.errors import ConfigError, RunError, unknown_name
from imitwalk.fileio import write_npz

__all__ = ["ACTIVATIONS", "MLP"]


def _relu(x: np.ndarray) -> np.ndarray:
    return np.maximum(x, 0.0)


ACTIVATIONS: dict[str, Callable[[np.ndarray], np.ndarray]] = {"tanh": np.tanh, "relu": _relu}


@dataclass(frozen=True)
class MLP:
    """Layers ``(W_i (out, in), b_i (out,))``: the activation after each but the last.

    Attributes:
        weights, biases: one per layer; activation: a name of :data:`ACTIVATIONS`.
    """

    weights: tuple[np.ndarray, ...]
    biases: tuple[np.ndarray, ...]
    activation: str = "tanh"

    def __post_init__(self) -> None:
        if self.activation not in ACTIVATIONS:
            raise unknown_name("activation", self.activation, ACTIVATIONS, ConfigError)
        if not self.weights or len(self.weights) != len(self.biases):
            raise ConfigError("an MLP needs one bias per weight matrix, and at least one layer")

    @property
    def sizes(self) -> tuple[int, int]:
        """``(inputs, outputs)``."""
        return self.weights[0].shape[1], self.weights[-1].shape[0]

    def __call__(self, x: np.ndarray) -> np.ndarray:
        """``(outputs,)`` for ``(inputs,)`` ``x``."""
        act = ACTIVATIONS[self.activation]
        h = np.asarray(x, dtype=np.float64)
        last = len(self.weights) - 1
        for i, (w, b) in enumerate(zip(self.weights, self.biases, strict=True)):
            h = w @ h + b
            if i < last:
                h = act(h)
        return h

    def save(self, path: str | Path) -> Path:
        """Write ``path`` (``.npz``) atomically."""
        arrays: dict[str, Any] = {f"w{i}": w for i, w in enumerate(self.weights)}
        arrays |= {f"b{i}": b for i, b in enumerate(self.biases)}
        arrays["activation"] = np.array(self.activation)
        return write_npz(path, arrays, compressed=False)

    @classmethod
    def load(cls, path: str | Path) -> MLP:
        """Read a network :meth:`save` wrote (a one-line :class:`RunError` if it cannot,
        from :func:`~imitwalk.readback.read_npz`)."""
        what = "a policy network (policy.npz of an 'imitwalk rl' run)"
        z = readback.read_npz(path, what, RunError, required=("w0", "b0", "activation"))
        n = sum(1 for k in z if k.startswith("w"))
        try:
            weights = tuple(np.asarray(z[f"w{i}"], dtype=float) for i in range(n))
            biases = tuple(np.asarray(z[f"b{i}"], dtype=float) for i in range(n))
        except (KeyError, ValueError) as exc:
            raise RunError(f"{path} is not {what}: {type(exc).__name__}: {exc}") from None
        act = str(z["activation"])
        for i in range(n - 1):
            if weights[i + 1].shape[1] != weights[i].shape[0] or biases[i].shape != (
                weights[i].shape[0],
            ):
                raise RunError(f"{path}: layer {i + 1}'s shape does not follow layer {i}'s")
        return cls(weights, biases, act)
