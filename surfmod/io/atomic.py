"""Atomic file writes: write a temporary file beside the target, fsync, then rename.

A failure at any point removes the temporary file and leaves an existing target as it
was, so no reader ever sees a half-written file.
"""

from __future__ import annotations

import contextlib
import os
import tempfile
from pathlib import Path

from ..errors import SurfmodError


def target_path(path, name: str = "path", suffixes: tuple[str, ...] = ()) -> Path:
    """Validate an output path: parent folder exists, suffix as expected."""
    try:
        p = Path(os.fspath(path))
    except TypeError:
        raise SurfmodError(f"{name}: expected a file path, got {type(path).__name__}") from None
    if p.is_dir():
        raise SurfmodError(f"{name}: {p} is a directory")
    if not p.parent.exists():
        raise SurfmodError(f"{name}: folder {p.parent} does not exist")
    if suffixes and p.suffix.lower() not in suffixes:
        raise SurfmodError(f"{name}: expected a file ending in {' or '.join(suffixes)}, got {p.name}")
    return p


def _final_mode(path: Path) -> int:
    """Mode the written file should end with.

    mkstemp creates 0600 files; an export must look like any other file the user writes
    (an overwritten file keeps its mode, a new one gets 0666 minus the umask).
    """
    with contextlib.suppress(FileNotFoundError):
        return path.stat().st_mode & 0o7777
    umask = os.umask(0)  # the only portable way to read the umask is to set it
    os.umask(umask)
    return 0o666 & ~umask


@contextlib.contextmanager
def atomic_path(path: Path):
    """Yield a temporary path in the target's folder; on success it replaces ``path``."""
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    os.close(fd)
    try:
        yield Path(tmp)
        with open(tmp, "rb+") as fh:
            os.fsync(fh.fileno())
        os.chmod(tmp, _final_mode(path))
        os.replace(tmp, path)
    except BaseException:
        with contextlib.suppress(FileNotFoundError):
            os.remove(tmp)
        raise
