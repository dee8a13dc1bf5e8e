"""Learning the stepping gait's gains: CMA-ES on training robots, checkpointed.

All of the stepping controller's gains (:class:`~imitwalk.step.gains.StepGains`) that
:attr:`StepLearnConfig.names` lists are chosen together by the covariance matrix
adaptation evolution strategy (Hansen, 2016; the ``cmaes`` package) in the unit box of
their ranges, starting from the shipped gains (:class:`~imitwalk.step.gains.StepGains`'s
defaults). Each generation
walks every candidate on the same few training robots, drawn from a protocol (``hard``
by default: friction, mass, servos, a shifted torso, noisy sensors, late servos,
slopes and kicks) at seeds that no judge uses (from :data:`~imitwalk.sim.seeds.TRAIN_FIRST`); each
generation draws new ones. A candidate's cost is the mean of its walks'
(:func:`~imitwalk.step.episode.score_walk`: falls first, then progress and heading).

At the end the best candidate of each generation, and the start, walk the same
:attr:`StepLearnConfig.final_robots` fresh robots for :attr:`StepLearnConfig.final_seconds`.
A winner replaces the start only if at least :data:`KEEP_MARGIN` fewer of those robots
fell with it (then the least cost decides among such winners): a generation's winner on
five short walks is partly luck. On CMU 07_06 one kept by its cost alone fell 11 of 40
eval robots where the start fell none; on the turning clip one kept for a single fall
fewer (3 against 4 of 10) kept 14 of `hard`'s 40 up against the start's 19.

The run folder holds ``cma.pkl`` (the optimiser) and ``log.jsonl`` after every
generation; the optimiser's random draws are seeded per generation, and its covariance
matrix is stored whole beside its pickle (which keeps one triangle of it), so ``resume``
ends exactly where an uninterrupted run would.
"""

from __future__ import annotations

import pickle
import time
from collections.abc import Callable
from dataclasses import asdict, dataclass, field, replace
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from imitwalk.errors import ConfigError, RunError, unknown_name
from imitwalk.fileio import atomic_write
from imitwalk.parallel import run_parallel
from imitwalk.robots import Robot
from imitwalk.runs import RunDir
from imitwalk.sim.seeds import FINAL_FIRST, TRAIN_FIRST
from imitwalk.step.episode import StepJob, StepScore, mean_cost, run_step_job
from imitwalk.step.gains import BOUNDS, StepGains
from imitwalk.step.style import GaitStyle

if TYPE_CHECKING:  # the caller loads the protocol (its draws need SciPy)
    from imitwalk.sim.protocol import Protocol, RobotDraw

__all__ = ["SEARCHED", "StepLearnConfig", "StepLearnResult", "learn_step"]

#: How many fewer final robots a generation's winner must fell than the start to replace
#: it (one fall is within the noise of ten robots).
KEEP_MARGIN = 2
#: The gains searched by default: all of them.
SEARCHED = tuple(BOUNDS)
#: The checkpoint's entry holding, whole, the optimiser's arrays that its pickle does not
#: keep exactly (:data:`_INEXACT`).
_EXACT = "cma_exact"
#: The arrays of ``cmaes.CMA`` that its ``__getstate__`` stores inexactly: ``_C``, the
#: covariance matrix, of which it keeps one triangle and rebuilds a symmetric matrix,
#: while the live one is not exactly symmetric after the second generation (a resumed
#: run's eigenvectors, and so its candidates, would differ from an uninterrupted run's).
_INEXACT = ("_C",)


@dataclass(frozen=True)
class StepLearnConfig:
    """How the gains are learned.

    Attributes:
        robots: training robots per generation; seconds: each walk [s];
        generations: CMA-ES generations; population: candidates per generation;
        sigma: CMA-ES's initial step, in the unit box of each gain's range;
        protocol: the protocol the training robots are drawn from; names: the gains
        searched; final_robots: robots of the final choice (0: keep the best
        generation winner as it is); final_seconds: their walks [s]; seed: CMA-ES's seed;
        engine: the physics engine.
    """

    robots: int = 5
    seconds: float = 8.0
    generations: int = 4
    population: int = 6
    sigma: float = 0.15
    protocol: str = "hard"
    names: tuple[str, ...] = SEARCHED
    final_robots: int = 10
    final_seconds: float = 15.0
    seed: int = 0
    engine: str = "mujoco"

    def __post_init__(self) -> None:
        for n in self.names:
            if n not in BOUNDS:
                raise unknown_name("gain", n, tuple(BOUNDS), ConfigError)
        checks = {
            "robots": (self.robots >= 1, ">= 1"),
            "seconds": (self.seconds > 0, "> 0"),
            "generations": (self.generations >= 1, ">= 1"),
            "population": (self.population >= 4, ">= 4"),
            "sigma": (0 < self.sigma <= 1, "in (0, 1]"),
            "final_robots": (self.final_robots >= 0, ">= 0"),
            "final_seconds": (self.final_seconds > 0, "> 0"),
        }
        for k, (ok, valid) in checks.items():
            if not ok:
                raise ConfigError(
                    f"learn setting {k}={getattr(self, k)!r} is out of range (expected {valid})"
                )

    def to_dict(self) -> dict:
        """Plain-JSON dictionary."""
        d = asdict(self)
        d["names"] = list(self.names)
        return d

    def budget(self) -> float:
        """Simulated seconds the run walks at most [s]."""
        gen = self.generations * self.population * self.robots * self.seconds
        final = ((self.generations + 1) * self.final_robots + 1) * self.final_seconds
        return gen + (final if self.final_robots else 0.0)


@dataclass(frozen=True)
class StepLearnResult:
    """What learning gave: the kept ``gains``; ``history``, per generation its best and
    mean cost and the best candidate's gains; ``final``, each finalist's cost on the
    final robots (``"start"`` and ``"generation N"``); the ``sim_seconds`` walked and the
    ``wall_seconds`` taken."""

    gains: StepGains
    history: list = field(default_factory=list)
    final: dict = field(default_factory=dict)
    sim_seconds: float = 0.0
    wall_seconds: float = 0.0


def _checkpoint(rd: RunDir) -> dict:
    """The run's ``cma.pkl`` (a one-line :class:`RunError` if it is not one this module
    wrote: empty, truncated, or of another shape)."""
    from cmaes import CMA

    path = rd.file("cma.pkl")
    try:
        with open(path, "rb") as fh:
            saved = pickle.load(fh)
    except OSError as exc:
        raise RunError(f"{path} cannot be read: {exc.strerror}") from None
    except Exception as exc:  # unpickling raises almost anything on a damaged file
        raise RunError(
            f"{path} is truncated or corrupt ({type(exc).__name__}); "
            "delete it and learn again without --resume"
        ) from None
    keys = ("config", "cma", "log", "sim_seconds", "wall")
    if not isinstance(saved, dict) or any(k not in saved for k in keys):
        raise RunError(f"{path} is not a stepping-gait checkpoint (expected {', '.join(keys)})")
    if not isinstance(saved["cma"], CMA) or not isinstance(saved["log"], list):
        raise RunError(f"{path} is not a stepping-gait checkpoint (its optimiser or log)")
    _restore_exact(saved["cma"], saved.get(_EXACT, {}), path)
    return saved


def _exact_state(opt: Any) -> dict[str, np.ndarray]:
    """Copies of the optimiser's arrays its pickle keeps inexactly (:data:`_INEXACT`)."""
    return {name: np.array(getattr(opt, name), copy=True) for name in _INEXACT}


def _restore_exact(opt: Any, exact: object, path: Path) -> None:
    """Put the arrays :func:`_exact_state` stored back into the unpickled ``opt`` (a
    checkpoint written before they were stored has none: its optimiser stays as
    unpickled). A one-line :class:`RunError` for arrays of another name or shape."""
    if not isinstance(exact, dict) or any(k not in _INEXACT for k in exact):
        raise RunError(
            f"{path} is not a stepping-gait checkpoint (its {_EXACT} holds {', '.join(_INEXACT)})"
        )
    for name, value in exact.items():
        live = getattr(opt, name, None)
        if not (
            isinstance(value, np.ndarray)
            and isinstance(live, np.ndarray)
            and value.shape == live.shape
            and value.dtype == live.dtype
        ):
            raise RunError(
                f"{path} is not a stepping-gait checkpoint (its {_EXACT} {name} is not the "
                "optimiser's array)"
            )
        setattr(opt, name, value)


def _robots(
    protocol: Protocol, robot: Robot, first: int, count: int, seconds: float
) -> list[RobotDraw]:
    return [protocol.draw(first + i, robot, seconds=seconds) for i in range(count)]


def _walk_all(
    candidates: list[StepGains],
    draws: list[RobotDraw],
    robot: Robot,
    styles: list[GaitStyle],
    cfg: StepLearnConfig,
) -> list[list[StepScore]]:
    """Every candidate on every robot; robot ``i`` walks ``styles[i % len(styles)]``."""
    jobs = [
        StepJob(robot, styles[i % len(styles)], g, d.seed, d.options, cfg.seconds, cfg.engine)
        for g in candidates
        for i, d in enumerate(draws)
    ]
    res = run_parallel(run_step_job, jobs)
    n = len(draws)
    return [res[i * n : (i + 1) * n] for i in range(len(candidates))]


def learn_step(
    robot: Robot,
    style: GaitStyle | list[GaitStyle],
    cfg: StepLearnConfig,
    run_dir: str | Path,
    protocol: Protocol,
    resume: bool = False,
    progress: Callable[[str], None] | None = None,
    start: StepGains | None = None,
) -> StepLearnResult:
    """Learn the gains of ``style`` on ``robot`` (see the module doc; a list of styles:
    the training robots take them in turn), checkpointed in
    ``run_dir`` after every generation; ``protocol`` (a
    :class:`~imitwalk.sim.protocol.Protocol`, the one ``cfg.protocol`` names) draws
    the training robots; ``start``: where the search starts (default: the shipped
    gains).

    Raises:
        RunError: ``resume`` without a checkpoint, or with other settings.
    """
    say = progress or (lambda _msg: None)
    styles = list(style) if isinstance(style, list) else [style]
    rd = RunDir(run_dir)
    rd.path.mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()
    start = start or StepGains()
    opt, log, spent, wall = _optimiser(rd, cfg, start, resume, say)
    t0 -= wall
    for gen in range(len(log), cfg.generations):
        spent += _generation(opt, gen, start, robot, styles, cfg, protocol, log, say)
        _save(rd, cfg, opt, log, spent, time.perf_counter() - t0)
    kept, final, spent = _final_choice(log, start, robot, styles, cfg, protocol, spent, say)
    return StepLearnResult(kept, log, final, spent, time.perf_counter() - t0)


def _optimiser(
    rd: RunDir, cfg: StepLearnConfig, start: StepGains, resume: bool, say: Callable[[str], None]
) -> tuple[Any, list[dict], float, float]:
    """The CMA-ES optimiser, the generations' log, the simulated seconds spent [s] and the
    wall time spent [s]: a fresh search from ``start``, or the checkpoint's (``resume``).

    Raises:
        RunError: ``resume`` without a checkpoint, or with other settings.
    """
    from cmaes import CMA

    if resume and rd.exists("cma.pkl"):
        saved = _checkpoint(rd)
        if saved["config"] != cfg.to_dict():
            raise RunError(f"{rd.path} was started with other settings; resume with the same ones")
        say(f"learn: resuming after generation {len(saved['log'])}")
        return saved["cma"], saved["log"], saved["sim_seconds"], saved["wall"]
    if resume:
        raise RunError(f"nothing to resume in {rd.path}: no cma.pkl")
    x0 = start.vector(cfg.names)
    bounds = np.tile([0.0, 1.0], (len(cfg.names), 1))
    opt = CMA(
        mean=x0, sigma=cfg.sigma, bounds=bounds, population_size=cfg.population, seed=cfg.seed
    )
    return opt, [], 0.0, 0.0


def _ask(opt: Any, cfg: StepLearnConfig, gen: int) -> list[np.ndarray]:
    """Generation ``gen``'s (from 0) candidates, ``cfg.population`` points of the unit box
    of the searched gains' ranges, each ``(len(cfg.names),)``."""
    # the optimiser's draws are seeded per generation: ``cmaes`` does not pickle its
    # random state, and a resumed run must draw what an uninterrupted one would
    opt.reseed_rng(cfg.seed * 100_003 + gen)
    return [opt.ask() for _ in range(opt.population_size)]


def _generation(
    opt: Any,
    gen: int,
    start: StepGains,
    robot: Robot,
    styles: list[GaitStyle],
    cfg: StepLearnConfig,
    protocol: Protocol,
    log: list[dict],
    say: Callable[[str], None],
) -> float:
    """One generation ``gen`` (from 0): its candidates walk fresh training robots, the
    optimiser is told their costs, and ``log`` gains its line. Returns the simulated
    seconds walked [s]."""
    xs = _ask(opt, cfg, gen)
    cands = [start.with_vector(cfg.names, x) for x in xs]
    draws = _robots(protocol, robot, TRAIN_FIRST + gen * cfg.robots, cfg.robots, cfg.seconds)
    scores = _walk_all(cands, draws, robot, styles, cfg)
    costs = [mean_cost(s) for s in scores]
    walked = sum(r.seconds for s in scores for r in s)
    opt.tell(list(zip(xs, costs, strict=True)))
    k = int(np.argmin(costs))
    falls = [sum(r.fell for r in s) for s in scores]
    log.append(
        {
            "generation": gen + 1,
            "best_cost": costs[k],
            "mean_cost": float(np.mean(costs)),
            "best_falls": falls[k],
            "robots": cfg.robots,
            "best_gains": cands[k].to_dict(),
        }
    )
    say(
        f"learn: generation {gen + 1}/{cfg.generations}: best cost {costs[k]:.3f} "
        f"({falls[k]}/{cfg.robots} fell), mean {np.mean(costs):.3f}"
    )
    return walked


def _save(
    rd: RunDir, cfg: StepLearnConfig, opt: Any, log: list[dict], spent: float, wall: float
) -> None:
    """The checkpoint (``cma.pkl``: the optimiser, the arrays its pickle keeps inexactly,
    the log, the simulated and wall seconds spent [s]) and ``log.jsonl``, each written
    whole. The live optimiser is left as it is: an uninterrupted run is not changed by
    its checkpoints."""
    state = {
        "config": cfg.to_dict(),
        "cma": opt,
        _EXACT: _exact_state(opt),
        "log": log,
        "sim_seconds": spent,
        "wall": wall,
    }
    blob = pickle.dumps(state)
    atomic_write(rd.file("cma.pkl"), lambda tmp: tmp.write_bytes(blob))
    rd.write_log(log)


def _final_choice(
    log: list[dict],
    start: StepGains,
    robot: Robot,
    styles: list[GaitStyle],
    cfg: StepLearnConfig,
    protocol: Protocol,
    spent: float,
    say: Callable[[str], None],
) -> tuple[StepGains, dict, float]:
    """The gains kept, each finalist's walk on the final robots, and ``spent`` plus what
    they walked [s]: the start and each generation's best walk ``cfg.final_robots``
    robots; a generation's best replaces the start only if it fells at least
    :data:`KEEP_MARGIN` fewer (without final robots: the best cost of the generations)."""
    finalists = {"start": start}
    for entry in log:
        finalists[f"generation {entry['generation']}"] = StepGains.from_dict(entry["best_gains"])
    final: dict = {}
    kept = StepGains.from_dict(min(log, key=lambda e: e["best_cost"])["best_gains"])
    if not cfg.final_robots:
        return kept, final, spent
    long = replace(cfg, seconds=cfg.final_seconds)
    draws = _robots(protocol, robot, FINAL_FIRST, cfg.final_robots, cfg.final_seconds)
    names = list(finalists)
    scores = _walk_all([finalists[n] for n in names], draws, robot, styles, long)
    spent += sum(r.seconds for s in scores for r in s)
    final = {
        n: {"cost": mean_cost(s), "falls": int(sum(r.fell for r in s))}
        for n, s in zip(names, scores, strict=True)
    }
    bar = final["start"]["falls"] - KEEP_MARGIN
    better = [n for n in names[1:] if final[n]["falls"] <= bar]
    best = min(better, key=lambda n: (final[n]["cost"], names.index(n))) if better else "start"
    kept = finalists[best]
    fell = f"{final[best]['falls']}/{cfg.final_robots}"
    say(f"learn: kept {best} ({fell} fell on the final robots)")
    # the nominal robot (no factor drawn) walks the kept gains once: a robot or clip
    # the stepping gait cannot walk at all is told so
    nominal = protocol.only(()).draw(FINAL_FIRST, robot, seconds=cfg.final_seconds)
    walk = _walk_all([kept], [nominal], robot, styles, long)[0][0]
    spent += walk.seconds
    if walk.fell:
        say(
            "learn: warning: the kept gains fall on the nominal robot at "
            f"{walk.fall_time_s:.1f} s; for this robot or clip try `--variant extended` "
            "(the per-tick learner)"
        )
    return kept, final, spent
