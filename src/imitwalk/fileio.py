"""Writing files (pure Python; NumPy only for ``.npz``): atomically, so that a reader
never sees a half-written file, durably (on disk before it is named, so that a machine
that loses power keeps the old file or the new one, never an empty one), and to paths
checked before any work starts."""

from __future__ import annotations

import os
import tempfile
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any

from imitwalk.errors import ConfigError, ImitwalkError

__all__ = [
    "atomic_write",
    "check_writable",
    "sync_file",
    "sync_folder",
    "writable_folder",
    "write_npz",
]


def sync_file(path: str | Path) -> None:
    """Flush ``path``'s data to the disk (``fsync``)."""
    fd = os.open(path, os.O_RDONLY)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)


def sync_folder(folder: str | Path) -> None:
    """Flush ``folder``'s entries to the disk, so that a rename into it lasts (POSIX; a
    no-op where a folder cannot be opened, as on Windows)."""
    try:
        fd = os.open(folder, os.O_RDONLY)
    except OSError:
        return
    try:
        os.fsync(fd)
    except OSError:
        pass  # some file systems refuse fsync on a folder: the rename is all they keep
    finally:
        os.close(fd)


def atomic_write(path: str | Path, write: Callable[[Path], object]) -> Path:
    """Write a file atomically and durably: ``write(tmp_path)``, flushed to the disk,
    renamed over ``path``, and the rename flushed (:func:`sync_file`,
    :func:`sync_folder`)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    os.close(fd)
    try:
        write(Path(tmp))
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)  # mkstemp makes 0600; give the file normal permissions
        sync_file(tmp)
        os.replace(tmp, path)
        sync_folder(path.parent)
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
