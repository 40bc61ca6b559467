"""Atomic file writes: a temporary file beside the target, renamed over it; a failure
removes it and leaves an existing target as it was.  A writer killed outright leaves
``.<target name>.surfmod-tmp-<pid>-<random>``, which the next write to the target removes
once its process is gone.  No ``fsync`` before the rename: it cost more than meshing a
small part, and durability across a power loss is left to the file system, as OCCT's own
writers leave it.  See :doc:`/errors` (section "Atomic writes").
"""

from __future__ import annotations

import contextlib
import os
import secrets
from pathlib import Path

from . import checks
from .errors import SurfmodError

TMP_MARK = ".surfmod-tmp-"


def target_path(path, name: str = "path", suffixes: tuple[str, ...] = ()) -> Path:
    """Validate an output path: usable length, parent folder exists, suffix as expected.

    >>> target_path("a" * 300 + ".step")
    Traceback (most recent call last):
    ...
    surfmod.errors.SurfmodError: path: file name of 305 bytes is longer than the limit 255
    """
    p = checks.file_path(path, name)
    if p.is_dir():
        raise SurfmodError(f"{name}: {p} is a directory")
    if not p.parent.exists():
        raise SurfmodError(f"{name}: folder {p.parent} does not exist")
    if suffixes and p.suffix.lower() not in suffixes:
        raise SurfmodError(f"{name}: expected a file ending in {' or '.join(suffixes)}, got {p.name}")
    # the temporary name adds its mark, a pid and a random part to the target's name
    if len(os.fsencode(f".{p.name}{TMP_MARK}4294967295-0123456789abcdef")) > checks.MAX_PATH_COMPONENT:
        raise SurfmodError(f"{name}: file name {p.name[:40]}... is too long to write atomically")
    return p


def _final_mode(path: Path) -> int:
    """Mode the written file should end with.

    The temporary file is created 0600; an export must look like any other file the user
    writes (an overwritten file keeps its mode, a new one gets 0666 minus the umask).
    """
    with contextlib.suppress(FileNotFoundError):
        return path.stat().st_mode & 0o7777
    umask = os.umask(0)  # the only portable way to read the umask is to set it
    os.umask(umask)
    return 0o666 & ~umask


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # exists, owned by someone else
        return True
    return True


def remove_litter(path: Path) -> list[Path]:
    """Remove the temporary files that killed writers left beside ``path``; return them.

    Only files named ``.<name>.surfmod-tmp-<pid>-<hex>`` whose process ``pid`` no longer
    runs are removed, so a write in progress elsewhere is never disturbed.
    """
    prefix = f".{path.name}{TMP_MARK}"
    removed = []
    try:
        entries = list(os.scandir(path.parent))
    except OSError:
        return removed
    for entry in entries:
        if not entry.name.startswith(prefix):
            continue
        pid, _, rand = entry.name[len(prefix) :].partition("-")
        if not (pid.isdigit() and rand) or _alive(int(pid)):
            continue
        with contextlib.suppress(OSError):
            os.remove(entry.path)
            removed.append(Path(entry.path))
    return removed


@contextlib.contextmanager
def atomic_path(path: Path):
    """Yield a temporary path in the target's folder; on success it replaces ``path``.

    >>> import tempfile, pathlib
    >>> target = pathlib.Path(tempfile.mkdtemp()) / "out.txt"
    >>> with atomic_path(target) as tmp:
    ...     _ = tmp.write_text("done")
    >>> target.read_text(), sorted(p.name for p in target.parent.iterdir())
    ('done', ['out.txt'])
    """
    path = Path(path)
    remove_litter(path)
    tmp = path.parent / f".{path.name}{TMP_MARK}{os.getpid()}-{secrets.token_hex(8)}"
    fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600)
    os.close(fd)
    try:
        yield tmp
        os.chmod(tmp, _final_mode(path))
        os.replace(tmp, path)
    except BaseException:
        with contextlib.suppress(FileNotFoundError):
            os.remove(tmp)
        raise
