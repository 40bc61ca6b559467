"""Read STEP files (``STEPControl``) in a child process, so a damaged file cannot take the
caller down.

OCCT's STEP reader dereferences whatever the file says: a deleted line, a flipped byte or
a NaN coordinate can make it crash with SIGSEGV or loop forever, and neither can be caught
inside the process.  So the reading happens in one long-lived :class:`surfmod.child.Server`
(started on first use, reused afterwards, so the normal case pays the interpreter start
once; its start, OCCT's import included, overlaps the caller's own and is not charged to a
file's time limit):

* the child reads the file, checks that every coordinate of the shape is finite and of
  sane size, and returns the shape as OCCT binary BRep bytes (``BinTools``), or raises
  the reason it refused;
* if the child dies (a crash in OCCT) or does not answer within the time limit (it is
  then killed), :func:`read_step_file` raises :class:`~surfmod.errors.DamagedFileError`
  naming the file, and the next read starts a fresh child.

The child is the plain ``python -m surfmod.child`` process of :mod:`surfmod.child`, so it
works from threads, from joblib/loky workers and from daemon processes alike, and it dies
with its parent.
"""

from __future__ import annotations

import atexit
import os
import signal
import threading
import warnings

from .. import checks
from ..child import ChildFailure, Server
from ..errors import DamagedFileError, InsideOutWarning, SurfmodError


def _load_occt() -> int:
    """The reader child's warm-up: OCCT's STEP reader imported before the first file."""
    from . import step  # noqa: F401

    return os.getpid()


def _read_and_check(path: str, max_coordinate: float) -> tuple[bytes, list]:
    """Read ``path`` with OCCT, check its coordinates, return the shape as BinTools bytes
    and what the model says of its solids' orientation: those inside out in the file,
    read outward (:func:`~surfmod.occ.step.outward_solids`), and those whose faces
    disagree (:func:`~surfmod.occ.solids.faces_at_odds`)."""
    from .finite import check_numbers
    from .solids import faces_at_odds
    from .step import brep_bytes, read_step

    turned: list = []  # the solids inside out in the file, turned outward
    shape = read_step(path, turned)
    at_odds = faces_at_odds(shape)  # solids whose faces disagree: said, left to mesh and mass
    check_numbers(shape, path, max_coordinate)
    return brep_bytes(shape), (turned, at_odds)


class _Reader:
    """The reader child of this process, one read at a time (a lock: threads share it);
    a forked process starts its own rather than share its parent's."""

    def __init__(self) -> None:
        self.server = Server(warmup=(_load_occt, ()))
        self.owner = os.getpid()
        self.lock = threading.Lock()

    def _own(self) -> None:
        if self.owner != os.getpid():  # forked: the parent's child is not this process's to use or kill
            self.server.proc, self.owner = None, os.getpid()

    def start(self) -> None:
        with self.lock:
            self._own()
            self.server.start()

    def read(self, path: str, timeout: float, max_coordinate: float) -> tuple[bytes, list]:
        with self.lock:
            self._own()
            try:
                return self.server.call(_read_and_check, (path, max_coordinate), timeout, f"reading {path}")
            except ChildFailure as exc:
                if exc.cause == "start":
                    raise DamagedFileError("STEP reader: the reader process did not start") from None
                if exc.cause == "deadline":
                    raise DamagedFileError(
                        f"path: reading {path} did not finish within {timeout:g} s; the reader was stopped "
                        "(a damaged file can make OCCT loop; raise timeout= for a huge file)") from None
                code = exc.returncode
                how = f"signal {signal.Signals(-code).name}" if code and code < 0 else f"exit code {code}"
                raise DamagedFileError(f"path: OCCT crashed reading {path} ({how}); the file is damaged") from None
            except SurfmodError as exc:
                msg = str(exc)  # every refusal names the file (a kernel failure names its operation)
                raise DamagedFileError(msg if path in msg else f"path: {path}: {msg}") from None
            except Exception as exc:  # noqa: BLE001 - any reader fault is the file's, named
                raise DamagedFileError(f"path: reading {path} failed ({type(exc).__name__}: {exc})") from None

    def close(self) -> None:
        with self.lock:
            if self.owner == os.getpid():
                self.server.close()


_READER = _Reader()
atexit.register(_READER.close)


#: default time limit of one read: a base plus an allowance per megabyte of file
TIMEOUT_BASE = 30.0
TIMEOUT_PER_MB = 10.0
#: default largest coordinate magnitude accepted from a file (model units)
MAX_COORDINATE = 1e9


def read_step_file(path, name: str = "path", *, timeout: float | None = None, max_coordinate: float = MAX_COORDINATE):
    """The TopoDS shape in the STEP file ``path``, read in the worker process.

    ``timeout`` defaults to ``TIMEOUT_BASE + TIMEOUT_PER_MB`` per megabyte of file.
    Raises :class:`~surfmod.errors.SurfmodError` naming ``name`` for a path that is not a
    readable file, and :class:`~surfmod.errors.DamagedFileError` (a ``KernelError``) naming
    the file when its text holds NaN or infinity (:func:`surfmod.checks.step_file`), or OCCT
    refuses it, crashes on it, runs past ``timeout`` seconds, or yields NaN or coordinates
    beyond ``max_coordinate``.

    >>> import os, tempfile, surfmod as sm
    >>> path = os.path.join(tempfile.mkdtemp(), "p.step")
    >>> sm.export_step(sm.sphere(1.0), path)
    >>> read_step_file(path).ShapeType().name
    'TopAbs_SHELL'
    """
    if timeout is not None:
        timeout = checks.positive(timeout, "timeout")
    max_coordinate = checks.positive(max_coordinate, "max_coordinate")
    p = checks.step_file(path, name)
    if timeout is None:
        timeout = TIMEOUT_BASE + TIMEOUT_PER_MB * p.stat().st_size / 1e6
    _READER.start()  # the child imports OCCT while this process does the same
    from .step import brep_from_bytes

    try:
        data, (turned, at_odds) = _READER.read(str(p), timeout, max_coordinate)
    except DamagedFileError as exc:
        msg = str(exc)
        raise DamagedFileError(msg if msg.startswith(f"{name}:") else f"{name}: {msg.removeprefix('path: ')}") from None
    shape = brep_from_bytes(data)
    for number, volume in turned:
        warnings.warn(f"{p.name}: solid {number} is inside out in the file (enclosed volume {volume:.6g}): "
                      "read outward", InsideOutWarning, stacklevel=3)
    for number, edges, faces in at_odds:
        warnings.warn(f"{p.name}: solid {number} is inconsistently oriented: {edges} edge(s) run the same way in "
                      f"both their faces (faces {', '.join(map(str, faces[:10]))}{' ...' if len(faces) > 10 else ''})",
                      InsideOutWarning, stacklevel=3)
    return shape


def stop_worker() -> None:
    """Stop the reader process (it restarts on the next read); also done at exit.

    >>> stop_worker()
    """
    _READER.close()
