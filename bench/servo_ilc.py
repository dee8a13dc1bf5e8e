"""A prototype: the servos' sag learned while walking, from the encoders (repetitive ILC).

Each loop tick's target error of the leg joints (the target the controller asked for less
what the encoders measure one tick later) is summed over a gait cycle; at the cycle's
end a correction per loop tick grows by ``gain`` × that error, smoothed over ±``width``
ticks around the loop and led by ``lead`` ticks, and is added to every later target.
It walks a run's controller with the correction at each gain on validation robots.

Usage: ``python bench/servo_ilc.py RUN [--gains 0,0.2,0.5] [--protocol servo] [--robots 40]
[--first 300000] [--seconds 30] [--controller learned]``; prints JSON.
"""

from __future__ import annotations

import argparse
import json
from dataclasses import dataclass

import numpy as np

from imitwalk.balance.feedback import TickPolicy
from imitwalk.judge.protocol import load_protocol
from imitwalk.judge.replay import load_run
from imitwalk.parallel import run_parallel
from imitwalk.robots import load_robot

LEG = ("hip", "knee", "ankle")


class _Repetitive:
    """``TickPolicy`` plus a per-loop-tick correction learned from the encoders."""

    def __init__(self, inner: TickPolicy, names, gain: float, width: int, lead: int, leak: float,
                 offsets=None):  # fmt: skip
        self.inner, self.gain, self.width, self.lead, self.leak = inner, gain, width, lead, leak
        self.offsets = offsets  # the feedforward, added after the error is taken
        self.mask = np.array([any(p in n for p in LEG) for n in names], dtype=float)
        n_loop = inner.n_loop
        self.c = np.zeros((n_loop, len(names)))
        self.e = np.zeros((n_loop, len(names)))
        self.hits = np.zeros(n_loop)
        self.prev = None  # (loop tick, desired target)
        self.q0 = inner.q0
        self.wanted: list = []

    def __call__(self, k, obs):
        if self.prev is not None:
            i, want = self.prev
            self.e[i] += (want - obs.joints) * self.mask
            self.hits[i] += 1
        want = self.inner(k, obs)
        i = self.inner._phase[-1]
        if self.prev is not None and i < self.prev[0] and self.hits.all():  # a cycle ended
            err = self.e / self.hits[:, None]
            err = np.roll(err, -self.lead, axis=0)
            kernel = np.ones(2 * self.width + 1) / (2 * self.width + 1)
            pad = np.concatenate([err[-self.width :], err, err[: self.width]])
            smooth = np.stack(
                [np.convolve(pad[:, j], kernel, "valid") for j in range(err.shape[1])], 1
            )
            self.c = (1.0 - self.leak) * self.c + self.gain * smooth
            self.e[:], self.hits[:] = 0.0, 0.0
        self.prev = (i, want)
        self.wanted.append(want)
        ff = 0.0 if self.offsets is None else self.offsets[min(k, len(self.offsets) - 1)]
        return want + self.c[i] + ff


@dataclass(frozen=True)
class _Job:
    run_dir: str
    robot: object
    controller: str
    options: object
    seconds: float
    gain: float
    width: int
    lead: int
    leak: float


def _walk(job: _Job):
    from imitwalk.retarget.feedforward import walk_offsets
    from imitwalk.sim.metrics import walk_metrics
    from imitwalk.sim.mujoco import make_plant, run

    lr = load_run(job.run_dir)
    ref, settings = lr.ref, lr.settings_of(job.controller)
    offsets = walk_offsets(ref, job.robot, lr.scale, job.seconds, settings["feedforward"])
    assert not settings["wait"], "the prototype plays references that do not wait"
    inner = TickPolicy(ref, lr.scale, tuple(lr.laws[job.controller]), job.robot.joint_names,
                       job.seconds)  # fmt: skip
    pol = _Repetitive(inner, job.robot.joint_names, job.gain, job.width, job.lead, job.leak,
                      offsets)  # fmt: skip
    ro = run(make_plant(job.robot, ref.sim_options(job.options)), pol, len(inner.q_ref))
    m = walk_metrics(ro, ref.expected_distance(lr.scale, ro.seconds), inner.q_ref,
                     ref.track(lr.scale, ro.seconds))  # fmt: skip
    legs = pol.mask.astype(bool)
    want = np.asarray(pol.wanted)[: len(ro.q)]  # the targets before the feedforward
    late = ro.q[len(ro.q) // 2 :, legs] - want[len(ro.q) // 2 :, legs]
    return m.fell, m.fall_time_s, m.forward_distance_m, float(np.sqrt(np.mean(late**2)))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("run_dir")
    ap.add_argument("--robot", default="hoap2")
    ap.add_argument("--controller", default="learned")
    ap.add_argument("--protocol", default="servo")
    ap.add_argument("--gains", default="0,0.2,0.5")
    ap.add_argument("--width", type=int, default=3)
    ap.add_argument("--lead", type=int, default=2)
    ap.add_argument("--leak", type=float, default=0.0, help="the correction's forgetting per cycle")
    ap.add_argument("--robots", type=int, default=40)
    ap.add_argument("--first", type=int, default=300_000)
    ap.add_argument("--seconds", type=float, default=30.0)
    a = ap.parse_args()
    run, robot, proto = load_run(a.run_dir), load_robot(a.robot), load_protocol(a.protocol)
    draws = [
        proto.draw(a.first + s, robot, run.ref.sim_options(), a.seconds) for s in range(a.robots)
    ]
    for g in (float(x) for x in a.gains.split(",")):
        jobs = [
            _Job(a.run_dir, robot, a.controller, d.options, a.seconds, g, a.width, a.lead, a.leak)
            for d in draws
        ]
        res = run_parallel(_walk, jobs)
        print(
            json.dumps(
                {
                    "gain": g,
                    "falls": sum(r[0] for r in res),
                    "fall_times": sorted(round(r[1], 1) for r in res if r[0]),
                    "distance_m": round(float(np.mean([r[2] for r in res])), 2),
                    "track_rms_deg": round(float(np.degrees(np.mean([r[3] for r in res]))), 3),
                }
            ),
            flush=True,
        )


if __name__ == "__main__":
    main()
