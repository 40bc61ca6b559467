"""Post-processors (:func:`programs`): a :class:`~surfmod.cam.job.Job` as G-code for
``"linuxcnc"`` (one RS274NGC program with tool changes) or ``"grbl"`` (one program per tool).

Heights are rounded up to the written digits: the tool never sits lower than the verified
path.  See :doc:`/guide/cam` (section "A job from stock").
"""

from __future__ import annotations

import textwrap

import numpy as np

from ..atomic import atomic_path, target_path
from ..errors import SurfmodError
from .arcs import TOLERANCE as ARC_TOLERANCE, find_arcs
from .roughing import FEED, RAPID

POSTS = ("linuxcnc", "grbl")
SUFFIXES = (".nc", ".gcode", ".ngc", ".tap", ".cnc")


def round_up(values: np.ndarray, digits: int) -> np.ndarray:
    """Heights rounded up to the written digits: rounding must never lower the tool."""
    scale = 10.0**digits
    return np.ceil(np.round(values * scale, 6)) / scale


#: the move lines of the last few operations written: a job's program is made for its
#: verification, again for the file and once more with the verdict in its header; the
#: moves (most of the time: the arcs) are the same each time
_WRITTEN: dict = {}
WRITTEN_KEPT = 8


def _moves(op, digits: int, arcs: bool = True) -> list[str]:
    """G0/G1 (and G2/G3) lines of an operation's motion, feeds modal (written when they
    change).  Circular runs (:func:`surfmod.cam.arcs.find_arcs`, found on the heights as
    written) become one arc word each, its centre ``I J`` from the written start.

    An operation that ``extends`` one written before (a finishing with a repair's cross
    passes appended) keeps that one's lines and writes only the rest, when the written
    motion ends with a move and the rest's second move is one that are no longer across
    than the arcs' ``tolerance`` (a retract, a descent): no arc holds such a move, and
    every arc has four or more, so no arc of the whole crosses the join and the greedy
    search finds the same arcs on each side (:func:`_joins`)."""
    entry = _WRITTEN.get((id(op), digits, arcs))
    if entry is not None and entry[0] is op:  # the entry holds its operation: no other can take its id
        return list(entry[1])
    head = _WRITTEN.get((id(op.extends), digits, arcs))
    if head is not None and not (head[0] is op.extends and _joins(head[0], op)):
        head = None
    if len(_WRITTEN) >= WRITTEN_KEPT:
        _WRITTEN.clear()
    pts, kind = np.array(op.motion.points, float), op.motion.kind
    if head is None:
        lines, state = _move_lines(pts, kind, op.tool, digits, arcs, ((None, None, None), None))
    else:
        m = len(head[0].motion.points)
        lines, state = _move_lines(pts[m:], kind[m:], op.tool, digits, arcs, head[2])
        lines = head[1] + lines
    _WRITTEN[id(op), digits, arcs] = (op, lines, state)
    return list(lines)


def _joins(head, op) -> bool:
    """Does ``op``'s motion extend ``head``'s (same tool) at a join no arc can cross: the
    last move of ``head`` and the second move after it no longer across than the arcs'
    tolerance?"""
    a, b = head.motion, op.motion
    m = len(a.points)
    if head.tool != op.tool or len(b.points) < m + 2 or m < 2:
        return False
    across = np.hypot(*(b.points[[m - 1, m + 1], :2] - b.points[[m - 2, m], :2]).T)
    return bool(np.all(across <= ARC_TOLERANCE) and np.array_equal(b.points[:m], a.points)
                and np.array_equal(b.kind[:m], a.kind))


def _move_lines(pts: np.ndarray, kind: np.ndarray, tool, digits: int, arcs: bool, state: tuple):
    """The lines of the moves to ``pts`` and the writer's state after them (the last
    position written and the feed in force), from ``state``."""
    # arcs are found on the path itself: an arc between ends rounded up lies above it
    found = find_arcs(pts, kind) if arcs else []
    pts[:, 2] = round_up(pts[:, 2], digits)
    fmt = f"%.{digits}f"
    # rounded first and + 0.0: no "-0.0000" words
    cols = [np.char.mod(fmt, np.round(pts[:, k], digits) + 0.0) for k in range(3)]
    arc_at = {a.start: a for a in found if kind[a.start + 1] != RAPID}
    lines = []
    last, feed_now = state

    def feed_word(k):
        nonlocal feed_now
        f = tool.feed if kind[k] == FEED else tool.plunge_feed
        if f == feed_now:
            return ""
        feed_now = f
        return f" F{f:g}"

    i, n = 0, len(pts)
    while i < n:
        xyz = (cols[0][i], cols[1][i], cols[2][i])
        if xyz != last:
            words = " ".join(f"{a}{v}" for a, v, w in zip("XYZ", xyz, last) if v != w)
            lines.append(f"G0 {words}" if kind[i] == RAPID else f"G1 {words}{feed_word(i)}")
            last = xyz
        arc = arc_at.get(i)
        if arc is None:
            i += 1
            continue
        j = arc.end
        end = (cols[0][j], cols[1][j], cols[2][j])
        words = f"X{end[0]} Y{end[1]}" + (f" Z{end[2]}" if end[2] != last[2] else "")
        ij = [fmt % (round(arc.centre[k] - float(last[k]), digits) + 0.0) for k in range(2)]
        lines.append(f"{'G3' if arc.ccw else 'G2'} {words} I{ij[0]} J{ij[1]}{feed_word(j)}")
        last, i = end, j  # a next arc may start where this one ends
    return lines, (last, feed_now)


def _operation(op, job, post: str, digits: int, coolant: bool, arcs: bool) -> list[str]:
    t = op.tool
    safe = f"{round_up(np.array([job.safe_height]), digits)[0]:.{digits}f}"
    out = [_comment(f"operation: {op.name}, tool {t.number}: {t}, flute length {t.flute_length:g} mm"),
           f"(estimated time {op.time_estimate:.0f} s, cutting length {op.length:.0f} mm)"]
    if post == "linuxcnc":
        out += [f"T{t.number} M6", f"G43 H{t.number}"]
    out += [f"G0 Z{safe}", f"S{t.spindle:.0f} M3"]
    if coolant:
        out.append("M8")
    out += _moves(op, digits, arcs)
    out += [f"G0 Z{safe}"] + (["M9"] if coolant else []) + ["M5"]
    return out


#: The longest line LinuxCNC's interpreter reads (rs274ngc's LINELEN): a longer one is
#: refused with "Command too long" and the program does not run.
LINE_LENGTH = 255


def _comment(text: str) -> str:
    """A comment: RS274NGC comments do not nest, so parentheses inside become brackets."""
    return "(" + text.replace("(", "[").replace(")", "]") + ")"


def _header(job, title: str, note: str | None) -> list[str]:
    lo, hi = job.stock
    # the note's findings one comment line each, wrapped: LinuxCNC refuses a longer line
    notes = [_comment(line) for part in (note or "").split("; ") for line in textwrap.wrap(part, LINE_LENGTH - 2)]
    return ["%", _comment(title)] + notes + [
            f"(stock X{lo[0]:g}..{hi[0]:g} Y{lo[1]:g}..{hi[1]:g} Z{lo[2]:g}..{hi[2]:g} mm, part coordinates)",
            "G21 G90 G17 G94 (mm, absolute, XY plane, feed per minute)", "G40 G49 G80 (no compensation, no offset)"]


def programs(job, post: str = "linuxcnc", *, digits: int = 4, coolant: bool = False, arcs: bool = True,
             note: str | None = None) -> list[str]:
    """The program texts of ``job``: one for ``"linuxcnc"``, one per tool for ``"grbl"``;
    circular runs of the moves as ``G2``/``G3`` unless ``arcs=False`` (all ``G1``);
    ``note``: comment lines under the title (what the verification found, a line per finding)."""
    if post not in POSTS:
        raise SurfmodError(f"post: expected one of {', '.join(POSTS)}, got {post!r}")
    if int(digits) != digits or not 1 <= digits <= 6:
        raise SurfmodError(f"digits: expected an integer 1..6, got {digits!r}")
    if post == "linuxcnc":
        body = _header(job, f"surfmod job: {len(job.operations)} operations, LinuxCNC", note)
        for op in job.operations:
            body += _operation(op, job, post, digits, coolant, bool(arcs))
        return ["\n".join(body + ["M30", "%", ""])]
    texts = []
    for number in dict.fromkeys(op.tool.number for op in job.operations):
        ops = [op for op in job.operations if op.tool.number == number]
        body = _header(job, f"surfmod job, GRBL program for tool {number}: {ops[0].tool}; change the tool, "
                            f"set its length, then run", note)
        for op in ops:
            body += _operation(op, job, post, digits, coolant, bool(arcs))
        texts.append("\n".join(body + ["M30", "%", ""]))
    return texts


def program_paths(path, job, post: str) -> list:
    """Where :func:`export_job` writes: ``path`` (LinuxCNC), ``STEM_T<n>SUFFIX`` per tool (GRBL)."""
    target = target_path(path, "path", SUFFIXES)
    if post != "grbl":
        return [target]
    numbers = dict.fromkeys(op.tool.number for op in job.operations)
    return [target.with_name(f"{target.stem}_T{n}{target.suffix}") for n in numbers]


def export_job(job, path, post: str = "linuxcnc", **kw) -> list:
    """Write the program(s) of ``job`` atomically; returns the paths written.  All texts
    are made before the first file is written, so bad input writes nothing."""
    texts = programs(job, post, **kw)
    paths = program_paths(path, job, post)
    for p, text in zip(paths, texts):
        with atomic_path(p) as tmp:
            tmp.write_text(text, encoding="ascii")
    return paths
