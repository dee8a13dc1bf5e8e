"""PPO on the walking environment (Stable-Baselines3), into a run folder the judge reads.

:func:`train` is ``imitwalk rl``: PPO (Schulman et al. 2017) with Stable-Baselines3's
``MlpPolicy`` on :class:`~imitwalk.envs.walk.WalkEnv`, ``envs`` of them in as many
processes, the action rescaled to [−1, 1]. Two settings, as the field runs them:

- ``joints``: from scratch, tracking the clip retargeted to the robot (DeepMimic's);
- ``residual``: offsets on imitwalk's stepping gait (residual RL).

The budget is counted in simulated seconds of experience, as imitwalk's own learning
is (``sim_seconds_used_for_learning``). After every rollout it writes the model (for
``--resume``), the deterministic policy in NumPy (``policy.npz``, what the judge and an
exported controller play) and a log line. A resumed run continues from the last
rollout's model and step count; its environments start new episodes, so it does not
repeat an uninterrupted run bit for bit.

RUN_DIR/
  config.json   ``learner: "rl"``, the PPO settings and the environment's
  style.json    the clip's stepping gait (the residual's base, the judge's distances)
  gains.json    ``default``: the stepping gait's gains (the residual's base)
  actor.json    the observation layout, action box and clock (:mod:`imitwalk.rl.actor`)
  policy.npz    the policy's network (:mod:`imitwalk.rl.network`)
  snapshots/    the network every ``snapshot_every`` simulated seconds
  ppo.zip       the PPO model with its optimiser (resume)
  log.jsonl     one line per rollout
  metrics.json  the :class:`~imitwalk.runs.LearnSummary`
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from imitwalk.envs.sb3net import from_sb3
from imitwalk.envs.setup import WalkConfig, WalkSetup, build_setup
from imitwalk.errors import ConfigError, RunError
from imitwalk.fileio import atomic_write
from imitwalk.runs import LearnSummary, RunDir

if TYPE_CHECKING:
    import gymnasium as gym
    from stable_baselines3 import PPO
    from stable_baselines3.common.callbacks import BaseCallback
    from stable_baselines3.common.vec_env import VecEnv

    from imitwalk.rl.actor import ActorSpec

__all__ = ["LOG_STD_INIT", "PPOConfig", "actor_spec", "train"]


#: The initial exploration noise by action mode [log of the box's half-width]. Residual:
#: 0.02 rad; measured on 6 ``hard`` training robots, noise of 0.055 rad (−1) made the
#: stepping gait fall after 6.8 s on average, against 15.2 s without noise and 15.8 s
#: with 0.02 rad. Joints: 0.18 rad.
LOG_STD_INIT = {"residual": -2.0, "joints": -1.0}


@dataclass(frozen=True)
class PPOConfig:
    """PPO's settings (Stable-Baselines3's names).

    Attributes:
        budget: simulated seconds of experience [s]; envs: environments, one process
        each; seed: PPO's and the environments' seed; n_steps: ticks per environment
        per rollout; batch_size, epochs, learning_rate, gamma, gae_lambda, clip_range,
        ent_coef: PPO's (γ 0.995: a 2 s horizon at the 100 Hz control rate, as
        legged_gym's 0.99 at 50 Hz); hidden: the policy's and value's hidden layer widths;
        log_std_init: the initial log standard deviation of the action noise, in the
        box's half-widths (``None``: :data:`LOG_STD_INIT`'s for the action mode);
        snapshot_every: keep the policy every this many simulated
        seconds [s] (``snapshots/policy_S.npz``), to measure what learning needed.
    """

    budget: float = 20_000.0
    envs: int = 2
    seed: int = 0
    n_steps: int = 1024
    batch_size: int = 256
    epochs: int = 10
    learning_rate: float = 3e-4
    gamma: float = 0.995
    gae_lambda: float = 0.95
    clip_range: float = 0.2
    ent_coef: float = 0.0
    hidden: tuple[int, ...] = (256, 256)
    log_std_init: float | None = None
    snapshot_every: float = 2_000.0

    def __post_init__(self) -> None:
        if not isinstance(self.budget, int | float) or not np.isfinite(self.budget):
            raise ConfigError(f"budget={self.budget!r}: must be a finite number of seconds > 0")
        if self.budget <= 0:
            raise ConfigError(f"budget={self.budget:g}: must be > 0 simulated seconds")
        for name in ("envs", "n_steps", "batch_size", "epochs"):
            v = getattr(self, name)
            if not isinstance(v, int) or v < 1:
                raise ConfigError(f"{name}={v!r}: must be a whole number ≥ 1")
        if not self.hidden or any(int(h) < 1 for h in self.hidden):
            raise ConfigError(f"hidden={self.hidden!r}: layer widths must be ≥ 1")

    def to_dict(self) -> dict:
        """Plain-JSON dictionary."""
        d = asdict(self)
        d["hidden"] = list(self.hidden)
        return d


def actor_spec(setup: WalkSetup) -> ActorSpec:
    """The :class:`~imitwalk.rl.actor.ActorSpec` of an environment's policy."""
    from imitwalk.rl.actor import ActorSpec

    t = setup.target
    q0 = setup.robot.stand.copy() if setup.config.action == "residual" else t.q[0].copy()
    return ActorSpec(
        setup.layout, setup.low.copy(), setup.high.copy(), q0, t.start_ticks, t.loop_ticks, t.phase0
    )


def _make_env(walk: dict) -> Callable[[], gym.Env]:
    def make() -> gym.Env:
        import gymnasium as gym
        from stable_baselines3.common.monitor import Monitor

        from imitwalk.envs.walk import WalkEnv

        env = WalkEnv(**walk)
        # gymnasium's stub wants NumPy numbers for the bounds; Python floats work alike
        return Monitor(gym.wrappers.RescaleAction(env, -1.0, 1.0))  # type: ignore[arg-type]

    return make


def _start(rd: RunDir, walk: WalkConfig, cfg: PPOConfig, resume: bool) -> WalkSetup:
    """Check the folder, build the environment's setup, write the run's fixed files."""
    config = {"learner": "rl", "rl": cfg.to_dict(), "env": walk.to_dict()}
    if resume:  # the same settings; the budget may grow
        if not rd.exists("ppo.zip"):
            raise RunError(f"nothing to resume in {rd.path}: no ppo.zip")
        saved = rd.read_json("config.json")
        mine = {k: v for k, v in cfg.to_dict().items() if k != "budget"}  # may grow
        theirs = {k: v for k, v in dict(saved.get("rl") or {}).items() if k != "budget"}
        if theirs != mine or saved.get("env") != walk.to_dict():
            raise RunError(f"{rd.path} was started with other settings; resume with the same ones")
        return build_setup(walk)
    if rd.exists("config.json") or rd.exists("checkpoint.json"):
        raise RunError(f"{rd.path} already holds a run; pass --resume or choose another --out")
    setup = build_setup(walk)
    Path(rd.path).mkdir(parents=True, exist_ok=True)
    rd.write_json("config.json", {**config, "robot": setup.robot.name, "source": setup.gait.source})
    setup.gait.save(rd.file("style.json"))
    rd.write_json("gains.json", {"default": setup.gains.to_dict()})
    actor_spec(setup).save(rd.file("actor.json"))
    return setup


def train(
    walk: WalkConfig,
    cfg: PPOConfig,
    out: str | Path,
    resume: bool = False,
    progress: Callable[[str], None] | None = None,
) -> LearnSummary:
    """Train PPO on ``walk``'s environment into the run folder ``out`` (the module doc).

    Raises:
        ConfigError: bad settings. RunError: ``out`` holds another run (without
            ``resume``) or nothing to resume.
    """
    import torch
    from stable_baselines3.common.vec_env import DummyVecEnv, SubprocVecEnv

    rd = RunDir(out)
    setup = _start(rd, walk, cfg, resume)
    if progress is not None:
        what = "residual on the stepping gait" if walk.action == "residual" else "joint targets"
        progress(
            f"rl: PPO, {what}, {cfg.budget:,.0f} simulated s on {cfg.envs} processes, "
            f"training robots of protocol {walk.protocol}"
        )
    dt = setup.dt
    total = int(round(cfg.budget / dt))
    wall = _wall_clock(rd, resume)
    kwargs = walk.to_dict()
    kwargs["weights"] = walk.weights
    makers = [_make_env(kwargs)] * cfg.envs
    venv = SubprocVecEnv(makers) if cfg.envs > 1 else DummyVecEnv(makers)
    venv.seed(cfg.seed)
    torch.manual_seed(cfg.seed)
    # one thread for the network: its batches are small, and a second thread's waiting
    # takes the core an environment's process needs (PPO 1.3 x faster on 2 cores)
    threads = torch.get_num_threads()
    torch.set_num_threads(1)
    try:
        model = _model(rd, venv, walk, cfg, resume)
        every = max(int(round(cfg.snapshot_every / dt)), 1)
        steps = int(model.num_timesteps)
        checkpoint = _Checkpoints(rd, cfg.budget, dt, every, wall, progress, steps, steps // every)
        _learn(model, venv, total, resume, checkpoint)
    finally:
        torch.set_num_threads(threads)
    return _finish(rd, walk, cfg, float(model.num_timesteps) * dt, wall)


def _wall_clock(rd: RunDir, resume: bool) -> Callable[[], float]:
    """``wall()``: the run's wall-clock seconds of learning [s], from now on plus, when
    resuming, those of ``checkpoint.json``."""
    wall0 = time.perf_counter()
    before = rd.read_json("checkpoint.json") if resume and rd.exists("checkpoint.json") else {}
    wall_before = float(before.get("wall_seconds", 0.0))

    def wall() -> float:
        return wall_before + time.perf_counter() - wall0

    return wall


def _model(rd: RunDir, venv: VecEnv, walk: WalkConfig, cfg: PPOConfig, resume: bool) -> PPO:
    """The PPO model on ``venv``: ``ppo.zip``'s when resuming (the log cut back to its
    step count), else a new one with ``cfg``'s settings."""
    from stable_baselines3 import PPO

    if resume:
        model = PPO.load(rd.file("ppo.zip"), env=venv, device="cpu")
        done = int(model.num_timesteps)  # log lines past the saved model are redone
        rd.write_log([e for e in rd.read_log() if int(e.get("timesteps", 0)) <= done])
        return model
    hidden = list(cfg.hidden)
    return PPO(
        "MlpPolicy",
        venv,
        n_steps=cfg.n_steps,
        batch_size=cfg.batch_size,
        n_epochs=cfg.epochs,
        learning_rate=cfg.learning_rate,
        gamma=cfg.gamma,
        gae_lambda=cfg.gae_lambda,
        clip_range=cfg.clip_range,
        ent_coef=cfg.ent_coef,
        policy_kwargs={
            "net_arch": {"pi": hidden, "vf": hidden},
            "log_std_init": (
                LOG_STD_INIT[walk.action] if cfg.log_std_init is None else cfg.log_std_init
            ),
        },
        seed=cfg.seed,
        device="cpu",
        verbose=0,
    )


def _learn(model: PPO, venv: VecEnv, total: int, resume: bool, checkpoint: _Checkpoints) -> None:
    """PPO up to ``total`` ticks in all, ``checkpoint`` after every update and at the end;
    closes ``venv`` whatever happens."""
    try:
        remaining = max(total - int(model.num_timesteps), 0)
        if remaining:
            model.learn(
                total_timesteps=remaining,
                callback=_checkpoint_callback(checkpoint),
                reset_num_timesteps=not resume,
            )
        checkpoint(model)
    finally:
        venv.close()


@dataclass
class _Checkpoints:
    """Saves a run's PPO model, its policy (and a snapshot every ``every`` ticks) and a
    log line each time it is called on a model that has stepped since.

    Attributes:
        rd: the run folder; budget: the run's simulated seconds [s]; dt: one tick [s];
        every: ticks between snapshots; wall: the run's wall-clock seconds so far [s];
        progress: optional ``callback(line)``; saved: the step count last saved;
        snapshots: ``saved // every`` when the last snapshot was kept.
    """

    rd: RunDir
    budget: float
    dt: float
    every: int
    wall: Callable[[], float]
    progress: Callable[[str], None] | None
    saved: int
    snapshots: int

    def __call__(self, m: PPO) -> None:
        """Save the model, its policy and a log line: after each update, so that the
        model, the policy and the step count always agree."""
        steps = int(m.num_timesteps)
        if steps == self.saved:
            return
        self.saved = steps
        # SB3 declares the buffer optional; learn() has made it by the first callback
        eps = list(m.ep_info_buffer)  # type: ignore[arg-type]
        line = self._log_line(steps, eps)
        self._save(m, steps)
        self.rd.write_log([*self.rd.read_log(), line])
        self.rd.write_json("checkpoint.json", {"timesteps": steps, "wall_seconds": self.wall()})
        if self.progress is not None:
            ret = "-" if line["episode_return"] is None else f"{line['episode_return']:.1f}"
            length = "-" if not eps else f"{line['episode_seconds']:.1f} s"
            self.progress(
                f"  PPO {steps * self.dt:,.0f}/{self.budget:,.0f} sim s: episode return {ret}, "
                f"episodes last {length} ({self.wall():.0f} s wall)"
            )

    def _log_line(self, steps: int, eps: list[dict]) -> dict:
        """``log.jsonl``'s line after ``steps`` ticks: simulated and wall seconds [s], and
        the mean return and length [s] of the episodes in ``eps`` (SB3's ``r``, ``l``)."""
        return {
            "timesteps": steps,
            "sim_seconds": steps * self.dt,
            "episode_return": float(np.mean([e["r"] for e in eps])) if eps else None,
            "episode_seconds": float(np.mean([e["l"] for e in eps])) * self.dt if eps else None,
            "wall_seconds": self.wall(),
        }

    def _save(self, m: PPO, steps: int) -> None:
        """Write ``ppo.zip`` and ``policy.npz``, and a snapshot once ``every`` ticks more
        have passed."""
        atomic_write(self.rd.file("ppo.zip"), lambda tmp: _save_model(m, tmp))
        net = from_sb3(m)
        net.save(self.rd.file("policy.npz"))
        if steps // self.every > self.snapshots:
            self.snapshots = steps // self.every
            net.save(self.rd.file("snapshots") / f"policy_{steps * self.dt:.0f}.npz")


def _checkpoint_callback(checkpoint: _Checkpoints) -> BaseCallback:
    """An SB3 callback that calls ``checkpoint`` at each rollout's start (the last
    rollout's update done)."""
    from stable_baselines3.common.callbacks import BaseCallback

    class Checkpoint(BaseCallback):
        def _on_step(self) -> bool:
            return True

        def _on_rollout_start(self) -> None:  # the last rollout's update is done
            checkpoint(self.model)  # type: ignore[arg-type]  # SB3 says BaseAlgorithm: this PPO

    return Checkpoint()


def _finish(
    rd: RunDir, walk: WalkConfig, cfg: PPOConfig, sim_seconds: float, wall: Callable[[], float]
) -> LearnSummary:
    """Write ``metrics.json``: the run's summary after ``sim_seconds`` of experience [s]."""
    log = rd.read_log()
    summary = LearnSummary(
        learner="rl",
        scale_reached=1.0,
        scales_passed=[1.0],
        iterations=len(log),
        sim_seconds_used_for_learning=sim_seconds,
        wall_seconds_for_learning=wall(),
        config={"rl": cfg.to_dict(), "env": walk.to_dict()},
    )
    rd.write_json("metrics.json", summary.to_dict())
    return summary


def _save_model(model: PPO, tmp: Path) -> None:
    with open(tmp, "wb") as fh:  # a file object: SB3 adds no ".zip" to its name
        model.save(fh)
