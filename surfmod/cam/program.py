"""A program read back as a controller reads it: the straight pieces the tool moves along.

This reads the dialect the posts of :mod:`surfmod.cam.post` write (millimetres, absolute,
XY plane: ``G0``/``G1``/``G2``/``G3`` with ``X Y Z I J F``, ``T n M6``, ``G43 H n``,
``S… M3``/``M5``, ``M8``/``M9``, ``M30``) from the text itself, not from the job that made
it, so the verification (:mod:`surfmod.cam.verify`) judges what the machine will run:
rounded coordinates, arcs and all.  A word outside that dialect raises ``SurfmodError``
naming the line, since a move it cannot follow cannot be judged.

Arcs become chords whose sagitta is at most ``chord`` (they lie inside the arc by that).
The first moves of a program start where the controller stands; an axis not yet
written is taken from the move's end (the tool comes down or across from where it is).
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

import numpy as np

from ..errors import SurfmodError

#: the most chords one arc word becomes (the chord grows beyond it)
MAX_CHORDS = 4096
_NUMBER = r"[-+]?(?:\d+\.?\d*|\.\d+)"
#: a word, or the end of a line (the whole text is read at once)
_TOKEN = re.compile(rf"([A-Z_])({_NUMBER})|\n")
#: a line that is not words only
_BAD_LINE = re.compile(rf"^(?!(?:[A-Z]{_NUMBER})*$).+", re.M)
_COMMENT = re.compile(r"\([^)\n]*\)|;[^\n]*")
#: a line that is only ``%`` (white space aside), and white space at either end of a line
_EDGES = re.compile(r"^[^\S\n]*%[^\S\n]*$|^[^\S\n]+|[^\S\n]+$", re.M)
#: words the posts write that do not move the tool (modes already in force, coolant, end)
_QUIET_G = {17.0, 21.0, 40.0, 43.0, 49.0, 80.0, 90.0, 94.0}
_QUIET_M = {8.0, 9.0, 30.0, 2.0}


@dataclass(frozen=True)
class ProgramMoves:
    """The straight pieces of a program in order: ``start``/``end`` ``(M, 3)`` tool-tip
    points, ``rapid`` ``(M,)`` (G0), ``tool`` ``(M,)`` number of the tool in the spindle,
    ``spindle`` ``(M,)`` whether it turns, ``line`` ``(M,)`` the source line (from 1)."""

    start: np.ndarray
    end: np.ndarray
    rapid: np.ndarray
    tool: np.ndarray
    spindle: np.ndarray
    line: np.ndarray

    def __len__(self) -> int:
        return len(self.line)


def _arc(start, end, centre, ccw: bool, chord: float) -> np.ndarray:
    """Chord end points of an XY arc (Z linear in the angle), the last one ``end``."""
    r = math.hypot(start[0] - centre[0], start[1] - centre[1])
    a0 = math.atan2(start[1] - centre[1], start[0] - centre[0])
    a1 = math.atan2(end[1] - centre[1], end[0] - centre[0])
    sweep = (a1 - a0) % (2 * math.pi) if ccw else -((a0 - a1) % (2 * math.pi))
    if abs(sweep) < 1e-12 and math.hypot(end[0] - start[0], end[1] - start[1]) < 1e-9:
        sweep = 2 * math.pi if ccw else -2 * math.pi  # start = end: a full circle
    step = 2 * math.acos(max(1 - chord / r, -1.0)) if r > chord else math.pi
    n = min(MAX_CHORDS, max(1, math.ceil(abs(sweep) / max(step, 1e-12))))
    t = np.arange(1, n + 1) / n
    pts = np.column_stack([centre[0] + r * np.cos(a0 + sweep * t), centre[1] + r * np.sin(a0 + sweep * t),
                           start[2] + (end[2] - start[2]) * t])
    pts[-1] = end
    return pts


def _last(mask: np.ndarray, at: np.ndarray) -> np.ndarray:
    """Index of the last word of ``mask`` at or before each word index of ``at`` (-1: none)."""
    return np.concatenate([[-1], np.maximum.accumulate(np.where(mask, np.arange(len(mask)), -1))])[at + 1]


def read_program(text: str, *, tool: int = 0, chord: float = 1e-4) -> ProgramMoves:
    """The moves of one program ``text`` (see the module); ``tool``: the tool in the
    spindle before any ``M6`` (a GRBL program per tool), ``chord``: the arcs' sagitta.

    The words of the whole text are read at once and the modes carried from line to line
    as arrays (a program of 100,000 lines in a fraction of a second); the first line that
    breaks the dialect is the one named, as a controller reading line by line would stop.

    >>> moves = read_program("T1 M6\\nG0 Z5\\nS1000 M3\\nG0 X0 Y0\\nG1 Z0 F100\\nG1 X10\\nM5\\nM30")
    >>> moves.end.tolist()[-1], moves.rapid.tolist(), moves.tool.tolist()
    ([10.0, 0.0, 0.0], [True, False, False], [1, 1, 1])
    """
    raw = str(text).splitlines()
    # comments out, each line stripped, upper case, spaces out: what each line says
    body = _EDGES.sub("", _COMMENT.sub("", "\n".join(raw))).upper().replace(" ", "")
    errors = []  # (line, rank within the line, message): the first is raised
    bad = _BAD_LINE.search(body)
    if bad:
        number = body.count("\n", 0, bad.start()) + 1
        errors.append((number, 0, f"program: line {number}: cannot read {raw[number - 1].strip()!r}"))
    # the words, each with its line (from 0); a last word that says nothing stands for "none"
    letters, values = zip(*_TOKEN.findall(body + "\n_0"))
    letter = np.array(letters, dtype="U1")
    newline = letter == ""
    line = np.cumsum(newline)[~newline]
    letter, values = letter[~newline], [v for v in values if v]
    value = np.fromiter(map(float, values), float, len(values))
    g, m = letter == "G", letter == "M"
    moving = g & np.isin(value, (0.0, 1.0, 2.0, 3.0))
    outside = ((g & ~moving & ~np.isin(value, list(_QUIET_G))) | (m & ~np.isin(value, [3.0, 5.0, 6.0, *_QUIET_M]))
               | ~np.isin(letter, list("GMXYZIJTFSHN_")))
    if outside.any():
        w = int(np.argmax(outside))
        number = int(line[w]) + 1
        errors.append((number, 1, f"program: line {number}: {letter[w]}{values[w]} is outside the posts' dialect"))
    # the modes in force at the end of each line: set by its last word of them or by an earlier line
    n_lines = len(raw)
    end_word = np.searchsorted(line, np.arange(n_lines), side="right") - 1
    motion = np.where((w := _last(moving, end_word)) >= 0, value[w], -1).astype(np.int64)
    spindle = value[_last(m & np.isin(value, (3.0, 5.0)), end_word)] == 3.0
    selected = np.where((w := _last(letter == "T", end_word)) >= 0, value[w], tool).astype(np.int64)
    changed = line[_last(m & (value == 6.0), end_word)]
    current = np.where(changed < n_lines, selected[np.minimum(changed, n_lines - 1)], int(tool))
    # each line's coordinates (the last word of an axis wins)
    axes = np.full((n_lines + 1, 5), np.nan)
    for k, a in enumerate("XYZIJ"):
        w = np.flatnonzero(letter == a)
        last = np.ones(len(w), bool)
        last[:-1] = line[w][1:] != line[w][:-1]
        axes[line[w[last]], k] = value[w[last]]
    moved = np.flatnonzero(~np.isnan(axes[:n_lines, :3]).all(axis=1))
    if np.any(early := motion[moved] < 0):
        number = int(moved[np.argmax(early)]) + 1
        errors.append((number, 2, f"program: line {number}: coordinates before any G0/G1/G2/G3"))
    # the position after each such line: every axis as last written
    target = axes[moved, :3]
    held = np.maximum.accumulate(np.where(np.isnan(target), -1, np.arange(len(moved))[:, None]), axis=0)
    end = np.where(held >= 0, target[held, np.arange(3)], np.nan)
    pos = np.roll(end, 1, axis=0)
    pos[:1] = np.nan
    start = np.where(np.isnan(pos), end, pos)  # an axis not yet written: the tool stands there
    run = ~np.isnan(end).any(axis=1)
    moved, start, end = moved[run], start[run], end[run]
    arc = np.isin(motion[moved], (2, 3))
    if np.any(open_arc := arc & np.isnan(axes[moved, 3:]).any(axis=1)):
        number = int(moved[np.argmax(open_arc)]) + 1
        errors.append((number, 3, f"program: line {number}: an arc needs both I and J"))
    if errors:
        raise SurfmodError(min(errors)[2])
    chords = {k: _arc(start[k], end[k], (start[k, 0] + axes[moved[k], 3], start[k, 1] + axes[moved[k], 4]),
                      motion[moved[k]] == 3, chord) for k in np.flatnonzero(arc)}
    count = np.ones(len(moved), np.int64)
    count[list(chords)] = [len(c) for c in chords.values()]
    first = np.cumsum(count) - count
    ends = np.repeat(end, count, axis=0)
    for k, c in chords.items():
        ends[first[k]:first[k] + len(c)] = c
    starts = np.roll(ends, 1, axis=0)
    starts[first] = start  # each line's first piece starts where the tool stood
    where = np.repeat(moved, count)
    return ProgramMoves(starts, ends, motion[where] == 0, current[where], spindle[where], where + 1)


def concatenate(parts: list[ProgramMoves]) -> ProgramMoves:
    """The moves of several programs run one after the other (GRBL's program per tool)."""
    return ProgramMoves(*(np.concatenate([getattr(p, name) for p in parts])
                          for name in ("start", "end", "rapid", "tool", "spindle", "line")))
