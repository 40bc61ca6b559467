"""Run one call of a foreign mesher in a child process, with a deadline.

gmsh, given a face whose wire a damaged file left open, can loop for ever inside one C
call, which no Python timeout interrupts.  :func:`call` runs such a call in a fresh
``spawn`` child (no fork of the caller's threads or OCCT state); the caller gets its value,
or the exception it raised, or :class:`ChildFailure` when it did not answer by the deadline
(the child is then killed) or died (a crash inside the library).
"""

from __future__ import annotations

import multiprocessing
import pickle


class ChildFailure(Exception):
    """The child did not finish by its deadline, or died; ``str`` says which."""


def _entry(conn, fn, args):
    try:
        value = ("ok", fn(*args))
    except BaseException as exc:  # noqa: BLE001 - sent to the parent, which re-raises it
        value = ("raised", exc)
    try:
        conn.send(value)
    except (pickle.PicklingError, TypeError, AttributeError) as exc:
        conn.send(("raised", RuntimeError(f"{type(value[1]).__name__}: {value[1]} ({exc})")))
    conn.close()


def call(fn, args: tuple, seconds: float, what: str):
    """``fn(*args)`` in a child process; ``fn`` and ``args`` must pickle (a module-level
    function, paths and arrays).  Raises :class:`ChildFailure` naming ``what`` when the
    child is still running after ``seconds`` or dies.

    >>> call(divmod, (7, 2), 60.0, "divmod")
    (3, 1)
    """
    ctx = multiprocessing.get_context("spawn")
    receive, send = ctx.Pipe(duplex=False)
    process = ctx.Process(target=_entry, args=(send, fn, args), daemon=True)
    process.start()
    send.close()
    try:
        if not receive.poll(seconds):
            raise ChildFailure(f"{what} did not finish within {seconds:.0f} s")
        try:
            kind, value = receive.recv()
        except EOFError:
            process.join(5.0)
            raise ChildFailure(f"{what} died (exit code {process.exitcode})") from None
    finally:
        receive.close()
        if process.is_alive():
            process.kill()
        process.join(5.0)
    if kind == "raised":
        raise value
    return value
