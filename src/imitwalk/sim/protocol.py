"""Named robustness protocols: which robots a controller is judged on (pure NumPy).

A protocol is a versioned JSON file (``imitwalk/sim/protocols/NAME.json``, or a user's own
file of the same form) that lists every *factor* it draws, each with its range and
where that range comes from. :meth:`Protocol.draw` turns a seed into one robot: the
:class:`~imitwalk.sim.types.SimOptions` it is simulated with and, per factor, how far
its draw lies from nominal as a percentile of the factor's own distribution (0: at
nominal; 1: as far as the range goes), so that falls can be broken down by the factor
drawn furthest from nominal.

Factors (every key of each is listed in :data:`FACTORS`):

* ``friction``: the floor's sliding friction, uniform in ``[min, max]`` (``nominal``:
  the robot's own, for the percentile);
* ``mass``: each body's mass (and inertia) × U(1 − spread, 1 + spread);
* ``servo``: each servo's stiffness × U(1 − spread, 1 + spread);
* ``torso_com``: the torso's centre of mass moved by U(−c, c) in x and y, with
  ``c = max_m × height / at_height_m`` (the robot's standing height);
* ``gyro_noise``, ``accel_noise``: white sensor noise of standard deviation ``sigma``
  [rad/s], [m/s²] (not a draw: no percentile);
* ``servo_delay``: the command reaches the servos U(min_s, max_s) late [s];
* ``slope``: the floor slopes U(min_deg, max_deg) along the walk (+: uphill);
* ``cross_slope``: the floor slopes U(min_deg, max_deg) across the walk (+: rising to
  the robot's left);
* ``pushes``: a kick every U(every_min_s, every_max_s) seconds, in a uniformly random
  horizontal direction, of a speed U(0, v) with ``v = max_speed ×
  sqrt(height / at_height_m)`` [m/s] (Froude scaling: the same kick for a small and a
  large robot), applied as a velocity change of the whole robot (an impulse of its mass
  × Δv);
* ``initial_twist``: the base starts with a normal random velocity, σ ``linear`` [m/s]
  and ``angular`` [rad/s].

The draws of ``eval`` are exactly those of :func:`imitwalk.sim.perturb.perturbed` with the
evaluation's initial twist, so figures judged before protocols existed stay comparable.
Each other factor draws from its own random stream, so adding a factor to a protocol
does not change the others' draws.
"""

from __future__ import annotations

import json
import math
from collections.abc import Collection
from dataclasses import dataclass, field, replace
from importlib import resources
from pathlib import Path
from typing import Any

import numpy as np
from scipy.stats import chi2, norm

from imitwalk.errors import ConfigError, unknown_name
from imitwalk.sim.protocolcheck import FACTORS, checked, fail
from imitwalk.sim.seeds import DRAW_STREAM
from imitwalk.sim.types import SimOptions, jitter_draws

__all__ = ["FACTORS", "PROTOCOLS", "Protocol", "RobotDraw", "load_protocol"]

#: The stream of each factor that does not share :func:`~imitwalk.sim.perturb.perturbed`'s
#: (see the module doc).
_STREAM = {"torso_com": 1, "servo_delay": 2, "slope": 3, "pushes": 4, "cross_slope": 5}

#: The protocols shipped with imitwalk, by name.
PROTOCOLS = tuple(
    sorted(
        f.name[:-5]
        for f in resources.files("imitwalk.sim.protocols").iterdir()
        if f.name.endswith(".json")
    )
)


@dataclass(frozen=True)
class RobotDraw:
    """One robot of a protocol.

    Attributes:
        seed: its seed; options: how it is simulated.
        deviation: factor → how far its draw lies from nominal, a percentile in [0, 1]
            of the factor's own distribution (drawn factors only).
    """

    seed: int
    options: SimOptions
    deviation: dict[str, float] = field(default_factory=dict)

    @property
    def furthest(self) -> str | None:
        """The factor drawn furthest from nominal (``None``: the nominal robot)."""
        if not self.deviation or max(self.deviation.values()) <= 0.0:
            return None
        return max(self.deviation, key=lambda f: self.deviation[f])


@dataclass(frozen=True)
class Protocol:
    """A validated protocol (see the module doc); :func:`load_protocol` reads one."""

    name: str
    version: int
    description: str
    engine: str
    nominal_first: bool
    factors: dict[str, dict]
    path: str = ""

    def draw(
        self,
        seed: int,
        robot: Any,  # a robots.Robot (this NumPy-only module may not import robots' MuJoCo)
        base: SimOptions | None = None,
        seconds: float = 30.0,
    ) -> RobotDraw:
        """Robot ``seed`` (``robot``: its height and bodies scale and count the draws;
        ``base``: options kept, e.g. rates or the reference's own slope; ``seconds``:
        pushes are drawn up to this time)."""
        base = base or SimOptions()
        if seed == 0 and self.nominal_first:
            return RobotDraw(0, replace(base, seed=0))
        f = self.factors
        dev: dict[str, float] = {}
        opt: dict[str, Any] = {"seed": seed}
        shared = np.random.default_rng([seed, DRAW_STREAM])
        twist = np.concatenate([shared.normal(0, 1, 3), shared.normal(0, 1, 3)])
        u_friction = shared.random()
        if "initial_twist" in f:
            sd = np.repeat([f["initial_twist"]["linear"], f["initial_twist"]["angular"]], 3)
            opt["init_twist"] = tuple((twist * sd).tolist())
            dev["initial_twist"] = float(chi2.cdf(np.sum(twist**2), 6)) if sd.any() else 0.0
        if "friction" in f:
            lo, hi, nom = (f["friction"][k] for k in ("min", "max", "nominal"))
            opt["friction"] = value = lo + (hi - lo) * u_friction
            d = abs(value - nom)
            dev["friction"] = (min(d, max(nom - lo, 0)) + min(d, max(hi - nom, 0))) / (
                (hi - lo) or 1.0
            )
        for key, attr in (("mass", "mass_jitter"), ("servo", "kp_jitter")):
            if key in f:
                opt[attr] = f[key]["spread"]
        model = robot.compile() if ("mass" in f or "servo" in f) else None
        if model is not None:
            probe = replace(base, **opt)
            mass, kp = jitter_draws(probe, model.nbody, robot.joint_names)
            for key, draws, spread in (
                ("mass", mass[1:] / probe.mass_scale, probe.mass_jitter),
                ("servo", kp / probe.kp_scale, probe.kp_jitter),
            ):
                if key in f:
                    dev[key] = _spread_percentile((draws - 1.0) / spread) if spread else 0.0
        h = float(robot.height)
        if "torso_com" in f:
            c = f["torso_com"]["max_m"] * h / f["torso_com"]["at_height_m"]
            u = self._stream(seed, "torso_com").uniform(-1, 1, 2)
            opt["com_shift"] = (float(c * u[0]), float(c * u[1]), 0.0)
            dev["torso_com"] = float(np.max(np.abs(u)) ** 2)
        for key in ("gyro_noise", "accel_noise"):
            if key in f:
                opt[key] = f[key]["sigma"]
        if "servo_delay" in f:
            lo, hi = f["servo_delay"]["min_s"], f["servo_delay"]["max_s"]
            r = self._stream(seed, "servo_delay").random()
            opt["servo_delay"] = lo + (hi - lo) * r
            dev["servo_delay"] = float(r)
        if "slope" in f:
            lo, hi = f["slope"]["min_deg"], f["slope"]["max_deg"]
            value = lo + (hi - lo) * self._stream(seed, "slope").random()
            opt["slope_deg"] = base.slope_deg + value
            dev["slope"] = _symmetric_percentile(value, lo, hi)
        if "cross_slope" in f:
            lo, hi = f["cross_slope"]["min_deg"], f["cross_slope"]["max_deg"]
            value = lo + (hi - lo) * self._stream(seed, "cross_slope").random()
            opt["cross_slope_deg"] = base.cross_slope_deg + value
            dev["cross_slope"] = _symmetric_percentile(value, lo, hi)
        if "pushes" in f:
            opt["pushes"], dev["pushes"] = self._pushes(seed, h, seconds)
        return RobotDraw(seed, replace(base, **opt), dev)

    def _stream(self, seed: int, factor: str) -> np.random.Generator:
        return np.random.default_rng([seed, DRAW_STREAM, _STREAM[factor]])

    def _pushes(
        self, seed: int, height: float, seconds: float
    ) -> tuple[tuple[tuple[float, float, float], ...], float]:
        p = self.factors["pushes"]
        rng = self._stream(seed, "pushes")
        top = p["max_speed"] * math.sqrt(height / p["at_height_m"])
        out, fractions = [], []
        t = rng.uniform(p["every_min_s"], p["every_max_s"])
        while t < seconds:
            angle, frac = rng.uniform(0.0, 2 * np.pi), rng.random()
            v = top * frac
            out.append((float(t), float(v * np.cos(angle)), float(v * np.sin(angle))))
            fractions.append(frac)
            t += max(rng.uniform(p["every_min_s"], p["every_max_s"]), 1e-3)
        # the largest kick's percentile among as many: P(max of n uniforms <= x) = x^n
        dev = float(max(fractions) ** len(fractions)) if fractions else 0.0
        return tuple(out), dev

    def only(self, factors: Collection[str]) -> Protocol:
        """This protocol with only ``factors`` drawn (the others at nominal; each kept
        factor draws exactly as in the full protocol).

        Raises:
            ConfigError: a factor this protocol does not draw (listing the ones it does).
        """
        for f in factors:
            if f not in self.factors:
                raise unknown_name(f"factor of protocol {self.name}", f, self.factors, ConfigError)
        kept = {f: v for f, v in self.factors.items() if f in factors}
        return replace(self, name=f"{self.name}[{','.join(kept)}]", factors=kept)

    def to_dict(self) -> dict:
        """The protocol as its file holds it."""
        return {
            "name": self.name,
            "version": self.version,
            "description": self.description,
            "engine": self.engine,
            "nominal_first": self.nominal_first,
            "factors": self.factors,
        }


def _symmetric_percentile(value: float, lo: float, hi: float) -> float:
    """P(|X| <= |value|) for X ~ U(lo, hi): how far from 0 a draw lies."""
    d = abs(value)
    return (min(d, max(-lo, 0.0)) + min(d, max(hi, 0.0))) / ((hi - lo) or 1.0)


def _spread_percentile(u: np.ndarray) -> float:
    """How spread ``K`` draws of U(−1, 1) are, as a percentile: their mean square against
    its normal approximation (mean 1/3, variance 4 / (45 K))."""
    z = (float(np.mean(u**2)) - 1.0 / 3.0) / math.sqrt(4.0 / (45.0 * len(u)))
    return float(norm.cdf(z))


def load_protocol(name_or_path: str | Path) -> Protocol:
    """A shipped protocol by name (:data:`PROTOCOLS`), or a protocol file (``.json``).

    Raises:
        ConfigError: an unknown name (the message lists the shipped ones), a file that
            is not valid JSON, an unknown key or factor, a range whose minimum is above
            its maximum, a negative value, ... (one line each).
    """
    text = str(name_or_path)
    if text in PROTOCOLS:
        raw = resources.files("imitwalk.sim.protocols").joinpath(f"{text}.json").read_text()
        where = text
    elif text.endswith(".json"):
        path = Path(text)
        if not path.is_file():
            raise ConfigError(f"protocol file not found: {path}")
        try:
            raw = path.read_text(encoding="utf-8")
        except (OSError, UnicodeDecodeError) as exc:
            raise ConfigError(f"cannot read protocol file {path}: {exc}") from None
        where = str(path)
    else:
        raise unknown_name("protocol", text, PROTOCOLS, ConfigError)
    try:
        data = json.loads(raw)
    except (json.JSONDecodeError, RecursionError) as exc:
        msg = exc.msg if isinstance(exc, json.JSONDecodeError) else "nested too deeply"
        raise fail(where, f"not valid JSON: {msg}") from None
    return Protocol(**checked(data, where), path=where)
