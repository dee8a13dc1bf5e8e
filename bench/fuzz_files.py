"""What imitwalk reads back and writes, against seeded mutations: counts per input.

Runs the cases of ``tests/test_fuzz_files.py`` (``tests/file_fuzz.py``) and prints JSON:
per input (``reference``: a reference ``.npz``; ``run``: a run folder's JSON files;
``out``: output paths) the cases, project errors, accepted results, accepted but
unusable ones, other exceptions, hangs, the wall time and the first few failures. The
reference the mutations start from is retargeted first (the default clip, no search).

Usage: ``python bench/fuzz_files.py [--cases 2000] [--inputs reference run out]``
"""

from __future__ import annotations

import argparse
import contextlib
import io
import json
import sys
import tempfile
import time
from pathlib import Path

from imitwalk.cli.main import main as cli

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))

from file_fuzz import INPUTS, fuzz  # noqa: E402


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cases", type=int, default=2000, help="cases per input (2000)")
    ap.add_argument("--inputs", nargs="+", default=list(INPUTS), choices=INPUTS)
    args = ap.parse_args()
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


if __name__ == "__main__":
    main()
