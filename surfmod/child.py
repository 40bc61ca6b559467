"""Run one call of a foreign mesher in a child process, with a deadline.

gmsh, given a face whose wire a damaged file left open, can loop for ever inside one C
call, which no Python timeout interrupts.  :func:`call` runs such a call in a fresh
``python -m surfmod.child`` process (no fork of the caller's threads or OCCT state, and,
unlike multiprocessing's spawn, no re-import of the caller's ``__main__``: a user script
with no ``if __name__ == "__main__"`` guard works); the caller gets its value, or the
exception it raised, or :class:`ChildFailure` when it did not answer by the deadline (the
child is then killed) or died (a crash inside the library).
"""

from __future__ import annotations

import os
import pickle
import select
import struct
import subprocess
import sys
import threading
import time
from pathlib import Path


class ChildFailure(Exception):
    """The child did not finish by its deadline, held too much memory, or died; ``str``
    says which, and ``cause`` is ``"deadline"``, ``"memory"``, ``"died"`` (then
    ``returncode`` is the child's exit code, negative for a signal) or ``"start"`` (a
    :class:`Server`'s warm-up failed, however)."""

    def __init__(self, message: str, cause: str = "died", returncode: int | None = None):
        super().__init__(message)
        self.cause, self.returncode = cause, returncode


#: seconds between two looks at the child's memory when it has a memory budget
MEMORY_POLL = 0.25
#: seconds between two looks of a child (or a worker) at its parent
PARENT_POLL = 0.5
#: seconds a :class:`Server`'s warm-up call may take (its child's start and imports)
WARMUP_SECONDS = 120.0
_watching: list = []


def die_with(parent_pid: int) -> None:
    """End this process as soon as ``parent_pid`` is no longer its parent (the parent
    died, killed or not, and the process was handed to another): a daemon thread looks
    every ``PARENT_POLL`` s.  The process may be deep inside an OCCT or gmsh call, which
    no Python signal handler interrupts, hence ``os._exit``.  Once per process."""
    if os.getppid() != parent_pid:  # orphaned already
        os._exit(1)
    if _watching:
        return

    def watch():
        while os.getppid() == parent_pid:
            time.sleep(PARENT_POLL)
        os._exit(1)

    _watching.append(threading.Thread(target=watch, daemon=True, name="surfmod-die-with-parent"))
    _watching[0].start()


def resident_bytes(pid: int) -> float:
    """Resident memory of process ``pid`` in bytes (Linux ``/proc``); NaN where it cannot
    be read (another system, or the process is gone)."""
    try:
        with open(f"/proc/{pid}/statm") as f:
            return float(f.read().split()[1]) * os.sysconf("SC_PAGE_SIZE")
    except (OSError, ValueError, IndexError):
        return float("nan")


def call(fn, args: tuple, seconds: float, what: str):
    """``fn(*args)`` in a fresh child process (a :class:`Server` for one call); ``fn`` and
    ``args`` must pickle (a module-level function, paths and arrays).  Raises
    :class:`ChildFailure` naming ``what`` when the child is still running after
    ``seconds`` or dies.

    >>> call(divmod, (7, 2), 60.0, "divmod")
    (3, 1)
    """
    server = Server()
    try:
        return server.call(fn, args, seconds, what)
    finally:
        server.close()


def _over_budget(pid: int, deadline: float, seconds: float, what: str, memory: float | None):
    """The :class:`ChildFailure` of a child past its deadline or its memory, else None."""
    if time.monotonic() >= deadline:
        return ChildFailure(f"{what} did not finish within {seconds:g} s", "deadline")
    if memory and resident_bytes(pid) > memory:
        return ChildFailure(f"{what} held more than {memory / 2**30:.3g} GiB", "memory")
    return None


class Server:
    """One child process that runs calls one after another, so that many short calls pay
    the child's start (imports, compiled kernels loaded) once, not once each; a call
    over its budget kills the child, and the next call starts a fresh one.  A child left
    holding more than half the memory budget after a call is retired too, so what one
    file's shapes leave behind never reaches the next file's budget.  Not shared between
    threads (give each thread its own, or a lock).

    ``warmup`` (``(fn, args)``, optional) is the first call of every fresh child, sent
    as it starts: it runs while the caller goes on (:meth:`start` early, e.g. to import
    a library in the child while the caller imports its own), and its time is charged to
    :data:`WARMUP_SECONDS`, not to the next call's deadline.

    >>> server = Server()
    >>> server.call(divmod, (7, 2), 60.0, "divmod"), server.call(divmod, (9, 4), 60.0, "divmod")
    ((3, 1), (2, 1))
    >>> server.close()
    """

    def __init__(self, warmup: tuple | None = None):
        self.proc = None
        self.warmup = warmup
        self._warming = False

    def start(self) -> None:
        """Start the child (and its warm-up) now if none runs; calls wait for it."""
        if self.proc is None or self.proc.poll() is not None:
            self.proc = subprocess.Popen([sys.executable, "-m", "surfmod.child"], stdin=subprocess.PIPE,
                                         stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, env=_child_env())
            self.proc.stdin.write(_framed(pickle.dumps(list(sys.path))))
            self._warming = self.warmup is not None
            if self._warming:
                self.proc.stdin.write(_framed(pickle.dumps(self.warmup)))
            self.proc.stdin.flush()

    def close(self) -> None:
        """End the child (it is killed: it may be inside a call that never returns)."""
        if self.proc is not None:
            self.proc.kill()
            self.proc.wait()
            self.proc = None

    def call(self, fn, args: tuple, seconds: float, what: str, memory: float | None = None):
        """``fn(*args)`` in the child; ``fn`` and ``args`` must pickle.  Raises
        :class:`ChildFailure` naming ``what`` when the child is still running after
        ``seconds``, holds more than ``memory`` bytes resident (looked at every
        ``MEMORY_POLL`` s, on Linux), or dies."""
        self.start()
        if self._warming:
            self._warming = False
            try:
                self._answer(WARMUP_SECONDS, f"{what}: the child's start", None)
            except ChildFailure as exc:
                raise ChildFailure(str(exc), "start", exc.returncode) from None
        try:
            self.proc.stdin.write(_framed(pickle.dumps((fn, args))))
            self.proc.stdin.flush()
        except BrokenPipeError:
            self.close()
            raise ChildFailure(f"{what}: the child died before the call") from None
        return self._answer(seconds, what, memory)

    def _answer(self, seconds: float, what: str, memory: float | None):
        """The value of the call the child is working on (see :meth:`call`)."""
        fd, deadline = self.proc.stdout.fileno(), time.monotonic() + seconds
        while not select.select([fd], [], [], max(min(deadline - time.monotonic(), MEMORY_POLL), 0.0))[0]:
            failure = _over_budget(self.proc.pid, deadline, seconds, what, memory)
            if failure is not None:
                self.close()
                raise failure
        blob = _read_framed(fd)
        if blob is None:
            code = self.proc.wait()
            self.proc = None
            raise ChildFailure(f"{what} died (exit code {code})", "died", code)
        held = resident_bytes(self.proc.pid) if memory else 0.0
        if held > memory / 2 if memory else False:
            self.close()
        if held > memory if memory else False:  # between two looks, or at the end: over all the same
            raise ChildFailure(f"{what} held more than {memory / 2**30:.3g} GiB", "memory")
        kind, value = pickle.loads(blob)
        if kind == "raised":
            raise value
        return value


def _child_env() -> dict:
    """The environment of a child: the caller's, with the folder holding this surfmod
    first on ``PYTHONPATH``, so ``-m surfmod.child`` finds the package the caller runs
    (a checkout on ``sys.path`` only, not installed, included)."""
    env = dict(os.environ)
    root = str(Path(__file__).resolve().parents[1])
    env["PYTHONPATH"] = root + (os.pathsep + env["PYTHONPATH"] if env.get("PYTHONPATH") else "")
    return env


def _framed(blob: bytes) -> bytes:
    return struct.pack("<Q", len(blob)) + blob


def _read_exact(fd, n: int) -> bytes | None:
    parts, left = [], n
    while left:
        part = os.read(fd, min(left, 1 << 20)) if isinstance(fd, int) else fd.read(left)
        if not part:
            return None
        parts.append(part)
        left -= len(part)
    return b"".join(parts)


def _read_framed(fd) -> bytes | None:
    """One length-prefixed message from a descriptor or a binary stream; None at its end."""
    header = _read_exact(fd, 8)
    return None if header is None else _read_exact(fd, struct.unpack("<Q", header)[0])


def _answer(fn, args) -> bytes:
    try:
        value = ("ok", fn(*args))
    except BaseException as exc:  # noqa: BLE001 - sent to the parent, which re-raises it
        value = ("raised", exc)
    try:
        return pickle.dumps(value)
    except (pickle.PicklingError, TypeError, AttributeError) as exc:
        return pickle.dumps(("raised", RuntimeError(f"{type(value[1]).__name__}: {value[1]} ({exc})")))


def _main() -> None:
    die_with(os.getppid())  # a caller killed (or a Dask worker) takes its child with it
    # the reply goes to a private copy of stdout: a library may write to descriptor 1
    reply = os.fdopen(os.dup(1), "wb")
    os.dup2(os.open(os.devnull, os.O_WRONLY), 1)
    stream = sys.stdin.buffer
    sys.path[:] = pickle.loads(_read_framed(stream))
    while (request := _read_framed(stream)) is not None:  # framed calls until the parent closes the pipe
        reply.write(_framed(_answer(*pickle.loads(request))))
        reply.flush()


if __name__ == "__main__":
    _main()
