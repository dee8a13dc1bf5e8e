"""Seeded mutations of hoap2's joint map and MJCF, loaded as a user's robot (issues 34, 60).

Each case is hoap2's two files with one of them mutated the way a hostile or careless
user would: truncated, a byte flipped, a line deleted or doubled, a byte that is not
UTF-8, a number made NaN, infinite, huge, negative or zero, a vector of the wrong
length, a field of the wrong type, a key renamed, deep nesting; and, in two of five
MJCF cases, one number of a physical attribute (a mass, size, position, timestep, joint
range or servo gain) set to a value no humanoid has. A case passes if loading it raises
an :class:`~imitwalk.errors.ImitwalkError` in one line that names the file, or gives a
:class:`Robot` whose arrays are finite (a torque limit may be ``inf``: no limit), whose
mass, height, timestep, joint ranges and servo gains are within the bounds of
:mod:`imitwalk.robots.plausible` (``accepted_implausible`` otherwise), and whose
``robot info`` is valid JSON. Cases run in a worker process with a time limit, so a
hang is counted, not waited for. Used by ``tests/test_fuzz_robot.py``.

As a command line, from the repository root, it runs the cases and prints one JSON
object: per input (the joint map, the MJCF) how many cases ended in each outcome, and the
first failing cases::

    python -m tests.helpers.fuzz_robot [--cases 4000] [--seed 1] [--timeout 20]
"""

from __future__ import annotations

import argparse
import json
import multiprocessing as mp
import random
import re
import shutil
import tempfile
import time
import traceback
from dataclasses import dataclass
from pathlib import Path

#: hoap2's files in the repository (this file is ``tests/helpers/fuzz_robot.py``).
HOAP2 = Path(__file__).resolve().parents[2] / "src" / "imitwalk" / "robots" / "hoap2"
OUTCOMES = (
    "project_error",
    "accepted",
    "other_exception",
    "accepted_nonfinite",
    "accepted_implausible",
    "hang",
)
_VALUES = [
    None,
    True,
    False,
    0,
    -1,
    5,
    1e308,
    float("nan"),
    float("inf"),
    -float("inf"),
    "",
    "x",
    "l_knee",
    [],
    {},
    [1, 2],
    {"l": 5},
    {"joint": 5},
    10**400,
    [[[[]]]],
]
_NUMBER = re.compile(r"-?\d+\.?\d*(?:e-?\d+)?")


@dataclass(frozen=True)
class Case:
    """One mutated pair of files: ``kind`` ``"map"`` or ``"mjcf"``, ``how`` (in words),
    the joint map and the MJCF as bytes."""

    kind: str
    how: str
    jmap: bytes
    mjcf: bytes


def _paths(obj, prefix=()):
    yield prefix
    if isinstance(obj, dict):
        for k, v in obj.items():
            yield from _paths(v, (*prefix, k))
    elif isinstance(obj, list):
        for i, v in enumerate(obj):
            yield from _paths(v, (*prefix, i))


def _set(obj, path, value, delete=False):
    *head, last = path
    for k in head:
        obj = obj[k]
    if delete:
        del obj[last]
    else:
        obj[last] = value


def _text_mutation(rng: random.Random, data: bytes) -> tuple[str, bytes]:
    lines = data.split(b"\n")
    kind = rng.choice(["truncate", "flip", "non-utf8", "delete line", "double line", "number"])
    if kind == "truncate":
        i = rng.randrange(len(data))
        return f"truncated at byte {i}", data[:i]
    if kind == "flip":
        i = rng.randrange(len(data))
        return f"byte {i} flipped", data[:i] + bytes([data[i] ^ (1 << rng.randrange(8))]) + data[
            i + 1 :
        ]
    if kind == "non-utf8":
        names = [m.start() + 6 for m in re.finditer(rb'name="', data)]
        i = rng.choice(names) if names else rng.randrange(len(data))
        return f"byte 0xff at {i}", data[:i] + b"\xff" + data[i:]
    if kind in ("delete line", "double line"):
        i = rng.randrange(len(lines))
        rest = lines[:i] + lines[i + 1 :] if kind == "delete line" else lines[: i + 1] + lines[i:]
        return f"line {i + 1}: {kind}", b"\n".join(rest)
    text = data.decode()
    nums = list(_NUMBER.finditer(text))
    m = rng.choice(nums)
    new = rng.choice(["nan", "inf", "-inf", "1e400", "-1", "0", "1e30", "-1e30", "NaN", "", "1 2"])
    return f"number {m.group()!r} at {m.start()} -> {new!r}", (
        text[: m.start()] + new + text[m.end() :]
    ).encode()


#: MJCF attributes with a physical meaning, and values no humanoid has (NaN among them).
_PHYSICAL = re.compile(
    r'\b(mass|size|pos|timestep|range|kp|diaginertia|fromto|ctrlrange|forcerange)="([^"]*)"'
)
_WILD = ["nan", "inf", "1e308", "1e30", "-1e30", "0", "1e-30", "-1", "1e5", "300"]


def _physical_mutation(rng: random.Random, data: bytes) -> tuple[str, bytes]:
    """One number of a physical attribute (a mass, size, position, timestep, range, gain)
    set to a value no humanoid has."""
    text = data.decode()
    m = rng.choice(list(_PHYSICAL.finditer(text)))
    nums = m.group(2).split()
    i, new = rng.randrange(len(nums)), rng.choice(_WILD)
    nums[i] = new
    how = f"{m.group(1)}={m.group(2)!r} at {m.start()}: number {i} -> {new!r}"
    value = f'{m.group(1)}="{" ".join(nums)}"'
    return how, (text[: m.start()] + value + text[m.end() :]).encode()


def _map_mutation(rng: random.Random, jmap: dict, raw: bytes) -> tuple[str, bytes]:
    if rng.random() < 0.3:
        return _text_mutation(rng, raw)
    obj = json.loads(raw)
    path = rng.choice([p for p in _paths(obj) if p])
    roll = rng.random()
    if roll < 0.2:
        _set(obj, path, None, delete=True)
        how = f"{'.'.join(map(str, path))} deleted"
    elif roll < 0.3 and isinstance(path[-1], str):
        *head, last = path
        parent = obj
        for k in head:
            parent = parent[k]
        parent[last + "_x"] = parent.pop(last)
        how = f"{'.'.join(map(str, path))} renamed"
    elif roll < 0.35:
        deep = "[" * 1000 + "]" * 1000
        return "deep nesting", raw.replace(b'"torso"', b'"torso": ' + deep.encode() + b', "x"', 1)
    else:
        value = rng.choice(_VALUES)
        _set(obj, path, value)
        how = f"{'.'.join(map(str, path))} = {str(value)[:30]}"
    return how, json.dumps(obj).encode()


def cases(n: int, seed: int = 0):
    """``n`` cases, half of each kind, from ``seed``."""
    rng = random.Random(seed)
    xml = (HOAP2 / "hoap2.xml").read_bytes()
    jm = json.loads((HOAP2 / "hoap2.json").read_text())
    jm.pop("mjcf")
    raw = json.dumps(jm, indent=1).encode()
    for i in range(n):
        if i % 2 == 0:
            how, data = _map_mutation(rng, jm, raw)
            yield Case("map", how, data, xml)
        else:
            mutate = _physical_mutation if rng.random() < 0.4 else _text_mutation
            how, data = mutate(rng, xml)
            yield Case("mjcf", how, raw, data)


def _implausible(robot) -> str | None:
    """Which bound of :mod:`imitwalk.robots.plausible` an accepted robot is outside
    (``None``: none), checked here on the robot record and its model."""
    from imitwalk.robots import plausible as p

    model = robot.compile()
    (m0, m1), (h0, h1), (t0, t1) = p.TOTAL_MASS_KG, p.HEIGHT_M, p.TIMESTEP_S
    (r0, r1), (k0, k1) = p.JOINT_RANGE_RAD, p.SERVO_KP
    checks = {
        "total_mass": m0 <= robot.total_mass <= m1,
        "height": h0 <= robot.height <= h1,
        "torso_height": 0 < robot.torso_height <= robot.height,
        "body_mass": model.body_mass.max() <= p.BODY_MASS_KG,
        "body_inertia": model.body_inertia.max() <= p.BODY_INERTIA_KGM2,
        "timestep": t0 <= model.opt.timestep <= t1,
        "limits": bool(((r0 <= robot.limits) & (robot.limits <= r1)).all())
        and bool((robot.limits[:, 0] < robot.limits[:, 1]).all()),
        "kp": bool(((k0 < robot.kp) & (robot.kp <= k1)).all()),
    }
    bad = [name for name, ok in checks.items() if not ok]
    return f"implausible {', '.join(bad)}" if bad else None


def _finite_robot(robot) -> str | None:
    """What is wrong with an accepted robot (``None``: nothing): a non-finite array or
    number, or a value outside the plausibility bounds."""
    import numpy as np

    from imitwalk.cli.progress import _finite

    for name in ("signs", "stand", "stand_qpos", "limits", "kp"):
        if not np.isfinite(getattr(robot, name)).all():
            return f"{name} not finite"
    if not (np.asarray(robot.torque_limit) > 0).all() or np.isnan(robot.torque_limit).any():
        return "torque_limit not > 0"
    for name in ("total_mass", "torso_height", "height"):
        if not np.isfinite(getattr(robot, name)):
            return f"{name} not finite"
    if (why := _implausible(robot)) is not None:
        return why
    info = {"limits": robot.limits.tolist(), "torque": robot.torque_limit.tolist()}
    json.dumps(_finite(info), allow_nan=False)
    return None


def run_case(case: Case, folder: Path) -> tuple[str, str]:
    """``(outcome, detail)`` of loading one case (in this process)."""
    import imitwalk.robots as robots
    from imitwalk.errors import ImitwalkError
    from imitwalk.robots import build

    robots._CACHE.clear()
    build._MODELS.clear()
    if folder.exists():
        shutil.rmtree(folder)
    folder.mkdir(parents=True)
    (folder / "bot.xml").write_bytes(case.mjcf)
    (folder / "bot.json").write_bytes(case.jmap)
    try:
        robot = robots.load_robot(folder / "bot.xml", folder / "bot.json")
    except ImitwalkError as exc:
        msg = str(exc)
        if "\n" in msg:
            return "other_exception", "two lines"
        if "bot.xml" not in msg and "bot.json" not in msg:
            return "other_exception", f"names neither file: {msg}"[:300]
        return "project_error", msg
    except BaseException as exc:  # what the fuzz is for: anything else is a defect
        if isinstance(exc, KeyboardInterrupt):
            raise
        tb = traceback.format_exc().strip().splitlines()
        return "other_exception", f"{type(exc).__name__}: {exc} @ {tb[-3].strip()}"[:300]
    bad = _finite_robot(robot)
    if bad is None:
        return "accepted", ""
    return ("accepted_implausible" if bad.startswith("implausible") else "accepted_nonfinite"), bad


def _serve(conn, folder: str) -> None:
    while True:
        case = conn.recv()
        if case is None:
            return
        conn.send(run_case(case, Path(folder)))


class Runner:
    """Runs cases in a worker process, each within ``timeout`` [s]."""

    def __init__(self, timeout: float = 20.0):
        self.timeout = timeout
        self.folder = tempfile.mkdtemp(prefix="imitwalk-fuzz-")
        self._start()

    def _start(self) -> None:
        ctx = mp.get_context("fork")
        self.conn, child = ctx.Pipe()
        self.proc = ctx.Process(target=_serve, args=(child, self.folder), daemon=True)
        self.proc.start()

    def __call__(self, case: Case) -> tuple[str, str]:
        self.conn.send(case)
        if self.conn.poll(self.timeout):
            try:
                return self.conn.recv()
            except EOFError:
                pass
        hung = self.proc.is_alive()
        self.proc.kill()
        self.proc.join()
        self._start()
        return ("hang", f"over {self.timeout:g} s") if hung else ("other_exception", "crashed")

    def close(self) -> None:
        try:
            self.conn.send(None)
        except OSError:
            pass
        self.proc.join(5)
        if self.proc.is_alive():
            self.proc.kill()
        shutil.rmtree(self.folder, ignore_errors=True)


def fuzz(n: int, seed: int = 0, timeout: float = 20.0) -> dict:
    """Counts of each outcome per kind, and the failing cases (at most 20)."""
    counts = {k: dict.fromkeys(OUTCOMES, 0) for k in ("map", "mjcf")}
    failures = []
    runner = Runner(timeout)
    try:
        for case in cases(n, seed):
            outcome, detail = runner(case)
            counts[case.kind][outcome] += 1
            if outcome not in ("project_error", "accepted") and len(failures) < 20:
                failures.append({"kind": case.kind, "how": case.how, outcome: detail})
    finally:
        runner.close()
    return {"cases": n, "seed": seed, "timeout_s": timeout, "counts": counts, "failures": failures}


def main(argv: list[str] | None = None) -> int:
    """The command line (see the module's docstring); prints the JSON report, returns 0."""
    ap = argparse.ArgumentParser(
        prog="python -m tests.helpers.fuzz_robot",
        description="Fuzz the robot loader: seeded mutations of hoap2's joint map and MJCF.",
    )
    ap.add_argument("--cases", type=int, default=4000, help="cases, half per input (4000)")
    ap.add_argument("--seed", type=int, default=1, help="random seed (1)")
    ap.add_argument("--timeout", type=float, default=20.0, help="time limit per case [s] (20)")
    args = ap.parse_args(argv)
    t0 = time.perf_counter()
    out = fuzz(args.cases, args.seed, args.timeout)
    out["wall_seconds"] = round(time.perf_counter() - t0, 1)
    print(json.dumps(out, indent=2))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
