"""Writing files (pure Python; NumPy only for ``.npz``): atomically, so that a reader
never sees a half-written file, and to paths checked before any work starts."""

from __future__ import annotations

import os
import tempfile
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any

from imitwalk.errors import ConfigError, ImitwalkError

__all__ = ["atomic_write", "check_writable", "writable_folder", "write_npz"]


def atomic_write(path: str | Path, write: Callable[[Path], object]) -> Path:
    """Write a file atomically: ``write(tmp_path)`` then rename over ``path``."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    os.close(fd)
    try:
        write(Path(tmp))
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)  # mkstemp makes 0600; give the file normal permissions
        os.replace(tmp, path)
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)
    return path


def write_npz(path: str | Path, arrays: Mapping[str, Any], compressed: bool = True) -> Path:
    """Write ``arrays`` (name → array) as an ``.npz`` at ``path``, atomically
    (:func:`atomic_write`); ``compressed``: ``np.savez_compressed``, else ``np.savez``."""
    import numpy as np

    save = np.savez_compressed if compressed else np.savez

    def write(tmp: Path) -> None:
        with open(tmp, "wb") as fh:
            save(fh, **dict(arrays))

    return atomic_write(path, write)


def writable_folder(folder: Path) -> bool:
    """True if a file can be created in ``folder`` (tried: a probe file is made and
    removed, so that read-only file systems and permissions are both found out)."""
    try:
        fd, probe = tempfile.mkstemp(prefix=".imitwalk-probe.", dir=folder)
    except OSError:
        return False
    os.close(fd)
    os.unlink(probe)
    return True


def check_writable(
    path: str | Path, flag: str = "--out", error: type[ImitwalkError] = ConfigError
) -> Path:
    """Refuse, before any work starts, a file path that cannot be written: a folder, a
    path whose parent folder is missing or is a file, or a folder that cannot be
    written in. ``flag`` names the path's command-line flag in the message.

    Returns:
        ``path`` as a :class:`Path`.
    """
    path = Path(path)
    if path.is_dir():
        raise error(f"{flag} {path} is a folder; give the name of a file to write")
    parent = path.parent
    if not parent.exists():
        raise error(f"{flag} {path}: folder {parent} does not exist; create it first")
    if not parent.is_dir():
        raise error(f"{flag} {path}: {parent} is a file, not a folder")
    if not writable_folder(parent):
        raise error(f"{flag} {path}: cannot write in {parent}; choose another {flag}")
    return path
