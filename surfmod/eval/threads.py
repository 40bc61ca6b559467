"""How many threads the compiled evaluation kernels may use: every thread numba may start
for work of at least :data:`PARALLEL_MIN_POINTS` points, capped by :func:`set_threads`
(``1``: always single-threaded) or for a ``with`` block by :func:`limit`.  Results are the
same bit for bit whatever the count.  See :doc:`/guide/surfaces` (section "Large evaluations
and threads").

>>> from surfmod.eval import threads
>>> previous = threads.set_threads(1)
>>> threads.threads_for(10**7)
1
>>> with threads.limit(None):
...     threads.threads_for(10**7) >= 1
True
>>> threads.set_threads(previous)
1
"""

from __future__ import annotations

import os
import sys
from contextlib import contextmanager

from ..errors import SurfmodError

#: fewest points (grid points or scattered pairs) worth starting the worker threads for
PARALLEL_MIN_POINTS = 1 << 16

_requested: int | None = None


def numba_threads() -> int:
    """Threads numba may start: ``NUMBA_NUM_THREADS`` (read by numba at import), which
    defaults to the number of cores.  Read from the environment while numba is not
    imported yet, so that asking does not import it."""
    numba = sys.modules.get("numba")
    if numba is not None:
        return int(numba.config.NUMBA_NUM_THREADS)
    try:
        return max(1, int(os.environ["NUMBA_NUM_THREADS"]))
    except (KeyError, ValueError):
        return os.cpu_count() or 1


def set_threads(count: int | None) -> int | None:
    """Cap the threads of the evaluation kernels at ``count`` (``None``: as many as
    numba may start); returns the previous setting.

    >>> from surfmod.eval import threads
    >>> old = threads.set_threads(2)
    >>> threads.set_threads(old)
    2
    """
    global _requested
    if count is not None and (isinstance(count, bool) or not isinstance(count, int) or count < 1):
        raise SurfmodError(f"count: expected a positive integer or None, got {count!r}")
    previous, _requested = _requested, count
    return previous


@contextmanager
def limit(count: int | None):
    """:func:`set_threads` for the duration of a ``with`` block.

    >>> import numpy as np, surfmod as sm
    >>> from surfmod.eval import threads
    >>> net = np.zeros((4, 4, 3)); net[..., 0], net[..., 1] = np.mgrid[0:4, 0:4]
    >>> with threads.limit(1):
    ...     sm.BSplineSurface(net, (3, 3)).grid([0.5], [0.25])
    array([[[1.5 , 0.75, 0.  ]]])
    """
    previous = set_threads(count)
    try:
        yield
    finally:
        set_threads(previous)


def threads_for(points: int) -> int:
    """Threads to use for ``points`` evaluations: 1 below :data:`PARALLEL_MIN_POINTS`,
    else the cap of :func:`set_threads` within what numba may start.

    >>> from surfmod.eval import threads
    >>> threads.threads_for(10)
    1
    """
    if points < PARALLEL_MIN_POINTS:
        return 1
    available = numba_threads()
    return max(1, min(available, _requested or available))


@contextmanager
def running_on(count: int):
    """Numba's thread count set to ``count`` for a ``with`` block (it is per calling
    thread), restored afterwards.  Only entered for ``count > 1``: asking numba starts
    its thread pool."""
    import numba

    previous = numba.get_num_threads()
    numba.set_num_threads(count)
    # hand out the iterations of a prange one at a time (numba's default splits them
    # evenly up front): on a shared machine a descheduled thread then delays only the
    # chunk it holds, the others take the rest
    chunk = numba.set_parallel_chunksize(1)
    try:
        yield
    finally:
        numba.set_parallel_chunksize(chunk)
        numba.set_num_threads(previous)
