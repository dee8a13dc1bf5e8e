"""Seeded mutations of the files imitwalk reads back and of the paths it writes (issue 60).

Three inputs, each a case ``(input, index)`` drawn from ``random.Random(f"{input}:{index}")``:

* ``reference``: a real reference ``.npz`` (:meth:`Reference.load`) with its bytes
  truncated or flipped, an array dropped or replaced by one of another shape or type, or
  a metadata field deleted or set to a value of another type;
* ``run``: a run folder's ``metrics.json``, ``config.json`` or ``log.jsonl``
  (:class:`~imitwalk.runs.RunDir`) truncated, flipped, or with a field changed;
* ``out``: an output path (:func:`imitwalk.fileio.check_writable` and
  :meth:`RunDir.check_writable`): a folder, a missing parent, a file as the parent, a
  read-only file system, or a good path.

:func:`run_case` gives ``"error"`` (an :class:`~imitwalk.errors.ImitwalkError` in one
line), ``"accepted"`` (a reference that plays: its trajectory, summary and command are
valid; a run file read as a record; a path that is then written), ``"wrong"`` (accepted
but not usable, or an output refused after leaving something behind), ``"other"`` (any
other exception: a traceback on the CLI) or ``"hang"`` (past the time limit).

Used by ``tests/test_fuzz_files.py`` and ``tests/test_cli_hostile_files.py``. As a command
line, from the repository root, it runs the same cases and prints JSON: per input the
cases, the counts of each outcome, the first few failures and the wall time. The
reference the mutations start from is retargeted first (the default clip, no search)::

    python -m tests.helpers.fuzz_files [--cases 2000] [--inputs reference run out]
"""

from __future__ import annotations

import argparse
import contextlib
import io
import json
import random
import shutil
import signal
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from imitwalk.errors import ImitwalkError

INPUTS = ("reference", "run", "out")
OUTCOMES = ("error", "accepted", "wrong", "other", "hang")
#: JSON values of every type, and numbers no field should hold.
VALUES = [None, True, 0, -1, 1e308, float("nan"), "", "x", [], {}, [1, 2], {"a": 1}, [[[[]]]]]
#: Arrays a reference field should not hold.
ARRAYS = [
    np.zeros(0),
    np.zeros((2, 2)),
    np.zeros((1, 3, 4)),
    np.array(np.nan),
    np.full((1, 5), np.inf),
    np.array(["a", "b"]),
    np.array([1, 0, 2]),
    np.zeros((1, 40, 25), dtype=np.float16),
]
#: A finished run's metrics.json.
SUMMARY = {
    "learner": "step",
    "scale_reached": 1.0,
    "scales_passed": [1.0],
    "iterations": 1,
    "sim_seconds_used_for_learning": 1.0,
    "wall_seconds_for_learning": 1.0,
    "config": {},
}


class Hang(BaseException):
    """A case ran past the time limit."""


@dataclass(frozen=True)
class Case:
    """One mutated input: ``kind`` (of :data:`INPUTS`), the file name and its bytes (for
    ``out``: the path kind), and what was done."""

    kind: str
    name: str
    data: bytes
    mutation: str


def _bytes_mutation(rng: random.Random, data: bytes) -> tuple[bytes, str]:
    op = rng.choice(["truncate", "flip", "empty", "junk"])
    if op == "truncate":
        k = rng.randrange(len(data))
        return data[:k], f"truncated at byte {k}"
    if op == "flip":
        k = rng.randrange(len(data))
        return data[:k] + bytes([data[k] ^ rng.randrange(1, 256)]) + data[k + 1 :], f"flip {k}"
    if op == "empty":
        return b"", "empty"
    return b"HIERARCHY\nROOT Hips\n" + data[:100], "another format"


def _npz(arrays: dict[str, np.ndarray]) -> bytes:
    buf = io.BytesIO()
    np.savez(buf, **arrays)
    return buf.getvalue()


def _reference_mutation(rng: random.Random, seed: bytes) -> tuple[bytes, str]:
    if rng.random() < 0.3:
        return _bytes_mutation(rng, seed)
    with np.load(io.BytesIO(seed)) as z:
        arrays = {k: z[k] for k in z.files}
    meta = json.loads(str(arrays["meta_json"]))
    roll = rng.random()
    if roll < 0.25:
        key = rng.choice(sorted(arrays))
        del arrays[key]
        return _npz(arrays), f"array {key} dropped"
    if roll < 0.5:
        key = rng.choice(sorted(k for k in arrays if k != "meta_json"))
        value = rng.choice(ARRAYS)
        arrays[key] = value
        return _npz(arrays), f"array {key} -> {value.dtype}{value.shape}"
    key = rng.choice(sorted(meta))
    if roll < 0.6:
        del meta[key]
        how = f"meta {key} deleted"
    elif roll < 0.7 and isinstance(meta[key], dict) and meta[key]:
        sub = rng.choice(sorted(meta[key]))
        meta[key][sub] = rng.choice(VALUES)
        how = f"meta {key}.{sub} = {str(meta[key][sub])[:20]}"
    else:
        meta[key] = rng.choice(VALUES)
        how = f"meta {key} = {str(meta[key])[:20]}"
    arrays["meta_json"] = np.array(json.dumps(meta))
    return _npz(arrays), how


def _run_mutation(rng: random.Random) -> tuple[str, bytes, str]:
    name = rng.choice(["metrics.json", "config.json", "log.jsonl"])
    doc: object = {
        "metrics.json": SUMMARY,
        "config.json": {"learner": "step", "learn": {"seed": 0}},
        "log.jsonl": {"iteration": 0, "cost": 1.0},
    }[name]
    text = json.dumps(doc).encode()
    if rng.random() < 0.4:
        data, how = _bytes_mutation(rng, text)
        return name, data, how
    assert isinstance(doc, dict)
    d = dict(doc)
    key = rng.choice(sorted(d))
    if rng.random() < 0.3:
        del d[key]
        how = f"{key} deleted"
    else:
        d[key] = rng.choice(VALUES)
        how = f"{key} = {str(d[key])[:20]}"
    text = json.dumps([d] if rng.random() < 0.15 else d)
    if name == "log.jsonl" and rng.random() < 0.3:
        text, how = text + "\n[1]", how + ", a line not an object"
    return name, text.encode(), how


def make_case(kind: str, index: int, seed: bytes) -> Case:
    """The ``index``-th case of ``kind`` (``seed``: a real reference's bytes)."""
    rng = random.Random(f"{kind}:{index}")
    if kind == "reference":
        data, how = _reference_mutation(rng, seed)
        return Case(kind, "ref.npz", data, how)
    if kind == "run":
        name, data, how = _run_mutation(rng)
        return Case(kind, name, data, how)
    what = rng.choice(["folder", "missing parent", "file parent", "read-only", "good", "deep"])
    return Case(kind, rng.choice(["file", "run folder"]), b"", what)


def _check_reference(path: Path) -> str:
    from imitwalk.retarget import Reference

    ref = Reference.load(path)
    scale = float(ref.scales[0])
    q = ref.trajectory(scale, 1.0)
    if q.shape[1] != len(ref.joint_names) or not np.isfinite(q).all():
        return "wrong"
    json.dumps(ref.summary(), allow_nan=True, default=str)
    ref.command.describe()
    ref.sim_options()
    ref.expected_distance(scale, 1.0)
    return "accepted"


def _check_run(folder: Path, name: str) -> str:
    from imitwalk.runs import RunDir

    rd = RunDir(folder)
    if name == "metrics.json":
        rd.read_summary()
    elif name == "config.json":
        rd.read_json(name, ("learn",))
    else:
        rd.read_log()
    return "accepted"


def _check_out(folder: Path, target: str, what: str) -> str:
    from imitwalk.fileio import atomic_write, check_writable
    from imitwalk.runs import RunDir

    (folder / "afile").write_text("x")
    (folder / "adir").mkdir()
    path = {
        "folder": folder / "adir",
        "missing parent": folder / "nope" / "out",
        "file parent": folder / "afile" / "out",
        "read-only": Path("/proc/imitwalk-out"),
        "good": folder / "out",
        "deep": folder / "nope" / "deeper" / "out",
    }[what]
    before = sorted(p.name for p in folder.rglob("*"))
    try:
        if target == "file":
            check_writable(path)
        else:
            RunDir(path).check_writable()
    except ImitwalkError:
        after = sorted(p.name for p in folder.rglob("*"))
        if after != before:
            return "wrong"
        raise
    if target == "file":
        atomic_write(path, lambda tmp: tmp.write_text("x"))
    else:
        path.mkdir(exist_ok=True)
        (path / "config.json").write_text("{}")
    return "accepted"


def run_case(case: Case, folder: Path, seconds: float = 10.0) -> tuple[str, str]:
    """``(outcome, detail)`` of one case, run in ``folder`` (emptied first)."""
    shutil.rmtree(folder, ignore_errors=True)
    folder.mkdir(parents=True)

    def alarm(signum, frame):
        raise Hang

    old = signal.signal(signal.SIGALRM, alarm)
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        if case.kind == "reference":
            (folder / case.name).write_bytes(case.data)
            return _check_reference(folder / case.name), ""
        if case.kind == "run":
            (folder / case.name).write_bytes(case.data)
            return _check_run(folder, case.name), ""
        return _check_out(folder, case.name, case.mutation), ""
    except Hang:
        return "hang", f"> {seconds:g} s"
    except ImitwalkError as exc:
        msg = str(exc)
        return ("error", msg) if "\n" not in msg else ("other", "two lines: " + msg)
    except Exception as exc:  # what the fuzz is for
        return "other", f"{type(exc).__name__}: {exc}"[:300]
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, old)


def fuzz(kind: str, cases: range, seed: bytes, folder: Path) -> dict:
    """Counts of each outcome over ``cases`` of ``kind``, and the failing cases (20)."""
    counts = dict.fromkeys(OUTCOMES, 0)
    failures = []
    for i in cases:
        case = make_case(kind, i, seed)
        outcome, detail = run_case(case, folder)
        counts[outcome] += 1
        if outcome not in ("error", "accepted") and len(failures) < 20:
            failures.append(f"case {i} ({case.name}: {case.mutation}): {outcome}: {detail}")
    return {"counts": counts, "failures": failures}


def main(argv: list[str] | None = None) -> int:
    """The command line (see the module's docstring); prints the JSON report, returns 0."""
    from imitwalk.cli.main import main as cli

    ap = argparse.ArgumentParser(
        prog="python -m tests.helpers.fuzz_files",
        description="What imitwalk reads back and writes, against seeded mutations: "
        "counts per input.",
    )
    ap.add_argument("--cases", type=int, default=2000, help="cases per input (2000)")
    ap.add_argument("--inputs", nargs="+", default=list(INPUTS), choices=INPUTS)
    args = ap.parse_args(argv)
    out = {}
    with tempfile.TemporaryDirectory() as tmp:
        ref = Path(tmp) / "ref.npz"
        with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
            assert cli(["retarget", "--out", str(ref), "--no-search", "--set", "scales=[0.5]"]) == 0
        seed = ref.read_bytes()
        for kind in args.inputs:
            t = time.perf_counter()
            report = fuzz(kind, range(args.cases), seed, Path(tmp) / "case")
            report["failures"] = report["failures"][:5]
            out[kind] = {
                "cases": args.cases,
                **report,
                "wall_seconds": round(time.perf_counter() - t, 1),
            }
    print(json.dumps(out, indent=2))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
