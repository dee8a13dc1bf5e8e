"""The per-tick learner's shared context and its first stage, the trials
(:mod:`imitwalk.balance.ticklearn` runs the stages).

Trials pick, one setting at a time and each from its candidates, at the trial scale, on
many short walks of training robots (:class:`~imitwalk.balance.tickrun.Trial`): first,
with no feedback, how the reference is played (:data:`REFERENCE_SETTINGS`), then the
feedback law's gains (:data:`~imitwalk.balance.tickstore.TRIAL_GAINS`). A gain whose
feature is held to the nominal robot's profile first walks the nominal robot once.

The trial scale is the top scale until a table cannot tell its candidates apart there
(:func:`~imitwalk.balance.tickrun.blind`); it is then walked again one scale of the
schedule lower, down to the first, and the trials after it (the trust trial too) stay
there. G1's trials so walk at 0.3; hoap2's and OP3's are never walked lower.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from dataclasses import asdict, dataclass, field, replace

from imitwalk.balance.feedback import Episode, FeedbackLaw
from imitwalk.balance.tickconfig import TickLearnConfig
from imitwalk.balance.ticklog import LogEntry, TrialsEntry
from imitwalk.balance.tickmodel import nominal_profile
from imitwalk.balance.tickrun import (
    TickJob,
    TickResult,
    Trial,
    best,
    blind,
    most_falls,
    run_tick_episode,
)
from imitwalk.balance.tickstore import TRIAL_GAINS, TrialGain, feedback_law, stack_episodes
from imitwalk.parallel import run_parallel
from imitwalk.retarget.reference import Reference
from imitwalk.robots import Robot
from imitwalk.runs import RunDir
from imitwalk.sim.protocol import RobotDraw, load_protocol
from imitwalk.sim.seeds import TRIAL_SEED_BASE

__all__ = [
    "REFERENCE_SETTINGS",
    "Learner",
    "TickProgress",
    "checkpoint",
    "gains_key",
    "profile",
    "say_table",
    "trial",
    "trials",
]

#: How the reference is played, tried in this order before the gains, each named as in
#: :class:`~imitwalk.balance.tickconfig.TrialConfig` and :class:`TickJob`.
REFERENCE_SETTINGS = ("feedforward", "wait")


@dataclass
class TickProgress:
    """Where a run is (``checkpoint.json``); nothing else crosses the stages.

    Attributes:
        stage: ``"trials"``, ``"schedule"``, ``"trust"`` or ``"done"``.
        settings: how the reference is played, by name (:data:`REFERENCE_SETTINGS`),
            as the trials picked them so far; gains: the trial-picked gains so far, by
            setting name; trial: the next gain; profiles: the nominal robot's profile
            of each profiled feature, per loop tick (:func:`profile`).
        trial_scale: the scale the trials walk at (``None``: the top scale; lowered
            where a table is :func:`~imitwalk.balance.tickrun.blind`).
        scale_index, iteration: where the schedule is; passed: scales passed.
        trust: the fraction of the learned law kept (``None`` until decided).
        tried: every candidate's trial results so far, by key (run once each).
        sim_seconds, wall_seconds: what learning has cost so far [s].
    """

    stage: str = "trials"
    settings: dict = field(default_factory=dict)
    gains: dict = field(default_factory=dict)
    trial: int = 0
    profiles: dict = field(default_factory=dict)
    trial_scale: float | None = None
    scale_index: int = 0
    iteration: int = 0
    passed: list = field(default_factory=list)
    trust: float | None = None
    tried: dict = field(default_factory=dict)
    sim_seconds: float = 0.0
    wall_seconds: float = 0.0


class Learner:
    """The stages' shared context: the run folder, the robots and the budget."""

    def __init__(
        self,
        ref: Reference,
        robot: Robot,
        cfg: TickLearnConfig,
        rd: RunDir,
        progress: Callable[[str], None] | None,
    ) -> None:
        self.ref, self.robot, self.cfg, self.rd = ref, robot, cfg, rd
        self.say = progress or (lambda _line: None)
        self.protocol = load_protocol(cfg.train_protocol)
        self.scales = cfg.scales()
        self.ref_path = str(rd.file("reference.npz"))

    def trial_scale(self, state: TickProgress) -> float:
        """The scale the trials walk at (:attr:`TickProgress.trial_scale`)."""
        return self.scales[-1] if state.trial_scale is None else state.trial_scale

    def at(self, state: TickProgress) -> str:
        """What a trial's key adds for a lowered scale ("" at the top scale)."""
        return "" if state.trial_scale is None else f" at {state.trial_scale:g}"

    def lower(self, state: TickProgress, table: list) -> bool:
        """Whether ``table`` is :func:`~imitwalk.balance.tickrun.blind` and the trials
        can go one scale lower; if so, they do (``state.trial_scale``)."""
        below = [s for s in self.scales if s < self.trial_scale(state) - 1e-9]
        if not below or not blind(table):
            return False
        state.trial_scale = below[-1]
        self.say(f"trials: every candidate fell on every robot; trials go on at {below[-1]:g}")
        return True

    def robots(
        self, n: int, first: int, seconds: float, protocol: str | None = None
    ) -> list[RobotDraw]:
        """``n`` training robots from the ``first``-th on, drawn from ``protocol`` (a
        name; ``None``: the learner's ``train_protocol``)."""
        p = self.protocol if protocol is None else load_protocol(protocol)
        return [p.draw(first + j, self.robot, self.ref.sim_options(), seconds) for j in range(n)]

    def run(
        self,
        state: TickProgress,
        scale: float,
        laws: Sequence[FeedbackLaw],
        draws: Sequence[RobotDraw],
        seconds: float,
        explore: float = 0.0,
        rng: int = 0,
        settings: dict | None = None,
        first: int = 0,
        stop: Callable[[list[TickResult]], bool] | None = None,
    ) -> list[TickResult]:
        """Walk ``laws`` on ``draws`` (the ``first``-th robot on), the reference played
        with ``settings`` (default: the ones kept); with ``stop``, the shortest prefix of
        the walks it accepts (:func:`~imitwalk.parallel.run_parallel`)."""
        t0 = time.perf_counter()
        settings = state.settings if settings is None else settings
        jobs = [
            TickJob(
                self.ref_path,
                self.robot,
                scale,
                tuple(laws),
                d.seed,
                d.options,
                seconds,
                explore,
                (self.cfg.seed, rng, first + j),
                self.cfg.engine,
                **settings,
            )
            for j, d in enumerate(draws)
        ]
        spent: list = []
        out = run_parallel(run_tick_episode, jobs, self.cfg.workers, stop, spent)
        state.sim_seconds += sum(r.seconds for r in out + spent)
        state.wall_seconds += time.perf_counter() - t0
        return out


def trial(
    lr: Learner,
    state: TickProgress,
    key: str,
    laws: Sequence[FeedbackLaw],
    heading: bool = False,
    settings: dict | None = None,
    most: int | None = None,
    protocol: str | None = None,
) -> Trial:
    """The trials of ``laws`` at the trial scale (the heading's walks if ``heading``), the
    reference played with ``settings`` (default: the ones kept), on training robots from
    ``protocol`` (``None``: ``train_protocol``), run once per key (kept in the
    checkpoint, so that a resumed run neither repeats nor re-counts them).

    With ``most`` (:func:`~imitwalk.balance.tickrun.most_falls`) its walks stop once it
    has fallen more often (below 0: not walked). Every pick is the same as without the cut
    (tested); a cut trial is finished if a later use of its key needs the rest. Walks
    running when it was cut end at their next tick (:func:`~imitwalk.parallel.abandoned`),
    paid for (``sim_seconds``) but not kept: the trial is the same prefix of its robots
    whatever the workers, its cost not (07_06: 1,971 and 1,981 simulated seconds)."""
    t = lr.cfg.trials
    n, seconds = (t.heading_robots, t.heading_seconds) if heading else (t.robots, t.seconds)
    settings = state.settings if settings is None else settings
    key += "".join(f";{k} {v:g}" for k, v in settings.items() if v)
    key = f"{key}@{n}x{seconds:g}s" + ("" if protocol is None else f" [{protocol}]") + lr.at(state)
    done = [TickResult(**r) for r in state.tried.get(key, [])]
    limit = n if most is None else most
    fell = sum(r.fell for r in done)
    if len(done) < n and fell <= limit:
        draws = lr.robots(n - len(done), TRIAL_SEED_BASE + 1 + len(done), seconds, protocol)
        stop = None if most is None else (lambda out: fell + sum(r.fell for r in out) > limit)
        res = lr.run(
            state,
            lr.trial_scale(state),
            laws,
            draws,
            seconds,
            settings=settings,
            first=len(done),
            stop=stop,
        )
        done += res
    state.tried[key] = [asdict(replace(r, episode=None)) for r in done]
    return Trial(done, n)


def gains_key(gains: dict) -> str:
    """The trials' key of a law with ``gains`` by setting name (a missing one is 0)."""
    return ",".join(f"{g.name}={gains.get(g.name, 0.0):g}" for g in TRIAL_GAINS)


def say_table(lr: Learner, head: str, table: list[tuple[float, Trial]]) -> None:
    """One progress line: per candidate, its falls and mean |yaw| ± its standard error."""
    cells = []
    for v, t in table:
        s = t.summary()
        yaw = f"{s.abs_yaw_deg:.1f}±{s.abs_yaw_se_deg:.1f} deg"
        walked = f"{s.falls}/{s.robots} fell, {yaw}" if s.robots else "not walked"
        cells.append(f"[{v:g}: {walked}]")
    lr.say(f"{head} {' '.join(cells)}")


def _table(
    lr: Learner,
    state: TickProgress,
    values: Sequence[float],
    walk: Callable[[float, int | None], Trial],
    yaw_limit_deg: float | None = None,
) -> list:
    """The rows ``(value, Trial)`` of ``values``, each walked by ``walk(value, most)``
    (``most``: :func:`~imitwalk.balance.tickrun.most_falls` against the rows before it) at
    the trial scale, and walked again one scale lower while the table is
    :func:`~imitwalk.balance.tickrun.blind` there (:meth:`Learner.lower`)."""
    while True:
        table: list[tuple[float, Trial]] = []
        for value in values:
            most = most_falls(table, value, yaw_limit_deg)
            table.append((float(value), walk(float(value), most)))
        if not lr.lower(state, table):
            return table


def _reference_settings(lr: Learner, state: TickProgress, log: list[LogEntry]) -> None:
    """Stage 1's first choices: how the reference is played, one setting at a time, with
    no feedback, at the trial scale, on the balance gains' robots
    (``trials.balance_protocol``, whose servos sag unevenly: what the feedforward is for).
    Without a task-space plan (the paper's mapping) the reference is played as it is."""
    cfg = lr.cfg
    laws = [feedback_law(cfg, {})]
    for name in REFERENCE_SETTINGS[len(state.settings) :]:
        candidates = getattr(cfg.trials, name) if lr.ref.plan else (0.0,)

        def walk(value: float, most: int | None, name: str = name) -> Trial:
            settings = {**state.settings, name: value}
            return trial(
                lr,
                state,
                gains_key({}),
                laws,
                False,
                settings,
                most,
                protocol=cfg.trials.balance_protocol,
            )

        table = _table(lr, state, candidates, walk)
        state.settings[name] = kept = best(table)[0]
        rows = [{"value": v, **t.summary().to_dict()} for v, t in table]
        log.append(
            TrialsEntry(name, kept, lr.trial_scale(state), cfg.trials.balance_protocol, rows)
        )
        say_table(lr, f"trials: reference {name} = {state.settings[name]:g}", table)
        checkpoint(lr, state, log)


def profile(lr: Learner, state: TickProgress, feature: str) -> None:
    """The nominal robot's ``feature`` per loop tick (into ``state.profiles``), under the
    law the trials kept so far: one walk of ``trials.seconds`` at the trial scale (taken
    once: a later drop of that scale does not take it again), its
    start-up and, if it fell, its last half second left out (its start-up too if nothing
    else is left)."""
    cfg, ref = lr.cfg, lr.ref
    key = f"nominal robot: {feature} profile@{cfg.trials.seconds:g}s" + lr.at(state)
    laws = [feedback_law(cfg, state.gains, state.profiles)]
    nominal = RobotDraw(0, ref.sim_options())
    (res,) = lr.run(state, lr.trial_scale(state), laws, [nominal], cfg.trials.seconds)
    ep = res.episode
    assert ep is not None  # walks record their ticks
    end = len(ep.phase) - (round(0.5 / ref.dt) if res.fell else 0)
    start = ref.starts.shape[1] if end > ref.starts.shape[1] else 0
    cut = Episode(ep.phase[start:end], ep.features[start:end], ep.actions[start:end])
    p = nominal_profile([cut], (feature,), ref.loops.shape[1])[:, 0]
    state.profiles[feature] = p.tolist()
    state.tried[key] = [asdict(replace(res, episode=None))]
    fell = f", fell at {res.fall_time_s:.1f} s" if res.fell else ""
    lr.say(f"trials: the nominal robot's {feature} {p.min():+.3f}..{p.max():+.3f}{fell}")


def trials(lr: Learner, state: TickProgress, log: list[LogEntry]) -> None:
    """Stage 1: how the reference is played, then one gain at a time, each from its
    candidates, at the trial scale."""
    cfg = lr.cfg
    _reference_settings(lr, state, log)
    while state.trial < len(TRIAL_GAINS):
        g = TRIAL_GAINS[state.trial]
        if g.profiled and g.feature not in state.profiles:
            profile(lr, state, g.feature)
            checkpoint(lr, state, log)
        limit = cfg.trials.yaw_limit_deg if g.steers else None
        protocol = getattr(cfg.trials, g.protocol) if g.protocol else None

        def walk(
            value: float, most: int | None, g: TrialGain = g, protocol: str | None = protocol
        ) -> Trial:
            gains = {**state.gains, g.name: value}
            laws = [feedback_law(cfg, gains, state.profiles)]
            return trial(lr, state, gains_key(gains), laws, g.steers, most=most, protocol=protocol)

        table = _table(lr, state, getattr(cfg.trials, g.name), walk, limit)
        state.gains[g.name] = kept = best(table, limit)[0]
        log.append(
            TrialsEntry(
                gain=g.name,
                kept=kept,
                scale=lr.trial_scale(state),
                protocol=protocol or cfg.train_protocol,
                table=[{"value": v, **t.summary().to_dict()} for v, t in table],
                channel=g.channel,
                feature=g.feature,
            )
        )
        say_table(lr, f"trials: {g.feature} -> {g.channel} = {kept:g}", table)
        state.trial += 1
        checkpoint(lr, state, log)
    state.stage = "schedule" if cfg.lqr.enabled else "done"


def checkpoint(
    lr: Learner, state: TickProgress, log: list[LogEntry], data: list | None = None
) -> None:
    if data is not None:
        lr.rd.write_arrays("data.npz", stack_episodes(data))
    lr.rd.write_log([e.to_dict() for e in log])
    lr.rd.write_json("checkpoint.json", asdict(state))
