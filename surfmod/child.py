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


class ChildFailure(Exception):
    """The child did not finish by its deadline, or died; ``str`` says which."""


def call(fn, args: tuple, seconds: float, what: str):
    """``fn(*args)`` in a child process; ``fn`` and ``args`` must pickle (a module-level
    function, paths and arrays).  Raises :class:`ChildFailure` naming ``what`` when the
    child is still running after ``seconds`` or dies.

    >>> call(divmod, (7, 2), 60.0, "divmod")
    (3, 1)
    """
    # the import path first, on its own: the child needs it before it can unpickle ``fn``
    request = pickle.dumps(list(sys.path)) + pickle.dumps((fn, args))
    proc = subprocess.Popen([sys.executable, "-m", "surfmod.child"], stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                            stderr=subprocess.DEVNULL)
    try:
        out, _ = proc.communicate(request, timeout=seconds)
    except subprocess.TimeoutExpired:
        proc.kill()
        proc.communicate()
        raise ChildFailure(f"{what} did not finish within {seconds:.0f} s") from None
    if proc.returncode != 0 or not out:
        raise ChildFailure(f"{what} died (exit code {proc.returncode})")
    kind, value = pickle.loads(out)
    if kind == "raised":
        raise value
    return value


def _main() -> None:
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
