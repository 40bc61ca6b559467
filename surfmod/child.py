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
import subprocess
import sys
import threading
import time


class ChildFailure(Exception):
    """The child did not finish by its deadline, or died; ``str`` says which."""


#: seconds between two looks at the child's memory when it has a memory budget
MEMORY_POLL = 0.25
#: seconds between two looks of a child (or a worker) at its parent
PARENT_POLL = 0.5
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


def call(fn, args: tuple, seconds: float, what: str, memory: float | None = None):
    """``fn(*args)`` in a child process; ``fn`` and ``args`` must pickle (a module-level
    function, paths and arrays).  Raises :class:`ChildFailure` naming ``what`` when the
    child is still running after ``seconds``, holds more than ``memory`` bytes resident
    (looked at every ``MEMORY_POLL`` s, on Linux), or dies.

    >>> call(divmod, (7, 2), 60.0, "divmod")
    (3, 1)
    """
    # the import path first, on its own: the child needs it before it can unpickle ``fn``
    request = pickle.dumps(list(sys.path)) + pickle.dumps((fn, args))
    proc = subprocess.Popen([sys.executable, "-m", "surfmod.child"], stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                            stderr=subprocess.DEVNULL)
    deadline = time.monotonic() + seconds
    while True:
        left = deadline - time.monotonic()
        try:
            # the request is sent once; a retry after a timeout goes on where it stopped
            out, _ = proc.communicate(request, timeout=max(min(left, MEMORY_POLL) if memory else left, 0.0))
            break
        except subprocess.TimeoutExpired:
            request = None
            if time.monotonic() >= deadline:
                failure = f"{what} did not finish within {seconds:.0f} s"
            elif memory and resident_bytes(proc.pid) > memory:
                failure = f"{what} held more than {memory / 2**30:.3g} GiB"
            else:
                continue
            proc.kill()
            proc.communicate()
            raise ChildFailure(failure) from None
    if proc.returncode != 0 or not out:
        raise ChildFailure(f"{what} died (exit code {proc.returncode})")
    kind, value = pickle.loads(out)
    if kind == "raised":
        raise value
    return value


def _main() -> None:
    die_with(os.getppid())  # a caller killed (or a Dask worker) takes its child with it
    # the reply goes to a private copy of stdout: a library may write to descriptor 1
    reply = os.fdopen(os.dup(1), "wb")
    os.dup2(os.open(os.devnull, os.O_WRONLY), 1)
    stream = sys.stdin.buffer
    sys.path[:] = pickle.load(stream)
    fn, args = pickle.load(stream)
    try:
        value = ("ok", fn(*args))
    except BaseException as exc:  # noqa: BLE001 - sent to the parent, which re-raises it
        value = ("raised", exc)
    try:
        blob = pickle.dumps(value)
    except (pickle.PicklingError, TypeError, AttributeError) as exc:
        blob = pickle.dumps(("raised", RuntimeError(f"{type(value[1]).__name__}: {value[1]} ({exc})")))
    reply.write(blob)
    reply.flush()


if __name__ == "__main__":
    _main()
