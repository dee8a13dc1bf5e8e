"""Fitting the learned models from recorded episodes, and assembling a controller.

Pure NumPy: the per-tick gyro model of the paper (actions (φ, r, h)) and the step model
of the balance channels are both :class:`~imitwalk.predictor.SensoryMotorModel` s,
refitted deterministically from everything recorded so far. Episodes are stored as
concatenated arrays plus lengths, so a run folder holds everything needed to rebuild
the controller.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from imitwalk.balance import StepController, step_target, upgrade_step_actions
from imitwalk.controller import ActionSelector
from imitwalk.ensemble import ModelEnsemble
from imitwalk.errors import RunError
from imitwalk.gait import GaitModel
from imitwalk.learnconfig import LearnConfig
from imitwalk.policy import WalkPolicy, startup_ramp
from imitwalk.predictor import SensoryMotorModel

__all__ = [
    "Models",
    "build_policy",
    "fit_models",
    "stack_episodes",
    "step_model",
    "unstack_episodes",
]

#: At most this many of the latest tick samples train the gyro model.
MAX_TICK_SAMPLES = 40000


@dataclass
class Models:
    """The fitted models (``None`` where there is no data yet or the part is off)."""

    tick: SensoryMotorModel | None = None
    step: ModelEnsemble | None = None
    step_data: tuple = ((), ())

    def held_out(self, results: list[dict]) -> dict:
        """Prediction quality of these models on new episodes (before refitting on them)."""
        out = {}
        for kind, model in (("tick", self.tick), ("step", self.step)):
            eps = [r[kind] for r in results if kind in r and len(r[kind][0]) > 3]
            if model is not None and eps:
                try:
                    out[kind] = model.evaluate(eps).to_dict()
                except ValueError:
                    continue
        return out


def _latest(episodes: list, cap: int) -> list:
    out, total = [], 0
    for ep in reversed(episodes):
        out.append(ep)
        total += len(ep[0])
        if total >= cap:
            break
    return out[::-1]


def step_model(config: LearnConfig, n_centers: int | None = None) -> ModelEnsemble:
    """The run's step model, unfitted: an ensemble of RBF networks with linear terms on
    the step states and channel values (``n_centers``: another size, for diagnostics)."""
    return ModelEnsemble(
        n_members=config.step.ensemble,
        random_state=config.seed,
        n_centers=config.step.n_centers if n_centers is None else n_centers,
        ridge=config.step.ridge,
        angle_action=False,
        linear=True,
    )


def fit_models(data: dict, config: LearnConfig) -> Models:
    """Fit the gyro model (if the tick search is on) and the step model (if channels are)."""
    models = Models()
    tick_eps = [e for e in data.get("tick", []) if len(e[0]) > 3]
    if config.tick.enabled and tick_eps:
        models.tick = SensoryMotorModel(
            n_centers=config.tick.n_centers, ridge=config.tick.ridge, random_state=config.seed
        ).fit(_latest(tick_eps, MAX_TICK_SAMPLES))
    step_eps = [e for e in data.get("step", []) if len(e[0]) > 3]
    if config.steps and sum(len(e[0]) for e in step_eps) >= 30:
        models.step = step_model(config).fit(step_eps)
    models.step_data = ([e[0] for e in step_eps], [e[1] for e in step_eps])
    return models


def step_limits(models: Models, config: LearnConfig) -> np.ndarray | None:
    """Per-channel search limits: where the step model has data (10 % beyond the largest
    recorded value), never beyond ``c_max`` — the search must not extrapolate."""
    if models.step is None or not models.step_data[1]:
        return None
    seen = np.abs(np.vstack(models.step_data[1])[:, :-1]).max(axis=0)
    return np.minimum(np.asarray(config.step.c_max, dtype=float), 1.1 * seen)


def build_policy(
    gait: GaitModel,
    scale: float,
    config: LearnConfig,
    models: Models,
    explore: float = 0.0,
    rng_seed=None,
    robot=None,
) -> WalkPolicy:
    """The controller at ``scale``: tick search and step channels as configured."""
    rng = np.random.default_rng(rng_seed) if explore > 0 else None
    emb = gait.embedding(scale)
    r_mean = float(np.mean(gait.nominal[gait._key(scale)][:, 1]))
    t = config.tick
    selector = None
    if t.enabled and models.tick is not None:
        selector = ActionSelector(
            emb,
            models.tick,
            weights=t.weights if t.state == "gyro" else (*t.weights, 1.0, 1.0),
            eps_phi=t.eps_phi * gait.phase_step(scale),
            eps_r=t.eps_r * r_mean,
            eps_h=t.eps_h * r_mean,
            n_phi=t.grid[0],
            n_r=t.grid[1],
            n_h=t.grid[2],
            horizon=t.horizon,
        )
    tick_explore = (0.0, 0.0)
    if t.enabled and explore > 0:
        tick_explore = (
            t.explore * explore * t.eps_r * r_mean,
            t.explore * explore * t.eps_h * r_mean,
        )
    steps, channel_ik = None, None
    if config.steps:
        ref = gait.ref
        if not ref.plan:
            raise RunError("the balance channels need a walkable reference (mapping 'walkable')")
        if robot is None:
            raise RunError("the balance channels need the robot (for their IK)")
        from imitwalk.retarget.online import OnlineIK  # MuJoCo, through the IK

        channel_ik = OnlineIK(robot, ref, scale)
        steps = StepController(
            config.step,
            gait.n_ticks,
            float(ref.params_at(scale).get("ds", 0.1)),
            model=models.step,
            rng=rng,
            explore=config.step.explore * explore,
            scale=scale,
            target=(
                step_target(*models.step_data, scale, len(config.step.state_names))
                if models.step is not None
                else None
            ),
            limits=step_limits(models, config),
            ramp=startup_ramp(gait, scale) if config.step.ramp_scale else None,
        )
    return WalkPolicy(
        gait,
        scale,
        tick_selector=selector,
        tick_state=t.state,
        steps=steps,
        channel_ik=channel_ik,
        explore=tick_explore,
        rng=rng,
    )


def stack_episodes(data: dict) -> dict[str, np.ndarray]:
    """Episodes → arrays for ``data.npz`` (``{kind}_S``, ``{kind}_A``, ``{kind}_len``)."""
    out = {}
    for kind, eps in data.items():
        if not eps:
            continue
        out[f"{kind}_S"] = np.vstack([e[0] for e in eps])
        out[f"{kind}_A"] = np.vstack([e[1] for e in eps])
        out[f"{kind}_len"] = np.array([len(e[0]) for e in eps])
    return out


def unstack_episodes(arrays: dict[str, np.ndarray]) -> dict:
    """Inverse of :func:`stack_episodes`."""
    data: dict = {"tick": [], "step": []}
    for kind in data:
        if f"{kind}_len" not in arrays:
            continue
        cut = np.cumsum(arrays[f"{kind}_len"])[:-1]
        if kind == "step":  # a run written before the time channel: add it, as 0
            arrays = {**arrays, "step_A": upgrade_step_actions(arrays["step_A"])}
        data[kind] = list(
            zip(np.split(arrays[f"{kind}_S"], cut), np.split(arrays[f"{kind}_A"], cut), strict=True)
        )
    return data
