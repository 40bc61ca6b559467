"""G-code (RS-274, ISO 6983) export of tool paths, atomic."""

from __future__ import annotations

from ..errors import SurfmodError
from ..atomic import atomic_path, target_path
from .post import SUFFIXES, export_job
from .toolpath import Toolpath


def export_gcode(toolpath, path, *, feed: float = 600.0, safe_height: float | None = None, post: str | None = None,
                 **kw):
    """Write a tool path as G-code: G21/G90, ``G0`` rapid to ``safe_height``, ``G1``
    moves at ``feed`` (mm/min), retract and ``M2``.  Atomic.

    A machining :class:`~surfmod.Job` goes through a post-processor instead
    (:mod:`surfmod.cam.post`): ``post="linuxcnc"`` (default, one RS274NGC program with
    tool changes) or ``"grbl"`` (one program per tool); the paths written are returned.

    >>> import surfmod as sm, tempfile, os
    >>> tp = sm.toolpath(sm.plane((0, 0, 0), (4, 0, 0), (0, 4, 0)), sm.Tool("flat", 1.0), stepover=1.5)
    >>> p = os.path.join(tempfile.mkdtemp(), "p.nc")
    >>> sm.export_gcode(tp, p, feed=800, safe_height=10)
    >>> open(p).read().splitlines()[-3:]
    ['G0 Z10.0000', 'M2', '%']
    """
    if hasattr(toolpath, "operations"):
        return export_job(toolpath, path, post or "linuxcnc", **kw)
    if post is not None:
        raise SurfmodError("post: a post-processor applies to a machining Job (sm.machine), not to a Toolpath")
    if not isinstance(toolpath, Toolpath):
        raise SurfmodError(f"toolpath: expected a surfmod Toolpath, got {type(toolpath).__name__}")
    target = target_path(path, "path", SUFFIXES)
    text = toolpath.to_gcode(feed=feed, safe_height=safe_height, **kw)
    with atomic_path(target) as tmp:
        tmp.write_text(text, encoding="ascii")
