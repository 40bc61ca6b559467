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
_WORD = re.compile(r"([A-Z])\s*([-+]?(?:\d+\.?\d*|\.\d+))")
_COMMENT = re.compile(r"\([^)]*\)|;.*$")
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


def read_program(text: str, *, tool: int = 0, chord: float = 1e-4) -> ProgramMoves:
    """The moves of one program ``text`` (see the module); ``tool``: the tool in the
    spindle before any ``M6`` (a GRBL program per tool), ``chord``: the arcs' sagitta.

    >>> moves = read_program("T1 M6\\nG0 Z5\\nS1000 M3\\nG0 X0 Y0\\nG1 Z0 F100\\nG1 X10\\nM5\\nM30")
    >>> moves.end.tolist()[-1], moves.rapid.tolist(), moves.tool.tolist()
    ([10.0, 0.0, 0.0], [True, False, False], [1, 1, 1])
    """
    pos = np.full(3, np.nan)
    motion, current, selected, spindle = None, int(tool), int(tool), False
    starts, ends, rapid, tools, turning, lines = [], [], [], [], [], []
    for number, raw in enumerate(str(text).splitlines(), start=1):
        body = _COMMENT.sub("", raw).strip().upper()
        if not body or body == "%":
            continue
        words = _WORD.findall(body.replace(" ", ""))
        if "".join(f"{a}{b}" for a, b in words) != body.replace(" ", ""):
            raise SurfmodError(f"program: line {number}: cannot read {raw.strip()!r}")
        target, centre, change = {}, {}, False
        for letter, value in words:
            v = float(value)
            if letter == "G":
                if v in (0.0, 1.0, 2.0, 3.0):
                    motion = int(v)
                elif v not in _QUIET_G:
                    raise SurfmodError(f"program: line {number}: G{value} is outside the posts' dialect")
            elif letter == "M":
                if v == 3.0:
                    spindle = True
                elif v == 5.0:
                    spindle = False
                elif v == 6.0:
                    change = True
                elif v not in _QUIET_M:
                    raise SurfmodError(f"program: line {number}: M{value} is outside the posts' dialect")
            elif letter in "XYZ":
                target["XYZ".index(letter)] = v
            elif letter in "IJ":
                centre["IJ".index(letter)] = v
            elif letter == "T":
                selected = int(v)
            elif letter not in "FSHN":
                raise SurfmodError(f"program: line {number}: {letter}{value} is outside the posts' dialect")
        if change:
            current = selected
        if not target:
            continue
        if motion is None:
            raise SurfmodError(f"program: line {number}: coordinates before any G0/G1/G2/G3")
        end = pos.copy()
        for axis, v in target.items():
            end[axis] = v
        start = np.where(np.isnan(pos), end, pos)  # an axis not yet written: the tool stands there
        if np.isnan(end).any():
            pos = end
            continue
        if motion in (2, 3):
            if len(centre) != 2:
                raise SurfmodError(f"program: line {number}: an arc needs both I and J")
            pts = _arc(start, end, (start[0] + centre[0], start[1] + centre[1]), motion == 3, chord)
        else:
            pts = end[None, :]
        prev = start
        for p in pts:
            starts.append(prev)
            ends.append(p)
            prev = p
        n = len(pts)
        rapid += [motion == 0] * n
        tools += [current] * n
        turning += [spindle] * n
        lines += [number] * n
        pos = end
    return ProgramMoves(np.array(starts, float).reshape(-1, 3), np.array(ends, float).reshape(-1, 3),
                        np.array(rapid, bool), np.array(tools, np.int64), np.array(turning, bool),
                        np.array(lines, np.int64))


def concatenate(parts: list[ProgramMoves]) -> ProgramMoves:
    """The moves of several programs run one after the other (GRBL's program per tool)."""
    return ProgramMoves(*(np.concatenate([getattr(p, name) for p in parts])
                          for name in ("start", "end", "rapid", "tool", "spindle", "line")))
