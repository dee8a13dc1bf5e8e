"""The robot's gait in task space: where the feet, the centre of mass and the pelvis go.

This is the walkable reference's plan (pure NumPy). Given the human
:class:`~imitwalk.retarget.template.GaitTemplate`, the robot's leg geometry, the
four reference parameters (:class:`GaitParams`) and a stride scale, it lays out, per
control tick:

* the **stance foot** flat and fixed on the floor;
* the **swing foot** along the human foot path (its forward progress and lift profile,
  scaled to the robot), flat, with clearance;
* the **centre of mass** moving forward steadily with a smooth **sinusoidal** lateral
  sway over the stance foot (a square-wave sway builds up a growing roll);
* the **pelvis** level, at a fixed height chosen to keep the knee bent;
* the **arms and waist** swinging as the human's do (scaled with the stride).

A :class:`~imitwalk.retarget.command.GaitCommand` bends this straight, level walk into
a turn, a sidestep or a walk up or down a slope: everything above is laid out relative
to a moving *walking frame* (see :mod:`imitwalk.retarget.command`).

Timing: the human cycle time; ``ds`` double support per transition; ψ = 0 is the left
heel strike, the right foot swings in ψ ∈ [ds, ½), the left in [½ + ds, 1). An
amplitude envelope ``e(t)`` ∈ [0, 1] scales stride, sway, lift and arm swing, so one
code path gives both the start-up from standing (``e`` rising over the first cycle)
and the steady loop (``e ≡ 1``), which is closed by construction.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from imitwalk.errors import ConfigError
from imitwalk.retarget.command import GaitCommand, check_side, cycle_motion, place, walking_frame
from imitwalk.retarget.params import GaitParams, LegGeometry, leg_scaled
from imitwalk.retarget.template import GaitTemplate

__all__ = [
    "FOOT_GAP",
    "KNEE_MIN_DEG",
    "START_CYCLES",
    "GaitCommand",
    "GaitParams",
    "LegGeometry",
    "TaskPlan",
    "knee_cap",
    "plan_walk",
]

#: Least gap between the soles' edges when a sidestep's closing step lands [m], for a leg of
#: :data:`~imitwalk.retarget.params.REFERENCE_LEG` (scaled with the robot's leg).
FOOT_GAP = 0.01

#: Start-up cycles: one of sway with both feet down, then two of growing stride.
START_CYCLES = 3

#: The knee keeps at least this flexion at the longest stride [deg] (a straight knee at
#: full stride was why a prototype's full-scale gait failed).
KNEE_MIN_DEG = 20.0


@dataclass(frozen=True)
class TaskPlan:
    """Per-tick task-space targets (``N`` ticks of ``dt``).

    ``l_sole``/``r_sole`` ``(N, 3)`` sole-centre positions [m] (soles flat on the ground);
    ``yaw`` ``(N, 2)`` heading of the left and right sole [rad] (0: +x); ``pitch`` the
    pelvis's forward pitch [rad] (into a slope); ``path`` ``(N, 5)`` the walking frame
    (:data:`~imitwalk.retarget.command.PATH_COLUMNS`), whose heading the pelvis takes; ``motion``
    ``(5,)`` how one steady cycle moves it (:func:`~imitwalk.retarget.command.cycle_motion`);
    ``com`` ``(N, 2)`` centre of mass x, y [m]; ``pelvis_z`` ``(N,)`` pelvis-frame
    height [m]; ``upper`` dict role → ``(N,)`` arm and waist angles [rad], offsets from
    the standing posture; ``phase`` ``(N,)`` ψ; ``stance`` ``(N, 2)`` bool, left/right
    foot on the floor; ``swing`` ``(N, 2)`` swing progress σ ∈ [0, 1] of each foot
    (NaN in stance); ``envelope`` ``(N,)``; ``stride`` per steady cycle [m]; ``period`` [s].
    """

    dt: float
    l_sole: np.ndarray
    r_sole: np.ndarray
    com: np.ndarray
    pelvis_z: np.ndarray
    upper: dict
    phase: np.ndarray
    stance: np.ndarray
    swing: np.ndarray
    envelope: np.ndarray
    stride: float
    period: float
    yaw: np.ndarray | None = None
    pitch: float = 0.0
    path: np.ndarray | None = None
    motion: np.ndarray | None = None


def _smoothstep(x: np.ndarray) -> np.ndarray:
    x = np.clip(x, 0.0, 1.0)
    return x * x * x * (x * (6.0 * x - 15.0) + 10.0)


def _profile(p: np.ndarray, s: np.ndarray) -> np.ndarray:
    """Evaluate a ``(PHASES,)`` profile sampled on [0, 1] at ``s``."""
    return np.interp(s, np.linspace(0.0, 1.0, len(p)), p)


@dataclass(frozen=True)
class _Clock:
    """The plan's ticks: ``n`` of them, the first ``n_out`` returned (one more cycle is laid
    out, so the last steps land where the next cycle expects), ``n_cyc`` per cycle.

    ``k`` ``(n,)`` tick index; ``psi`` ``(n,)`` phase ψ; ``e`` ``(n,)`` stride envelope;
    ``e_sway`` ``(n,)`` sway envelope; ``stepping`` ``(n,)`` bool, the feet may step.
    """

    n: int
    n_out: int
    n_cyc: int
    k: np.ndarray
    psi: np.ndarray
    e: np.ndarray
    e_sway: np.ndarray
    stepping: np.ndarray


@dataclass(frozen=True)
class _FootTrack:
    """Per-tick foot targets: ``soles`` ``{"l", "r"}`` -> ``(n, 3)`` sole centre [m];
    ``yaw`` ``(n, 2)`` sole heading [rad]; ``stance`` ``(n, 2)`` bool; ``swing`` ``(n, 2)``
    swing progress σ (NaN in stance)."""

    soles: dict[str, np.ndarray]
    yaw: np.ndarray
    stance: np.ndarray
    swing: np.ndarray


def _stance_half_width(
    geom: LegGeometry, params: GaitParams, cmd: GaitCommand, scale: float
) -> float:
    """Lateral distance of each sole from the walking line [m]."""
    # a sidestep's closing step brings the feet half a sidestep closer than they stand:
    # the stance widens if that would leave less than FOOT_GAP between the soles
    y_foot = geom.hip_y + params.width
    if cmd.side_m:
        side = abs(cmd.side_m * scale)
        y_foot = max(y_foot, (geom.foot_width + leg_scaled(FOOT_GAP, geom.leg) + side / 2) / 2)
    return y_foot


def _clock(n_cyc: int, cycles: int, start: bool) -> _Clock:
    """Ticks, phase and envelopes of ``cycles`` steady cycles of ``n_cyc`` ticks, after the
    start-up cycles if ``start``."""
    ramp = START_CYCLES if start else 0
    n_out = n_cyc * (ramp + cycles)
    n = n_out + n_cyc  # one extra cycle, so the last steps land where the next cycle expects
    k = np.arange(n)
    psi = (k % n_cyc) / n_cyc
    # the sway builds up over the first start-up cycle (feet down), so the lateral rocking
    # is in full swing before a foot leaves the floor; then the stride grows over the
    # other start-up cycles, slowly enough that no step is longer than a steady one
    e = np.ones(n) if not start else _smoothstep((k - n_cyc) / ((ramp - 1) * n_cyc))
    e_sway = np.ones(n) if not start else _smoothstep(k / n_cyc)
    stepping = k >= (n_cyc if start else 0)
    return _Clock(n, n_out, n_cyc, k, psi, e, e_sway, stepping)


def _lift_shape(template: GaitTemplate) -> np.ndarray:
    """``(PHASES,)`` the swing foot's lift profile, at least a half sine, peak 1."""
    shape_z = np.maximum(
        template.swing_z, np.sin(np.pi * np.linspace(0.0, 1.0, len(template.swing_z)))
    )
    shape_z /= shape_z.max()
    return shape_z


def _landing_spot(
    clock: _Clock,
    path: np.ndarray,
    i: int,
    sigma: float,
    window: tuple[float, float],
    ds: float,
    stride: float,
    lateral: float,
) -> np.ndarray:
    """Where a foot lifting off at tick ``i`` lands: ``(3,)`` x, y [m] and heading [rad],
    a quarter stride ahead of the walking frame ``path`` ``(n, 5)`` at mid swing."""
    a, b = window
    n_cyc = clock.n_cyc
    t_mid = i - sigma * (b - a) * n_cyc + (b - a + ds / 2) * n_cyc  # fractional
    ahead = float(np.interp(t_mid, clock.k, clock.e)) * stride / 4
    xy, th = place(path, t_mid, np.array([ahead, lateral]))
    return np.array([*xy, th])


def _foot_track(
    clock: _Clock,
    template: GaitTemplate,
    params: GaitParams,
    path: np.ndarray,
    stride: float,
    ds: float,
    y_foot: float,
    start: bool,
) -> _FootTrack:
    """Both feet, tick by tick: flat and fixed in stance, along the human foot path in
    swing (``path`` ``(n, 5)`` the walking frame; ``y_foot`` [m] each sole off its line)."""
    n, n_cyc, psi = clock.n, clock.n_cyc, clock.psi
    soles = {"l": np.zeros((n, 3)), "r": np.zeros((n, 3))}
    yaw = np.zeros((n, 2))
    stance = np.zeros((n, 2), dtype=bool)
    swing = np.full((n, 2), np.nan)
    # swing windows in phase: right [ds, 0.5), left [0.5 + ds, 1)
    windows = {"r": (ds, 0.5), "l": (0.5 + ds, 1.0)}
    lateral = {"l": y_foot, "r": -y_foot}
    land = {  # where each foot stands: x, y [m] and heading [rad]
        "l": np.array([0.0, y_foot, 0.0]),
        "r": np.array([0.0 if start else -stride / 2, -y_foot, 0.0]),
    }
    lift_off = dict(land)
    shape_z = _lift_shape(template)
    for i in range(n):
        for j, f in enumerate("lr"):
            a, b = windows[f]
            if clock.stepping[i] and a <= psi[i] < b:
                sigma = (psi[i] - a) / (b - a)
                if sigma * (b - a) * n_cyc < 1.0:  # first swing tick: choose the landing spot
                    lift_off[f] = land[f]
                    land[f] = _landing_spot(
                        clock, path, i, sigma, windows[f], ds, stride, lateral[f]
                    )
                u = _profile(template.swing_x, sigma)
                soles[f][i, :2] = lift_off[f][:2] + (land[f][:2] - lift_off[f][:2]) * u
                soles[f][i, 2] = params.lift * _profile(shape_z, sigma)
                yaw[i, j] = lift_off[f][2] + (land[f][2] - lift_off[f][2]) * u
                swing[i, j] = sigma
            else:
                soles[f][i] = (*land[f][:2], 0.0)
                yaw[i, j] = land[f][2]
                stance[i, j] = True
    return _FootTrack(soles, yaw, stance, swing)


def _arm_swing(template: GaitTemplate, clock: _Clock, scale: float) -> dict[str, np.ndarray]:
    """Role -> ``(n,)`` arm and waist angle offsets from the standing posture [rad], the
    human's swing over ψ scaled with the stride."""
    psi = clock.psi
    grid = np.arange(len(template.waist)) / len(template.waist)
    arm = lambda prof: np.interp(psi, grid, prof, period=1.0)  # noqa: E731
    amp = clock.e * scale
    return {
        "l_shoulder_pitch": -amp * arm(template.shoulder[:, 0] - template.shoulder[:, 0].mean()),
        "r_shoulder_pitch": -amp * arm(template.shoulder[:, 1] - template.shoulder[:, 1].mean()),
        "l_elbow": -amp * arm(template.elbow[:, 0] - template.elbow[:, 0].mean()),
        "r_elbow": -amp * arm(template.elbow[:, 1] - template.elbow[:, 1].mean()),
        "waist_yaw": amp * arm(template.waist),
    }


def plan_walk(
    template: GaitTemplate,
    geom: LegGeometry,
    params: GaitParams,
    scale: float,
    dt: float,
    cycles: int = 1,
    start: bool = False,
    cap_scale: float | None = 1.0,
    command: GaitCommand | None = None,
) -> TaskPlan:
    """Lay out ``cycles`` steady cycles, after :data:`START_CYCLES` start-up cycles if ``start``.

    The start-up begins standing with both feet side by side: in its first cycle the
    sway builds up while both feet stay down; then the feet step, with the stride
    growing smoothly from zero; then the steady cycles follow.

    Args:
        template: the human gait; geom: the robot's legs; params: reference parameters.
        scale: stride scale (1.0: the human stride scaled by the leg-length ratio).
        dt: control period [s]; the cycle time is rounded to a whole number of ticks.
        cycles: steady cycles (envelope 1); start: prepend the start-up cycles.
        cap_scale: the longest stride the gait is built for; the hip is never higher
            than :func:`knee_cap` allows at that stride (or at ``scale`` if longer), so
            the knee stays bent; ``None`` for no cap.
        command: turn, sidestep, stride fraction and slope (default: straight ahead on
            level ground); a turn or sidestep needs ``start``.

    Raises:
        ConfigError: a turn or sidestep without ``start``.
    """
    cmd = command or GaitCommand()
    params = params.for_leg(geom.leg)
    check_side(cmd, geom.leg)
    n_cyc = max(2, round(template.period / dt))
    period = n_cyc * dt
    stride = cmd.forward * scale * template.stride * geom.leg / template.leg_length
    ds = float(np.clip(params.ds, 0.0, 0.45))
    y_foot = _stance_half_width(geom, params, cmd, scale)
    if not start and (cmd.turn_deg or cmd.side_m):
        raise ConfigError("a turning or sidestepping plan needs start=True")
    clock = _clock(n_cyc, cycles, start)
    path = walking_frame(clock.e, stride / period, cmd, scale, period, dt)  # (N, 5)
    if not start:  # steady: CoM midway between the feet at mid double support
        path[:, 0] -= stride / 4 + stride * ds / 2
    com_y = clock.e_sway * params.sway * y_foot * np.sin(2 * np.pi * (clock.psi - ds / 2))
    feet = _foot_track(clock, template, params, path, stride, ds, y_foot, start)
    hip = params.height * geom.hip_height
    if cap_scale is not None:
        hip = min(hip, knee_cap(template, geom, params, max(cap_scale, scale), start, cmd))
    pelvis_z = np.full(clock.n, hip + geom.hip_z)
    pitch = float(np.radians(cmd.slope_deg))
    # on a slope the CoM sits over the feet along gravity: its height × tan(slope) uphill
    lean = params.lean + (hip + geom.hip_z) * np.tan(pitch)
    c, s = np.cos(path[:, 2]), np.sin(path[:, 2])
    com = path[:, :2] + np.stack([c * lean - s * com_y, s * lean + c * com_y], axis=1)
    upper = _arm_swing(template, clock, scale)
    cut = slice(0, clock.n_out)
    return TaskPlan(
        dt=dt,
        l_sole=feet.soles["l"][cut],
        r_sole=feet.soles["r"][cut],
        com=com[cut],
        pelvis_z=pelvis_z[cut],
        upper={key: val[cut] for key, val in upper.items()},
        phase=clock.psi[cut],
        stance=feet.stance[cut],
        swing=feet.swing[cut],
        envelope=clock.e[cut],
        stride=stride,
        period=period,
        yaw=feet.yaw[cut],
        pitch=pitch,
        path=path[cut],
        motion=cycle_motion(path, clock.n_out - n_cyc, n_cyc),
    )


def knee_cap(
    template: GaitTemplate,
    geom: LegGeometry,
    params: GaitParams,
    scale: float,
    start: bool = True,
    command: GaitCommand | None = None,
) -> float:
    """Highest hip height above the soles [m] that keeps the knee bent ``KNEE_MIN_DEG``.

    Measured on the plan of the longest stride (``scale``), start-up included if
    ``start``, with a steady cycle after it: at every tick, each
    ankle (sole minus its offsets) must be within ``leg * cos(κ/2)`` of its hip (thigh and
    shank taken as equal, so a knee bent by κ shortens the leg by that factor), the hip
    taken ``hip_ahead`` in front of the centre of mass and ``hip_y`` to the side (both
    turned with the pelvis, the ankle offset with its sole).
    """
    plan = plan_walk(
        template, geom, params, scale, 0.01, cycles=1, start=start, cap_scale=None, command=command
    )
    assert plan.path is not None and plan.yaw is not None  # plan_walk sets both
    reach = geom.leg * np.cos(np.radians(KNEE_MIN_DEG) / 2)
    c, s = np.cos(plan.path[:, 2]), np.sin(plan.path[:, 2])
    best = np.inf
    for j, (side, sole) in enumerate(((1.0, plan.l_sole), (-1.0, plan.r_sole))):
        hip_x = plan.com[:, 0] + c * geom.hip_ahead - s * side * geom.hip_y
        hip_y = plan.com[:, 1] + s * geom.hip_ahead + c * side * geom.hip_y
        dx = hip_x - (sole[:, 0] - np.cos(plan.yaw[:, j]) * geom.sole_x)
        dy = hip_y - (sole[:, 1] - np.sin(plan.yaw[:, j]) * geom.sole_x)
        dz2 = np.maximum(reach**2 - dx**2 - dy**2, (0.5 * geom.leg) ** 2)
        best = min(best, float(np.min(np.sqrt(dz2) + sole[:, 2] + geom.ankle)))
    return best
