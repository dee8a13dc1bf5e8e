"""A trained Stable-Baselines3 policy's actor copied out as imitwalk's NumPy network
(:class:`~imitwalk.rl.network.MLP`), so that the judge and the runtime play it without
PyTorch."""

from __future__ import annotations

from typing import TYPE_CHECKING

from imitwalk.rl.network import MLP

if TYPE_CHECKING:
    from stable_baselines3 import PPO

__all__ = ["from_sb3"]


def from_sb3(model: PPO) -> MLP:
    """The mean-action network of a Stable-Baselines3 ``PPO`` with an ``MlpPolicy`` whose
    feature extractor is a plain flatten (the default)."""
    import torch

    pol = model.policy
    layers = [m for m in pol.mlp_extractor.policy_net if isinstance(m, torch.nn.Linear)]
    acts = {type(m).__name__ for m in pol.mlp_extractor.policy_net} - {"Linear"}
    name = {"Tanh": "tanh", "ReLU": "relu"}.get(next(iter(acts), "Tanh"), "tanh")
    # torch declares the action head an nn.Module; an MlpPolicy's is an nn.Linear
    layers.append(pol.action_net)  # type: ignore[arg-type]
    weights = tuple(layer.weight.detach().cpu().numpy().astype(float) for layer in layers)
    biases = tuple(layer.bias.detach().cpu().numpy().astype(float) for layer in layers)
    return MLP(weights, biases, name)
