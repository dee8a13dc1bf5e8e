"""Seeded mutations of the real mocap files, and a time-limited run of the reader on each.

Used by ``tests/test_fuzz_mocap.py``, and a command line (below). A case is ``(format,
index)``; its mutation is drawn from ``random.Random(f"{format}:{index}")``, so every
run makes the same cases. :func:`run_case` gives one of

* ``"error"``: the reader raised an :class:`~imitwalk.errors.ImitwalkError`;
* ``"accepted"``: it returned a Motion within the bounds of :mod:`imitwalk.mocap.bounds`
  (checked here again, independently of the readers);
* ``"implausible"``: it returned a Motion outside them, or not finite;
* ``"other"``: it raised any other exception (a traceback on the CLI);
* ``"hang"``: it ran longer than the time limit.

The seeds are the real files of ``../shared/mocap``, cut short where reading them whole
would take most of the time (the AMC to its first 120 frames, the BVH files to 121).

As a command line, from the repository root, it runs the cases of the test and prints
JSON: per format the cases, project errors, other exceptions, accepted results,
accepted but implausible or non-finite ones, hangs (over the time limit), the wall time
and the first few failures. Needs the shared fixtures (``$IMITWALK_SHARED_MOCAP``, else
``../shared/mocap`` beside the repository)::

    python -m tests.helpers.fuzz_mocap [--cases 2000] [--formats bvh amc c3d deepmimic]
"""

from __future__ import annotations

import argparse
import json
import os
import random
import re
import signal
import tempfile
import time
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from imitwalk.errors import ImitwalkError
from imitwalk.mocap import load_motion
from imitwalk.mocap.bounds import FPS_RANGE, LEG_RANGE_M, MAX_COORD_M, MAX_REACH_LEGS

FORMATS = ("bvh", "amc", "c3d", "deepmimic")
OUTCOMES = ("error", "accepted", "implausible", "other", "hang")
BAD_NUMBERS = [
    "nan",
    "inf",
    "-inf",
    "NaN",
    "1e308",
    "1e400",
    "-1e300",
    "0",
    "-1",
    "1e-320",
    "5e-324",
    "1" + "0" * 400,
    "3e38",
    "-0",
]


class Hang(BaseException):
    """The reader ran past the time limit (a BaseException: no reader may swallow it)."""


@dataclass(frozen=True)
class Case:
    """One mutated input: its files (name -> bytes), the one to read, and what was done."""

    files: dict[str, bytes]
    main: str
    mutation: str


def _cut_bvh(text: str, frames: int) -> str:
    head, motion = text.split("MOTION", 1)
    rows = motion.strip().splitlines()
    return (
        head
        + "MOTION\n"
        + f"Frames: {frames}\n"
        + rows[1]
        + "\n"
        + "\n".join(rows[2 : 2 + frames])
        + "\n"
    )


def _cut_amc(text: str, frames: int) -> str:
    out, seen = [], 0
    for line in text.splitlines():
        if line.strip().isdigit():
            seen += 1
            if seen > frames:
                break
        out.append(line)
    return "\n".join(out) + "\n"


def seeds(shared: Path) -> dict[str, list[dict[str, bytes]]]:
    """Per format, the seed file sets (name -> bytes; the first name is read)."""
    bvh = [
        _cut_bvh((shared / "cmu_bvh" / f).read_text(), 121).encode()
        for f in ("07_04.bvh", "07_06.bvh")
    ]
    amc = _cut_amc((shared / "cmu_asf_amc" / "test.amc").read_text(), 120).encode()
    asf = (shared / "cmu_asf_amc" / "test.asf").read_bytes()
    dm = ["humanoid3d_walk.txt", "walker_turn_left0.txt", "walker_turn_right0.txt"]
    return {
        "bvh": [{"clip.bvh": b} for b in bvh],
        "amc": [{"clip.amc": amc, "clip.asf": asf}],
        "c3d": [{"clip.c3d": (shared / "c3d" / "treadmill_events.c3d").read_bytes()}],
        "deepmimic": [{"clip.txt": (shared / "deepmimic" / f).read_bytes()} for f in dm],
    }


_NUMBER = re.compile(rb"(?<![\w.])-?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?(?![\w.])")


def _lines(data: bytes, rng: random.Random, op: str) -> tuple[bytes, str]:
    lines = data.split(b"\n")
    i = rng.randrange(len(lines))
    if op == "delete line":
        del lines[i]
    elif op == "duplicate line":
        lines.insert(i, lines[i])
    elif op == "swap lines":
        j = rng.randrange(len(lines))
        lines[i], lines[j] = lines[j], lines[i]
    elif op == "wrong vector length":
        nums = list(_NUMBER.finditer(lines[i]))
        if nums and rng.random() < 0.5:
            m = rng.choice(nums)
            lines[i] = lines[i][: m.start()] + lines[i][m.end() :]
        else:
            lines[i] = lines[i] + b" 0.5"
    return b"\n".join(lines), f"{op} at line {i + 1}"


def _number(data: bytes, rng: random.Random) -> tuple[bytes, str]:
    nums = list(_NUMBER.finditer(data))
    if not nums:
        return data, "no number"
    m = rng.choice(nums)
    new = rng.choice(BAD_NUMBERS).encode()
    return data[: m.start()] + new + data[
        m.end() :
    ], f"number at byte {m.start()} -> {new[:12].decode()}"


def _words(data: bytes, rng: random.Random) -> tuple[bytes, str]:
    words = list(re.finditer(rb"[A-Za-z_:]+", data))
    a, b = rng.choice(words), rng.choice(words)
    return data[: a.start()] + b.group() + data[
        a.end() :
    ], f"word {a.group()[:20]!r} -> {b.group()[:20]!r}"


def _generic(data: bytes, rng: random.Random) -> tuple[bytes, str]:
    op = rng.choice(
        [
            "truncate",
            "flip",
            "non-utf8",
            "delete line",
            "duplicate line",
            "swap lines",
            "wrong vector length",
            "number",
            "number",
            "word",
        ]
    )
    if op == "truncate":
        k = rng.randrange(len(data))
        return data[:k], f"truncated at byte {k}"
    if op == "flip":
        k = rng.randrange(len(data))
        return data[:k] + bytes([data[k] ^ rng.randrange(1, 256)]) + data[
            k + 1 :
        ], f"byte {k} flipped"
    if op == "non-utf8":
        k = rng.randrange(len(data))
        return data[:k] + b"\xff\xfe\xc3" + data[k:], f"non-UTF-8 bytes at {k}"
    if op == "number":
        return _number(data, rng)
    if op == "word":
        return _words(data, rng)
    return _lines(data, rng, op)


def _bvh(data: bytes, rng: random.Random) -> tuple[bytes, str]:
    text = data.decode()
    op = rng.choice(["deep nesting", "channels", "rotation order", "frames"])
    if op == "deep nesting":
        depth = rng.choice([50, 1000, 5000])
        nest = "".join(f"JOINT n{i}\n{{\nOFFSET 0 1 0\n" for i in range(depth)) + "}\n" * depth
        k = text.index("JOINT")
        return (text[:k] + nest + text[k:]).encode(), f"{depth} nested joints"
    if op == "channels":
        new = rng.choice(
            [
                "CHANNELS 3 Xrotation Xrotation Xrotation",
                "CHANNELS nan",
                "CHANNELS 1e400",
                "CHANNELS 7 Xrotation Yrotation Zrotation Xposition Yposition Zposition Wrot",
                "CHANNELS 2 Xposition Xposition",
                "CHANNELS -1",
            ]
        )
        lines = text.split("\n")
        idx = [i for i, ln in enumerate(lines) if ln.strip().startswith("CHANNELS")]
        i = rng.choice(idx)
        lines[i] = new
        return "\n".join(lines).encode(), f"line {i + 1} -> {new}"
    if op == "rotation order":
        perm = "".join(rng.choice("XYZ") for _ in range(3))
        k = text.index("Zrotation Yrotation Xrotation")
        new = " ".join(f"{a}rotation" for a in perm)
        return (text[:k] + new + text[k + 29 :]).encode(), f"rotation order {perm}"
    value = rng.choice(["nan", "inf", "0", "-5", "1e400", "4.5", "1e9"])
    key = rng.choice(["Frames:", "Frame Time:"])
    return re.sub(rf"{key}.*", f"{key} {value}", text, count=1).encode(), f"{key} {value}"


def _asf(files: dict[str, bytes], rng: random.Random) -> tuple[dict[str, bytes], str]:
    text = files["clip.asf"].decode()
    op = rng.choice(["cycle", "self child", "axis", "dof", "root", "units", "generic"])
    if op == "generic":
        new, what = _generic(files["clip.asf"], rng)
        return {**files, "clip.asf": new}, f"ASF {what}"
    if op in ("cycle", "self child"):
        head, tail = text.split(":hierarchy", 1)
        rows = [ln.split() for ln in tail.splitlines()]
        kids = {r[0]: r[1:] for r in rows if len(r) > 1}
        i, row = rng.choice([(i, r) for i, r in enumerate(rows) if len(r) > 1])
        child = rng.choice(row[1:])
        below = kids.get(child, [child])[0] if op == "cycle" else child
        rows[i] = [w for w in row if w != child]  # ``child`` now hangs from its own child
        rows.insert(i + 1, [below, child])
        text = head + ":hierarchy" + "\n".join("  " + " ".join(r) for r in rows) + "\n"
    elif op == "axis":
        order = rng.choice(["XQZ", "XX", "XXX", "xyzw", "20"])
        text = re.sub(r"(axis [^\n]*?)XYZ", rf"\g<1>{order}", text, count=rng.randint(1, 5))
    elif op == "dof":
        text = re.sub(
            r"dof rx ry rz", rng.choice(["dof rq", "dof rx rx", "dof tx", "dof"]), text, count=1
        )
    elif op == "root":
        text = re.sub(
            rng.choice([r"order .*", r"axis XYZ", r"position .*", r"orientation .*"]),
            rng.choice(
                [
                    "order TX TX TX RX RY RZ",
                    "axis XX",
                    "position 0 0",
                    "orientation 0 0",
                    "order TX TY TZ RQ",
                ]
            ),
            text,
            count=1,
        )
    else:
        text = re.sub(
            r"length 0.45", f"length {rng.choice(['inf', '1e-300', '0', 'nan', '-1'])}", text
        )
    return {**files, "clip.asf": text.encode()}, f"ASF {op}"


def _deepmimic(data: bytes, rng: random.Random) -> tuple[bytes, str]:
    doc = json.loads(data)
    op = rng.choice(["deep nesting", "frames", "quaternion", "dt", "value"])
    if op == "deep nesting":
        return b'{"Loop": "wrap", "Frames": ' + b"[" * rng.choice([100, 1000, 100000]) + b"]", op
    if op == "frames":
        doc["Frames"] = rng.choice([5, "x", None, [], [5], {"a": 1}, [[0.03] * 44]])
        return json.dumps(doc).encode(), f"Frames -> {str(doc['Frames'])[:20]}"
    t = rng.randrange(len(doc["Frames"]))
    frame = doc["Frames"][t]
    if op == "quaternion":
        col = rng.choice([4, 8, 12, 16, 21, 25, 30, 35, 39])
        scale = rng.choice([1e155, 1e-155, 1e300, 0.0])
        frame[col : col + 4] = [v * scale for v in frame[col : col + 4]]
        return json.dumps(doc).encode(), f"frame {t} quaternion at {col} x {scale:g}"
    if op == "dt":
        frame[0] = rng.choice([5e-324, 0.0, -0.03, 1e9, 1e-320])
        return json.dumps(doc).encode(), f"frame {t} dt {frame[0]:g}"
    col = rng.randrange(44)
    frame[col] = "__value__"
    raw = rng.choice(
        [
            "NaN",
            "Infinity",
            "-Infinity",
            "1e400",
            "1" + "0" * 400,
            "true",
            '"a"',
            "null",
            "[1]",
            "-1e308",
            "0",
        ]
    )
    return json.dumps(doc).replace(
        '"__value__"', raw
    ).encode(), f"frame {t} col {col} -> {raw[:12]}"


def _c3d(data: bytes, rng: random.Random) -> tuple[bytes, str]:
    params = 61 * 512  # the parameter section ends where the data start (block 62)
    op = rng.choice(["truncate", "param flip", "data flip", "sample", "rename", "rename", "events"])
    if op == "truncate":
        k = rng.randrange(len(data))
        return data[:k], f"truncated at byte {k}"
    if op in ("param flip", "data flip"):
        lo, hi = (0, params) if op == "param flip" else (params, len(data))
        k = rng.randrange(lo, hi)
        return data[:k] + bytes([data[k] ^ rng.randrange(1, 256)]) + data[k + 1 :], f"{op} at {k}"
    if op == "sample":
        k = params + 4 * rng.randrange((len(data) - params) // 4)
        value = rng.choice([np.nan, np.inf, -np.inf, 3e38, -3e38, 0.0])
        return data[:k] + np.float32(value).tobytes() + data[k + 4 :], f"float at {k} -> {value}"
    if op == "rename":
        key = rng.choice(
            [b"POINT", b"LABELS", b"UNITS", b"RATE", b"USED", b"EVENT", b"TIMES", b"FRAMES"]
        )
        k = data.find(key)
        return data[:k] + b"Q" + data[k + 1 :], f"{key.decode()} renamed"
    k = data.find(b"TIMES")  # the dimensions of EVENT:TIMES follow its name
    at = k + 5 + 2 + rng.randrange(3)
    return data[:at] + bytes([rng.randrange(256)]) + data[at + 1 :], "EVENT:TIMES dimensions"


def make_case(fmt: str, index: int, pool: dict[str, list[dict[str, bytes]]]) -> Case:
    """The ``index``-th mutated input of format ``fmt`` (reproducible)."""
    rng = random.Random(f"{fmt}:{index}")
    files = dict(rng.choice(pool[fmt]))
    main = next(iter(files))
    if fmt == "amc" and rng.random() < 0.5:
        files, what = _asf(files, rng)
        return Case(files, main, what)
    special = {"bvh": _bvh, "deepmimic": _deepmimic, "c3d": _c3d}.get(fmt)
    if special is not None and rng.random() < 0.5:
        data, what = special(files[main], rng)
    else:
        data, what = (_c3d if fmt == "c3d" else _generic)(files[main], rng)
    files[main] = data
    return Case(files, main, what)


def plausible(m) -> str:
    """``""`` if the Motion ``m`` is finite and within the bounds, else what is not."""
    if not (np.isfinite(m.fps) and FPS_RANGE[0] <= m.fps <= FPS_RANGE[1]):
        return f"fps {m.fps}"
    data = m.data
    if (m.format == "c3d" and np.any(np.isinf(data))) or (
        m.format != "c3d" and not np.all(np.isfinite(data))
    ):
        return "non-finite data"
    k = m.keypoints
    for name, v in k.items():
        if (
            v.shape != (m.n_frames, 3)
            or not np.all(np.isfinite(v))
            or np.abs(v).max() > MAX_COORD_M
        ):
            return f"keypoint {name}"
    legs = []
    for s in "lr":
        leg = np.linalg.norm(k[f"{s}_knee"] - k[f"{s}_hip"], axis=1)
        leg = np.median(leg + np.linalg.norm(k[f"{s}_ankle"] - k[f"{s}_knee"], axis=1))
        if not LEG_RANGE_M[0] <= leg <= LEG_RANGE_M[1]:
            return f"leg {leg:.3g} m"
        legs.append(leg)
    for name, v in k.items():
        if np.linalg.norm(v - k["pelvis"], axis=1).max() > MAX_REACH_LEGS * max(legs):
            return f"keypoint {name} far from the pelvis"
    return ""


def _alarm(signum, frame):
    raise Hang


def run_case(case: Case, folder: Path, limit_s: float = 10.0) -> tuple[str, str]:
    """Write ``case`` into ``folder``, read it within ``limit_s``; ``(outcome, detail)``."""
    for name, data in case.files.items():
        (folder / name).write_bytes(data)
    old = signal.signal(signal.SIGALRM, _alarm)
    signal.setitimer(signal.ITIMER_REAL, limit_s)
    try:
        with warnings.catch_warnings(), np.errstate(all="ignore"):
            warnings.simplefilter("ignore")
            m = load_motion(folder / case.main)
        why = plausible(m)
        return ("implausible", why) if why else ("accepted", "")
    except Hang:
        return "hang", f"> {limit_s:g} s"
    except ImitwalkError as exc:
        return "error", str(exc)
    except Exception as exc:  # what the suite looks for
        return "other", f"{type(exc).__name__}: {exc}"[:300]
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, old)


#: The repository's root (this file is ``tests/helpers/fuzz_mocap.py``).
ROOT = Path(__file__).resolve().parents[2]


def main(argv: list[str] | None = None) -> int:
    """The command line (see the module's docstring); prints the JSON report, returns 0."""
    ap = argparse.ArgumentParser(
        prog="python -m tests.helpers.fuzz_mocap",
        description="The mocap readers against seeded mutations of the real files: "
        "counts per format.",
    )
    ap.add_argument("--cases", type=int, default=2000, help="cases per format (2000)")
    ap.add_argument("--formats", nargs="+", default=list(FORMATS), choices=FORMATS)
    ap.add_argument("--limit", type=float, default=10.0, help="time limit per case [s] (10)")
    args = ap.parse_args(argv)
    shared = Path(os.environ.get("IMITWALK_SHARED_MOCAP", ROOT.parent / "shared" / "mocap"))
    pool = seeds(shared)
    out = {}
    for fmt in args.formats:
        counts = dict.fromkeys(("error", "other", "accepted", "implausible", "hang"), 0)
        failures = []
        t = time.perf_counter()
        with tempfile.TemporaryDirectory() as tmp:
            for i in range(args.cases):
                case = make_case(fmt, i, pool)
                outcome, detail = run_case(case, Path(tmp), args.limit)
                counts[outcome] += 1
                if outcome not in ("error", "accepted") and len(failures) < 5:
                    failures.append(f"case {i} ({case.mutation}): {outcome}: {detail}")
        out[fmt] = {
            "cases": args.cases,
            "project_errors": counts["error"],
            "other_exceptions": counts["other"],
            "accepted": counts["accepted"],
            "accepted_implausible": counts["implausible"],
            "hangs": counts["hang"],
            "wall_seconds": round(time.perf_counter() - t, 1),
            "failures": failures,
        }
    print(json.dumps(out, indent=2))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
