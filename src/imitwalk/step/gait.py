"""A stepping run's gait: the style it walks, and what judging and replay need of it.

A per-tick or faithful run judges its walk against its joint-space
:class:`~imitwalk.retarget.reference.Reference`; a stepping run has no fixed trajectory,
so :class:`StepGait` answers the same questions (``dt``, ``period``, ``sim_options``,
``expected_distance``, ``track``, ``trajectory``, ``kick_time``) from the style and the
controller's nominal schedule (:mod:`imitwalk.step.schedule`), and says where the
clip came from for the report (``source``, ``cycles``). It is saved as ``style.json``.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from imitwalk import readback
from imitwalk.errors import ConfigError, RunError
from imitwalk.fileio import atomic_write
from imitwalk.retarget.provenance import Provenance
from imitwalk.sim.types import SimOptions
from imitwalk.step.fields import as_number
from imitwalk.step.schedule import START_STEPS, nominal_distance, nominal_track, start_seconds
from imitwalk.step.style import GaitStyle, longest_step

#: The format version ``style.json`` is written in (and the newest :meth:`StepGait.load`
#: reads; a file without one reads as 1). 2: the style's ``stride_share`` (a format-1
#: style walks all of its clip's stride).
GAIT_FORMAT = 2

__all__ = ["GAIT_FORMAT", "StepGait"]


@dataclass
class StepGait:
    """The gait of a stepping run.

    Attributes:
        style: the walk at scale 1 (:class:`~imitwalk.step.style.GaitStyle`); robot: the
        robot's name; dt: the control period [s]; source: the clip; cycles: ``(C, 2)``
        the clip's frames of the cycles averaged; provenance: the clip as it was read and
        the robot as it was named (a built-in name or a joint map's path).
    """

    style: GaitStyle
    robot: str
    dt: float = 0.01
    source: str = ""
    cycles: np.ndarray = field(default_factory=lambda: np.zeros((0, 2), dtype=int))
    provenance: Provenance = field(default_factory=Provenance)

    def __post_init__(self) -> None:
        self.check()

    def check(self) -> None:
        """Refuse a gait no walk can be made of (run on every gait made; its style checks
        itself, :meth:`GaitStyle.check <imitwalk.step.style.GaitStyle.check>`).

        ``dt`` must be finite, at least one physics step (``1 / SimOptions().physics_hz``,
        1 ms) and shorter than the style's single support [s]; the style, at scale 1,
        must step (``step_length`` nonzero: negative walks backward) and step shorter than
        its legs reach (:func:`~imitwalk.step.style.longest_step`, as
        :func:`~imitwalk.step.style.hip_height` requires of every style made from a clip).

        Raises:
            ConfigError: one line naming the field (``style.``: the style's), its valid
                range and the value.
        """
        if not isinstance(self.style, GaitStyle):
            raise ConfigError(f"style must be a GaitStyle (got {type(self.style).__name__})")
        least, ss = 1.0 / SimOptions().physics_hz, self.style.single_support
        as_number(self.dt, "dt")
        if not (np.isfinite(self.dt) and least - 1e-12 <= self.dt < ss):
            raise ConfigError(
                f"dt must be a finite number, the control period [s], with {least:g} (a "
                f"physics step) <= dt < {ss:g} (the style's single support) (got {self.dt:g})"
            )
        step, longest = self.style.step_length, longest_step(self.style.geometry)
        if not 0.0 < abs(step) < longest:
            raise ConfigError(
                f"style.step_length must be a finite number with 0 < |step_length| < "
                f"{longest:.4g} m (the legs' reach at scale 1; negative: backward) "
                f"(got {step:g})"
            )

    @property
    def period(self) -> float:
        """One gait cycle, two steps [s]."""
        return 2.0 * self.style.step_time

    def at_scale(self, scale: float) -> GaitStyle:
        """The style with its stride and arm swing × ``scale`` (the pelvis height and
        timing as at scale 1)."""
        st = self.style
        if scale == 1.0:
            return st
        upper = {k: np.asarray(v) * scale for k, v in st.upper.items()}
        return replace(st, step_length=st.step_length * scale, upper=upper)

    def sim_options(self, base: SimOptions | None = None) -> SimOptions:
        """``base`` (default options if ``None``) at the control rate of this gait."""
        base = base or SimOptions()
        hz = 1.0 / self.dt
        return base if abs(base.control_hz - hz) < 1e-9 else replace(base, control_hz=hz)

    def start_s(self) -> float:
        """When the first foot lifts off in the nominal schedule [s]."""
        return start_seconds(self.style.step_time)

    def expected_distance(self, scale: float, seconds: float) -> float:
        """Forward travel [m] of the nominal schedule over ``seconds`` from standing
        (:func:`~imitwalk.step.schedule.nominal_distance`)."""
        st = self.at_scale(scale)
        return nominal_distance(st.step_length, st.step_time, seconds)

    def track(self, scale: float, seconds: float) -> np.ndarray:
        """``(T, 3)`` the commanded forward and sideways travel [m] and heading [rad]
        per control tick (:func:`~imitwalk.step.schedule.nominal_track`; the heading turns
        with the style's :attr:`~imitwalk.step.style.GaitStyle.turn`)."""
        st = self.at_scale(scale)
        return nominal_track(st.step_length, st.step_time, st.turn / 2, self.dt, seconds)

    def ground_path(self, scale: float, seconds: float) -> np.ndarray:
        """``(T, 2)`` the commanded path on the ground [m]: the forward travel along the
        commanded heading."""
        tr = self.track(scale, seconds)
        step = np.diff(np.concatenate([[0.0], tr[:, 0]]))
        return np.stack([np.cumsum(step * np.cos(tr[:, 2])), np.cumsum(step * np.sin(tr[:, 2]))], 1)

    def trajectory(self, scale: float, seconds: float) -> None:
        """A stepping gait has no fixed joint trajectory: joints are judged against the
        commanded ones."""
        return None

    def kick_time(self, phase: int, phases: int) -> float:
        """When [s] a kick at ``phase`` of ``phases`` comes: four steps after the stride
        reached the style's, plus that share of a nominal cycle."""
        return (
            self.start_s() + (START_STEPS + 4) * self.style.step_time + phase * self.period / phases
        )

    # -- persistence ------------------------------------------------------------
    def to_dict(self) -> dict:
        """Plain-JSON dictionary (with its ``format``, :data:`GAIT_FORMAT`)."""
        return {
            readback.FORMAT_KEY: GAIT_FORMAT,
            "style": self.style.to_dict(),
            "robot": self.robot,
            "dt": self.dt,
            "source": self.source,
            "cycles": np.asarray(self.cycles, dtype=int).tolist(),
            "settings": self.provenance.to_settings(),
        }

    def save(self, path: str | Path) -> Path:
        """Write ``path`` (JSON) atomically."""
        text = json.dumps(self.to_dict(), indent=1)
        return atomic_write(path, lambda tmp: tmp.write_text(text + "\n"))

    @classmethod
    def load(cls, path: str | Path) -> StepGait:
        """Read a gait :meth:`save` wrote, checked (:meth:`check`,
        :meth:`GaitStyle.check <imitwalk.step.style.GaitStyle.check>`).

        Raises:
            RunError: one line: the file cannot be read, is not a gait, or a field is out
                of its range (``PATH: style.step_time must be a finite number > 0 [s]
                (got nan)``).
        """
        path = Path(path)
        try:
            d = json.loads(path.read_text())
            if not isinstance(d, dict):
                raise TypeError(f"a JSON {type(d).__name__}, not an object")
            readback.check_format(d, GAIT_FORMAT, str(path), RunError)
            return cls(
                style=GaitStyle.from_dict(d["style"], where="style."),
                robot=str(d["robot"]),
                dt=as_number(d["dt"], "dt"),
                source=str(d.get("source", "")),
                cycles=np.asarray(d.get("cycles", []), dtype=int).reshape(-1, 2),
                provenance=Provenance.from_settings(dict(d.get("settings") or {})),
            )
        except ConfigError as exc:
            raise RunError(f"{path}: {exc}") from None
        except FileNotFoundError:
            raise RunError(f"{path} not found: is {path.parent} a finished imitwalk run?") from None
        except (OSError, ValueError, KeyError, TypeError, AttributeError) as exc:
            raise RunError(f"{path} is not a stepping gait: {type(exc).__name__}: {exc}") from None
