"""G-code (RS-274, ISO 6983) export of tool paths, atomic."""

from __future__ import annotations

import numpy as np

from .. import checks
from ..errors import SurfmodError
from ..atomic import atomic_path, target_path
from .post import SUFFIXES, export_job, round_up


def _is_toolpath(obj) -> bool:
    """Duck typing (no import of ``toolpath``, which imports this writer): a tool path has
    ``(N, 3)`` points and a tool with a cutter and a radius."""
    points = getattr(obj, "points", None)
    tool = getattr(obj, "tool", None)
    return (isinstance(points, np.ndarray) and points.ndim == 2 and points.shape[1] == 3 and len(points) > 0
            and hasattr(tool, "cutter") and hasattr(tool, "radius") and hasattr(obj, "stepover"))


def gcode_text(toolpath, *, feed: float = 600.0, plunge_feed: float | None = None,
               safe_height: float | None = None, spindle: float | None = None, digits: int = 4) -> str:
    """G-code for a :class:`~surfmod.Toolpath` (millimetres, absolute).  Heights are
    rounded up to ``digits`` decimals, so the written path never sits lower than the
    verified one; x and y are rounded to nearest.

    >>> import surfmod as sm
    >>> tp = sm.toolpath(sm.plane((0, 0, 0), (2, 0, 0), (0, 2, 0)), sm.Tool("flat", 1.0), stepover=1.5)
    >>> [ln for ln in gcode_text(tp).splitlines() if ln.startswith("G1 ")][:2]
    ['G1 Z0.0000 F200', 'G1 X0.2500 Y0.0000 Z0.0000 F600']
    """
    if not _is_toolpath(toolpath):
        raise SurfmodError(f"toolpath: expected a surfmod Toolpath, got {type(toolpath).__name__}")
    feed = checks.positive(feed, "feed")
    plunge = feed / 3 if plunge_feed is None else checks.positive(plunge_feed, "plunge_feed")
    if int(digits) != digits or not 0 <= digits <= 8:
        raise SurfmodError(f"digits: expected an integer 0..8, got {digits!r}")
    digits = int(digits)
    points = np.array(toolpath.points, dtype=float)
    points[:, 2] = round_up(points[:, 2], digits)
    top = float(points[:, 2].max())
    if safe_height is None:
        safe = top + max(5.0, toolpath.tool.radius)
    else:
        safe = float(checks.finite_array(safe_height, "safe_height"))
        if safe <= top:
            raise SurfmodError(f"safe_height: {safe:g} must be above the highest path point {top:.6g}")
    number = f"{{:.{digits}f}}"
    tool = toolpath.tool
    lines = [
        "%",
        f"(surfmod drop-cutter zig-zag: {tool.cutter.comment})",
        f"(stepover {toolpath.stepover:.6g} mm, scallop {toolpath.scallop:.4g} mm, {len(points)} points)",
    ]
    tolerance = getattr(toolpath, "tolerance", None)
    if tolerance is not None:
        lines.append(f"(every move checked: no cut deeper than {tolerance:.4g} mm)")
    lines += ["G21 (millimetres)", "G90 (absolute)", "G17 (XY plane)"]
    if spindle is not None:
        lines.append(f"S{checks.positive(spindle, 'spindle'):.0f} M3")
    x0, y0, z0 = points[0]
    lines += [
        f"G0 Z{number.format(safe)}",
        f"G0 X{number.format(x0)} Y{number.format(y0)}",
        f"G1 Z{number.format(z0)} F{plunge:g}",
    ]
    columns = [np.char.mod(f"%.{digits}f", points[1:, k]) for k in range(3)]
    body = list(np.char.add(np.char.add(np.char.add("G1 X", columns[0]), np.char.add(" Y", columns[1])),
                            np.char.add(" Z", columns[2])))
    if body:
        body[0] = f"{body[0]} F{feed:g}"
    lines += body
    lines += [f"G0 Z{number.format(safe)}"]
    if spindle is not None:
        lines.append("M5")
    lines += ["M2", "%", ""]
    return "\n".join(lines)


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
    target = target_path(path, "path", SUFFIXES)
    text = gcode_text(toolpath, feed=feed, safe_height=safe_height, **kw)
    with atomic_path(target) as tmp:
        tmp.write_text(text, encoding="ascii")
