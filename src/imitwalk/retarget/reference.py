"""The retargeted gait as a typed record, saved and loaded as ``.npz``.

A :class:`Reference` holds, for a grid of stride scales, one closed gait cycle of
robot joint angles (the loop) and the start-up from standing that leads into it,
plus everything needed to judge it: IK residuals, clipped joints, kinematic checks,
the reference parameters and the search that found them, and where it came from.
"""

from __future__ import annotations

import json
from dataclasses import asdict, dataclass, field, fields, is_dataclass, replace
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from imitwalk.errors import RunError
from imitwalk.fileio import write_npz
from imitwalk.readback import FORMAT_KEY
from imitwalk.retarget.command import GaitCommand, advance
from imitwalk.retarget.params import GaitParams
from imitwalk.retarget.provenance import Provenance
from imitwalk.retarget.reffile import REFERENCE_FORMAT, read_reference_file
from imitwalk.retarget.searchreport import SearchReport
from imitwalk.sim.types import SimOptions

if TYPE_CHECKING:
    from imitwalk.retarget.plan import TaskPlan

__all__ = ["PLAN_KEYS", "Reference", "plan_arrays"]

#: The fields a reference file stores as JSON objects of their own shape.
_TYPED = frozenset({"params", "search", "command", "provenance", "plan"})

#: Arrays of a stored task-space plan (upper-body roles in :data:`UPPER`; ``yaw`` and
#: ``path`` as in :class:`~imitwalk.retarget.plan.TaskPlan`; references written before
#: commanded gaits lack them and read as straight).
PLAN_KEYS = ("l_sole", "r_sole", "com", "pelvis_z", "upper", "yaw", "path")
UPPER = ("l_shoulder_pitch", "r_shoulder_pitch", "l_elbow", "r_elbow", "waist_yaw")


def plan_arrays(plan: TaskPlan) -> dict[str, np.ndarray]:
    """A :class:`~imitwalk.retarget.plan.TaskPlan` as the arrays a reference stores."""
    assert plan.yaw is not None and plan.path is not None  # plan_walk sets both
    upper = np.stack([plan.upper.get(u, np.zeros(len(plan.phase))) for u in UPPER], axis=1)
    return {
        "l_sole": plan.l_sole,
        "r_sole": plan.r_sole,
        "com": plan.com,
        "pelvis_z": plan.pelvis_z,
        "upper": upper,
        "yaw": plan.yaw,
        "path": plan.path,
    }


@dataclass(frozen=True)
class Reference:
    """A robot gait retargeted from mocap, built once (a frozen record: a changed copy is
    :func:`dataclasses.replace`'s).

    Attributes:
        robot: robot name; joint_names: ``n`` roles, the columns of every trajectory.
        mapping: ``"walkable"`` (IK on the robot, the default) or ``"paper"``.
        dt: control period [s]; period: cycle time [s] (a whole number of ticks).
        scales: ``(S,)`` stride scales of the grid.
        loops: ``(S, N, n)`` one closed cycle per scale [rad]; loops[s, 0] follows loops[s, -1].
        starts: ``(S, M, n)`` start-up from standing into loops[s, 0] [rad].
        strides: ``(S,)`` forward travel per cycle [m].
        start_travel: ``(S, M)`` forward travel the start-up commands by each tick [m].
        phase: ``(N,)`` gait phase ψ of each loop tick (0 at the left heel strike).
        stance: ``(N, 2)`` bool, left/right foot planned on the floor.
        residual_mm: ``(S, M + N)`` worst IK task error per tick [mm].
        clipped: one dict per (scale, joint) that sat on a joint limit.
        checks: kinematic checks of the largest scale (tilt, clearance, closure, skate).
        params: the reference parameters (``None``: the paper's mapping has none);
            search: the report of the search for them (``None``: not searched).
        source: the mocap file; cycles: ``(C, 2)`` source frames of the gait cycles
            used; provenance: the clip as it was read and the robot as it was named.
        plan: the task-space plan the walkable IK solved, per scale and tick of the
            start-up and loop (``(S, M + N, ...)`` arrays named by :data:`PLAN_KEYS`);
            empty for the paper's mapping. The balance channels re-solve it with offsets.
        command: the :class:`~imitwalk.retarget.command.GaitCommand` it was built for
            (the default: straight ahead on level ground).
        motion: ``(S, 5)`` how one loop moves the walking frame, per scale
            (:func:`~imitwalk.retarget.command.cycle_motion`); empty: one stride ahead.
    """

    robot: str
    joint_names: tuple[str, ...]
    mapping: str
    dt: float
    period: float
    scales: np.ndarray
    loops: np.ndarray
    starts: np.ndarray
    strides: np.ndarray
    start_travel: np.ndarray
    phase: np.ndarray
    stance: np.ndarray
    residual_mm: np.ndarray
    clipped: list[dict[str, Any]] = field(default_factory=list)
    checks: dict[str, Any] = field(default_factory=dict)
    params: GaitParams | None = None
    search: SearchReport | None = None
    source: str = ""
    provenance: Provenance = field(default_factory=Provenance)
    cycles: np.ndarray = field(default_factory=lambda: np.zeros((0, 2), dtype=int))
    plan: dict[str, np.ndarray] = field(default_factory=dict)
    command: GaitCommand = field(default_factory=GaitCommand)
    motion: np.ndarray = field(default_factory=lambda: np.zeros((0, 5)))

    # -- access ---------------------------------------------------------------
    def _bracket(self, scale: float) -> tuple[int, int, float]:
        s = self.scales
        if not s[0] - 1e-9 <= scale <= s[-1] + 1e-9:
            raise RunError(f"scale {scale} is outside the reference's range {s[0]:g}..{s[-1]:g}")
        if len(s) == 1:
            return 0, 0, 0.0
        j = int(np.clip(np.searchsorted(s, scale), 1, len(s) - 1))
        w = float(np.clip((scale - s[j - 1]) / (s[j] - s[j - 1]), 0.0, 1.0))
        return j - 1, j, w

    def at_scale(self, scale: float) -> tuple[np.ndarray, np.ndarray, float]:
        """Start-up ``(M, n)``, loop ``(N, n)`` and stride [m] at ``scale``.

        Between grid scales the two neighbouring IK solutions are blended linearly.
        """
        i, j, w = self._bracket(scale)
        mix = lambda a: (1.0 - w) * a[i] + w * a[j]  # noqa: E731
        return mix(self.starts), mix(self.loops), float(mix(self.strides))

    def plan_at(self, scale: float) -> dict[str, np.ndarray]:
        """The task-space plan ``(M + N, ...)`` arrays at ``scale`` (blended between grid
        scales, as :meth:`at_scale` blends the joint angles)."""
        if not self.plan:
            raise RunError("this reference has no task-space plan (the paper's mapping?)")
        i, j, w = self._bracket(scale)
        out = {k: (1.0 - w) * v[i] + w * v[j] for k, v in self.plan.items()}
        n = out["pelvis_z"].shape[0]
        if "yaw" not in out:  # written before commanded gaits: straight ahead
            out["yaw"] = np.zeros((n, 2))
        if "path" not in out:
            fwd = out["com"][:, 0] - out["com"][0, 0]
            out["path"] = np.stack([fwd, 0 * fwd, 0 * fwd, fwd, 0 * fwd], axis=1)
        return out

    def motion_at(self, scale: float) -> np.ndarray:
        """``(5,)`` how one loop at ``scale`` moves the walking frame (blended between
        grid scales): displacement x, y [m] in the frame, heading change [rad], forward
        and sideways travel [m]."""
        i, j, w = self._bracket(scale)
        stride = (1.0 - w) * self.strides[i] + w * self.strides[j]
        if len(self.motion) == 0 or not np.any(self.motion[:, 1:3]):  # straight: one stride
            return np.array([stride, 0.0, 0.0, stride, 0.0])
        return (1.0 - w) * self.motion[i] + w * self.motion[j]

    def planned_load(self, scale: float, T: int) -> tuple[np.ndarray, np.ndarray]:
        """``(T, 2)`` the feet the plan has down (left, right) and ``(T,)`` the left sole's
        share of the load (the centre of mass between the soles; 1 or 0 in single support)
        over ``T`` ticks from standing."""
        plan = self.plan_at(scale)
        rows = self.loop_index(np.arange(T))[0]
        down = np.stack([plan["l_sole"][rows, 2], plan["r_sole"][rows, 2]], 1) <= 1e-4
        yl, yr, yc = plan["l_sole"][rows, 1], plan["r_sole"][rows, 1], plan["com"][rows, 1]
        share = np.clip((yc - yr) / np.maximum(yl - yr, 1e-6), 0.0, 1.0)
        one = np.where(down[:, 1] & ~down[:, 0], 0.0, share)
        return down, np.where(down[:, 0] & ~down[:, 1], 1.0, one)

    def loop_index(self, k: int | np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Where tick ``k`` from standing (int or int array) falls in the stored start-up
        and loop: the stored tick ``i`` and how many whole cycles ``c`` the loop has been
        repeated before it (0 within the stored ticks)."""
        m, n = self.starts.shape[1], self.loops.shape[1]
        k = np.asarray(k)
        c = np.where(k < m + n, 0, (k - m) // n)
        return k - c * n, c

    def plan_row(self, plan: dict, motion: np.ndarray, k: int) -> dict:
        """Tick ``k`` from standing of ``plan`` (:meth:`plan_at`), the loop repeated and
        moved on by ``motion`` (:meth:`motion_at`) per cycle."""
        i, c = (int(x) for x in self.loop_index(k))
        row = {key: v[i] for key, v in plan.items()}
        return advance(row, plan["path"][self.starts.shape[1]], motion, c)

    def track(self, scale: float, seconds: float) -> np.ndarray:
        """``(T, 3)`` the walking frame's commanded forward and sideways travel [m] and
        heading [rad] at each control tick of ``seconds`` from standing (straight: the
        forward travel of :meth:`expected_distance`, then zeros)."""
        steps = max(1, round(seconds / self.dt))
        if not self.plan:
            out = np.zeros((steps, 3))
            out[:, 0] = [self.expected_distance(scale, (k + 1) * self.dt) for k in range(steps)]
            return out
        path, motion = self.plan_at(scale)["path"], self.motion_at(scale)
        i, c = self.loop_index(np.arange(steps))
        out = path[i][:, [3, 4, 2]] - path[0][[3, 4, 2]]
        return out + c[:, None] * motion[[3, 4, 2]]

    def ground_path(self, scale: float, seconds: float) -> np.ndarray:
        """``(T, 2)`` the walking frame's commanded path on the ground [m] from the start,
        per control tick (:meth:`track` integrated in the turning frame)."""
        tr = self.track(scale, seconds)
        d = np.diff(tr[:, :2], axis=0, prepend=tr[:1, :2])
        h = tr[:, 2]
        dx = d[:, 0] * np.cos(h) - d[:, 1] * np.sin(h)
        dy = d[:, 0] * np.sin(h) + d[:, 1] * np.cos(h)
        return np.stack([np.cumsum(dx), np.cumsum(dy)], axis=1)

    def sim_options(self, base: SimOptions | None = None) -> SimOptions:
        """``base`` (default options if ``None``) on the ground the gait was built for:
        the command's slope added to ``base``'s own."""
        base = base or SimOptions()
        slope = self.command.slope_deg
        return replace(base, slope_deg=base.slope_deg + slope) if slope else base

    def trajectory(self, scale: float, seconds: float) -> np.ndarray:
        """``(T, n)`` joint targets for ``seconds``: the start-up, then the loop repeated."""
        start, loop, _ = self.at_scale(scale)
        steps = max(1, round(seconds / self.dt))
        reps = int(np.ceil(max(0, steps - len(start)) / len(loop))) + 1
        return np.vstack([start, *([loop] * reps)])[:steps]

    def expected_distance(self, scale: float, seconds: float) -> float:
        """Forward travel [m] the reference commands over ``seconds`` from standing.

        The start-up's own commanded travel, then a stride per cycle of the loop.
        """
        i, j, w = self._bracket(scale)
        travel = (1.0 - w) * self.start_travel[i] + w * self.start_travel[j]
        _, _, stride = self.at_scale(scale)
        k = round(seconds / self.dt)
        m, n = self.starts.shape[1], self.loops.shape[1]
        if k <= m:
            return float(travel[max(0, k - 1)])
        return float(travel[-1] + stride * (k - m) / n)

    # -- persistence ----------------------------------------------------------
    def save(self, path: str | Path) -> Path:
        """Write ``path`` (``.npz``) atomically, its metadata of format
        :data:`~imitwalk.retarget.reffile.REFERENCE_FORMAT`."""
        arrays: dict[str, np.ndarray] = {f"plan_{k}": a for k, a in self.plan.items()}
        meta: dict[str, Any] = {}
        for f in fields(self):
            v = getattr(self, f.name)
            if isinstance(v, np.ndarray):
                arrays[f.name] = v
            elif f.name not in _TYPED:
                meta[f.name] = v
        meta["params"] = self.params.to_dict() if self.params is not None else {}
        meta["search"] = self.search.to_dict() if self.search is not None else {}
        meta["command"] = self.command.to_dict()
        meta["settings"] = {
            "mapping": self.mapping,
            "control_hz": 1.0 / self.dt,
            "scales": self.scales.tolist(),
            **self.provenance.to_settings(),
        }
        arrays["q"] = self.loops[-1]  # the joint trajectory at the largest scale, (N, n)
        meta = {FORMAT_KEY: REFERENCE_FORMAT, **meta}
        arrays["meta_json"] = np.array(json.dumps(meta, default=_jsonable))
        return write_npz(path, arrays)

    @classmethod
    def load(cls, path: str | Path) -> Reference:
        """Read a reference written by :meth:`save` (a one-line :class:`RunError` naming
        the file and what is wrong if it is not one)."""
        meta, read = read_reference_file(path)
        plan = {k[5:]: read.pop(k) for k in list(read) if k.startswith("plan_")}
        known = {f.name for f in fields(cls)} - _TYPED
        arrays: dict[str, Any] = {k: v for k, v in read.items() if k in known}
        params = meta.get("params") or {}
        return cls(
            **{k: v for k, v in meta.items() if k in known},
            **arrays,
            plan=plan,
            params=GaitParams(**params) if params else None,
            search=SearchReport.from_dict(meta.get("search") or {}),
            command=GaitCommand.from_dict(meta.get("command")),
            provenance=Provenance.from_settings(meta.get("settings") or {}),
        )

    def summary(self) -> dict:
        """Plain-JSON description (no per-tick arrays)."""
        return {
            "robot": self.robot,
            "mapping": self.mapping,
            "dt": self.dt,
            "period_s": self.period,
            "scales": self.scales.tolist(),
            "strides_m": self.strides.tolist(),
            "params": self.params.to_dict() if self.params is not None else {},
            "checks": self.checks,
            "command": self.command.to_dict(),
            "source": self.source,
        }


def _jsonable(v: object) -> object:
    if isinstance(v, np.generic):
        return v.item()
    if isinstance(v, np.ndarray):
        return v.tolist()
    if is_dataclass(v) and not isinstance(v, type):
        return asdict(v)
    raise TypeError(f"not JSON serialisable: {type(v).__name__}")
