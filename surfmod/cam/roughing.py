"""Z-level roughing: clearing a block of stock down to the part plus an allowance.

The part grown by the allowance is bounded by the drop-cutter surface of the tool grown by
it (:func:`offset_tool`; its tip is ``A`` below the real one), sampled on an (x, y) grid over the stock: ``h(x, y)`` is the
lowest tip height that keeps the tool ``A`` clear of the part.  At a level ``z`` the tool
may stand wherever ``h ≤ z``; the region is cleared by contour-parallel rings, the
isolines of the distance to where it may not stand, ``stepover`` apart (each point of
the region lies within ``stepover`` of a ring, so the tool, wider than that, sweeps it
all; each ring engages at most ``stepover`` of material radially beside the one before
it).  Rings are clipped to the stock grown by ``radius + stepover / 2``, cut from the far
side inwards towards the part (open stock is entered from the air, sideways); a closed
ring is entered by a ramp along itself from the level above (never a straight plunge).
Links go up to the clearance height above the stock, except a short link (at most
``1.5 stepover``) at the level when it stays where the tool may stand.

Every cutter location is lifted onto the exact drop-cutter height where the grid put it
too low, and every move is checked between its ends (:func:`move_gouge`), split and
lifted until none cuts into the allowance: roughing never cuts into the part plus the
allowance, beyond the mesh's deflection.
"""

from __future__ import annotations

from dataclasses import dataclass

import contourpy
import numpy as np
from scipy import ndimage

from ..errors import SurfmodError
from .drop_cutter import TriangleGrid, drop
from .tool import Tool
from .toolpath_moves import lift_moves, move_gouge

RAPID, FEED, PLUNGE = 0, 1, 2
#: Ramp angle of entries (degrees) and the most turns a ramp goes round a short ring
#: before it steepens (up to ``MAX_RAMP_ANGLE``; beyond, the ring is not entered).
RAMP_ANGLE = 3.0
MAX_RAMP_ANGLE = 15.0
MAX_RAMP_TURNS = 12
#: Grid cells for the height field: about this many per stepover, at most MAX_CELLS.
CELLS_PER_STEPOVER = 3
MAX_CELLS = 1_500_000
#: Splitting rounds for moves that cut between their ends (each halves the moves cut).
SPLIT_ROUNDS = 12


@dataclass(frozen=True)
class Motion:
    """Cutter locations ``points (N, 3)`` and how the tool moves to each ``kind (N,)``:
    ``RAPID`` (G0), ``FEED`` (G1 at the cutting feed), ``PLUNGE`` (G1 at the plunge/ramp
    feed)."""

    points: np.ndarray
    kind: np.ndarray


class _Builder:
    def __init__(self):
        self.points, self.kinds = [], []

    def add(self, pts, kind):
        pts = np.atleast_2d(np.asarray(pts, float))
        self.points.append(pts)
        self.kinds.append(np.full(len(pts), kind, np.int8))

    @property
    def last(self):
        return self.points[-1][-1] if self.points else None

    def motion(self) -> Motion:
        if not self.points:
            return Motion(np.zeros((0, 3)), np.zeros(0, np.int8))
        return Motion(np.concatenate(self.points), np.concatenate(self.kinds))


def offset_tool(tool: Tool, allowance: float) -> Tool:
    """A tool holding the tool grown by ``allowance``: its drop height, plus the allowance,
    keeps the real tool at least that far from the part.  A ball grows into the ball
    ``R + A`` (exact); a flat or bull end into the flat end ``R + A``, which holds the
    exact offset (the bull ``R + A`` with corner ``c + A``) and drops an order of magnitude
    faster: on a slope of angle θ it stays up to ``A (sin θ + cos θ - 1)`` further away
    (at most 0.41 A, at 45°), material the finishing pass removes."""
    if allowance <= 0:
        return tool
    if tool.kind == "ball":
        return Tool("ball", tool.radius + allowance)
    return Tool("flat", tool.radius + allowance)


def _resample(line: np.ndarray, step: float, closed: bool) -> np.ndarray:
    """Points along ``line`` at most ``step`` apart (its own vertices kept)."""
    if closed and np.any(line[0] != line[-1]):
        line = np.vstack([line, line[:1]])
    seg = np.diff(line, axis=0)
    n = np.maximum(np.ceil(np.linalg.norm(seg, axis=1) / step).astype(int), 1)
    t = np.concatenate([np.arange(k) / k for k in n])
    start = np.repeat(line[:-1], n, axis=0)
    out = start + np.repeat(seg, n, axis=0) * t[:, None]
    return np.vstack([out, line[-1:]])


def _clip(line: np.ndarray, lo: np.ndarray, hi: np.ndarray):
    """The pieces of the polyline inside the box ``lo``–``hi`` (vertices outside dropped,
    pieces split there) and whether the line stayed whole (closed ring inside)."""
    inside = np.all((line >= lo) & (line <= hi), axis=1)
    if inside.all():
        return [line], True
    pieces, current = [], []
    # rotate a closed ring so that it starts outside: no piece wraps round the seam
    k = int(np.argmin(inside))
    line, inside = np.roll(line[:-1], -k, axis=0), np.roll(inside[:-1], -k)
    for p, ok in zip(line, inside):
        if ok:
            current.append(p)
        elif current:
            pieces.append(np.array(current))
            current = []
    if current:
        pieces.append(np.array(current))
    return [p for p in pieces if len(p) >= 2], False


def rough(part_grid: TriangleGrid, lift: float, grown: Tool, tool: Tool, allowance: float, stock: np.ndarray,
          stepdown: float, stepover: float, clearance: float, step: float | None = None, progress=None):
    """The roughing :class:`Motion` of ``tool`` over ``part_grid`` (the part's triangles
    bucketed for the ``grown`` tool, heights raised by ``lift`` for the mesh deflection)
    inside the ``stock`` box ``[[x0, y0, z0], [x1, y1, z1]]``, and a report dict."""
    R = tool.radius
    step = min(R / 4, stepover / 2) if step is None else step
    safe = float(stock[1, 2] + clearance)
    bottom = float(stock[0, 2])

    def height(xy):
        h = drop(part_grid, grown.kind, np.asarray(xy, float).reshape(-1, 2), corner=grown.corner)
        return np.maximum(np.where(np.isnan(h), bottom, h + lift + allowance), bottom)

    # rings reach a radius beyond the stock (the outermost cuts air, each next one at most
    # `stepover` more), so walls of stock narrower than the tool are cleared too
    g = R + 0.5 * stepover
    lo_box, hi_box = stock[0, :2] - g, stock[1, :2] + g
    cell = stepover / CELLS_PER_STEPOVER
    span = stock[1, :2] - stock[0, :2] + 2 * (R + 2 * stepover)
    cells = float(np.prod(span / cell + 1))
    if cells > MAX_CELLS:
        cell *= np.sqrt(cells / MAX_CELLS)
    origin = stock[0, :2] - (R + 2 * stepover)
    nx, ny = (np.floor(span / cell).astype(int) + 1)
    xs, ys = origin[0] + cell * np.arange(nx), origin[1] + cell * np.arange(ny)
    X, Y = np.meshgrid(xs, ys, indexing="ij")
    H = height(np.column_stack([X.ravel(), Y.ravel()])).reshape(nx, ny)
    if progress is not None:
        progress.update()

    low = float(H[(X >= lo_box[0]) & (X <= hi_box[0]) & (Y >= lo_box[1]) & (Y <= hi_box[1])].min())
    top = float(stock[1, 2])
    n_levels = int(np.ceil((top - low) / stepdown - 1e-9))
    levels = [top - stepdown * k for k in range(1, n_levels)] + [low]
    # flat floors (a level area of h at least the tool's) get a level of their own
    inner = H[(X >= lo_box[0]) & (X <= hi_box[0]) & (Y >= lo_box[1]) & (Y <= hi_box[1])]
    values, counts = np.unique(np.round(inner, 6), return_counts=True)
    for v, c in zip(values, counts):
        if c * cell * cell >= np.pi * R * R and low < v < top and min(abs(v - lv) for lv in levels) > 1e-3:
            levels.append(float(v))
    levels = sorted(set(levels), reverse=True)
    if low >= top:
        levels = []

    out = _Builder()
    out.add([[stock[0, 0], stock[0, 1], safe]], RAPID)
    in_box = (X >= lo_box[0]) & (X <= hi_box[0]) & (Y >= lo_box[1]) & (Y <= hi_box[1])
    previous = top
    ramps, max_angle = 0, 0.0
    for z in levels:
        free = H <= z + 1e-9
        if not free[in_box].any():
            previous = z
            continue
        if free.all():  # nothing of the part at this level: rings of the stock box, outside in
            dist = ndimage.distance_transform_edt(in_box) * cell
            order = 1
        else:
            dist = ndimage.distance_transform_edt(free) * cell
            order = -1
        top_d = float(dist[in_box & free].max())
        # the first ring a cell inside where the tool may stand (half a cell can lie beyond it)
        rings_at = cell + stepover * np.arange(int(max(top_d - cell, 0.0) / stepover) + 1)
        if order < 0:
            rings_at = rings_at[::-1]
        gen = contourpy.contour_generator(xs, ys, dist.T, line_type=contourpy.LineType.Separate)
        for level_d in rings_at:
            for line in gen.lines(float(level_d)):
                closed = len(line) > 2 and np.allclose(line[0], line[-1])
                pieces, whole = _clip(line, lo_box, hi_box) if order < 0 else ([line], True)
                for piece in pieces:
                    _cut_piece(out, piece, closed and whole, z, previous, safe, height, step, stepover, stock,
                               lo_box, hi_box)
        previous = z
        if progress is not None:
            progress.update(0)
    out.add([[out.last[0], out.last[1], safe]], RAPID)
    ceiling = float(part_grid.triangles[..., 2].max()) + lift + allowance
    motion = _verify(out.motion(), height, ceiling)
    return motion, {"levels": levels, "cell": cell, "low": low}


def _cut_piece(out: _Builder, piece, closed: bool, z, previous, safe, height, step, stepover, stock, lo_box, hi_box):
    pts = _resample(piece, step, closed)
    path = np.column_stack([pts, np.full(len(pts), z)])
    path[:, 2] = np.maximum(path[:, 2], height(pts))
    if closed:
        # ramp along the ring from just above the level before, going round as needed
        L = float(np.linalg.norm(np.diff(pts, axis=0), axis=1).sum())
        drop_z = previous + 0.5 - z
        need = drop_z / np.tan(np.radians(RAMP_ANGLE))
        turns = min(int(np.ceil(need / max(L, 1e-9))), MAX_RAMP_TURNS)
        if L * turns < drop_z / np.tan(np.radians(MAX_RAMP_ANGLE)):
            return  # a ring too short to ramp into (a sliver): left for the finishing tool
        ramp = np.vstack([pts[:-1]] * turns + [pts[:1]])
        s = np.r_[0, np.cumsum(np.linalg.norm(np.diff(ramp, axis=0), axis=1))]
        rz = np.maximum(previous + 0.5 - drop_z * s / s[-1], height(ramp))
        start = np.array([ramp[0, 0], ramp[0, 1], safe])
        _link(out, start, safe)
        out.add([[ramp[0, 0], ramp[0, 1], max(previous + 0.5, rz[0])]], RAPID)
        out.add(np.column_stack([ramp, rz])[1:], PLUNGE)
        out.add(path[1:], FEED)
        return
    # open piece, its ends on the stock's grown side: lead in from outside the stock
    p0 = path[0, :2]
    out_dir = np.where(p0 <= lo_box + 1e-6, -1.0, np.where(p0 >= hi_box - 1e-6, 1.0, 0.0))
    if not out_dir.any():
        out_dir = np.sign(p0 - stock[:, :2].mean(axis=0))
    lead = p0 + out_dir * (stepover + 1.0)
    lead_z = float(max(z, height(lead[None])[0]))
    last = out.last
    near = (last is not None and abs(last[2] - z) < 1e-9
            and np.linalg.norm(last[:2] - p0) <= 1.5 * stepover
            and _level_clear(height, last[:2], p0, z, step))
    if near:
        out.add(path, FEED)
        return
    _link(out, np.array([lead[0], lead[1], safe]), safe)
    out.add([[lead[0], lead[1], lead_z]], RAPID)
    out.add(path, FEED)


def _level_clear(height, a, b, z, step) -> bool:
    n = int(np.ceil(np.linalg.norm(b - a) / step)) + 1
    t = np.linspace(0, 1, n + 1)[:, None]
    return bool(np.all(height(a + t * (b - a)) <= z + 1e-9))


def _link(out: _Builder, target, safe):
    """Up to the clearance height, across, (the caller goes down)."""
    last = out.last
    if last is not None and last[2] < safe:
        out.add([[last[0], last[1], safe]], RAPID)
    out.add([target], RAPID)


def _gouge(height, pts: np.ndarray, ceiling: float, which: np.ndarray | None = None) -> np.ndarray:
    """:func:`move_gouge` of the moves ``which`` (default all) that dip below ``ceiling``
    (the highest drop height: moves wholly above it clear); -inf elsewhere."""
    depth = np.full(max(len(pts) - 1, 0), -np.inf)
    which = np.arange(len(depth)) if which is None else which
    low = which[np.minimum(pts[which, 2], pts[which + 1, 2]) <= ceiling]
    if low.size:
        pairs = np.stack([pts[low], pts[low + 1]], axis=1)  # each move on its own
        got = move_gouge(height, pairs.reshape(-1, 3))
        depth[low] = got[0::2]
    return depth


def _verify(motion: Motion, height, ceiling: float) -> Motion:
    """Split and lift moves until none cuts below the drop-cutter height between its ends
    (only the halves of split moves are judged again)."""
    pts, kind = motion.points.copy(), motion.kind.copy()
    depth = _gouge(height, pts, ceiling)
    for _ in range(SPLIT_ROUNDS):
        bad = np.flatnonzero(depth > 1e-9)
        if not bad.size:
            break
        mid = 0.5 * (pts[bad] + pts[bad + 1])
        mid[:, 2] = np.maximum(mid[:, 2], height(mid[:, :2]))
        pts = np.insert(pts, bad + 1, mid, axis=0)
        kind = np.insert(kind, bad + 1, kind[bad + 1])
        depth = np.insert(depth, bad + 1, 0.0)
        # move bad[j] is now moves bad[j] + j and bad[j] + j + 1
        halves = np.sort(np.concatenate([bad + np.arange(bad.size), bad + np.arange(bad.size) + 1]))
        depth[halves] = _gouge(height, pts, ceiling, halves)[halves]
    if depth.size and depth.max() > 1e-9:
        pts, _, depth = lift_moves(height, pts, _gouge(height, pts, ceiling), 0.0)
        if depth.max() > 1e-6:
            raise SurfmodError(f"rough: no safe roughing path: a move still cuts {depth.max():.3g} into the allowance")
    return Motion(pts, kind)
