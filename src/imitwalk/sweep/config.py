"""A sweep's file (JSON or TOML) and its cells.

::

    clips = ["default", "walks/07_04.bvh"]    # "default": the embedded clip; paths are
    robots = ["hoap2", "op3/op3.json"]        #   relative to this file
    settings = [[], ["generations=6"]]        # each: learning settings, as learn --set
    seeds = [0, 1]                            # learning seeds
    protocol = "eval"                         # the judge's robots ...
    judge_robots = 10                         # ... how many
    seconds = 30.0                            # ... and how long each walks [s]

Every key is optional (the defaults above are the single cell ``default × hoap2 × [] ×
0`` judged on 10 ``eval`` robots for 30 s). A key not listed is refused in one line that
lists the valid ones, and so are a setting, a protocol or a robot that ``learn`` would
refuse, before any cell runs.
"""

from __future__ import annotations

import hashlib
import json
import tomllib
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

from imitwalk.errors import ConfigError, ImitwalkError, unknown_name

__all__ = ["DEFAULT_CLIP", "KEYS", "Cell", "SweepConfig", "load_sweep"]

#: The name of the embedded clip in a sweep's ``clips``.
DEFAULT_CLIP = "default"
#: The keys a sweep's file may hold.
KEYS = ("clips", "robots", "settings", "seeds", "protocol", "judge_robots", "seconds")


@dataclass(frozen=True)
class Cell:
    """One clip learned on one robot with one set of settings and one seed.

    Attributes:
        clip: a mocap or robot-motion file's absolute path, or ``"default"``; robot: a
        built-in robot's name or a joint map's (or MJCF's) absolute path; settings:
        ``key=value`` learning settings; seed: the learning seed.
    """

    clip: str
    robot: str
    settings: tuple[str, ...]
    seed: int

    @property
    def name(self) -> str:
        """A folder name for the cell: readable, and unique by a hash of its content."""
        digest = hashlib.sha256(json.dumps(asdict(self)).encode()).hexdigest()[:8]
        clip = Path(self.clip).stem if self.clip != DEFAULT_CLIP else DEFAULT_CLIP
        robot = Path(self.robot).stem
        return f"{clip}-{robot}-seed{self.seed}-{digest}"


@dataclass(frozen=True)
class SweepConfig:
    """A sweep (see the module doc); :meth:`cells` lists its cells, in order."""

    clips: tuple[str, ...] = (DEFAULT_CLIP,)
    robots: tuple[str, ...] = ("hoap2",)
    settings: tuple[tuple[str, ...], ...] = ((),)
    seeds: tuple[int, ...] = (0,)
    protocol: str = "eval"
    judge_robots: int = 10
    seconds: float = 30.0
    source: str = field(default="", compare=False)

    def cells(self) -> list[Cell]:
        """Every clip × robot × settings × seed."""
        return [
            Cell(c, r, s, seed)
            for c in self.clips
            for r in self.robots
            for s in self.settings
            for seed in self.seeds
        ]

    def to_dict(self) -> dict[str, Any]:
        """Plain JSON (the sweep a folder holds, compared on resume)."""
        d = asdict(self)
        d.pop("source")
        return json.loads(json.dumps(d))


def _strings(d: dict, key: str, where: str) -> list[str]:
    v = d[key]
    if not isinstance(v, list) or not v or not all(isinstance(x, str) and x for x in v):
        raise ConfigError(f"{where}: {key} must be a non-empty list of names or paths")
    return v


def _resolve(path: str, base: Path, what: str, where: str) -> str:
    p = Path(path) if Path(path).is_absolute() else base / path
    if not p.is_file():
        raise ConfigError(
            f"{where}: {what} {path} not found (paths are relative to the sweep file)"
        )
    return str(p.resolve())


def _check(cfg: SweepConfig, where: str) -> None:
    """Refuse, before any cell runs, what learn or the judge would refuse."""
    from imitwalk.config import apply_overrides
    from imitwalk.robots import load_robot
    from imitwalk.sim.protocol import load_protocol
    from imitwalk.step.learn import StepLearnConfig

    try:
        load_protocol(cfg.protocol)
        for s in cfg.settings:
            apply_overrides(StepLearnConfig(), list(s))
        for r in cfg.robots:
            load_robot(r)
    except ImitwalkError as exc:
        raise ConfigError(f"{where}: {exc}") from None


def load_sweep(path: str | Path) -> SweepConfig:
    """Read and check a sweep's file (``.json`` or ``.toml``).

    Raises:
        ConfigError: one line: an unreadable file, an unknown key (listing the valid
            ones), a value of the wrong kind, or a clip, robot, setting or protocol that
            ``learn`` would refuse.
    """
    p = Path(path)
    where = str(p)
    d = _read_table(p, where)
    base = p.resolve().parent
    kw: dict[str, Any] = {"source": str(p.resolve())}
    if "clips" in d:
        kw["clips"] = tuple(
            c if c == DEFAULT_CLIP else _resolve(c, base, "clip", where)
            for c in _strings(d, "clips", where)
        )
    if "robots" in d:
        kw["robots"] = tuple(
            r if not r.endswith((".json", ".xml")) else _resolve(r, base, "robot", where)
            for r in _strings(d, "robots", where)
        )
    if "settings" in d:
        kw["settings"] = _settings(d["settings"], where)
    if "seeds" in d:
        kw["seeds"] = _seeds(d["seeds"], where)
    if "protocol" in d:
        kw["protocol"] = _protocol(d["protocol"], base, where)
    if "judge_robots" in d:
        kw["judge_robots"] = _judge_robots(d["judge_robots"], where)
    if "seconds" in d:
        kw["seconds"] = _seconds(d["seconds"], where)
    cfg = SweepConfig(**kw)
    _check(cfg, where)
    return cfg


def _read_table(p: Path, where: str) -> dict:
    """The sweep file ``p``'s table of keys (TOML by its suffix, else JSON), every key one
    of :data:`KEYS`."""
    if not p.is_file():
        raise ConfigError(f"sweep file not found: {p}")
    try:
        text = p.read_text(encoding="utf-8")
        d = tomllib.loads(text) if p.suffix.lower() == ".toml" else json.loads(text)
    except (UnicodeDecodeError, ValueError, tomllib.TOMLDecodeError) as exc:
        raise ConfigError(f"{where} is not a sweep's JSON or TOML: {exc}") from None
    if not isinstance(d, dict):
        raise ConfigError(f"{where}: a sweep is a table of keys ({', '.join(KEYS)})")
    for key in d:
        if key not in KEYS:
            raise unknown_name("sweep key", key, KEYS, ConfigError)
    return d


def _settings(s: Any, where: str) -> tuple[tuple[str, ...], ...]:
    """The ``settings`` key: a non-empty list of lists of ``"key=value"``."""
    ok = (
        isinstance(s, list)
        and s
        and all(isinstance(x, list) and all(isinstance(y, str) for y in x) for x in s)
    )
    if not ok:
        raise ConfigError(f'{where}: settings must be a list of lists of "key=value"')
    return tuple(tuple(x) for x in s)


def _seeds(s: object, where: str) -> tuple[int, ...]:
    """The ``seeds`` key: a non-empty list of integers >= 0."""
    if not isinstance(s, list) or not s or not all(type(x) is int and x >= 0 for x in s):
        raise ConfigError(f"{where}: seeds must be a non-empty list of integers >= 0")
    return tuple(s)


def _protocol(proto: object, base: Path, where: str) -> str:
    """The ``protocol`` key: a protocol's name, or a ``.json`` file relative to ``base``."""
    if not isinstance(proto, str):
        raise ConfigError(f"{where}: protocol must be a protocol's name or file")
    return _resolve(proto, base, "protocol", where) if proto.endswith(".json") else proto


def _judge_robots(n: object, where: str) -> int:
    """The ``judge_robots`` key: an integer >= 1."""
    if type(n) is not int or n < 1:
        raise ConfigError(f"{where}: judge_robots must be an integer >= 1")
    return n


def _seconds(t: object, where: str) -> float:
    """The ``seconds`` key: a number > 0 [s]."""
    if isinstance(t, bool) or not isinstance(t, int | float) or not t > 0:
        raise ConfigError(f"{where}: seconds must be a number > 0")
    return float(t)
