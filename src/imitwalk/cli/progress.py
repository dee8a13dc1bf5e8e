"""One line of progress on stderr, shared by the CLI's commands and the demo."""

from __future__ import annotations

import sys

__all__ = ["progress"]


def progress(message: str) -> None:
    """One line of progress on stderr (stdout stays clean for ``--json``)."""
    print(message, file=sys.stderr, flush=True)
