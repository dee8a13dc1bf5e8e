"""Shared pytest fixtures."""

from __future__ import annotations

import os
from pathlib import Path

import pytest


@pytest.fixture(scope="session")
def shared_mocap() -> Path:
    """Folder of the shared real mocap fixtures: ``$IMITWALK_SHARED_MOCAP``, else
    ``<repo root>/../shared/mocap``; skips the test if it is absent."""
    env = os.environ.get("IMITWALK_SHARED_MOCAP")
    path = Path(env) if env else Path(__file__).resolve().parents[1].parent / "shared" / "mocap"
    if not path.is_dir():
        pytest.skip(f"shared mocap folder not found: {path} (set IMITWALK_SHARED_MOCAP)")
    return path
