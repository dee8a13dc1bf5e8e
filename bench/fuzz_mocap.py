"""The mocap readers against seeded mutations of the real files: counts per format.

Runs the cases of ``tests/test_fuzz_mocap.py`` (``tests/mocap_fuzz.py``) and prints JSON:
per input format the cases, project errors, other exceptions, accepted results (finite,
within the bounds of ``imitwalk.mocap.bounds``), accepted but implausible or non-finite
ones, hangs (over the time limit), the wall time, and the first few failures.
Needs the shared fixtures (``$IMITWALK_SHARED_MOCAP``, else ``../shared/mocap``).

Usage: ``python bench/fuzz_mocap.py [--cases 2000] [--formats bvh amc c3d deepmimic]``
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))

from mocap_fuzz import FORMATS, make_case, run_case, seeds  # noqa: E402


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cases", type=int, default=2000, help="cases per format (2000)")
    ap.add_argument("--formats", nargs="+", default=list(FORMATS), choices=FORMATS)
    ap.add_argument("--limit", type=float, default=10.0, help="time limit per case [s] (10)")
    args = ap.parse_args()
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


if __name__ == "__main__":
    main()
