"""A learning run's folder: config, log, data, checkpoint, metrics — written atomically.

RUN_DIR/
  config.json      the learning settings and where the reference came from
  reference.npz    the retargeted reference the run learned on
  data.npz         every recorded episode (what the models are fitted on)
  log.jsonl        one line per learning iteration
  checkpoint.json  where the schedule is (written after every iteration)
  metrics.json     the learning summary (scale reached, cost of learning)
  evaluation.json  written by ``imitwalk evaluate``
"""

from __future__ import annotations

import json
from collections.abc import Callable
from dataclasses import asdict, dataclass, fields
from pathlib import Path
from typing import Any

import numpy as np

from imitwalk import readback
from imitwalk.errors import ConfigError, RunError
from imitwalk.fileio import atomic_write, check_writable, writable_folder, write_npz

__all__ = [
    "OUTCOMES",
    "RUN_FORMAT",
    "FaithfulOutcome",
    "LearnSummary",
    "RunDir",
    "StepOutcome",
    "TickOutcome",
    "check_resumed_clip",
]

#: The format of a run folder's ``config.json`` and ``metrics.json`` that this imitwalk
#: writes, and the newest it reads (:func:`~imitwalk.readback.check_format`; a file
#: without a ``format`` is a run written before versions, read as format 1).
RUN_FORMAT = 1
#: The run files that carry a ``format``.
_VERSIONED = ("config.json", "metrics.json")


def check_resumed_clip(run: Path, recorded: object, given: str) -> None:
    """Refuse to resume the run in ``run``, which records its clip as ``recorded`` (a path;
    anything else records none), with the clip ``given``: it passes as the same file, a
    file of the same bytes, or (the recorded path not found from here) a file of its name.

    Raises:
        ConfigError: one line naming both clips.
    """
    import filecmp

    if not isinstance(recorded, str) or not recorded:
        return
    was, now = Path(recorded), Path(given)
    if was.resolve() == now.resolve() or (not was.exists() and was.name == now.name):
        return
    if was.is_file() and now.is_file() and filecmp.cmp(was, now, shallow=False):
        return
    raise ConfigError(
        f"{given}: {run} was started on the clip {recorded}; resume it without a clip "
        "(or with that one), or learn this clip into a new folder"
    )


def _json_default(v: object) -> object:
    if isinstance(v, np.generic):
        return v.item()
    if isinstance(v, np.ndarray):
        return v.tolist()
    if isinstance(v, Path):
        return str(v)
    raise TypeError(f"not JSON serialisable: {type(v).__name__}")


#: The types of the fields every learner writes to ``metrics.json``.
_SUMMARY_TYPES = {
    "learner": str,
    "scale_reached": float,
    "scales_passed": list,
    "iterations": int,
    "sim_seconds_used_for_learning": float,
    "wall_seconds_for_learning": float,
    "config": dict,
}


@dataclass(frozen=True)
class StepOutcome:
    """What the stepping gait's learner kept: ``gains``, by name
    (:class:`~imitwalk.step.gains.StepGains`); ``final``, each finalist's cost and
    falls on the final choice's robots; ``pace``, how the stride was chosen
    (:class:`~imitwalk.step.pace.PaceChoice`'s dictionary; ``None`` in older runs)."""

    gains: dict[str, float]
    final: dict[str, dict[str, float]]
    pace: dict[str, Any] | None = None


@dataclass(frozen=True)
class TickOutcome:
    """What the per-tick learner kept.

    Attributes:
        trial_scale: the scale the trials walked at (the top one unless no candidate
            walked a robot there); trial_falls: the kept law's falls there.
        feedback_gains: the gains the trials kept, by channel.
        trust: the fraction of the model-based law kept (0: none).
        reference_settings: how the trials chose to play the reference, by name:
            ``feedforward``, the fraction of the servo feedforward added
            (:mod:`imitwalk.retarget.feedforward`), and ``wait``, the load share at which
            its clock waits before a lift-off (0 or absent: none).
    """

    trial_scale: float | None = None
    trial_falls: int | None = None
    feedback_gains: dict[str, float] | None = None
    trust: float | None = None
    reference_settings: dict[str, float] | None = None


@dataclass(frozen=True)
class FaithfulOutcome:
    """What the paper's learner kept: its gait model's report (``gait``)."""

    gait: dict[str, Any]


#: What a learner kept, by the learner's name (PPO's, ``rl``, keeps its policy files).
OUTCOMES: dict[str, type[StepOutcome] | type[TickOutcome] | type[FaithfulOutcome]] = {
    "step": StepOutcome,
    "tick": TickOutcome,
    "faithful": FaithfulOutcome,
}


@dataclass(frozen=True)
class LearnSummary:
    """What a learner reached and what it cost: the record behind ``metrics.json``.

    Attributes:
        learner: ``"step"`` (the stepping gait), ``"tick"`` (the per-tick learner),
            ``"faithful"`` (the paper's, as written) or ``"rl"`` (PPO,
            :mod:`imitwalk.envs.ppo`).
        scale_reached: the largest stride scale learned; scales_passed: every scale passed.
        iterations: learning iterations run (schedule iterations for ``tick``).
        sim_seconds_used_for_learning: simulated time of every learning walk [s];
        wall_seconds_for_learning: wall time [s].
        config: the learner's settings.
        outcome: what the learner kept, of its own kind (:data:`OUTCOMES`; ``None`` for
            ``rl``); :meth:`step` and :meth:`tick` give it typed.
    """

    learner: str
    scale_reached: float
    scales_passed: list[float]
    iterations: int
    sim_seconds_used_for_learning: float
    wall_seconds_for_learning: float
    config: dict
    outcome: StepOutcome | TickOutcome | FaithfulOutcome | None = None

    def step(self) -> StepOutcome:
        """The stepping gait's outcome (:class:`RunError` for another learner's run)."""
        if not isinstance(self.outcome, StepOutcome):
            raise RunError(f"a {self.learner} run, not a stepping gait's")
        return self.outcome

    def tick(self) -> TickOutcome:
        """The per-tick learner's outcome (:class:`RunError` for another learner's run)."""
        if not isinstance(self.outcome, TickOutcome):
            raise RunError(f"a {self.learner} run, not the per-tick learner's")
        return self.outcome

    def to_dict(self) -> dict:
        """Plain-JSON dictionary: the common fields, then the outcome's."""
        out = {k: v for k, v in asdict(self).items() if k != "outcome"}
        return out | (asdict(self.outcome) if self.outcome is not None else {})

    @classmethod
    def from_dict(cls, d: dict, where: str = "metrics.json") -> LearnSummary:
        """The record :meth:`to_dict` wrote; :class:`RunError` naming the missing keys
        if ``d`` (read from ``where``) lacks any."""
        required = [f.name for f in fields(cls) if f.name != "outcome"]
        missing = [k for k in required if not isinstance(d, dict) or k not in d]
        if missing:
            raise RunError(f"{where} lacks {', '.join(missing)}: not a finished imitwalk run")
        readback.check_fields(d, _SUMMARY_TYPES, where, RunError)
        kind = OUTCOMES.get(d["learner"])
        outcome = None
        if kind is not None:
            try:
                outcome = kind(**{f.name: d[f.name] for f in fields(kind) if f.name in d})
            except TypeError:  # a required field missing
                need = ", ".join(f.name for f in fields(kind))
                raise RunError(f"{where}: a {d['learner']} run's summary needs {need}") from None
        return cls(**{k: d[k] for k in required}, outcome=outcome)


class RunDir:
    """Read and write the files of one run folder."""

    def __init__(self, path: str | Path):
        self.path = Path(path)

    def check_writable(self, flag: str = "--out") -> None:
        """Refuse, before any work starts, a folder that cannot be one: a path that is a
        file, one whose parent folder is missing, or one that cannot be written in.
        ``flag`` names the folder's command-line argument in the message."""
        if self.path.exists() and not self.path.is_dir():
            raise RunError(f"{self.path} is a file, not a run folder; choose another {flag}")
        if not self.path.is_dir():  # a new folder: its parent as for any new file
            check_writable(self.path, flag, RunError)
        elif not writable_folder(self.path):
            raise RunError(f"{flag} {self.path}: cannot write in it; choose another {flag}")

    def check_new(self, resume: bool, flag: str = "--out") -> None:
        """Refuse, before any work starts, a folder a run would be learned into that
        holds files already: files that are not an imitwalk run (learning would overwrite a
        user's ``metrics.json`` or ``log.jsonl``) or, without ``resume``, a run. A new or
        empty folder passes. ``flag`` names the folder's command-line argument.

        Raises:
            RunError: one line naming the folder (and the first files it holds).
        """
        if not self.path.is_dir():
            return
        held = sorted(p.name for p in self.path.iterdir())
        if not held:
            return
        if not self.holds_run():
            shown = ", ".join(held[:3]) + (f" and {len(held) - 3} more" if len(held) > 3 else "")
            raise RunError(
                f"{flag} {self.path} holds files that are not an imitwalk run ({shown}); give "
                "an empty or new folder, or --resume for an imitwalk run"
            )
        if not resume:
            raise RunError(
                f"{self.path} already holds a run; pass --resume or choose another {flag}"
            )

    def holds_run(self) -> bool:
        """True if the folder holds a learning run's files, finished or not: a
        ``config.json`` naming its learner or settings, a checkpoint (``checkpoint.json``,
        ``cma.pkl``) or a stepping gait (``style.json``), here or in a subfolder (a
        reference choice's passes, :mod:`imitwalk.learning.refchoice`)."""
        folders = [self, *(RunDir(p) for p in self.path.iterdir() if p.is_dir())]
        return any(f._run_files() for f in folders)

    def _run_files(self) -> bool:
        """True if this folder itself holds a run's files (:meth:`holds_run`)."""
        if any(self.exists(m) for m in ("checkpoint.json", "cma.pkl", "style.json")):
            return True
        try:
            config = json.loads(self.file("config.json").read_text(encoding="utf-8"))
        except (OSError, UnicodeDecodeError, ValueError, RecursionError):
            return False
        return isinstance(config, dict) and ("learner" in config or "learn" in config)

    def file(self, name: str) -> Path:
        """Path of a file in the run folder."""
        return self.path / name

    def exists(self, name: str) -> bool:
        """True if the file is there."""
        return self.file(name).is_file()

    def write_json(self, name: str, obj: Any) -> Path:
        """Write ``obj`` as JSON atomically (``config.json`` and ``metrics.json`` with
        their ``format``, :data:`RUN_FORMAT`)."""
        if name in _VERSIONED and isinstance(obj, dict):
            obj = {readback.FORMAT_KEY: RUN_FORMAT, **obj}
        text = json.dumps(obj, indent=2, default=_json_default)
        return atomic_write(self.file(name), lambda tmp: tmp.write_text(text + "\n"))

    def read_summary(self) -> LearnSummary:
        """The run's ``metrics.json`` as a :class:`LearnSummary` (a one-line
        :class:`RunError` if it is missing, broken or incomplete)."""
        return LearnSummary.from_dict(
            self.read_json("metrics.json"), str(self.file("metrics.json"))
        )

    def read_json(self, name: str, required: tuple[str, ...] = ()) -> dict:
        """Read a JSON object holding the ``required`` keys; a one-line :class:`RunError`
        if it is missing, broken or not such an object, or (``config.json``,
        ``metrics.json``) of a newer format than :data:`RUN_FORMAT`; their ``format`` is
        checked and left out of the object returned."""
        p = self.file(name)
        if not p.exists():
            raise RunError(f"{p} not found: is {self.path} a finished imitwalk run?")
        doc = readback.read_json(p, f"the {name} of an imitwalk run", RunError, required)
        if name in _VERSIONED:  # checked, then left out: what it holds is what was written
            readback.check_format(doc, RUN_FORMAT, str(p), RunError)
            doc.pop(readback.FORMAT_KEY, None)
        return doc

    def write_log(self, entries: list[dict]) -> Path:
        """Rewrite the per-iteration log (one JSON object per line) atomically."""
        lines = "".join(json.dumps(e, default=_json_default) + "\n" for e in entries)
        return atomic_write(self.file("log.jsonl"), lambda tmp: tmp.write_text(lines))

    def read_log(self) -> list[dict]:
        """The per-iteration log (empty if none)."""
        p = self.file("log.jsonl")
        if not p.exists():
            return []
        try:
            lines = p.read_text(encoding="utf-8").splitlines()
            entries = [json.loads(line) for line in lines if line.strip()]
        except (OSError, UnicodeDecodeError, ValueError, RecursionError) as exc:
            raise RunError(f"{p} is not a learning log (one JSON object a line): {exc}") from None
        if not all(isinstance(e, dict) for e in entries):
            raise RunError(f"{p} is not a learning log: a line is not a JSON object")
        return entries

    def write_arrays(self, name: str, arrays: dict[str, np.ndarray]) -> Path:
        """Write a dict of arrays as compressed ``.npz`` atomically."""
        return write_npz(self.file(name), arrays)

    def read_arrays(self, name: str) -> dict[str, np.ndarray]:
        """Read an ``.npz`` written by :meth:`write_arrays`."""
        return readback.read_npz(self.file(name), f"the {name} of an imitwalk run", RunError)

    def start(
        self,
        config_json: dict,
        reference: Any,  # a retarget.reference.Reference (runs may not import retarget)
        resume: bool,
        settings: Callable[[dict[str, Any]], dict[str, Any]] | None = None,
    ) -> tuple[dict | None, list[dict]]:
        """Open a learning run: a fresh folder (``config.json`` and ``reference.npz``
        written) or, with ``resume``, the interrupted one, which must have been started
        with the same ``config_json["learn"]`` (compared after ``settings``, a function
        that reads the saved ones back into their canonical form).

        Returns:
            the saved ``checkpoint.json`` and log when resuming, else ``(None, [])``.

        Raises:
            RunError: nothing to resume, other settings, or a folder that holds a run.
        """
        if resume:
            if not self.exists("checkpoint.json"):
                raise RunError(f"nothing to resume in {self.path}: no checkpoint.json")
            saved = self.read_json("config.json", ("learn",))["learn"]
            if (settings(saved) if settings else saved) != config_json["learn"]:
                raise RunError(
                    f"{self.path} was started with other settings; resume with the same ones"
                )
            return self.read_json("checkpoint.json"), self.read_log()
        if self.exists("checkpoint.json"):
            raise RunError(
                f"{self.path} already holds a run; pass --resume or choose another --out"
            )
        self.path.mkdir(parents=True, exist_ok=True)
        self.write_json("config.json", config_json)
        reference.save(self.file("reference.npz"))
        return None, []
