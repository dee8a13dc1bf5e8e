"""What the CLI prints: progress lines on stderr, results on stdout (``emit``)."""

from __future__ import annotations

import json
import sys
from typing import Any

import numpy as np

__all__ = ["emit", "progress"]


def progress(message: str) -> None:
    """One line of progress on stderr (stdout stays clean for ``--json``)."""
    print(message, file=sys.stderr, flush=True)


def emit(obj: dict, as_json: bool, finite: bool = False) -> None:
    """Print ``obj`` as JSON, or as aligned ``key: value`` lines; ``finite``: a NaN or an
    infinity (a servo without a torque limit) is printed as ``null``, so the JSON is valid."""
    if finite:
        obj = _finite(obj)
    if as_json:
        print(json.dumps(obj, indent=2, default=_plain, allow_nan=not finite))
        return
    for key, val in obj.items():
        if isinstance(val, dict | list):
            text = json.dumps(val, default=_plain)
            val = text if len(text) <= 90 else text[:87] + "..."
        elif isinstance(val, float):
            val = f"{val:.4g}"
        print(f"{key:>28}: {val}")


def _finite(v: Any) -> Any:
    """``v`` with every non-finite float (also in dicts and lists) replaced by ``None``."""
    if isinstance(v, dict):
        return {k: _finite(x) for k, x in v.items()}
    if isinstance(v, list | tuple):
        return [_finite(x) for x in v]
    if isinstance(v, float | np.floating) and not np.isfinite(v):
        return None
    return v


def _plain(v: Any) -> Any:
    if hasattr(v, "item"):
        return v.item()
    if hasattr(v, "tolist"):
        return v.tolist()
    return str(v)
