"""A finished run, loaded to replay: its gait and every controller it can build.

:func:`load_run` reads a run folder of any learner: the stepping gait
(:mod:`imitwalk.step`, the default), the per-tick balance learner
(:mod:`imitwalk.balance.ticklearn`), the paper's as written (``faithful``,
:mod:`imitwalk.paper.learner`) or PPO's (``rl``, :mod:`imitwalk.envs.ppo`). Each gives a
:class:`LoadedRun`: its gait (a stepping or PPO run's :class:`~imitwalk.step.gait.StepGait`,
the others' joint-space reference), the scale
the run reached, the engine it learned on, and :meth:`~LoadedRun.policy`, a fresh
controller by name. A stepping run builds ``learned`` and ``default`` (the gains imitwalk
ships, where learning starts); a PPO run builds ``rl`` (its policy,
:class:`~imitwalk.rl.actor.PolicyActor`) and ``default`` (the stepping gait it was
trained beside, a residual policy's base); the others build theirs and ``open_loop``
(the reference played as it is).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from imitwalk.errors import ConfigError, RunError, unknown_name
from imitwalk.retarget.reference import Reference
from imitwalk.runs import LearnSummary, RunDir

if TYPE_CHECKING:
    from imitwalk.paper.evaluate import LearnedGait
    from imitwalk.robots import Robot
    from imitwalk.runtime.bundle import Bundle
    from imitwalk.sim.types import Observation
    from imitwalk.step.gait import StepGait

__all__ = ["LEARNERS", "OPEN_LOOP", "LoadedRun", "load_run"]

#: The controller every run can build: its reference played as it is.
OPEN_LOOP = "open_loop"


class _OpenLoop:
    """The reference's trajectory as a policy, starting where it starts."""

    def __init__(self, ref: Reference, scale: float, seconds: float) -> None:
        self.q = ref.trajectory(scale, seconds)
        self.q0 = self.q[0]

    def __call__(self, k: int, _obs: Observation) -> np.ndarray:
        return self.q[min(k, len(self.q) - 1)]


@dataclass(frozen=True)
class LoadedRun:
    """A finished run.

    Attributes:
        path: its folder; learner: ``"tick"`` or ``"faithful"``; ref: its reference;
        scale: the scale it reached; engine: the engine it learned on; metrics: its
        ``metrics.json`` (a :class:`~imitwalk.runs.LearnSummary`); laws: the per-tick
        run's feedback laws by controller name; settings: how the per-tick run's
        trials chose to play the reference (``feedforward``, ``wait``:
        :attr:`~imitwalk.runs.LearnSummary.reference_settings`), for its ``learned`` and
        ``feedback`` controllers (``fixed``, the hand-set baseline, and ``open_loop``
        play the reference as it is);
        gait: the faithful run's learned gait (:class:`~imitwalk.paper.evaluate.LearnedGait`);
        step_gains: a stepping run's gains by controller name
        (:class:`~imitwalk.step.gains.StepGains`); a PPO run's ``default``.
        actor: a PPO run's policy: its :class:`~imitwalk.rl.actor.ActorSpec` and
        :class:`~imitwalk.rl.network.MLP`.
    """

    path: str
    learner: str
    ref: Reference | StepGait
    scale: float
    engine: str
    metrics: LearnSummary
    laws: dict | None = None
    gait: LearnedGait | None = None
    settings: dict | None = None
    step_gains: dict | None = None
    actor: tuple | None = None

    @property
    def reference(self) -> Reference:
        """A joint-space run's reference (a stepping run has none: :attr:`step_gait`)."""
        if not isinstance(self.ref, Reference):
            raise RunError(f"{self.path} is a stepping run: it has no joint-space reference")
        return self.ref

    @property
    def step_gait(self) -> StepGait:
        """A stepping run's gait (a joint-space run has none: :attr:`reference`)."""
        from imitwalk.step.gait import StepGait

        if not isinstance(self.ref, StepGait):
            raise RunError(f"{self.path} is not a stepping run")
        return self.ref

    def settings_of(self, controller: str) -> dict:
        """How ``controller`` plays the reference: ``feedforward`` and ``wait`` (0: not)."""
        mine = (self.settings or {}) if controller in ("learned", "feedback") else {}
        return {
            "feedforward": float(mine.get("feedforward", 0.0)),
            "wait": float(mine.get("wait", 0.0)),
        }

    def controllers(self) -> tuple[str, ...]:
        """The controllers it can build (a joint-space run's ``open_loop`` last)."""
        if self.actor is not None:
            return ("rl", *tuple(self.step_gains or ()))
        if self.step_gains is not None:
            return tuple(self.step_gains)
        names = tuple(self.laws) if self.laws is not None else ("learned",)
        return (*names, OPEN_LOOP)

    def twin(self, controller: str) -> str:
        """The first controller that is ``controller``'s exact copy (itself if none is):
        a run whose model-based law was not kept has ``learned`` equal to ``feedback``,
        and a judge walks such a pair once."""
        if self.step_gains is not None:
            mine = self.step_gains.get(controller)
            return next((c for c, g in self.step_gains.items() if g == mine), controller)
        if self.laws is None or controller == OPEN_LOOP:
            return controller
        mine = [law.to_arrays("") for law in self.laws[controller]]
        for other in self.controllers():
            if self.settings_of(other) != self.settings_of(controller):
                continue
            theirs = [law.to_arrays("") for law in self.laws.get(other, ())]
            if len(theirs) == len(mine) and all(
                a.keys() == b.keys() and all(np.array_equal(a[k], b[k]) for k in a)
                for a, b in zip(mine, theirs, strict=True)
            ):
                return other
        return controller

    def bundle(self, controller: str, robot: Robot, scale: float | None = None) -> Bundle:
        """A stepping or PPO run's controller ``controller`` at ``scale`` (default: the
        scale reached) as :mod:`imitwalk.runtime` plays it, and ``imitwalk export``
        writes it.

        Raises:
            ConfigError: a controller this run cannot build (listing the ones it can), or
                a run of another learner (a joint-space reference is not exported).
        """
        from imitwalk.runtime.bundle import Bundle

        if self.step_gains is None:
            raise ConfigError(
                f"{self.path} is a {self.learner!r} run; export takes stepping and PPO runs "
                "(learners: step, rl)"
            )
        if controller not in self.controllers():
            raise unknown_name("controller", controller, self.controllers(), ConfigError)
        scale = self.scale if scale is None else scale
        source = {
            "run": self.path,
            "learner": self.learner,
            "controller": controller,
            "scale": scale,
        }
        if self.actor is not None and controller == "rl":
            if self.actor[0].layout.action == "joints":
                return Bundle("rl-joints", robot, self.ref.dt, actor=self.actor, source=source)
            style, gains = self.step_gait.at_scale(scale), self.step_gains["default"]
            return Bundle("rl-residual", robot, self.ref.dt, style, gains, self.actor, source)
        style, gains = self.step_gait.at_scale(scale), self.step_gains[controller]
        return Bundle("stepping", robot, self.ref.dt, style, gains, source=source)

    # Any: a policy ``(tick, observation) -> targets`` of one of several classes, whose
    # extras callers read where present (a faithful run's ``tick_actions``, ``first_loop_tick``)
    def policy(
        self, controller: str, robot: Robot, scale: float | None = None, seconds: float = 30.0
    ) -> Any:
        """A fresh controller ``controller`` (no exploration) at ``scale`` (default: the
        scale reached) for a walk of ``seconds`` [s].

        Raises:
            ConfigError: a controller this run cannot build (listing the ones it can).
        """
        scale = self.scale if scale is None else scale
        if self.step_gains is not None:  # played as exported: through imitwalk.runtime
            from imitwalk.runtime.controller import Controller

            return Controller(self.bundle(controller, robot, scale)).as_policy()
        if controller == OPEN_LOOP:
            return _OpenLoop(self.reference, scale, seconds)
        if controller not in self.controllers():
            raise unknown_name("controller", controller, self.controllers(), ConfigError)
        if self.laws is not None:
            from imitwalk.balance.feedback import TickPolicy
            from imitwalk.retarget.feedforward import walk_offsets

            s = self.settings_of(controller)
            ref = self.reference
            offsets = walk_offsets(ref, robot, scale, seconds, s["feedforward"])
            laws, names = self.laws[controller], robot.joint_names
            return TickPolicy(ref, scale, laws, names, seconds, offsets=offsets, wait=s["wait"])
        assert self.gait is not None  # a faithful run's
        return self.gait.policy(scale)


#: The learners whose runs :func:`load_run` reads, as ``config.json`` names them.
LEARNERS = ("step", "rl", "tick", "faithful")


def _gains(rd: RunDir, names: tuple[str, ...], what: str) -> dict:
    """The gains ``names`` of the run's ``gains.json`` (``what``: the run's kind, as a
    message says it), each a :class:`~imitwalk.step.gains.StepGains`.

    Raises:
        RunError: one line naming the file and the entry missing or invalid, and the
            entries such a run's gains.json holds; or an entry that lacks gains (learning
            writes every one: a gain missing is not taken from the defaults), listing them.
    """
    from imitwalk.step.gains import BOUNDS, StepGains

    path, saved = rd.file("gains.json"), rd.read_json("gains.json")
    holds = " and ".join(repr(n) for n in names)
    missing = [n for n in names if n not in saved]
    if missing:
        raise RunError(
            f"{path} lacks {', '.join(repr(n) for n in missing)}: {what}'s gains.json holds "
            f"{holds} (each a mapping of gain names to numbers)"
        )
    out = {}
    for name in names:
        try:
            out[name] = StepGains.from_dict(saved[name])
        except ConfigError as exc:
            raise RunError(f"{path}: {name!r}: {exc}") from None
        lacks = [g for g in BOUNDS if g not in saved[name]]
        if lacks:
            raise RunError(
                f"{path}: {name!r} lacks the gains {', '.join(lacks)} (a run's gains.json "
                "holds every one; learn the run again)"
            )
    return out


def load_run(run_dir: str | Path) -> LoadedRun:
    """Read a finished run folder (a one-line :class:`~imitwalk.errors.RunError` if it is
    not one).

    Its ``config.json`` names the learner (:data:`LEARNERS`); a run without one was
    written before learners were named and is read as ``faithful``'s, as it was then.

    Raises:
        RunError: a file is missing or invalid (which, and why), or the learner is not
            one of :data:`LEARNERS`.
    """
    rd = RunDir(run_dir)
    config, metrics = rd.read_json("config.json"), rd.read_summary()
    if not isinstance(config, dict):
        raise RunError(f"{rd.file('config.json')} is not a run's settings (not a JSON object)")
    learner = config.get("learner", "faithful")
    if not isinstance(learner, str) or learner not in LEARNERS:
        refused = unknown_name("learner", learner, LEARNERS, RunError)
        raise RunError(f"{rd.file('config.json')}: {refused}")
    learn = config.get("learn", {})
    if not isinstance(learn, dict):
        raise RunError(
            f"{rd.file('config.json')}: learn must be an object of the learning settings "
            f"(got a JSON {type(learn).__name__})"
        )
    engine = str(learn.get("engine", "mujoco"))
    if learner == "rl":
        from imitwalk.rl.actor import ActorSpec
        from imitwalk.rl.network import MLP
        from imitwalk.step.gait import StepGait

        gait = StepGait.load(rd.file("style.json"))
        default = _gains(rd, ("default",), "a PPO run")["default"]
        actor = (ActorSpec.load(rd.file("actor.json")), MLP.load(rd.file("policy.npz")))
        return LoadedRun(
            str(rd.path),
            "rl",
            gait,
            1.0,
            engine,
            metrics,
            step_gains={"default": default},
            actor=actor,
        )
    if learner == "step":
        from imitwalk.step.gait import StepGait

        gait = StepGait.load(rd.file("style.json"))
        gains = _gains(rd, ("learned", "default"), "a stepping run")
        return LoadedRun(
            str(rd.path),
            "step",
            gait,
            float(metrics.scale_reached),
            engine,
            metrics,
            step_gains=gains,
        )
    if learner == "tick":
        from imitwalk.balance.tickstore import load_laws

        ref = Reference.load(rd.file("reference.npz"))
        scale = float(metrics.scale_reached)
        laws, settings = load_laws(rd.path), metrics.tick().reference_settings
        return LoadedRun(str(rd.path), "tick", ref, scale, engine, metrics, laws, settings=settings)
    from imitwalk.paper.evaluate import load_gait

    lg = load_gait(rd.path)
    return LoadedRun(str(rd.path), "faithful", lg.ref, lg.scale, engine, metrics, gait=lg)
