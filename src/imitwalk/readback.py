"""Reading back the files imitwalk writes: ``.npz`` archives and JSON documents.

Whatever can be wrong with such a file (missing, a folder, empty, truncated, another
format, the wrong top-level type, keys missing or of the wrong type) becomes one line
that names the file and what is wrong, raised as the caller's
:class:`~imitwalk.errors.ImitwalkError` subclass (:class:`~imitwalk.errors.RunError` by
default). Pure Python and NumPy.

Each kind of file carries a ``format`` version (:data:`FORMAT_KEY`), written by the code
that writes it and checked by :func:`check_format` when it is read back: a file without
one was written before versions were, and is read as format 1; a file of a newer format
than this imitwalk reads is refused in one line naming the file and the formats it reads.
"""

from __future__ import annotations

import json
import zipfile
import zlib
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import Any

import numpy as np

from imitwalk.errors import ImitwalkError, RunError

__all__ = ["FORMAT_KEY", "check_fields", "check_format", "read_json", "read_npz"]

#: The key of a file's format version (an integer from 1).
FORMAT_KEY = "format"

#: JSON types by the name a message gives them.
_TYPE_NAMES = {
    dict: "an object",
    list: "a list",
    str: "a string",
    float: "a number",
    int: "an integer",
    bool: "true or false",
}


def _readable(path: str | Path, what: str, error: type[ImitwalkError]) -> Path:
    """``path`` as a :class:`Path` if it is a non-empty file."""
    path = Path(path)
    if path.is_dir():
        raise error(f"{path} is a folder, not {what}")
    if not path.is_file():
        raise error(f"{path} not found; expected {what}")
    if path.stat().st_size == 0:
        raise error(f"{path} is empty, not {what}")
    return path


def _start(path: Path, error: type[ImitwalkError], raw: bool = False) -> str:
    """The first two characters of ``path`` (``raw``), or its first few printable ones
    (to say what it seems to be)."""
    try:
        with open(path, "rb") as fh:
            head = fh.read(2 if raw else 24).decode("latin-1")
    except OSError as exc:
        raise error(f"{path} cannot be read: {exc.strerror}") from None
    if raw:
        return head
    text = "".join(c if c.isprintable() else " " for c in head).split()
    return " ".join(text)[:16]


def read_npz(
    path: str | Path,
    what: str = "an imitwalk .npz archive",
    error: type[ImitwalkError] = RunError,
    required: Iterable[str] = (),
) -> dict[str, np.ndarray]:
    """Every array of the ``.npz`` at ``path``, by name.

    Args:
        what: what the file should be, as a message names it (``"a reference .npz"``).
        error: the error class raised.
        required: array names the file must hold.

    Raises:
        error: the file is missing, a folder, empty, not an ``.npz`` (zip) archive,
            truncated or corrupt, holds pickled objects, or lacks a required array.
    """
    path = _readable(path, what, error)
    head = _start(path, error, raw=True)
    if head != "PK":  # a pickle (protocol 2 and up) begins with byte 0x80: said, not shown
        seems = "a Python pickle" if head[:1] == "\x80" else f"it begins {_start(path, error)!r}"
        raise error(f"{path} is not an .npz archive ({seems}); expected {what}")
    try:
        with np.load(path, allow_pickle=False) as z:
            arrays = {k: z[k] for k in z.files}
    except ValueError as exc:
        why = "it holds pickled objects" if "pickle" in str(exc) else "an array in it is corrupt"
        raise error(f"{path} is not {what}: {why}") from None
    except (OSError, EOFError, KeyError, RuntimeError, zipfile.BadZipFile, zlib.error) as exc:
        why = " ".join(str(exc).split())[:80]
        raise error(f"{path} is truncated or corrupt ({type(exc).__name__}: {why})") from None
    odd = [k for k, v in arrays.items() if not isinstance(v, np.ndarray)]
    if odd:
        raise error(f"{path}: {', '.join(odd)} is not a NumPy array; expected {what}")
    missing = [k for k in required if k not in arrays]
    if missing:
        raise error(f"{path} lacks {', '.join(missing)}: not {what}")
    return arrays


def read_json(
    path: str | Path,
    what: str = "an imitwalk JSON file",
    error: type[ImitwalkError] = RunError,
    required: Iterable[str] = (),
    kind: type = dict,
) -> Any:
    """The JSON document at ``path``; it must be of ``kind`` (an object unless told)
    and, for an object, hold the ``required`` keys.

    Raises:
        error: the file is missing, a folder, empty, not UTF-8, not valid JSON, of
            another top-level type, or lacks a required key.
    """
    path = _readable(path, what, error)
    try:
        doc = json.loads(path.read_text(encoding="utf-8"))
    except OSError as exc:
        raise error(f"{path} cannot be read: {exc.strerror}") from None
    except UnicodeDecodeError:
        raise error(f"{path} is not text (not UTF-8); expected {what}") from None
    except json.JSONDecodeError as exc:
        raise error(f"{path} is not valid JSON: {exc.msg} (line {exc.lineno})") from None
    except RecursionError:
        raise error(f"{path} is not valid JSON: nested too deeply") from None
    if not isinstance(doc, kind):
        found = _TYPE_NAMES.get(type(doc), type(doc).__name__)
        raise error(f"{path} holds {found}, not {_TYPE_NAMES.get(kind, kind.__name__)}: {what}")
    if isinstance(doc, dict):
        check_fields(doc, dict.fromkeys(required, object), str(path), error)
    return doc


def check_fields(
    d: Any,
    types: Mapping[str, type | tuple[type, ...]],
    where: str,
    error: type[ImitwalkError] = RunError,
    optional: Mapping[str, type | tuple[type, ...]] | None = None,
) -> dict:
    """``d`` if it is a dict holding every key of ``types``, each value of its type (a
    key of ``optional`` may be absent); ``where`` names the file in the message.

    Integers pass as floats, and booleans as neither.
    """
    if not isinstance(d, dict):
        found = _TYPE_NAMES.get(type(d), type(d).__name__)
        raise error(f"{where}: expected an object of {', '.join(types)}, found {found}")
    missing = [k for k in types if k not in d]
    if missing:
        raise error(f"{where} lacks {', '.join(missing)}")
    for key, want in {**types, **(optional or {})}.items():
        if key not in d or want is object:
            continue
        named = want if isinstance(want, tuple) else (want,)
        wants = (*named, int) if float in named else named
        v = d[key]
        if not isinstance(v, wants) or (isinstance(v, bool) and bool not in wants):
            names = " or ".join(_TYPE_NAMES.get(t, t.__name__) for t in named)
            found = _TYPE_NAMES.get(type(v), type(v).__name__)
            raise error(f"{where}: {key} is {found}, expected {names}")
    return d


def check_format(d: dict, newest: int, where: str, error: type[ImitwalkError] = RunError) -> int:
    """The format version of ``d`` (a file's JSON object or metadata, read from ``where``):
    its :data:`FORMAT_KEY`, or 1 if it has none (a file written before versions were).

    Raises:
        error: the version is not an integer from 1, or is newer than ``newest``, the
            newest this imitwalk reads (the message names the formats it reads).
    """
    v = d.get(FORMAT_KEY, 1)
    reads = "format 1" if newest == 1 else f"formats 1 to {newest}"
    if not isinstance(v, int) or isinstance(v, bool) or v < 1:
        raise error(f"{where}: {FORMAT_KEY} is {v!r}; this imitwalk reads {reads}")
    if v > newest:
        raise error(
            f"{where} is format {v}, written by a newer imitwalk; this one reads {reads}: "
            "upgrade imitwalk to read it"
        )
    return v
