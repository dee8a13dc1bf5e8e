"""Learning to balance every tick: trial-picked feedback, then the paper's loop on top.

Three stages, each checkpointed, so that an interrupted run resumes where it stopped
and ends where an uninterrupted one would:

1. **Trials** (:func:`trials`): first, with no feedback, how the reference is played:
   the fraction of the servo feedforward added to it
   (:mod:`imitwalk.retarget.feedforward`), then the load share at which its clock waits
   before a lift-off (:class:`~imitwalk.balance.feedback.TickPolicy`), both on training
   robots with a wider servo spread (``trials.balance_protocol``); then the feedback law,
   one gain at a time: gyro_y → ankle pitch, gyro_x → ankle roll, the torso's pitch less
   the nominal robot's → both hip pitches (on the same robots), that pitch → both ankle
   pitches (on sloped floors, ``trials.tilt_protocol``), heading → turn (steering:
   :data:`~imitwalk.balance.channels.PHASED`), each chosen from its candidates by trials
   (:class:`Trial`) on many short walks of training robots: the baseline the learned law
   starts from. The trials walk at the top scale, or lower where no candidate walked any
   robot there (:func:`~imitwalk.balance.tickrun.blind`).
2. **The paper's loop** (§5 steps 3–7, §6): from scale 0.3 up, execute on training
   robots (with exploration in a scale's first iteration), record, fit the per-tick
   model of eqs. 3–4 (:class:`~imitwalk.balance.tickmodel.PhaseModel`), turn it into gains by
   the receding-horizon eq.-6 search (:func:`~imitwalk.balance.lqr.horizon_gains`) and go on;
   a scale is passed by an iteration without exploration in which no training robot
   falls. The learned law acts on top of the trial-picked one.
3. **Trust** (:func:`_trust`): the learned law's gains × each of ``lqr.trust`` at the
   trials' scale, on the heading trials' robots (so the trial-picked law's walks there are
   reused); the smallest fraction that falls least is kept (0: the trial-picked law
   alone).

``scale_reached`` is the trials' scale if the kept law walked every trial robot there
without a fall, or the highest scale the schedule passed if that is higher (the first
scale if neither): the controllers are judged there. ``scales_passed``: how far the
schedule carried the model-based law.

Training robots come from ``train_protocol`` with seeds no evaluation uses.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace
from pathlib import Path

from imitwalk.balance.feedback import Episode, FeedbackLaw
from imitwalk.balance.lqr import Costs, horizon_gains
from imitwalk.balance.tickconfig import TickLearnConfig
from imitwalk.balance.ticklog import (
    LogEntry,
    ScheduleEntry,
    TrialsEntry,
    TrustEntry,
    entry_from_dict,
)
from imitwalk.balance.tickmodel import PhaseModel, nominal_profile
from imitwalk.balance.tickrun import Trial, best, most_falls, summarize
from imitwalk.balance.tickstore import feedback_law, load_learned, save_learned, unstack_episodes
from imitwalk.balance.ticktrials import (
    Learner,
    TickProgress,
    checkpoint,
    gains_key,
    say_table,
    trial,
    trials,
)
from imitwalk.config import to_dict
from imitwalk.retarget.reference import Reference
from imitwalk.robots import Robot
from imitwalk.runs import LearnSummary, RunDir, TickOutcome
from imitwalk.sim.seeds import TRAIN_SEED_BASE

__all__ = ["TickProgress", "learn_tick"]


def _learned_law(lr: Learner, episodes: list[Episode]) -> tuple[FeedbackLaw, PhaseModel]:
    """Fit the model on ``episodes`` and turn it into the learned law (and the model);
    the states are the features less their mean at each phase in ``episodes``."""
    c = lr.cfg.lqr
    n = lr.ref.loops.shape[1]
    shell = FeedbackLaw.zero(c.channels, c.features, c.box, n_ticks=n, memory=True)
    shell = replace(shell, nominal=nominal_profile(episodes, c.features, n))
    model = PhaseModel(n_phases=n, width=c.width, ridge=c.ridge).fit(episodes, shell)
    costs = Costs(c.costs(), c.action_cost, c.change_cost, c.horizon)
    return replace(shell, gains=horizon_gains(model, costs)), model


def _schedule(
    lr: Learner, state: TickProgress, log: list[LogEntry], data: list
) -> FeedbackLaw | None:
    """Stage 2: execute, record, fit, derive gains, scale up (paper §5–6)."""
    cfg = lr.cfg
    base = feedback_law(cfg, state.gains, state.profiles)
    learned, model = load_learned(lr.rd), None
    if data and state.scale_index < len(lr.scales):  # resumed: the model of the last iteration
        last = log[-1].scale if log and isinstance(log[-1], ScheduleEntry) else None
        if last is not None:
            learned, model = _learned_law(lr, [e for s, e in data if abs(s - last) < 1e-9])
    while state.scale_index < len(lr.scales):
        scale = lr.scales[state.scale_index]
        explore = cfg.lqr.explore if state.iteration == 0 else 0.0
        # the iterations so far (not moved by how many trials came first)
        n = sum(isinstance(e, ScheduleEntry) for e in log)
        draws = lr.robots(cfg.robots, TRAIN_SEED_BASE + 1 + cfg.robots * n, cfg.seconds)
        laws = [base] if learned is None else [base, learned]
        if learned is None:  # the first iteration records the trial-picked law's channels
            laws = [base, FeedbackLaw.zero(cfg.lqr.channels, cfg.lqr.features, cfg.lqr.box)]
        res = lr.run(state, scale, laws, draws, cfg.seconds, explore, rng=n)
        new = [(scale, r.episode) for r in res if r.episode is not None]
        held = None
        if model is not None:  # the last model, on episodes it has not seen
            assert learned is not None  # fitted together with the model
            pred = model.score_episodes([e for _, e in new], learned)
            held = pred.to_dict() if pred else None
        data.extend(new)
        near = [e for s, e in data if abs(s - scale) < 1e-9]
        learned, model = _learned_law(lr, near)
        fell = sum(r.fell for r in res)
        entry = ScheduleEntry(scale, state.iteration, explore, summarize(res), held)
        log.append(entry)
        ratio = f"{held['ratio_to_persistence']:.2f}" if held else "  - "
        lr.say(
            f"scale {scale:.2f} it {state.iteration} | fell {fell}/{len(res)} | "
            f"cost {entry.walks.cost:.3f} | model err / persistence {ratio}"
        )
        if explore == 0.0 and fell == 0:
            state.passed.append(scale)
            state.scale_index, state.iteration = state.scale_index + 1, 0
        elif state.iteration + 1 >= cfg.iterations:
            break
        else:
            state.iteration += 1
        save_learned(lr.rd, learned)
        checkpoint(lr, state, log, data)
    save_learned(lr.rd, learned)
    state.stage = "trust"
    return learned


def _trust(
    lr: Learner, state: TickProgress, log: list[LogEntry], learned: FeedbackLaw | None
) -> None:
    """Stage 3: how much of the learned law to keep, by the trials at the trials' scale
    (the law the schedule learned at the highest scale it passed) on the heading trials'
    robots: their 30 s walks are the evaluation's length, and the trial-picked law alone
    (fraction 0) has walked them already. The smallest fraction is walked first and the
    larger ones are cut as every trial is (:func:`~imitwalk.balance.tickrun.most_falls`):
    where the trial-picked law alone did not fall, a larger fraction could at best tie,
    and lose on its size, so it is not walked. Measured: this saves 280 simulated seconds
    on every run whose trial-picked law did not fall, and every run keeps its law
    (docs/history/benchmarks-0.2.md, "Learning cost")."""
    cfg = lr.cfg
    if learned is None:
        state.trust, state.stage = 0.0, "done"
        return
    base = feedback_law(cfg, state.gains, state.profiles)
    table: list[tuple[float, Trial]] = []
    for frac in sorted(cfg.lqr.trust):
        laws = [base] if frac == 0 else [base, replace(learned, gains=learned.gains * frac)]
        key = gains_key(state.gains) + ("" if frac == 0 else f";learned x {frac:g}")
        run = trial(lr, state, key, laws, heading=True, most=most_falls(table, frac))
        table.append((float(frac), run))
    kept = best(table)[0]
    state.trust, state.stage = kept, "done"
    rows = [{"fraction": f, **t.summary().to_dict()} for f, t in table]
    log.append(TrustEntry(lr.trial_scale(state), kept, rows))
    say_table(lr, f"trust at {lr.trial_scale(state):g}: kept {kept:g}", table)


def learn_tick(
    ref: Reference,
    robot: Robot,
    config: TickLearnConfig,
    run_dir: str | Path,
    resume: bool = False,
    progress: Callable[[str], None] | None = None,
) -> LearnSummary:
    """Learn to walk ``ref`` on ``robot`` with per-tick feedback; write ``run_dir``.

    Returns:
        the summary, also written as ``metrics.json``.
    """
    rd = RunDir(run_dir)
    cfg_json = {
        "learn": to_dict(config),
        "reference": ref.summary(),
        "robot": robot.name,
        "learner": "tick",
    }
    saved, lines = rd.start(cfg_json, ref, resume)
    log = [entry_from_dict(line) for line in lines]
    state = TickProgress(**saved) if saved else TickProgress()
    data = unstack_episodes(rd.read_arrays("data.npz")) if saved and rd.exists("data.npz") else []
    lr = Learner(ref, robot, config, rd, progress)
    if state.stage == "trials":
        trials(lr, state, log)
        checkpoint(lr, state, log, data)
    learned = load_learned(rd)
    if state.stage == "schedule":
        learned = _schedule(lr, state, log, data)
        checkpoint(lr, state, log, data)
    if state.stage == "trust":
        _trust(lr, state, log, learned)
        checkpoint(lr, state, log, data)
    kept = [t for t in log if isinstance(t, TrialsEntry | TrustEntry)][-1]
    row = next(r for r in kept.table if r.get("value", r.get("fraction")) == kept.kept)
    trial_falls, trial_scale = int(row["falls"]), lr.trial_scale(state)
    walked = [trial_scale] if trial_falls == 0 else []
    reached = max([*state.passed, *walked], default=lr.scales[0])
    summary = LearnSummary(
        learner="tick",
        scale_reached=reached,
        scales_passed=state.passed,
        iterations=sum(isinstance(e, ScheduleEntry) for e in log),
        sim_seconds_used_for_learning=state.sim_seconds,
        wall_seconds_for_learning=state.wall_seconds,
        config=to_dict(config),
        outcome=TickOutcome(
            trial_scale=trial_scale,
            trial_falls=trial_falls,
            feedback_gains=state.gains,
            trust=state.trust,
            reference_settings=state.settings,
        ),
    )
    rd.write_json("metrics.json", summary.to_dict())
    return summary
