"""The stride a robot's servos can carry: shorter steps where they are slower than the swing.

The stepping gait keeps the human's cadence and scales the stride to the robot's legs
(:mod:`imitwalk.step.style`). That asks each leg joint for the speeds of the human's
swing. A position servo cannot go faster than its **top speed**, the speed at which all
its torque is spent on the damping its MJCF gives the joint: ``τ_max / d``
(:func:`top_speeds`). Menagerie's ROBOTIS OP3 gives every joint 5 Nm and
1.084 Nm s/rad, so 4.6 rad/s (its Dynamixel XM430-W350's data sheet: 46 rpm, 4.8 rad/s,
without load); ``hoap2``'s top speed is 40 rad/s; a joint without damping (G1 in
Menagerie) has none.

:func:`servo_ratio` compares the two: the nominal swing's peak joint speeds
(:func:`swing_speeds`, by inverse kinematics of the style's single support) over the
top speeds. Up to 1, the style is walked as it is (``hoap2``: 0.4-0.7 on its clips).
Above it the servos lag the swing (OP3: 3.9-5.3), and :func:`choose_stride` lets trials
on training robots choose the stride: the shares of :data:`STRIDES`, longest first, walk
the same robots of :data:`PACE_PROTOCOL` for :data:`PACE_SECONDS` until one fells none,
and the longest with the fewest falls is kept (:class:`PaceChoice`).

Those robots vary what the servos must carry (mass, friction, servos, sensors) but are
not kicked: on ``hard``'s robots the kicks made the choice a draw's luck (OP3, strides
0.5, 0.35, 0.25: 3, 4, 3 of 8 robots fell in 15 s on one draw, 3, 0, 0 in 10 s on
another), where on ``eval``'s (10 robots, 20 s) 4, 0, 0 fell, and the nominal robot fell
at 0.5 and walked at 0.35. The gains then learn the kicks (:mod:`imitwalk.step.learn`).
The cadence is kept: on OP3 a slower one did not help (8 ``hard`` robots, 10 s, strides
1, 0.75, 0.5, 0.35, 0.25 fell 8, 6, 3, 0, 0 at the clip's cadence and 7, 4, 2, 2, 3 at
1.3 × its step time), and the swing's peak speed falls little with the stride (its lift
is most of it), so the ratio says when to try shorter strides but cannot pick one itself.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import asdict, dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from imitwalk.parallel import run_parallel
from imitwalk.robots import Robot
from imitwalk.sim.seeds import TRIAL_FIRST
from imitwalk.step.episode import StepJob, run_step_job
from imitwalk.step.gains import StepGains
from imitwalk.step.kinematics import BodyModel, FootPose
from imitwalk.step.style import GaitStyle, with_stride

if TYPE_CHECKING:  # loaded in choose_stride only when trials walk (its draws need SciPy)
    from imitwalk.sim.protocol import Protocol

__all__ = [
    "PACE_PROTOCOL",
    "PACE_ROBOTS",
    "PACE_SECONDS",
    "STRIDES",
    "PaceChoice",
    "choose_stride",
    "servo_ratio",
    "swing_speeds",
    "top_speeds",
]

#: The strides tried, as shares of the clip's, longest first.
STRIDES = (1.0, 0.7, 0.5, 0.35, 0.25, 0.15)
#: Training robots each stride walks.
PACE_ROBOTS = 8
#: How long each walks [s]: as long as the judge's walks (falls come at 6-29 s on OP3).
PACE_SECONDS = 30.0
#: The protocol those robots are drawn from.
PACE_PROTOCOL = "eval"


@dataclass(frozen=True)
class PaceChoice:
    """How the stride was chosen: ``ratio``, the swing's peak joint speed over the
    servos' top speed (:func:`servo_ratio`); ``share``, the stride kept (of the clip's);
    ``trials``, each stride tried (its share, as text) → its falls of ``robots``;
    ``sim_seconds`` walked [s]."""

    ratio: float
    share: float
    robots: int = 0
    trials: dict[str, int] = field(default_factory=dict)
    sim_seconds: float = 0.0

    def to_dict(self) -> dict:
        """Plain-JSON dictionary."""
        return asdict(self)


def top_speeds(robot: Robot) -> np.ndarray:
    """``(n,)`` each joint's top speed [rad/s]: its servo's torque limit over the joint's
    damping in the MJCF (``inf`` for a joint without damping)."""
    m = robot.compile()
    damping = np.array([m.dof_damping[m.jnt_dofadr[m.joint(j).id]] for j in robot.mj_joints])
    out = np.full(len(damping), np.inf)
    has = damping > 0
    out[has] = robot.torque_limit[has] / damping[has]
    return out


def swing_speeds(robot: Robot, style: GaitStyle, samples: int = 100) -> np.ndarray:
    """``(n,)`` each joint's peak speed [rad/s] over the style's nominal single support:
    the right foot swings from a step behind the left to a step ahead of it along the
    style's path, the pelvis level at its height and moving at the style's speed; the left
    leg stands (other joints: 0). By the leg IK of :class:`~imitwalk.step.kinematics.BodyModel`."""
    body = BodyModel(robot)
    length, half_w, dur = style.step_length, style.step_width / 2, style.single_support
    speed, z = style.speed, -style.pelvis_height
    gx = np.linspace(0.0, 1.0, len(style.swing_x))
    gz = np.linspace(0.0, 1.0, len(style.swing_z))
    times = np.linspace(0.0, dur, samples)
    q, out = robot.stand.copy(), []
    for k, t in enumerate(times):
        s = t / dur
        pelvis = speed * (t - dur / 2)  # ahead of the stance sole [m]
        swing_x = -length + 2.0 * length * float(np.interp(s, gx, style.swing_x))
        lift = style.clearance * float(np.interp(s, gz, style.swing_z))
        feet = {
            "l": FootPose(np.array([-pelvis, half_w, z]), 0.0),
            "r": FootPose(np.array([swing_x - pelvis, -half_w, z + lift]), 0.0),
        }
        q = body.solve_legs(q, feet, np.eye(3), iterations=30 if k == 0 else 8)
        out.append(q.copy())
    return np.abs(np.gradient(np.array(out), times, axis=0)).max(axis=0)


def servo_ratio(robot: Robot, style: GaitStyle) -> float:
    """The largest ratio over the joints of the swing's peak speed to the servo's top
    speed (:func:`swing_speeds` over :func:`top_speeds`; 0 where no joint has a top
    speed). Above 1, the servos cannot follow the style's swing."""
    return float(np.max(swing_speeds(robot, style) / top_speeds(robot)))


def choose_stride(
    robot: Robot,
    style: GaitStyle,
    protocol: Protocol | None = None,
    seconds: float = PACE_SECONDS,
    engine: str = "mujoco",
    gains: StepGains | None = None,
    progress: Callable[[str], None] | None = None,
) -> tuple[GaitStyle, PaceChoice]:
    """``style`` at the stride its servos carry, and how it was chosen (see the module
    doc): as it is if :func:`servo_ratio` is at most 1; else the strides of
    :data:`STRIDES`, longest first until one fells none, each walk :data:`PACE_ROBOTS`
    robots of ``protocol`` (default: the one :data:`PACE_PROTOCOL` names; seeds from
    :data:`~imitwalk.sim.seeds.TRIAL_FIRST`) for ``seconds`` [s] with ``gains`` (default:
    the shipped ones); the longest with the fewest falls is kept."""
    say = progress or (lambda _msg: None)
    ratio = servo_ratio(robot, style)
    if ratio <= 1.0:
        return style, PaceChoice(ratio=ratio, share=style.stride_share)
    if protocol is None:
        from imitwalk.sim.protocol import load_protocol

        protocol = load_protocol(PACE_PROTOCOL)
    gains = gains or StepGains()
    draws = [protocol.draw(TRIAL_FIRST + i, robot, seconds=seconds) for i in range(PACE_ROBOTS)]
    styles, falls, walked = [], [], 0.0
    for share in STRIDES:  # longest first; a stride no robot fell on ends the trials
        st = with_stride(style, share)
        jobs = [StepJob(robot, st, gains, d.seed, d.options, seconds, engine) for d in draws]
        res = run_parallel(run_step_job, jobs)
        styles.append(st)
        falls.append(sum(r.fell for r in res))
        walked += sum(r.seconds for r in res)
        if falls[-1] == 0:
            break
    best = falls.index(min(falls))  # the first of the fewest: the longest stride
    trials = {f"{share:g}": f for share, f in zip(STRIDES, falls, strict=False)}
    n = len(draws)
    say(
        f"  pace: the swing asks {ratio:.1f} x the servos' top speed; strides "
        + ", ".join(f"{k} fell {v}/{n}" for k, v in trials.items())
        + f"; kept {STRIDES[best]:g} of the clip's"
    )
    choice = PaceChoice(
        ratio=ratio, share=STRIDES[best], robots=n, trials=trials, sim_seconds=walked
    )
    return styles[best], choice
