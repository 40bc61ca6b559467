"""Read STEP files (``STEPControl``) in a child process, so a damaged file cannot take the
caller down.

OCCT's STEP reader dereferences whatever the file says: a deleted line, a flipped byte or
a NaN coordinate can make it crash with SIGSEGV or loop forever, and neither can be caught
inside the process.  So the reading happens in one long-lived worker process (started on
first use, reused afterwards, so the normal case pays the interpreter start once):

* the parent sends the path; the worker reads the file, checks that every coordinate of
  the shape is finite and of sane size, and sends the shape back as OCCT binary BRep bytes
  (``BinTools``), or the reason it refused;
* if the worker dies (a crash in OCCT) or does not answer within the time limit (it is
  then killed), the parent raises :class:`~surfmod.errors.DamagedFileError` naming the
  file, and starts a fresh worker on the next call.

The worker is a plain ``python -m surfmod.occ.isolated`` subprocess talking over its
stdin and a private copy of its stdout (OCCT's own messages go to /dev/null), so it works
from threads, from joblib/loky workers and from daemon processes alike.
"""

from __future__ import annotations

import atexit
import os
import pickle
import select
import signal
import struct
import subprocess
import sys
import threading
import time
import warnings
from pathlib import Path

from .. import checks
from ..errors import DamagedFileError, InsideOutWarning, SurfmodError

_HEADER = struct.Struct("!Q")


def _send(fh, obj) -> None:
    data = pickle.dumps(obj, protocol=pickle.HIGHEST_PROTOCOL)
    fh.write(_HEADER.pack(len(data)) + data)
    fh.flush()


def _recv_exact(fd: int, size: int, deadline: float | None) -> bytes:
    """``size`` bytes from ``fd``; ``EOFError`` when the writer died, ``TimeoutError`` past ``deadline``."""
    chunks, left = [], size
    while left:
        if deadline is not None:
            wait = deadline - time.monotonic()
            if wait <= 0 or not select.select([fd], [], [], wait)[0]:
                raise TimeoutError
        chunk = os.read(fd, min(left, 1 << 20))
        if not chunk:
            raise EOFError
        chunks.append(chunk)
        left -= len(chunk)
    return b"".join(chunks)


def _recv(fd: int, deadline: float | None):
    (size,) = _HEADER.unpack(_recv_exact(fd, _HEADER.size, deadline))
    return pickle.loads(_recv_exact(fd, size, deadline))


# -- the worker side ------------------------------------------------------------------------
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


def _worker_main() -> None:
    """Serve read requests from stdin until it closes."""
    reply = os.fdopen(os.dup(1), "wb")
    devnull = os.open(os.devnull, os.O_WRONLY)
    os.dup2(devnull, 1)  # OCCT prints banners to stdout: keep them off the protocol
    requests = sys.stdin.buffer.fileno()
    from . import step  # noqa: F401  (load OCCT before the first request)

    _send(reply, ("ready", os.getpid()))
    while True:
        try:
            path, max_coordinate = _recv(requests, None)
        except EOFError:
            return
        try:
            _send(reply, ("ok", *_read_and_check(path, max_coordinate)))
        except SurfmodError as exc:
            msg = str(exc)  # every refusal names the file (a kernel failure names its operation)
            _send(reply, ("error", type(exc).__name__, msg if path in msg else f"path: {path}: {msg}"))
        except Exception as exc:  # noqa: BLE001 - a reader fault must reach the parent as text, not kill the loop
            _send(reply, ("error", "KernelError", f"path: reading {path} failed ({type(exc).__name__}: {exc})"))


# -- the parent side ------------------------------------------------------------------------
class _Worker:
    """One reusable reader process; ``read`` is serialized by a lock."""

    def __init__(self) -> None:
        self._proc: subprocess.Popen | None = None
        self._ready = False
        self._owner = -1
        self._lock = threading.Lock()

    def _spawn(self) -> None:
        """Start a worker without waiting for it (it imports OCCT meanwhile)."""
        root = str(Path(__file__).resolve().parents[2])  # the folder holding the surfmod package
        env = dict(os.environ)
        env["PYTHONPATH"] = root + (os.pathsep + env["PYTHONPATH"] if env.get("PYTHONPATH") else "")
        self._proc = subprocess.Popen(
            [sys.executable, "-m", "surfmod.occ.isolated"],
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            stderr=subprocess.DEVNULL,
            env=env,
            close_fds=True,
        )
        self._ready = False

    def prestart(self) -> None:
        """Spawn the worker now if none runs, so its start overlaps the caller's own
        imports; ``read`` waits for it."""
        with self._lock:
            if self._owner != os.getpid():  # a forked child must not share the parent's worker
                self._proc, self._owner = None, os.getpid()
            if self._proc is None or self._proc.poll() is not None:
                self._spawn()

    def _wait_ready(self) -> None:
        proc = self._proc
        try:
            kind = _recv(proc.stdout.fileno(), time.monotonic() + 120.0)[0]
        except (EOFError, TimeoutError):
            kind = None
        if kind != "ready":
            self._proc = None
            self._kill(proc)
            raise DamagedFileError("STEP reader: the reader process did not start")
        self._ready = True

    @staticmethod
    def _kill(proc: subprocess.Popen) -> None:
        if proc.poll() is None:
            proc.kill()
        proc.wait()
        for fh in (proc.stdin, proc.stdout):
            try:
                fh.close()
            except OSError:
                pass

    def close(self) -> None:
        proc, self._proc = self._proc, None
        if proc is not None and self._owner == os.getpid():
            try:
                proc.stdin.close()  # the worker exits on EOF
                proc.wait(timeout=2)
            except (OSError, subprocess.TimeoutExpired):
                pass
            self._kill(proc)

    def read(self, path: str, timeout: float, max_coordinate: float) -> tuple[bytes, list]:
        with self._lock:
            if self._owner != os.getpid():  # a forked child must not share the parent's worker
                self._proc, self._owner = None, os.getpid()
            if self._proc is None or self._proc.poll() is not None:
                self._spawn()
            if not self._ready:  # the start is not charged to the file's time limit
                self._wait_ready()
            deadline = time.monotonic() + timeout
            proc = self._proc
            try:
                _send(proc.stdin, (path, max_coordinate))
                answer = _recv(proc.stdout.fileno(), deadline)
            except TimeoutError:
                self._proc = None
                self._kill(proc)
                raise DamagedFileError(
                    f"path: reading {path} did not finish within {timeout:g} s; the reader was stopped "
                    "(a damaged file can make OCCT loop; raise timeout= for a huge file)"
                ) from None
            except (EOFError, BrokenPipeError, OSError):
                self._proc = None
                self._kill(proc)
                code = proc.returncode
                how = f"signal {signal.Signals(-code).name}" if code and code < 0 else f"exit code {code}"
                raise DamagedFileError(
                    f"path: OCCT crashed reading {path} ({how}); the file is damaged"
                ) from None
        if answer[0] == "ok":
            return answer[1], answer[2]
        raise DamagedFileError(answer[2])  # answer = ("error", exception type, message)


_WORKER = _Worker()
atexit.register(_WORKER.close)


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
    the file when OCCT refuses it, crashes on it, runs past ``timeout`` seconds, or yields
    NaN or coordinates beyond ``max_coordinate``.

    >>> import os, tempfile, surfmod as sm
    >>> path = os.path.join(tempfile.mkdtemp(), "p.step")
    >>> sm.export_step(sm.sphere(1.0), path)
    >>> read_step_file(path).ShapeType().name
    'TopAbs_SHELL'
    """
    p = checks.file_path(path, name)
    if timeout is not None:
        timeout = checks.positive(timeout, "timeout")
    max_coordinate = checks.positive(max_coordinate, "max_coordinate")
    if not p.is_file():
        raise SurfmodError(f"{name}: no such file {p}")
    try:
        with open(p, "rb") as fh:
            head = fh.read(256)
    except OSError as exc:
        raise SurfmodError(f"{name}: cannot read {p} ({exc.strerror})") from None
    if b"ISO-10303-21" not in head:
        raise SurfmodError(f"{name}: {p} is not a STEP file (not a readable STEP header: ISO-10303-21 missing)")
    if timeout is None:
        timeout = TIMEOUT_BASE + TIMEOUT_PER_MB * p.stat().st_size / 1e6
    _WORKER.prestart()  # the worker imports OCCT while this process does the same
    from .step import brep_from_bytes

    try:
        data, (turned, at_odds) = _WORKER.read(str(p), timeout, max_coordinate)
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
    _WORKER.close()


if __name__ == "__main__":
    _worker_main()
