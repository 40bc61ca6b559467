"""An independent stock simulation for the CAM tests (written for the tests: it shares no
code with ``surfmod.cam`` / ``surfmod.uses`` and reads only what a controller reads).

The program is read back as LinuxCNC's own interpreter executes it: ``rs274 -g IN.ngc
OUT.txt`` prints the canonical machine commands (``STRAIGHT_TRAVERSE``, ``STRAIGHT_FEED``,
``ARC_FEED``, ``CHANGE_TOOL``, ``START_SPINDLE_CLOCKWISE`` …), parsed by
:func:`parse_canon`.  :func:`parse_gcode` is a second, much smaller reader of the G-code
text itself (G0/G1/G2/G3 in absolute millimetres on the XY plane) for programs without
an interpreter at hand.

The stock is a height field (dexels along Z) on a regular (x, y) grid: at each node the
top of the material left.  Each move sweeps the tool (an end mill with a shank of its own
radius: ``flat``, ``ball`` or ``bull`` = flat core of radius ``R - r`` then a torus of
corner radius ``r``) along the straight segment between its end points, and the stock
becomes the minimum of itself and the swept tool's lower envelope.  That envelope is
exact at every node: closed forms for a ball (the lowest point of the capsule the sphere
sweeps) and a flat end (the lowest disc position over the node), and for a bull on a
sloped move a golden-section search of the convex function ``t -> z(t) + f(d(t))``
(``f`` the tool profile's height at radius ``d``) on the interval where the tool covers
the node.  Arcs are replaced by chords whose sagitta is at most ``ARC_CHORD`` (or the
readers' ``arc_chord``: the chords lie inside the arc by at most that).

Work and memory are bounded: nodes are visited per move inside the move's box grown by
the tool radius, moves are batched up to ``PAIRS_PER_BATCH`` (node, move) pairs, and long
moves are split into pieces of at most ``PIECE`` tool radii.

A height field places a wall only to a cell.  :class:`SideDexels` adds lines along x and
along y (a tri-dexel stock with the height field): the interval each move's tool cuts from
a line is exact, and :func:`wall_points`, :func:`wall_left` and :func:`wall_reach`
measure the stock left normal to the part's steep faces where the tool can touch them.
Their work is counted before it starts (``CUT_PAIRS_LIMIT`` line-move pairs).
"""

from __future__ import annotations

import math
import re
import shutil
import subprocess
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from numba import njit
from scipy import ndimage

RS274 = shutil.which("rs274") or ("/usr/bin/rs274" if Path("/usr/bin/rs274").exists() else None)
PAIRS_PER_BATCH = 2_000_000
PIECE = 4.0  # tool radii per piece of a long move
ARC_CHORD = 1e-6  # mm, sagitta of the chords replacing an arc
GOLDEN_STEPS = 64  # 0.618**64 ~ 4e-14 of the covered parameter interval


@dataclass(frozen=True)
class Cutter:
    """A tool's shape: ``kind`` flat/ball/bull, ``radius`` R, ``corner`` r (bull only)."""

    kind: str
    radius: float
    corner: float = 0.0

    def __post_init__(self):
        if self.kind == "ball":
            object.__setattr__(self, "corner", float(self.radius))
        elif self.kind == "flat":
            object.__setattr__(self, "corner", 0.0)
        elif self.kind != "bull" or not 0 < self.corner < self.radius:
            raise ValueError(f"cutter: bad shape {self.kind} R={self.radius} r={self.corner}")

    def profile(self, d: np.ndarray) -> np.ndarray:
        """Height above the tip of the tool's lower surface at radius ``d`` (inf beyond R)."""
        d = np.asarray(d, dtype=float)
        core = self.radius - self.corner
        r = self.corner
        out = np.full(d.shape, np.inf)
        inside = d <= self.radius
        out[inside & (d <= core)] = 0.0
        ring = inside & (d > core)
        out[ring] = r - np.sqrt(np.maximum(r * r - (d[ring] - core) ** 2, 0.0))
        return out


@dataclass
class Move:
    """One straight piece of the program: ``rapid`` or feed, from ``a`` to ``b`` (tip
    points), with the tool number and spindle state it ran with and its source line."""

    a: np.ndarray
    b: np.ndarray
    rapid: bool
    tool: int
    spindle: bool
    line: int


@dataclass
class Program:
    moves: list[Move]
    tool_changes: list[int] = field(default_factory=list)
    length_offsets: list[int] = field(default_factory=list)  # tool whose G43 was active at each change
    spindle_starts: list[tuple[int, float]] = field(default_factory=list)  # (tool, speed)
    comments: list[str] = field(default_factory=list)
    ended: bool = False


def run_rs274(ngc: Path, out: Path | None = None, tool_table: Path | None = None) -> str:
    """The canonical commands LinuxCNC's interpreter prints for ``ngc`` (raises if
    rs274 is missing or reports an error)."""
    if RS274 is None:
        raise FileNotFoundError("rs274 (Debian package linuxcnc-uspace) is not installed")
    out = Path(out) if out is not None else Path(ngc).with_suffix(".canon")
    cmd = [RS274] + (["-t", str(tool_table)] if tool_table else []) + ["-g", str(ngc), str(out)]
    done = subprocess.run(cmd, stdin=subprocess.DEVNULL, capture_output=True, text=True, timeout=600)
    text = out.read_text() if out.exists() else ""
    if done.returncode != 0 or "PROGRAM_END" not in text and "PROGRAM_STOP" not in text:
        raise RuntimeError(f"rs274 failed ({done.returncode}): {done.stdout[-500:]} {done.stderr[-500:]}")
    return text


_CALL = re.compile(r"^\s*\d+\s+N\S*\s+([A-Z_]+)\((.*)\)\s*$")


def _numbers(args: str) -> list[float]:
    return [float(v) for v in re.split(r"[,\s]+", args.strip()) if v]


def _arc_points(start, end_xy, centre, rotation: int, z_end: float, chord: float = ARC_CHORD) -> np.ndarray:
    """Chord end points of an XY arc from ``start`` (3,) to ``end_xy`` round ``centre``
    (CCW for rotation > 0, |rotation| - 1 extra full turns), Z linear in the angle."""
    r0 = math.hypot(start[0] - centre[0], start[1] - centre[1])
    a0 = math.atan2(start[1] - centre[1], start[0] - centre[0])
    a1 = math.atan2(end_xy[1] - centre[1], end_xy[0] - centre[0])
    turns = abs(rotation) - 1
    if rotation > 0:
        sweep = (a1 - a0) % (2 * math.pi) or 2 * math.pi * (turns == 0 and np.allclose(start[:2], end_xy))
        sweep += 2 * math.pi * turns
    else:
        sweep = -((a0 - a1) % (2 * math.pi)) or -2 * math.pi * (turns == 0 and np.allclose(start[:2], end_xy))
        sweep -= 2 * math.pi * turns
    step = 2 * math.acos(max(1 - chord / max(r0, 1e-12), -1.0)) if r0 > chord else math.pi
    n = max(1, math.ceil(abs(sweep) / max(step, 1e-9)))
    if n > 10_000_000:
        raise ValueError("arc: too many chords")
    ang = a0 + sweep * np.arange(1, n + 1) / n
    pts = np.column_stack([centre[0] + r0 * np.cos(ang), centre[1] + r0 * np.sin(ang),
                           start[2] + (z_end - start[2]) * np.arange(1, n + 1) / n])
    pts[-1, :2] = end_xy
    return pts


def parse_canon(text: str, arc_chord: float = ARC_CHORD) -> Program:
    """The moves, tool changes and spindle starts of rs274's canonical output (arcs as
    chords of sagitta at most ``arc_chord``)."""
    prog = Program([])
    pos = None
    tool, spindle, offset_tool = 0, False, None
    pending_tool = 0
    for i, line in enumerate(text.splitlines()):
        m = _CALL.match(line)
        if not m:
            continue
        name, args = m.groups()
        if name in ("STRAIGHT_TRAVERSE", "STRAIGHT_FEED"):
            xyz = _numbers(args)[:3]
            if pos is None or xyz != pos.tolist():  # lists: a NumPy comparison per line cost seconds
                p = np.array(xyz)
                if pos is not None:
                    prog.moves.append(Move(pos, p, name == "STRAIGHT_TRAVERSE", tool, spindle, i + 1))
                pos = p
        elif name == "ARC_FEED":
            v = _numbers(args)
            if pos is None:
                raise ValueError(f"line {i + 1}: arc before any position")
            pts = _arc_points(pos, (v[0], v[1]), (v[2], v[3]), int(v[4]), v[5], arc_chord)
            for q in pts:
                prog.moves.append(Move(pos, q, False, tool, spindle, i + 1))
                pos = q
        elif name == "SELECT_TOOL":
            pending_tool = int(_numbers(args)[0])
        elif name == "CHANGE_TOOL":
            tool = int(_numbers(args)[0]) if args.strip() else pending_tool
            prog.tool_changes.append(tool)
            offset_tool = None
        elif name == "USE_TOOL_LENGTH_OFFSET":
            offset_tool = tool
            prog.length_offsets.append(tool)
        elif name in ("START_SPINDLE_CLOCKWISE", "START_SPINDLE_COUNTERCLOCKWISE"):
            spindle = True
        elif name == "SET_SPINDLE_SPEED":
            prog.spindle_starts.append((tool, _numbers(args)[-1]))
        elif name == "STOP_SPINDLE_TURNING":
            spindle = False
        elif name == "COMMENT":
            prog.comments.append(args.strip().strip('"'))
        elif name in ("PROGRAM_END", "PROGRAM_STOP"):
            prog.ended = True
    del offset_tool
    return prog


def read_back(ngc: Path, arc_chord: float = ARC_CHORD) -> Program:
    """The program at ``ngc`` as LinuxCNC's interpreter runs it (:func:`parse_canon` of
    ``rs274``'s output, beside it as ``.txt``), or read from its text by
    :func:`parse_gcode` where rs274 is not installed."""
    if RS274 is not None:
        return parse_canon(run_rs274(ngc, Path(ngc).with_suffix(".txt")), arc_chord=arc_chord)
    return parse_gcode(Path(ngc).read_text(), arc_chord=arc_chord)


_WORD = re.compile(r"([A-Z])\s*([-+]?\d*\.?\d+)")


def parse_gcode(text: str, arc_chord: float = ARC_CHORD) -> Program:
    """A second reader of the G-code text itself: G0/G1/G2/G3 (I, J or R arcs) with
    X Y Z words, absolute millimetres in the XY plane, T/M6, M3/M4/M5, M2/M30."""
    prog = Program([])
    pos = np.zeros(3)
    known = False
    motion, tool, spindle = 0, 0, False
    for i, raw in enumerate(text.splitlines()):
        line = re.sub(r"\(.*?\)|;.*$", "", raw.upper())
        words = _WORD.findall(line)
        if not words:
            continue
        g = [float(v) for k, v in words if k == "G"]
        mcodes = [int(float(v)) for k, v in words if k == "M"]
        vals = {k: float(v) for k, v in words if k not in "GM"}
        for code in g:
            if code in (0, 1, 2, 3):
                motion = int(code)
            elif code in (20, 91):
                raise ValueError(f"line {i + 1}: G{code:g} (inches / incremental) is not read here")
        if "T" in vals and 6 in mcodes:
            tool = int(vals["T"])
            prog.tool_changes.append(tool)
        if 3 in mcodes or 4 in mcodes:
            spindle = True
            prog.spindle_starts.append((tool, vals.get("S", 0.0)))
        if 5 in mcodes or 6 in mcodes:
            spindle = False if 5 in mcodes else spindle
        if 2 in mcodes or 30 in mcodes:
            prog.ended = True
        if not any(k in vals for k in "XYZ"):
            continue
        new = pos.copy()
        for j, k in enumerate("XYZ"):
            if k in vals:
                new[j] = vals[k]
        if motion in (0, 1):
            if known and np.any(new != pos):
                prog.moves.append(Move(pos, new, motion == 0, tool, spindle, i + 1))
        else:
            if "R" in vals:
                chord = new[:2] - pos[:2]
                half = np.linalg.norm(chord) / 2
                rr = vals["R"]
                h = math.sqrt(max(rr * rr - half * half, 0.0))
                left = np.array([-chord[1], chord[0]]) / (2 * half)
                # G2 with R > 0 takes the short arc: the centre lies right of the chord
                side = -1.0 if (motion == 2) == (rr > 0) else 1.0
                centre = pos[:2] + chord / 2 + side * h * left
            else:
                centre = pos[:2] + np.array([vals.get("I", 0.0), vals.get("J", 0.0)])
            start = pos
            for q in _arc_points(pos, new[:2], centre, 1 if motion == 3 else -1, new[2], arc_chord):
                prog.moves.append(Move(start, q, False, tool, spindle, i + 1))
                start = q
        pos, known = new, True
    return prog


# ----------------------------------------------------------------------------------------------
# swept tool envelopes: lowest point of the tool over nodes (qx, qy) along a -> b (tip points)

def _cover(qx, qy, a, b, R):
    """Parameter interval [t0, t1] (clipped to [0, 1]) where the axis is within R of each
    node, and a mask of nodes covered at all."""
    wx, wy = qx - a[0], qy - a[1]
    vx, vy = b[0] - a[0], b[1] - a[1]
    vv = vx * vx + vy * vy
    ww = wx * wx + wy * wy - R * R
    if vv == 0:
        ok = ww <= 0
        return np.zeros_like(qx), np.ones_like(qx), ok
    wv = wx * vx + wy * vy
    disc = wv * wv - vv * ww
    ok = disc >= 0
    root = np.sqrt(np.where(ok, disc, 0.0))
    t0, t1 = (wv - root) / vv, (wv + root) / vv
    ok &= (t1 >= 0) & (t0 <= 1)
    return np.clip(t0, 0, 1), np.clip(t1, 0, 1), ok


def envelope(cutter: Cutter, qx: np.ndarray, qy: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Lowest height of the tool swept straight from tip ``a`` to tip ``b`` over each node
    (inf where the tool never covers it)."""
    shape = np.shape(qx)
    return _envelope(cutter, np.ravel(qx).astype(float), np.ravel(qy).astype(float), a, b).reshape(shape)


def _envelope(cutter, qx, qy, a, b):
    R = cutter.radius
    if cutter.kind in KERNEL_KINDS:
        return _node_envelopes(KERNEL_KINDS[cutter.kind], qx, qy, *map(float, a[:3]), *map(float, b[:3]), float(R))
    t0, t1, ok = _cover(qx, qy, a, b, R)
    out = np.full(qx.shape, np.inf)
    dz = b[2] - a[2]
    # bull: on a level move the closest axis point is lowest; else minimise the convex
    # z(t) + f(d(t)) over the covered interval
    vx, vy = b[0] - a[0], b[1] - a[1]
    idx = np.flatnonzero(ok)
    qx, qy, lo, hi = qx[idx], qy[idx], t0[idx], t1[idx]

    def height(t):
        d = np.hypot(qx - a[0] - t * vx, qy - a[1] - t * vy)
        return a[2] + t * dz + cutter.profile(np.minimum(d, R))

    if dz == 0:
        vv = vx * vx + vy * vy
        t = np.clip(((qx - a[0]) * vx + (qy - a[1]) * vy) / vv, 0, 1) if vv > 0 else np.zeros_like(qx)
        out[idx] = height(t)
        return out
    g = (math.sqrt(5) - 1) / 2
    x1, x2 = hi - g * (hi - lo), lo + g * (hi - lo)
    f1, f2 = height(x1), height(x2)
    for _ in range(GOLDEN_STEPS):
        left = f1 <= f2  # the minimum lies in [lo, x2]
        hi = np.where(left, x2, hi)
        lo = np.where(left, lo, x1)
        keep_x, keep_f = np.where(left, x1, x2), np.where(left, f1, f2)
        fresh = np.where(left, hi - g * (hi - lo), lo + g * (hi - lo))
        fresh_f = height(fresh)
        x1, x2 = np.where(left, fresh, keep_x), np.where(left, keep_x, fresh)
        f1, f2 = np.where(left, fresh_f, keep_f), np.where(left, keep_f, fresh_f)
    out[idx] = np.minimum.reduce([height(lo), height(hi), f1, f2])
    return out


# ----------------------------------------------------------------------------------------------

@dataclass
class Report:
    """What the simulation found.  Depths in mm, positive = the fault happened."""

    gouge: float = -np.inf  # deepest cut below the part's height field
    gouge_at: tuple = ()
    rapid_cut: float = -np.inf  # most material a rapid removed at one node
    rapid_cut_lines: list = field(default_factory=list)
    rapid_part: float = -np.inf  # deepest a rapid's tool came below the part's top
    cut_without_spindle: int = 0  # feed moves that removed material with the spindle stopped
    unknown_tools: set = field(default_factory=set)
    moves: int = 0
    cutting_moves: int = 0

    def __str__(self):
        return (f"{self.moves} moves ({self.cutting_moves} cutting): gouge {self.gouge:.3g} at {self.gouge_at}, "
                f"rapid through stock {self.rapid_cut:.3g} (lines {self.rapid_cut_lines[:5]}), "
                f"rapid into part {self.rapid_part:.3g}, cuts with spindle off {self.cut_without_spindle}")


class Stock:
    """Height-field stock on the grid ``x0 + h i``, ``y0 + h j`` (i < nx, j < ny).

    ``top`` starts at the stock's top over the stock's (x, y) box and -inf outside it (no
    material there), so cuts off the stock remove nothing."""

    def __init__(self, box, h: float, *, origin=None):
        (x0, y0, z0), (x1, y1, z1) = np.asarray(box, dtype=float)
        self.box = np.array([[x0, y0, z0], [x1, y1, z1]])
        self.h = float(h)
        ox, oy = (x0, y0) if origin is None else origin
        # the grid's nodes inside the stock's (x, y) box
        self.x = ox + h * np.arange(math.ceil((x0 - ox) / h - 1e-9), math.floor((x1 - ox) / h + 1e-9) + 1)
        self.y = oy + h * np.arange(math.ceil((y0 - oy) / h - 1e-9), math.floor((y1 - oy) / h + 1e-9) + 1)
        if self.x.size * self.y.size > 40_000_000:
            raise ValueError("stock grid: too many nodes; choose a coarser h")
        X, Y = np.meshgrid(self.x, self.y, indexing="ij")
        inside = (X >= x0 - 1e-12) & (X <= x1 + 1e-12) & (Y >= y0 - 1e-12) & (Y <= y1 + 1e-12)
        self.top = np.where(inside, z1, -np.inf)
        self.bottom = z0

    def nodes(self):
        return np.meshgrid(self.x, self.y, indexing="ij")

    def _window(self, a, b, R):
        lo = np.minimum(a[:2], b[:2]) - R
        hi = np.maximum(a[:2], b[:2]) + R
        i0, i1 = np.searchsorted(self.x, lo[0], "left"), np.searchsorted(self.x, hi[0], "right")
        j0, j1 = np.searchsorted(self.y, lo[1], "left"), np.searchsorted(self.y, hi[1], "right")
        return i0, i1, j0, j1

    def sweep(self, cutter: Cutter, a, b):
        """(window slices, lowest tool height there) of one straight move, without cutting."""
        i0, i1, j0, j1 = self._window(a, b, cutter.radius)
        if i0 >= i1 or j0 >= j1:
            return None, None
        qx, qy = np.meshgrid(self.x[i0:i1], self.y[j0:j1], indexing="ij")
        return (slice(i0, i1), slice(j0, j1)), envelope(cutter, qx, qy, a, b)


def _pieces(a, b, R):
    n = max(1, math.ceil(np.linalg.norm(b[:2] - a[:2]) / (PIECE * R)))
    if n > 10_000_000:
        raise ValueError("move too long for the grid")
    t = np.linspace(0, 1, n + 1)[:, None]
    pts = a + t * (b - a)
    return list(zip(pts[:-1], pts[1:]))


def simulate(program: Program, cutters: dict[int, Cutter], stock: Stock, part_top: np.ndarray | None = None,
             *, eps: float = 1e-9, compiled: bool = True) -> Report:
    """Run every move of ``program`` through ``stock`` (cut in place) with the tool of
    each move's number in ``cutters``; ``part_top`` (the part's height field on the stock
    grid, -inf where no part) is checked against every move's tool.

    Runs of moves with a flat or ball end go through :func:`_sweep_moves` (the same
    arithmetic, node by node, compiled: a job's half a million moves in seconds instead
    of minutes); ``compiled=False`` takes every move through :func:`envelope`."""
    rep = Report()
    floor = np.full(stock.top.shape, -np.inf) if part_top is None else part_top
    lowest = np.full(stock.top.shape, np.inf)  # lowest any feed move's tool came
    moves = program.moves
    k = 0
    while k < len(moves):
        cutter = cutters.get(moves[k].tool)
        end = k + 1
        while end < len(moves) and moves[end].tool == moves[k].tool:
            end += 1
        if compiled and cutter is not None and cutter.kind in KERNEL_KINDS:
            _simulate_compiled(moves[k:end], cutter, stock, floor, lowest, rep, eps)
        else:
            for mv in moves[k:end]:
                _simulate_move(mv, cutter, stock, floor, lowest, rep, eps)
        k = end
    gap = floor - lowest
    k = np.unravel_index(np.argmax(gap), gap.shape)
    rep.gouge = float(gap[k])
    rep.gouge_at = (float(stock.x[k[0]]), float(stock.y[k[1]]))
    return rep


def _simulate_move(mv: Move, cutter: Cutter | None, stock: Stock, floor, lowest, rep: Report, eps: float):
    """One move of :func:`simulate` through :func:`envelope`."""
    rep.moves += 1
    if cutter is None:
        rep.unknown_tools.add(mv.tool)
        return
    removed = 0.0
    for a, b in _pieces(mv.a, mv.b, cutter.radius):
        win, env = stock.sweep(cutter, a, b)
        if win is None:
            continue
        depth = stock.top[win] - env
        removed = max(removed, float(depth.max(initial=-np.inf)))
        into_part = float((floor[win] - env).max(initial=-np.inf))
        if mv.rapid:
            if depth.max(initial=-np.inf) > eps:
                rep.rapid_cut_lines.append(mv.line)
            rep.rapid_cut = max(rep.rapid_cut, float(depth.max(initial=-np.inf)))
            rep.rapid_part = max(rep.rapid_part, into_part)
        np.minimum(lowest[win], env, out=lowest[win])
        np.minimum(stock.top[win], env, out=stock.top[win])
    if removed > eps and not mv.rapid:
        rep.cutting_moves += 1
        if not mv.spindle:
            rep.cut_without_spindle += 1


#: the cutters :func:`_sweep_moves` knows (a bull's golden-section search stays in NumPy)
KERNEL_KINDS = {"flat": 0, "ball": 1}


def _simulate_compiled(moves: list[Move], cutter: Cutter, stock: Stock, floor, lowest, rep: Report, eps: float):
    """A run of ``moves`` of one flat or ball ``cutter`` through :func:`_sweep_moves`,
    reported as :func:`_simulate_move` reports them."""
    a = np.array([m.a for m in moves], dtype=float).reshape(-1, 3)
    b = np.array([m.b for m in moves], dtype=float).reshape(-1, 3)
    rapid = np.array([m.rapid for m in moves], dtype=bool)
    removed, rapid_cut, rapid_part, over = _sweep_moves(
        a, b, rapid, KERNEL_KINDS[cutter.kind], float(cutter.radius), PIECE, eps, stock.x, stock.y, stock.top, floor,
        lowest)
    rep.moves += len(moves)
    for k in np.flatnonzero(over):
        rep.rapid_cut_lines += [moves[k].line] * int(over[k])
    if rapid.any():
        rep.rapid_cut = max(rep.rapid_cut, float(rapid_cut[rapid].max()))
        rep.rapid_part = max(rep.rapid_part, float(rapid_part[rapid].max()))
    cutting = (removed > eps) & ~rapid
    rep.cutting_moves += int(cutting.sum())
    rep.cut_without_spindle += sum(1 for k in np.flatnonzero(cutting) if not moves[k].spindle)


@njit(cache=True)
def _sweep_moves(a, b, rapid, kind, R, piece, eps, x, y, top, floor, lowest):  # pragma: no cover - compiled
    """:func:`_simulate_move` for every move ``a[k] -> b[k]`` of a flat (``kind`` 0) or
    ball (1) end of radius ``R``, node by node in the same arithmetic as :func:`_pieces`,
    :meth:`Stock.sweep` and :func:`envelope`; ``top`` and ``lowest`` cut in place.  Per
    move: the most material removed (0 at least), the deepest rapid cut and rapid into
    the part (-inf without a window), and how many pieces of a rapid cut over ``eps``."""
    m = a.shape[0]
    removed = np.zeros(m)
    rapid_cut = np.full(m, -np.inf)
    rapid_part = np.full(m, -np.inf)
    over = np.zeros(m, np.int64)
    for k in range(m):
        dx, dy = b[k, 0] - a[k, 0], b[k, 1] - a[k, 1]
        n = max(1, math.ceil(math.sqrt(dx * dx + dy * dy) / (piece * R)))
        if n > 10_000_000:
            raise ValueError("move too long for the grid")
        step = 1.0 / n
        for p in range(n):
            t0 = p * step
            t1 = 1.0 if p + 1 == n else (p + 1) * step
            ax, ay, az = a[k, 0] + t0 * (b[k, 0] - a[k, 0]), a[k, 1] + t0 * dy, a[k, 2] + t0 * (b[k, 2] - a[k, 2])
            bx, by, bz = a[k, 0] + t1 * (b[k, 0] - a[k, 0]), a[k, 1] + t1 * dy, a[k, 2] + t1 * (b[k, 2] - a[k, 2])
            i0 = np.searchsorted(x, min(ax, bx) - R, "left")
            i1 = np.searchsorted(x, max(ax, bx) + R, "right")
            j0 = np.searchsorted(y, min(ay, by) - R, "left")
            j1 = np.searchsorted(y, max(ay, by) + R, "right")
            if i0 >= i1 or j0 >= j1:
                continue
            depth_max, part_max = -np.inf, -np.inf
            for i in range(i0, i1):
                for j in range(j0, j1):
                    env = _node_envelope(kind, x[i], y[j], ax, ay, az, bx, by, bz, R)
                    depth_max = max(depth_max, top[i, j] - env)
                    part_max = max(part_max, floor[i, j] - env)
                    if env < lowest[i, j]:
                        lowest[i, j] = env
                    if env < top[i, j]:
                        top[i, j] = env
            removed[k] = max(removed[k], depth_max)
            if rapid[k]:
                if depth_max > eps:
                    over[k] += 1
                rapid_cut[k] = max(rapid_cut[k], depth_max)
                rapid_part[k] = max(rapid_part[k], part_max)
    return removed, rapid_cut, rapid_part, over


@njit(cache=True)
def _node_envelopes(kind, qx, qy, ax, ay, az, bx, by, bz, R):  # pragma: no cover - compiled
    """:func:`_node_envelope` over every node ``(qx[k], qy[k])``."""
    out = np.empty(qx.shape)
    for k in range(qx.size):
        out[k] = _node_envelope(kind, qx[k], qy[k], ax, ay, az, bx, by, bz, R)
    return out


@njit(cache=True, inline="always")
def _node_envelope(kind, qx, qy, ax, ay, az, bx, by, bz, R):  # pragma: no cover - compiled
    """The lowest height over one node of a flat (``kind`` 0) or ball (1) end of radius
    ``R`` swept straight from tip ``a`` to tip ``b``: the flat end's disc where the axis
    first (rising) or last (falling) comes within ``R`` of the node; the ball's lowest
    point of the capsule its centre sweeps (its ends' spheres and the cylinder between)."""
    wx, wy = qx - ax, qy - ay
    vx, vy = bx - ax, by - ay
    vv = vx * vx + vy * vy
    ww = wx * wx + wy * wy - R * R
    if vv == 0:
        ok, t0, t1 = ww <= 0, 0.0, 1.0
    else:
        wv = wx * vx + wy * vy
        disc = wv * wv - vv * ww
        ok = disc >= 0
        root = math.sqrt(disc) if ok else 0.0
        t0, t1 = (wv - root) / vv, (wv + root) / vv
        ok = ok and t1 >= 0 and t0 <= 1
        t0, t1 = min(max(t0, 0.0), 1.0), min(max(t1, 0.0), 1.0)
    if not ok:
        return np.inf
    dz = bz - az
    if kind == 0:
        return az + (t0 if dz > 0 else t1) * dz
    # the ball: the spheres at the ends, then the lower crossing of the cylinder (the
    # centre at a_z + R + s over the node)
    out = np.inf
    m = wx * wx + wy * wy
    if m <= R * R:
        out = min(out, az + R - math.sqrt(max(R * R - m, 0.0)))
    mb = (qx - bx) ** 2 + (qy - by) ** 2
    if mb <= R * R:
        out = min(out, bz + R - math.sqrt(max(R * R - mb, 0.0)))
    A = vx * vx + vy * vy
    if A <= 1e-24:
        return out
    L2 = A + dz * dz
    kk = wx * vx + wy * vy
    disc = kk * kk * dz * dz - A * (m * L2 - kk * kk - R * R * L2)
    if disc < 0:
        return out
    s = (kk * dz - math.sqrt(disc)) / A
    u = (kk + s * dz) / L2
    if u >= 0 and u <= 1:
        out = min(out, az + R + s)
    return out


# ----------------------------------------------------------------------------------------------
# the part as a height field, and the surface a tool can reach

def ray_hits(triangles: np.ndarray, axis: int, u: np.ndarray, v: np.ndarray, *, slack: float = 1e-12,
             block: int = 2_000_000):
    """Where lines parallel to coordinate ``axis`` (0 x, 1 y, 2 z) cross the triangles: the
    lines pass through the grid ``(u_i, v_j)`` of the two other coordinates (in their
    order: y, z for x lines; x, z for y lines; x, y for z lines).  Yields blocks of
    ``(i, j, position along axis, triangle index)``, exact on the triangles (barycentric
    test with ``slack``)."""
    tri = np.asarray(triangles, dtype=float)
    cu, cv = [k for k in range(3) if k != axis]
    lo, hi = tri[:, :, [cu, cv]].min(axis=1), tri[:, :, [cu, cv]].max(axis=1)
    i0 = np.searchsorted(u, lo[:, 0] - 1e-12, "left")
    i1 = np.searchsorted(u, hi[:, 0] + 1e-12, "right")
    j0 = np.searchsorted(v, lo[:, 1] - 1e-12, "left")
    j1 = np.searchsorted(v, hi[:, 1] + 1e-12, "right")
    ni, nj = np.maximum(i1 - i0, 0), np.maximum(j1 - j0, 0)
    for t, local in _blocks(ni * nj, block):
        ii = i0[t] + local // np.maximum(nj[t], 1)
        jj = j0[t] + local % np.maximum(nj[t], 1)
        inside, z = _crossing(tri[t], u[ii], v[jj], axis, slack)
        yield ii[inside], jj[inside], z[inside], t[inside]


def _blocks(counts: np.ndarray, block: int):
    """Each item ``i`` owning ``counts[i]`` pairs, in blocks of about ``block`` pairs (a
    block holds whole items): per block, each pair's item and its place among the item's
    pairs (``0 .. counts[i] - 1``)."""
    edges = np.r_[0, np.cumsum(counts)]
    starts = np.searchsorted(edges, np.arange(0, edges[-1] + block, block))
    for s0, s1 in zip(starts[:-1], starts[1:]):
        if s1 <= s0:
            continue
        ids = np.arange(s0, min(s1, len(counts)))
        c = counts[ids]
        yield np.repeat(ids, c), np.arange(c.sum()) - np.repeat(np.cumsum(c) - c, c)


def _crossing(tri, pu, pv, axis, slack):
    """Whether the line along ``axis`` through (pu, pv) (the other two coordinates in
    order) crosses each triangle (barycentric test with ``slack``), and where along it."""
    cu, cv = [k for k in range(3) if k != axis]
    A, B, C = tri[:, 0], tri[:, 1], tri[:, 2]
    v0, v1 = B - A, C - A
    den = v0[:, cu] * v1[:, cv] - v1[:, cu] * v0[:, cv]
    good = np.abs(den) > 1e-300
    den = np.where(good, den, 1.0)
    wx, wy = pu - A[:, cu], pv - A[:, cv]
    l1 = (wx * v1[:, cv] - v1[:, cu] * wy) / den
    l2 = (v0[:, cu] * wy - wx * v0[:, cv]) / den
    inside = good & (l1 >= -slack) & (l2 >= -slack) & (l1 + l2 <= 1 + slack)
    return inside, A[:, axis] + l1 * v0[:, axis] + l2 * v1[:, axis]


#: directions round a node beside a drop at which the part's height is read again
EDGE_DIRECTIONS = 16


def part_height(triangles: np.ndarray, x: np.ndarray, y: np.ndarray, *, block: int = 2_000_000,
                deflection: float = 0.0) -> np.ndarray:
    """Top of the triangles over each grid node ``(len(x), len(y))`` (-inf where none):
    a vertical ray from above, exact on the triangles.

    With ``deflection`` (the triangles' largest distance from the exact part), a node
    beside a step down takes the lowest height within twice that distance
    (``EDGE_DIRECTIONS`` points round it): a face's triangles end on chords of its edges,
    so over a hole the face can reach up to ``deflection`` past its exact edge, and a node
    there would read the face's height where the part is the hole's (gear f360grbl_gear:
    the top z 5 on a node 4 µm inside the 10 mm bore, a ball dropping into the bore read
    as a 4.27 mm gouge).  Twice: the directions miss the hole's radius by up to half their
    angle.  A step is a point round the node lower than the node's own triangle, continued
    as a plane, comes down over that distance, by more than the grid's spacing: on a
    steep face without one the lowest point round the node is only the face itself
    further down (stepcode_HEAD_BACK's 72° slope at (228.25, 52.75): 0.481 lower, its
    face eroded 0.145 along its normal, which the proof read as finishing's residual)."""
    top = np.full((len(x), len(y)), -np.inf)
    rise = np.zeros(top.shape)  # the slope of the node's top triangle (its gradient's length)
    tri = np.asarray(triangles, dtype=float)
    normal = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    with np.errstate(divide="ignore", invalid="ignore"):
        gradient = np.hypot(normal[:, 0], normal[:, 1]) / np.abs(normal[:, 2])
    for ii, jj, z, t in ray_hits(tri, 2, x, y, block=block):
        order = np.lexsort((z, jj, ii))  # per node, its highest hit last
        ii, jj, z, t = ii[order], jj[order], z[order], t[order]
        last = np.ones(len(ii), dtype=bool)  # a block of triangles may hit no node at all
        last[:-1] = (ii[1:] != ii[:-1]) | (jj[1:] != jj[:-1])
        ii, jj, z, t = ii[last], jj[last], z[last], t[last]
        higher = z > top[ii, jj]
        top[ii[higher], jj[higher]] = z[higher]
        rise[ii[higher], jj[higher]] = gradient[t[higher]]
    if deflection <= 0 or len(x) < 2 or len(y) < 2:
        return top
    h = min(float(np.min(np.diff(x))), float(np.min(np.diff(y))))
    drop = np.zeros(top.shape, bool)
    lowest = np.where(np.isfinite(top), top, -1e300)  # no part: lower than any (no inf - inf)
    for di, dj in ((1, 0), (-1, 0), (0, 1), (0, -1)):
        drop |= lowest - _shifted(lowest, di, dj, np.inf) > h
    ii, jj = np.nonzero(drop)
    ang = 2 * np.pi * np.arange(EDGE_DIRECTIONS) / EDGE_DIRECTIONS
    px = (x[ii][:, None] + 2 * deflection * np.cos(ang)).ravel()
    py = (y[jj][:, None] + 2 * deflection * np.sin(ang)).ravel()
    near = heights_at(tri, px, py).reshape(len(ii), EDGE_DIRECTIONS).min(axis=1)
    step = near < top[ii, jj] - 2 * deflection * rise[ii, jj] - h
    top[ii[step], jj[step]] = np.minimum(top[ii[step], jj[step]], near[step])
    return top


def _cross2(u: np.ndarray, v: np.ndarray) -> np.ndarray:
    return u[:, 0] * v[:, 1] - u[:, 1] * v[:, 0]


def disc_top(triangles: np.ndarray, centres: np.ndarray, radius: float) -> np.ndarray:
    """The highest point of the triangles over the disc of ``radius`` round each ``(x, y)``
    of ``centres`` (-inf where none lies over it): a flat end's drop height, exact on the
    triangles, where a height field sampled a cell apart misses a step between its nodes.
    A plane's highest point over a triangle cut by a disc lies at a corner inside the disc,
    where an edge crosses the circle, on the circle up the plane's slope, or (a level
    triangle) anywhere, the centre among them."""
    tri = np.asarray(triangles, float)
    lo, hi = tri[..., :2].min(axis=1), tri[..., :2].max(axis=1)
    normal = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    r2 = radius * radius
    out = np.full(len(centres), -np.inf)
    for k, c in enumerate(np.asarray(centres, float)):
        near = np.flatnonzero(np.all(lo <= c + radius, axis=1) & np.all(hi >= c - radius, axis=1))
        if not near.size:
            continue
        t, n = tri[near], normal[near]
        d = t[..., :2] - c
        z = np.where((d * d).sum(-1) <= r2, t[..., 2], -np.inf).max(axis=1)
        p, e = d, np.roll(d, -1, axis=1) - d
        zp, ze = t[..., 2], np.roll(t[..., 2], -1, axis=1) - t[..., 2]
        a, b, cc = (e * e).sum(-1), 2 * (p * e).sum(-1), (p * p).sum(-1) - r2
        root = np.sqrt(np.maximum(b * b - 4 * a * cc, 0.0))
        for sign in (-1.0, 1.0):
            s = (-b + sign * root) / np.maximum(2 * a, 1e-300)
            ok = (b * b - 4 * a * cc >= 0) & (a > 0) & (s >= 0) & (s <= 1)
            z = np.maximum(z, np.where(ok, zp + s * ze, -np.inf).max(axis=1))
        # on the circle up the slope, or the centre of a level triangle: kept if inside
        level = np.abs(n[:, 2]) > 1e-12 * np.abs(n).max(axis=1)
        g = -n[:, :2] / np.where(level, n[:, 2], 1.0)[:, None]
        gl = np.hypot(g[:, 0], g[:, 1])
        q = np.where((gl > 0)[:, None], radius * g / np.maximum(gl, 1e-300)[:, None], 0.0)
        v0, v1, v2 = d[:, 0], d[:, 1], d[:, 2]
        cross = [_cross2(v1 - v0, q - v0), _cross2(v2 - v1, q - v1), _cross2(v0 - v2, q - v2)]
        inside = level & ((np.min(cross, axis=0) >= 0) | (np.max(cross, axis=0) <= 0))
        zq = t[:, 0, 2] + ((q - v0) * g).sum(-1)
        z = np.maximum(z, np.where(inside, zq, -np.inf))
        out[k] = z.max()
    return out


def _disc_offsets(cutter: Cutter, h: float):
    n = int(math.floor(cutter.radius / h))
    di, dj = np.mgrid[-n:n + 1, -n:n + 1]
    d = h * np.hypot(di, dj)
    keep = d <= cutter.radius
    return di[keep], dj[keep], cutter.profile(d[keep])


def _shifted(a: np.ndarray, di: int, dj: int, fill: float) -> np.ndarray:
    """``a`` read at (i + di, j + dj), ``fill`` outside."""
    out = np.full_like(a, fill)
    nx, ny = a.shape
    si = slice(max(di, 0), nx + min(di, 0))
    sj = slice(max(dj, 0), ny + min(dj, 0))
    ti = slice(max(-di, 0), nx + min(-di, 0))
    tj = slice(max(-dj, 0), ny + min(-dj, 0))
    out[ti, tj] = a[si, sj]
    return out


def cutter_locations(top: np.ndarray, cutter: Cutter, h: float) -> np.ndarray:
    """Drop-cutter tip heights on the grid against the height field ``top`` (the dilation
    of the part's subgraph by the tool's lower surface, sampled on the same grid)."""
    cl = np.full(top.shape, -np.inf)
    for di, dj, f in zip(*_disc_offsets(cutter, h)):
        np.maximum(cl, _shifted(top, int(di), int(dj), -np.inf) - f, out=cl)
    return cl


def reachable(top: np.ndarray, cutter: Cutter, h: float, cl: np.ndarray | None = None) -> np.ndarray:
    """The surface the tool can reach: the opening of the part's height field ``top`` by
    the tool's lower surface (lowest tool surface over each node among all tool positions
    resting on the part).  ``reachable - top`` is the rest the tool cannot cut."""
    cl = cutter_locations(top, cutter, h) if cl is None else cl
    out = np.full(top.shape, np.inf)
    for di, dj, f in zip(*_disc_offsets(cutter, h)):
        np.minimum(out, _shifted(cl, int(di), int(dj), np.inf) + f, out=out)
    return out


def normal_residual(top: np.ndarray, surface: np.ndarray, h: float) -> np.ndarray:
    """Stock above ``surface`` measured along the surface's normal (vertical residual
    times cos of the slope, from central differences), NaN where either is undefined."""
    gx, gy = np.gradient(np.where(np.isfinite(surface), surface, np.nan), h)
    res = (top - surface) / np.sqrt(1 + gx * gx + gy * gy)
    return np.where(np.isfinite(res), res, np.nan)


# ----------------------------------------------------------------------------------------------
# dexels along x and y: the stock on vertical walls
#
# A tool coming from above carries its shank upwards, so the set one move removes is closed
# upwards and convex (a convex tool swept along a segment): a line along x (or y) at height
# z meets it in one interval, which only grows with z.  A line therefore records only the
# moves whose tool ends between its height and a corner radius below (where the tool's
# section still changes with height), plus the first line above them (the shank, whose
# section no longer changes); the stock left on a line is then the stock minus the union of
# what the lines at or below it recorded.  The intervals are exact: closed forms for flat
# and ball, a bracketed search of convex functions for bull.

CUT_PAIRS_LIMIT = 60_000_000  # (line, move) pairs one sweep may evaluate
_SLOPE = 1e6  # slope of the tool's section radius continued below its tip (see _numeric_cut)


def _ends_interval(es, eq, r2, q0):
    """Line (s, q0) against discs of squared radius ``r2`` at (es, eq): (lo, hi), empty lo > hi."""
    d2 = r2 - (q0 - eq) ** 2
    half = np.sqrt(np.maximum(d2, 0.0))
    return np.where(d2 >= 0, es - half, np.inf), np.where(d2 >= 0, es + half, -np.inf)


def _affine_interval(coef, const, lo_bound, hi_bound):
    """The s with ``lo_bound <= coef * s + const <= hi_bound`` (all s or none where coef is 0)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        a, b = (lo_bound - const) / coef, (hi_bound - const) / coef
    flat = coef == 0
    holds = (const >= lo_bound) & (const <= hi_bound)
    lo = np.where(flat, np.where(holds, -np.inf, np.inf), np.minimum(a, b))
    hi = np.where(flat, np.where(holds, np.inf, -np.inf), np.maximum(a, b))
    return lo, hi


def _stadium_cut(a, b, R, q0):
    """Line ``q = q0`` in the plane against the disc of radius R swept from a to b ((n, 2)
    arrays of (s, q)): the hull of the two end discs and the band between them."""
    lo1, hi1 = _ends_interval(a[:, 0], a[:, 1], R * R, q0)
    lo2, hi2 = _ends_interval(b[:, 0], b[:, 1], R * R, q0)
    vs, vq = b[:, 0] - a[:, 0], b[:, 1] - a[:, 1]
    L2 = vs * vs + vq * vq
    L = np.sqrt(L2)
    dq = q0 - a[:, 1]
    # along the segment: 0 <= (s - a_s) vs + dq vq <= L2; across it: |(s - a_s) vq - dq vs| <= R L
    tlo, thi = _affine_interval(vs, dq * vq, 0.0, L2)
    plo, phi = _affine_interval(vq, -dq * vs, -R * L, R * L)
    blo, bhi = np.maximum(tlo, plo) + a[:, 0], np.minimum(thi, phi) + a[:, 0]
    band = (L2 > 0) & (blo <= bhi)
    lo = np.minimum(np.minimum(lo1, lo2), np.where(band, blo, np.inf))
    hi = np.maximum(np.maximum(hi1, hi2), np.where(band, bhi, -np.inf))
    return lo, hi


def _below(a, b, zc, z0):
    """Parameter interval [t0, t1] of a -> b where the height ``zc`` (+ t (b - a)_z) is at
    most z0; t0 > t1 where never."""
    dz = b[:, 2] - a[:, 2]
    with np.errstate(divide="ignore", invalid="ignore"):
        tc = (z0 - zc) / dz
    never = np.where(dz == 0, zc > z0, False)
    t0 = np.where(dz < 0, np.clip(tc, 0, 1), 0.0)
    t1 = np.where(dz > 0, np.clip(tc, 0, 1), 1.0)
    t0 = np.where(never | ((dz > 0) & (tc < 0)) | ((dz < 0) & (tc > 1)), 1.0, t0)
    t1 = np.where(never | ((dz > 0) & (tc < 0)) | ((dz < 0) & (tc > 1)), 0.0, t1)
    return t0, t1


def _shank_cut(a, b, R, lift, q0, z0):
    """The part of the swept tool whose section is the full disc R (heights from tip +
    ``lift`` up) against the line: the stadium swept over the t where that part reaches z0."""
    t0, t1 = _below(a, b, a[:, 2] + lift, z0)
    v = b - a
    lo, hi = _stadium_cut((a + t0[:, None] * v)[:, :2], (a + t1[:, None] * v)[:, :2], R, q0)
    empty = t0 > t1
    return np.where(empty, np.inf, lo), np.where(empty, -np.inf, hi)


def _capsule_cut(a, b, R, q0, z0):
    """Line (s, q0, z0) against the capsule of radius R round the segment a -> b (centres)."""
    lo1, hi1 = _ends_interval(a[:, 0], a[:, 1], R * R - (z0 - a[:, 2]) ** 2, q0)
    lo2, hi2 = _ends_interval(b[:, 0], b[:, 1], R * R - (z0 - b[:, 2]) ** 2, q0)
    e = b - a
    E2 = (e * e).sum(axis=1)
    w0 = np.column_stack([np.zeros(len(a)), q0 - a[:, 1], z0 - a[:, 2]])
    w0e = (w0 * e).sum(axis=1)
    safe = np.where(E2 > 0, E2, 1.0)
    # distance² to the axis, a quadratic in X = s - a_s: c2 X² + c1 X + c0 <= 0
    c2 = 1 - e[:, 0] ** 2 / safe
    c1 = -2 * e[:, 0] * w0e / safe
    c0 = (w0 * w0).sum(axis=1) - w0e ** 2 / safe - R * R
    par = c2 < 1e-12
    disc = c1 * c1 - 4 * c2 * c0
    root = np.sqrt(np.maximum(disc, 0.0))
    with np.errstate(divide="ignore", invalid="ignore"):
        qlo = np.where(par, np.where(c0 <= 0, -np.inf, np.inf), (-c1 - root) / (2 * c2))
        qhi = np.where(par, np.where(c0 <= 0, np.inf, -np.inf), (-c1 + root) / (2 * c2))
    qlo = np.where(~par & (disc < 0), np.inf, qlo)
    qhi = np.where(~par & (disc < 0), -np.inf, qhi)
    tlo, thi = _affine_interval(e[:, 0], w0e, 0.0, E2)
    clo, chi = np.maximum(qlo, tlo) + a[:, 0], np.minimum(qhi, thi) + a[:, 0]
    cyl = (E2 > 0) & (clo <= chi)
    lo = np.minimum(np.minimum(lo1, lo2), np.where(cyl, clo, np.inf))
    hi = np.maximum(np.maximum(hi1, hi2), np.where(cyl, chi, -np.inf))
    return lo, hi


def _golden(f, lo, hi, steps=GOLDEN_STEPS):
    """Minimum of convex ``f`` on [lo, hi] per element (golden section)."""
    g = (math.sqrt(5) - 1) / 2
    x1, x2 = hi - g * (hi - lo), lo + g * (hi - lo)
    f1, f2 = f(x1), f(x2)
    for _ in range(steps):
        left = f1 <= f2
        hi, lo = np.where(left, x2, hi), np.where(left, lo, x1)
        keep_x, keep_f = np.where(left, x1, x2), np.where(left, f1, f2)
        fresh = np.where(left, hi - g * (hi - lo), lo + g * (hi - lo))
        fresh_f = f(fresh)
        x1, x2 = np.where(left, fresh, keep_x), np.where(left, keep_x, fresh)
        f1, f2 = np.where(left, fresh_f, keep_f), np.where(left, keep_f, fresh_f)
    xs = np.stack([lo, hi, x1, x2])
    fs = np.stack([f(lo), f(hi), f1, f2])
    k = np.argmin(fs, axis=0)
    return xs[k, np.arange(xs.shape[1])], fs[k, np.arange(fs.shape[1])]


def _numeric_cut(cutter: Cutter, a, b, q0, z0):
    """Any tool by bracketed searches.  At parameter t the line meets the tool's section at
    z0 (a disc of radius rho(z0 - tip_z)) where h(t) = rho - |q0 - q(t)| >= 0; rho is concave
    in height, so h is concave and {h >= 0} an interval, found by maximising h and bisecting
    each side.  On it, s(t) -+ sqrt(rho² - dq²) are convex / concave (the set of (t, s) in the
    swept tool is convex): their extremes are the interval's ends.  Below the tip rho is
    continued with slope ``_SLOPE`` (a concave continuation; it shifts t by ~1e-6 mm / |dz|)."""
    R, r = cutter.radius, cutter.corner
    core = R - r
    v = b - a

    def rho(u):
        uu = np.clip(u, 0.0, r)
        true = np.where(u >= r, R, core + np.sqrt(np.maximum(r * r - (r - uu) ** 2, 0.0))) if r > 0 else \
            np.full(np.shape(u), R)
        return np.minimum(np.where(u >= 0, true, core), core + _SLOPE * u)

    def h(t):
        return rho(z0 - a[:, 2] - t * v[:, 2]) - np.abs(q0 - a[:, 1] - t * v[:, 1])

    zero, one = np.zeros(len(a)), np.ones(len(a))
    tm, hm = _golden(lambda t: -h(t), zero, one)
    hit = -hm >= 0

    def bisect(inside, outside):
        for _ in range(GOLDEN_STEPS):
            mid = (inside + outside) / 2
            ok = h(mid) >= 0
            inside, outside = np.where(ok, mid, inside), np.where(ok, outside, mid)
        return inside

    t0 = np.where(h(zero) >= 0, zero, bisect(tm, zero))
    t1 = np.where(h(one) >= 0, one, bisect(tm, one))

    def half(t):
        u = z0 - a[:, 2] - t * v[:, 2]
        dq = q0 - a[:, 1] - t * v[:, 1]
        return np.sqrt(np.maximum(rho(np.maximum(u, 0.0)) ** 2 - dq * dq, 0.0))

    _, lo = _golden(lambda t: a[:, 0] + t * v[:, 0] - half(t), t0, t1)
    _, neg = _golden(lambda t: -(a[:, 0] + t * v[:, 0] + half(t)), t0, t1)
    return np.where(hit, lo, np.inf), np.where(hit, -neg, -np.inf)


def line_cut(cutter: Cutter, a, b, q0, z0, *, numeric: bool = False):
    """The interval of the line ``(s, q0, z0)`` (s free) the tool removes moving from tip a
    to tip b ((n, 3) arrays in (s, q, z) coordinates; q0, z0 (n,)); lo > hi where none."""
    a, b = np.atleast_2d(np.asarray(a, float)), np.atleast_2d(np.asarray(b, float))
    q0, z0 = np.broadcast_to(q0, len(a)).astype(float), np.broadcast_to(z0, len(a)).astype(float)
    if numeric or cutter.kind == "bull":
        return _numeric_cut(cutter, a, b, q0, z0)
    R = cutter.radius
    if cutter.kind == "flat":
        return _shank_cut(a, b, R, 0.0, q0, z0)
    up = np.array([0.0, 0.0, R])
    lo1, hi1 = _capsule_cut(a + up, b + up, R, q0, z0)
    lo2, hi2 = _shank_cut(a, b, R, R, q0, z0)
    return np.minimum(lo1, lo2), np.maximum(hi1, hi2)


def _merge(line, lo, hi, span):
    """Union of intervals per line: sorted disjoint (line, lo, hi) (values inside [0, span))."""
    if not len(line):
        return line, lo, hi
    key = line * span
    order = np.lexsort((lo, line))
    line, lo, hi = line[order], lo[order], hi[order]
    reach = np.maximum.accumulate(key[order] + hi)  # lines far apart: no leak across lines
    start = np.r_[True, key[order][1:] + lo[1:] > reach[:-1]]
    group = np.cumsum(start) - 1
    end = np.zeros(group[-1] + 1)
    np.maximum.at(end, group, hi)
    return line[start], lo[start], end


class SideDexels:
    """Dexels along ``axis`` (0: lines along x on the grid (y_j, z_k); 1: along y on (x_i,
    z_k)) through the stock box: the stock on each line is the box's extent minus the
    removed intervals.  :meth:`cut` sweeps moves; :meth:`removed` gives the union per line."""

    def __init__(self, box, axis: int, q: np.ndarray, z: np.ndarray):
        self.box = np.asarray(box, dtype=float)
        self.axis = int(axis)
        self.q = np.unique(np.asarray(q, dtype=float))
        zt = self.box[1, 2]
        z = np.unique(np.asarray(z, dtype=float))  # ascending: what a line removes, the lines above do
        self.z = z[z < zt]  # no stock above the box
        self.s0, self.s1 = self.box[0, self.axis], self.box[1, self.axis]
        self.span = (self.s1 - self.s0) + 4.0
        self._rec: list[tuple[np.ndarray, np.ndarray, np.ndarray]] = []
        self._union = None

    def _frame(self, p):
        return np.column_stack([p[:, self.axis], p[:, 1 - self.axis], p[:, 2]])

    def pairs(self, cutter: Cutter, a, b):
        """Per move (rows of a, b in x, y, z) its line window: (j0, j1, k0, k1) (k1 inclusive)."""
        R, r = cutter.radius, cutter.corner
        fa, fb = self._frame(a), self._frame(b)
        j0 = np.searchsorted(self.q, np.minimum(fa[:, 1], fb[:, 1]) - R, "left")
        j1 = np.searchsorted(self.q, np.maximum(fa[:, 1], fb[:, 1]) + R, "right")
        k0 = np.searchsorted(self.z, np.minimum(fa[:, 2], fb[:, 2]), "left")
        k1 = np.minimum(np.searchsorted(self.z, np.maximum(fa[:, 2], fb[:, 2]) + r, "left"), len(self.z) - 1)
        return fa, fb, j0, j1, k0, k1

    def cut(self, cutter: Cutter, a, b, *, limit: int = CUT_PAIRS_LIMIT, block: int = 1_000_000):
        """Record what the moves a[m] -> b[m] remove (lines between each move's lowest tip and
        a corner radius above its highest; the line above takes the shank's section)."""
        fa, fb, j0, j1, k0, k1 = self.pairs(cutter, np.asarray(a, float), np.asarray(b, float))
        nj, nk = np.maximum(j1 - j0, 0), np.where(k0 < len(self.z), np.maximum(k1 - k0 + 1, 0), 0)
        counts = nj * nk
        total = int(counts.sum())
        if total > limit:
            raise ValueError(f"side dexels: {total:.3g} line-move pairs (limit {limit:.3g}); pass a coarser h to "
                             f"side_grids or a larger limit")
        nz = len(self.z)
        for m, local in _blocks(counts, block):
            jj = j0[m] + local // np.maximum(nk[m], 1)
            kk = k0[m] + local % np.maximum(nk[m], 1)
            lo, hi = line_cut(cutter, fa[m], fb[m], self.q[jj], self.z[kk])
            lo, hi = np.maximum(lo, self.s0 - 1.0), np.minimum(hi, self.s1 + 1.0)
            keep = lo < hi
            self._union = None
            self._rec.append(_merge((jj * nz + kk)[keep], lo[keep] - self.s0 + 2.0, hi[keep] - self.s0 + 2.0,
                                    self.span))

    def removed(self):
        """Union of the removed intervals per line ``j * len(z) + k``, sorted: (line, lo, hi),
        each line's union taken with the lines below it (the removed set is closed upwards)."""
        nz = len(self.z)
        if self._union is not None:
            return self._union
        if not self._rec:
            return np.zeros(0, int), np.zeros(0), np.zeros(0)
        line = np.concatenate([r[0] for r in self._rec])
        lo = np.concatenate([r[1] for r in self._rec])
        hi = np.concatenate([r[2] for r in self._rec])
        line, lo, hi = _merge(line, lo, hi, self.span)
        self._rec = [(line, lo, hi)]
        k = line % nz
        out = [[], [], []]
        below = (np.zeros(0, int), np.zeros(0), np.zeros(0))
        for level in range(nz):
            at = k == level
            cur = _merge(np.r_[line[at], below[0] + 1], np.r_[lo[at], below[1]], np.r_[hi[at], below[2]],
                         self.span)
            for o, v in zip(out, cur):
                o.append(v)
            below = cur
        line, lo, hi = (np.concatenate(o) for o in out)
        order = np.argsort(line * self.span + lo, kind="stable")
        self._union = line[order], lo[order] + self.s0 - 2.0, hi[order] + self.s0 - 2.0
        return self._union

    def thickness(self, line, pos, outward):
        """Stock left on each line from ``pos`` in direction ``outward`` (+-1) to the nearest
        removed point (to the box's side where none); negative: the removed interval covers
        pos, by how far it reaches back."""
        rl, rlo, rhi = self.removed()
        line, pos, outward = np.asarray(line), np.asarray(pos, float), np.asarray(outward)
        base = line * self.span - self.s0 + 2.0
        klo, khi = rl * self.span + rlo - self.s0 + 2.0, rl * self.span + rhi - self.s0 + 2.0
        up = np.searchsorted(khi, base + pos, "right")  # first interval ending beyond pos
        upc = np.minimum(up, len(rl) - 1)
        has_up = (up < len(rl)) & (rl[upc] == line) if len(rl) else np.zeros(len(line), bool)
        t_up = np.where(has_up, rlo[upc] - pos if len(rl) else 0.0, self.s1 - pos)
        dn = np.searchsorted(klo, base + pos, "left") - 1  # last interval starting before pos
        dnc = np.clip(dn, 0, max(len(rl) - 1, 0))
        has_dn = (dn >= 0) & (rl[dnc] == line) if len(rl) else np.zeros(len(line), bool)
        t_dn = np.where(has_dn, pos - rhi[dnc] if len(rl) else 0.0, pos - self.s0)
        return np.where(outward > 0, t_up, t_dn)


def side_grids(box, h: float, *, phase: float = 0.5137):
    """Dexels along x and along y through the stock ``box`` a distance ``h`` apart, their
    lines set off the grid by ``phase`` cells (so that no line lies in a face of the part
    drawn on round coordinates)."""
    box = np.asarray(box, dtype=float)

    def ticks(lo, hi):
        n = int(math.floor((hi - lo) / h - phase)) + 1
        if n > 1_000_000:
            raise ValueError(f"side dexels: {n} lines along one axis (limit 1e6); choose a coarser h")
        return lo + h * (phase + np.arange(max(n, 0)))

    z = ticks(box[0, 2], box[1, 2])
    return SideDexels(box, 0, ticks(box[0, 1], box[1, 1]), z), SideDexels(box, 1, ticks(box[0, 0], box[1, 0]), z)


@dataclass
class WallPoints:
    """Where the dexel lines of one :class:`SideDexels` cross steep faces of the part: line
    id, position along the line, outward sense along it (+-1), the face's unit outward
    normal (n, 3), the point (n, 3), and the room outside it along the line to the part's
    next crossing or the stock's side."""

    line: np.ndarray
    pos: np.ndarray
    outward: np.ndarray
    normal: np.ndarray
    point: np.ndarray
    room: np.ndarray

    def __len__(self):
        return len(self.line)

    def take(self, mask):
        return WallPoints(*(getattr(self, f)[mask] for f in ("line", "pos", "outward", "normal", "point", "room")))


def vertex_normals(triangles: np.ndarray, owner: np.ndarray) -> np.ndarray:
    """Unit normals (M, 3, 3) at each triangle's corners, averaged (weighted by the corner's
    angle) over the triangles of the same face (``owner``) meeting at that corner: a
    smooth face's normal, nearer its own than a facet's (a facet of a hole of radius 3
    meshed to 0.01 tilts by up to 0.08 rad)."""
    tri = np.asarray(triangles, dtype=float)
    n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    n /= np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-300)
    corners = tri.reshape(-1, 3)
    key = np.column_stack([np.repeat(np.asarray(owner), 3), np.round(corners / 1e-9)])
    _, vid = np.unique(key, axis=0, return_inverse=True)
    vid = vid.ravel()
    e1 = np.roll(tri, -1, axis=1) - tri
    e2 = np.roll(tri, 1, axis=1) - tri
    cos = (e1 * e2).sum(axis=2) / np.maximum(np.linalg.norm(e1, axis=2) * np.linalg.norm(e2, axis=2), 1e-300)
    weight = np.arccos(np.clip(cos, -1, 1)).ravel()
    acc = np.zeros((vid.max() + 1, 3))
    np.add.at(acc, vid, weight[:, None] * np.repeat(n, 3, axis=0))
    acc /= np.maximum(np.linalg.norm(acc, axis=1, keepdims=True), 1e-300)
    return acc[vid].reshape(-1, 3, 3)


def wall_points(triangles: np.ndarray, dex: SideDexels, *, steep: float = 60.0,
                normals: np.ndarray | None = None) -> WallPoints:
    """The crossings of the dexel lines with the part's faces steeper than ``steep`` degrees
    whose normal lies within 45 degrees of the line (each steep point is measured by the
    family of lines nearer its normal).  Inside and outside alternate along a line (the
    part's closed surface), which orients each crossing whatever the triangles' winding;
    lines left with an odd count (through a vertex) are dropped.  ``normals`` (from
    :func:`vertex_normals`) are interpolated at each crossing instead of the facet's."""
    tri = np.asarray(triangles, dtype=float)
    nz = len(dex.z)
    parts = [list(p) for p in zip(*ray_hits(tri, dex.axis, dex.q, dex.z))]
    if not parts:
        return WallPoints(*(np.zeros((0,) + s) for s in ((), (), (), (3,), (3,), ())))
    jj, kk, pos, t = (np.concatenate(p) for p in parts)
    line = jj * nz + kk
    order = np.lexsort((pos, line))
    line, pos, t = line[order], pos[order], t[order]
    n = np.cross(tri[t, 1] - tri[t, 0], tri[t, 2] - tri[t, 0])
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    # a line through an edge meets both triangles there: one crossing (same sense), unless
    # it grazes the surface (opposite senses: in and out at once, both kept)
    twin = np.r_[False, (line[1:] == line[:-1]) & (np.abs(pos[1:] - pos[:-1]) <= 1e-9)
                 & (np.sign(n[1:, dex.axis]) == np.sign(n[:-1, dex.axis]))]
    line, pos, t, n = line[~twin], pos[~twin], t[~twin], n[~twin]
    count = np.bincount(line, minlength=len(dex.q) * nz)
    even = count[line] % 2 == 0
    line, pos, t, n = line[even], pos[even], t[even], n[even]
    first = np.r_[True, line[1:] != line[:-1]]
    rank = np.arange(len(line)) - np.maximum.accumulate(np.where(first, np.arange(len(line)), 0))
    outward = np.where(rank % 2 == 0, -1, 1)
    point = np.zeros((len(line), 3))
    point[:, dex.axis] = pos
    point[:, 1 - dex.axis] = dex.q[line // nz]
    point[:, 2] = dex.z[line % nz]
    if normals is not None:  # barycentric weights of the crossing on its triangle
        A, v0, v1 = tri[t, 0], tri[t, 1] - tri[t, 0], tri[t, 2] - tri[t, 0]
        w = point - A
        d00, d01, d11 = (v0 * v0).sum(1), (v0 * v1).sum(1), (v1 * v1).sum(1)
        d20, d21 = (w * v0).sum(1), (w * v1).sum(1)
        den = np.maximum(d00 * d11 - d01 * d01, 1e-300)
        b1, b2 = (d11 * d20 - d01 * d21) / den, (d00 * d21 - d01 * d20) / den
        vn = normals[t]
        smooth = (1 - b1 - b2)[:, None] * vn[:, 0] + b1[:, None] * vn[:, 1] + b2[:, None] * vn[:, 2]
        smooth /= np.maximum(np.linalg.norm(smooth, axis=1, keepdims=True), 1e-300)
        n = np.where((smooth * n).sum(1, keepdims=True) >= 0, smooth, -smooth)
    n *= np.where(n[:, dex.axis] * outward >= 0, 1.0, -1.0)[:, None]
    same_next = np.r_[line[1:] == line[:-1], False]
    same_prev = np.r_[False, line[1:] == line[:-1]]
    nxt = np.where(same_next, np.r_[pos[1:], 0.0] - pos, dex.s1 - pos)
    prv = np.where(same_prev, pos - np.r_[0.0, pos[:-1]], pos - dex.s0)
    room = np.where(outward > 0, nxt, prv)
    keep = (np.abs(n[:, 2]) <= math.cos(math.radians(steep))) & (np.abs(n[:, dex.axis]) >= np.abs(n[:, 1 - dex.axis]))
    return WallPoints(line, pos, outward, n, point, room).take(keep)


def wall_left(dex: SideDexels, walls: WallPoints) -> np.ndarray:
    """Stock left outside each wall point measured along its normal: the thickness along
    the line to the nearest removed point times the normal's share along the line (the
    distance of that point from the face's plane), at most the room outside it; negative
    where a removed interval covers the point (a cut into the wall, by as much)."""
    along = dex.thickness(walls.line, walls.pos, walls.outward)
    return np.minimum(along, walls.room) * np.abs(walls.normal[:, dex.axis])


#: most points :func:`surface_distance` measures (each against every triangle's box)
SURFACE_POINTS_LIMIT = 20_000


def _closest_on_triangles(p, a, b, c):
    """The point of each triangle (a, b, c: (k, 3)) nearest ``p`` (3,) (Ericson's regions)."""
    ab, ac, ap, bp, cp = b - a, c - a, p - a, p - b, p - c
    d1, d2 = (ab * ap).sum(1), (ac * ap).sum(1)
    d3, d4 = (ab * bp).sum(1), (ac * bp).sum(1)
    d5, d6 = (ab * cp).sum(1), (ac * cp).sum(1)
    va, vb, vc = d3 * d6 - d5 * d4, d5 * d2 - d1 * d6, d1 * d4 - d3 * d2
    with np.errstate(divide="ignore", invalid="ignore"):
        total = va + vb + vc
        face = a + ab * (vb / total)[:, None] + ac * (vc / total)[:, None]
        on_ab = a + ab * (d1 / (d1 - d3))[:, None]
        on_ac = a + ac * (d2 / (d2 - d6))[:, None]
        on_bc = b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)))[:, None]
    cases = [(d1 <= 0) & (d2 <= 0), (d3 >= 0) & (d4 <= d3), (vc <= 0) & (d1 >= 0) & (d3 <= 0),
             (d6 >= 0) & (d5 <= d6), (vb <= 0) & (d2 >= 0) & (d6 <= 0),
             (va <= 0) & (d4 - d3 >= 0) & (d5 - d6 >= 0)]
    out = face
    for case, q in reversed(list(zip(cases, [a, b, on_ab, c, on_ac, on_bc]))):
        out = np.where(case[:, None], q, out)
    return out


def surface_distance(triangles: np.ndarray, points: np.ndarray, reach: float) -> np.ndarray:
    """Distance from each point (n, 3) to the nearest of the triangles, ``inf`` where none
    lies within ``reach`` (only triangles whose box comes that near are measured)."""
    points = np.atleast_2d(np.asarray(points, float))
    if len(points) > SURFACE_POINTS_LIMIT:
        raise ValueError(f"surface_distance: {len(points)} points, more than {SURFACE_POINTS_LIMIT}")
    tri = np.asarray(triangles, float)
    lo, hi = tri.min(axis=1) - reach, tri.max(axis=1) + reach
    out = np.full(len(points), np.inf)
    for k, p in enumerate(points):
        near = np.flatnonzero(np.all((lo <= p) & (p <= hi), axis=1))
        if near.size:
            t = tri[near]
            q = _closest_on_triangles(p, t[:, 0], t[:, 1], t[:, 2])
            d = float(np.linalg.norm(q - p, axis=1).min())
            out[k] = d if d <= reach else np.inf
    return out


def wall_reach(walls: WallPoints, top: np.ndarray, x: np.ndarray, y: np.ndarray, cutter: Cutter, *,
               offset: float = 0.0, below: float = 0.0, slack: float = 1e-3, eps: float = 1e-9,
               triangles: np.ndarray | None = None, ring: int = 64, quick: tuple | None = None,
               block: int = 4_000_000) -> np.ndarray:
    """Which wall points the tool can touch from above: the tool grown by ``offset`` placed
    against the point along its normal (a ball's centre at P + (R + offset) n, a flat end's
    rim, a bull's torus) must clear the part's height field ``top`` on the grid (x, y)
    within its radius less a cell (the point's own face lies at the full radius), by eps.
    Points under overhangs and in corners tighter than the tool fail, and so does every
    face turned downwards (more than ``1e-3`` of its normal): a tool whose body goes up
    has no surface turned upwards to touch it with.  With ``below`` the tool must also
    clear the part touching the face ``below`` lower (slid down the face's steepest
    descent): a stepdown's stair above a floor is not the wall's to hold."""
    if below > 0:
        n = walls.normal
        down = n[:, 2:3] * n - np.array([0.0, 0.0, 1.0])  # steepest descent along the face
        down *= below / np.maximum(-down[:, 2:3], 1e-12)
        lower = WallPoints(walls.line, walls.pos, walls.outward, n, walls.point + down, walls.room)
        kw = dict(offset=offset, slack=slack, eps=eps, triangles=triangles, ring=ring, quick=quick, block=block)
        return wall_reach(walls, top, x, y, cutter, **kw) & wall_reach(lower, top, x, y, cutter, **kw)
    R, r = cutter.radius, cutter.corner
    core = R - r
    h = float(x[1] - x[0])
    tip = _placed(walls, cutter, offset)
    reach_r = R + offset - slack
    if quick is not None:  # the reach map at the node nearest each tip (beyond it: nothing)
        grid, pad = quick
        i = np.rint((tip[:, 0] - x[0]) / h).astype(int) + pad
        j = np.rint((tip[:, 1] - y[0]) / h).astype(int) + pad
        ok = (i >= 0) & (i < grid.shape[0]) & (j >= 0) & (j < grid.shape[1])
        clear = np.where(ok, grid[np.clip(i, 0, grid.shape[0] - 1), np.clip(j, 0, grid.shape[1] - 1)], -np.inf)
        return (clear <= tip[:, 2] + eps) & (walls.normal[:, 2] >= -1e-3)
    m = int(math.ceil(reach_r / h)) + 1
    di, dj = (g.ravel() for g in np.mgrid[-m:m + 1, -m:m + 1])
    out = np.zeros(len(walls), bool)
    per = max(1, block // len(di))
    for c0 in range(0, len(walls), per):
        tp = tip[c0:c0 + per]
        ic = np.rint((tp[:, 0] - x[0]) / h).astype(int)[:, None] + di
        jc = np.rint((tp[:, 1] - y[0]) / h).astype(int)[:, None] + dj
        inside = (ic >= 0) & (ic < len(x)) & (jc >= 0) & (jc < len(y))
        icc, jcc = np.clip(ic, 0, len(x) - 1), np.clip(jc, 0, len(y) - 1)
        d = np.hypot(x[icc] - tp[:, :1], y[jcc] - tp[:, 1:2])
        grown = r - np.sqrt(np.maximum((r + offset) ** 2 - np.maximum(d - core, 0.0) ** 2, 0.0))
        near = inside & (d <= reach_r)
        clear = np.where(near, top[icc, jcc] - grown, -np.inf).max(axis=1)
        out[c0:c0 + per] = clear <= tp[:, 2] + eps
    if triangles is not None and out.any():
        idx = np.flatnonzero(out)
        ang = 2 * np.pi * np.arange(ring) / ring
        px = (tip[idx, :1] + reach_r * np.cos(ang)).ravel()
        py = (tip[idx, 1:2] + reach_r * np.sin(ang)).ravel()
        grown = r - math.sqrt(max((r + offset) ** 2 - max(reach_r - core, 0.0) ** 2, 0.0))
        rim = heights_at(triangles, px, py).reshape(len(idx), ring).max(axis=1) - grown
        out[idx] = rim <= tip[idx, 2] + eps
    return out & (walls.normal[:, 2] >= -1e-3)


def reach_map(top: np.ndarray, h: float, cutter: Cutter, *, offset: float = 0.0, slack: float = 1e-3):
    """(map, pad): per node of the grid padded by ``pad`` nodes on each side, the lowest
    tip height at which the tool grown by ``offset`` clears the height field ``top``
    within its radius less ``slack``, for any axis within half a cell
    diagonal of the node: the grown profile is read that much further out and the disc
    shrunk by it, so the map errs towards reachable (:func:`wall_reach` then confirms)."""
    R, r = cutter.radius, cutter.corner
    core = R - r
    shift = h * math.sqrt(0.5)
    radius = R + offset - slack - shift
    m = int(math.floor(max(radius, 0.0) / h))
    di, dj = np.mgrid[-m:m + 1, -m:m + 1]
    d = h * np.hypot(di, dj)
    foot = d <= radius
    grown = r - np.sqrt(np.maximum((r + offset) ** 2 - np.maximum(d + shift - core, 0.0) ** 2, 0.0))
    # padded by the footprint (a tool beyond the grid still sees the nodes it covers)
    filled = np.pad(np.where(np.isfinite(top), top, -1e300), m + 1, constant_values=-1e300)
    return ndimage.grey_dilation(filled, footprint=foot, structure=np.where(foot, -grown, 0.0), mode="constant",
                                 cval=-1e300), m + 1


def _placed(walls: WallPoints, cutter: Cutter, offset: float) -> np.ndarray:
    """Tip of the tool grown by ``offset`` touching each wall point along its normal."""
    r, core = cutter.corner, cutter.radius - cutter.corner
    n = walls.normal
    nh = n[:, :2] / np.maximum(np.linalg.norm(n[:, :2], axis=1, keepdims=True), 1e-300)
    tip = walls.point + (r + offset) * n
    tip[:, :2] += core * nh
    tip[:, 2] -= r
    return tip


def heights_at(triangles: np.ndarray, px: np.ndarray, py: np.ndarray, *, cell: float = 1.0,
               block: int = 4_000_000) -> np.ndarray:
    """Top of the triangles over scattered points (-inf where none): the triangles are
    binned by their (x, y) boxes into cells, each point tested against its cell's."""
    tri = np.asarray(triangles, dtype=float)
    lo, hi = tri[:, :, :2].min(axis=1), tri[:, :, :2].max(axis=1)
    origin = lo.min(axis=0)
    c0 = np.floor((lo - origin) / cell).astype(np.int64)
    c1 = np.floor((hi - origin) / cell).astype(np.int64)
    ncol = int(c1[:, 1].max()) + 1
    ni, nj = c1[:, 0] - c0[:, 0] + 1, c1[:, 1] - c0[:, 1] + 1
    count = ni * nj
    if count.sum() > 50_000_000:
        raise ValueError("heights_at: triangles span too many cells; choose a larger cell")
    t = np.repeat(np.arange(len(tri)), count)
    local = np.arange(count.sum()) - np.repeat(np.cumsum(count) - count, count)
    key = (c0[t, 0] + local // nj[t]) * ncol + c0[t, 1] + local % nj[t]
    order = np.argsort(key, kind="stable")
    key, t = key[order], t[order]
    out = np.full(len(px), -np.inf)
    pi, pj = np.floor((px - origin[0]) / cell).astype(np.int64), np.floor((py - origin[1]) / cell).astype(np.int64)
    ok = (pi >= 0) & (pj >= 0) & (pj < ncol)
    pk = np.where(ok, pi * ncol + pj, -1)
    first, last = np.searchsorted(key, pk, "left"), np.searchsorted(key, pk, "right")
    for p, local in _blocks(np.where(ok, last - first, 0), block):
        k = t[first[p] + local]
        inside, z = _crossing(tri[k], px[p], py[p], 2, 1e-12)
        np.maximum.at(out, p[inside], z[inside])
    return out
