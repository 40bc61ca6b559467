"""The program reader as it read before it read the whole text at once: a loop over the
lines that carries the modes from one to the next, the twin
:func:`surfmod.cam.program.read_program` is held equal to (``tests/test_cam_verify.py``)."""

from __future__ import annotations

import re

import numpy as np

from surfmod.cam.program import _QUIET_G, _QUIET_M, ProgramMoves, _arc
from surfmod.errors import SurfmodError

_WORD = re.compile(r"([A-Z])\s*([-+]?(?:\d+\.?\d*|\.\d+))")
_COMMENT = re.compile(r"\([^)]*\)|;.*$")


def read_program_lines(text: str, *, tool: int = 0, chord: float = 1e-4) -> ProgramMoves:
    """:func:`surfmod.cam.program.read_program` one line at a time, as a controller reads:
    the same ``ProgramMoves``, bit for bit, and the same ``SurfmodError`` for a line
    outside the dialect."""
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
