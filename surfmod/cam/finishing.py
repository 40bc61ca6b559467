"""Finishing in a job: the drop-cutter raster over the whole part, waterline (constant-Z)
contours on its steep regions, and a report of the rest the tool cannot reach.

Passes and levels are spaced by the scallop rule; every height is a drop-cutter height of
the tool grown by the mesh's deflection (:func:`surfmod.cam.toolpath.meshed_part` with
``clear=True``), never a vertical lift, and every move is judged as the raster's are; a
contour's chord that still cuts is split at exact contour points (:func:`_follow`) before
any move is lifted.  See :doc:`/guide/cam` (section "A job from stock").
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy import ndimage
from scipy.spatial import cKDTree

from ..errors import SurfmodError
from .cutters import Flat
from .drop_cutter import TriangleGrid, drop, upward_normals
from .roughing import FEED, PLUNGE, RAMP_ANGLE, RAPID, Moves
from .tool import Tool
from .toolpath import REFINE_SHARE, MeshedPart, raster_path
from .toolpath_moves import NoSafePathError, lift_moves, move_gouge
from .waterline import ContourPoints, fiber_pairs, sampling_within, waterline

#: Steep regions: slopes within this many degrees below the threshold count too (the
#: classification samples the drop-cutter surface, the raster's slope bound its triangles).
STEEP_MARGIN = 1.0
#: cross passes of a repair stand this share of the finishing's stepover apart (cos 45°)
RECUT_SHARE = math.cos(math.radians(45.0))
#: triangles within this slope (degrees) of level are floors: a waterline level runs just above each
FLOOR_SLOPE = 0.5
#: Clearance (mm) of entries and retracts above the highest stock the roughing can have left.
REST_CLEARANCE = 1.0
#: Grid spacing of the rest map: a tool radius over this, or the part's size over REST_CELLS.
REST_PER_RADIUS = 8
REST_CELLS = 500
#: Rounds of splitting a gouging waterline chord beyond the halvings that bring the longest
#: chord to the chord tolerance (a split lands near, not at, the middle).
SPLIT_SLACK = 3


@dataclass(frozen=True)
class Leftover:
    """What a roughing pass left: over any (x, y) column, stock at most ``above`` higher
    than the part's highest point within ``reach`` of the column (the roughing tool's
    radius plus its allowance: its grown tool stood at every column it could, levels
    ``stepdown`` apart); on a flat floor it cut at a level of its own, ``on_floors``
    (its allowance and its mesh's lift)."""

    reach: float
    above: float
    on_floors: float


class _StockTop:
    """The height above which no stock is left over the finishing tool's footprint."""

    def __init__(self, part: MeshedPart, tool: Tool, rest: Leftover | None, stock: np.ndarray, safe: float):
        self.part, self.rest, self.stock, self.safe = part, rest, stock, safe
        self.grid = None if rest is None else TriangleGrid(part.grid.triangles, tool.radius + rest.reach)

    def __call__(self, xy) -> np.ndarray:
        xy = np.asarray(xy, float).reshape(-1, 2)
        if self.grid is None:
            return np.full(len(xy), min(float(self.stock[1, 2]) + REST_CLEARANCE, self.safe))
        h = drop(self.grid, Flat(self.grid.radius), xy)  # the highest part point within the reach of the footprint
        h = np.nan_to_num(h, nan=float(self.stock[0, 2])) + self.part.lift + self.rest.above + REST_CLEARANCE
        return np.minimum(h, self.safe)


def _enter(out: Moves, p, top: float, part: MeshedPart, tool: Tool, safe: float, allowed: float):
    """From the clearance height over ``p``: rapid down to ``top`` (above any stock left),
    then a ball plunges, a flat or bull end descends by a helix onto ``p`` (half its radius
    wide, narrower where the part stands within it: the helix may not rise above the part's
    drop heights and then fall onto ``p``; a plunge when even an eighth of the radius does)."""
    out.add([[p[0], p[1], safe]], RAPID)
    start = np.array([p[0], p[1], max(top, p[2])])
    if not tool.cutter.plunges and top > p[2]:
        for rho in tool.radius / np.array([2.0, 4.0, 8.0]):
            turns = max(1, int(np.ceil((top - p[2]) / np.tan(np.radians(RAMP_ANGLE)) / (2 * np.pi * rho))))
            t = np.linspace(0, 1, 48 * turns + 1)
            ang = 2 * np.pi * turns * t
            helix = p[:2] + rho * np.column_stack([np.cos(ang) - 1, np.sin(ang)])
            hz = np.maximum(top - (top - p[2]) * t, np.nan_to_num(part.height(helix), nan=-np.inf))
            hz[-1] = p[2]
            pts = np.column_stack([helix, hz])
            if move_gouge(part.height, pts).max() <= REFINE_SHARE * allowed:
                out.add([[helix[0, 0], helix[0, 1], max(top, hz[0])]], RAPID)
                out.add(pts, PLUNGE)
                return
    out.add([start], RAPID)
    out.add([p], PLUNGE)


def _leave(out: Moves, top: float, safe: float):
    """Up at the feed to above the stock left, then rapidly to the clearance height."""
    p = out.last
    if p[2] < top:
        out.add([[p[0], p[1], top]], FEED)
    out.add([[p[0], p[1], safe]], RAPID)


def add_raster(out: Moves, pts: np.ndarray, top, part: MeshedPart, tool: Tool, safe: float, allowed: float, what: str):
    """A raster's cutter locations ``pts`` added to ``out``: entered from the clearance
    height (the entry judged on the drop-cutter heights), cut, and left above the stock."""
    before = sum(len(q) for q in out.points)
    _enter(out, pts[0], float(top(pts[:1, :2])[0]), part, tool, safe, allowed)
    entry = np.concatenate(out.points)[max(before - 1, 0):]
    if move_gouge(part.height, entry).max() > allowed:
        raise NoSafePathError(f"toolpath: no safe path: {what} cuts the part")
    out.add(pts[1:], FEED)
    _leave(out, float(top(pts[-1:, :2])[0]), safe)


def _slopes(tri: np.ndarray):
    """The triangles' upward unit normals and their slopes (degrees)."""
    n = upward_normals(tri)
    return n, np.degrees(np.arccos(np.clip(n[:, 2], -1, 1)))


def _levels(tri, slope, steep, spacing, top, bottom, reach):
    """Tip heights from ``top`` down to ``bottom``: each next one ``spacing · sin θ_min``
    lower, ``θ_min`` the least slope of the steep triangles within the tool's reach of the
    band; heights with no steep triangle near are skipped."""
    lo_t, hi_t = tri[steep, :, 2].min(axis=1), tri[steep, :, 2].max(axis=1)
    s_sl = np.sin(np.radians(slope[steep]))

    def near(z):
        return (hi_t >= z - spacing) & (lo_t <= z + reach + spacing)

    out, z = [], top
    while z > bottom:
        here = near(z)
        if here.any():
            out.append(z)
            z -= spacing * float(s_sl[here].min())
        else:  # jump down to the next steep triangle
            below = hi_t[hi_t < z - spacing]
            if not len(below):
                break
            z = float(below.max()) + 0.5 * spacing
    if z <= bottom and near(bottom).any() and (not out or out[-1] > bottom + 1e-9):
        out.append(bottom)
    return np.array(out, float)


def _with_floors(levels: np.ndarray, tri: np.ndarray, slope: np.ndarray, bottom: float, above) -> np.ndarray:
    """``levels`` plus a level at each offset in ``above`` from each flat floor (triangles
    within ``FLOOR_SLOPE`` of level) between the lowest and the highest level: the contour
    along a wall's foot, and the lowest the holder lets the tool go beside that floor.
    Levels spaced along the wall rarely fall on a floor, and the raster's passes across
    the fillet the tool leaves there are too far apart on its slope (a ring of 0.1-0.3 mm
    round a boss or a pocket wall, for a scallop of 0.03-0.08)."""
    if not len(levels):
        return levels
    flat = slope < FLOOR_SLOPE
    heights = np.unique(np.round(tri[flat, :, 2].mean(axis=1), 9))
    floors = np.concatenate([heights + a for a in np.atleast_1d(above)])
    floors = floors[(floors >= max(bottom, levels.min())) & (floors <= levels.max())]
    merged = np.unique(np.concatenate([levels, floors]))[::-1]
    keep = np.r_[True, -np.diff(merged) > 1e-6]
    return merged[keep]


def _pieces(loop: np.ndarray, keep: np.ndarray):
    """Runs of ``keep`` along a closed ``loop``, each grown by one point at either end;
    the whole loop closed (first point repeated) when all of it is kept."""
    n = len(loop)
    if keep.all():
        return [np.vstack([loop, loop[:1]])]
    k0 = int(np.argmin(keep))
    idx = np.roll(np.arange(n), -k0)
    flags = keep[idx]
    out, start = [], None
    for i in range(n + 1):
        on = flags[i] if i < n else False
        if on and start is None:
            start = i
        elif not on and start is not None:
            sel = idx[np.arange(start - 1, i + 1) % n]
            out.append(loop[sel])
            start = None
    return out


def _chord(part: MeshedPart, tool: Tool, tolerance: float) -> float:
    """Chord tolerance of the contours (their margin from the mesh is it plus the mesh's deflection)."""
    return max(min(tolerance / 8, 1e-3 * tool.radius), 1e-7 * float(np.max(part.box[1] - part.box[0])))


def _judge(part: MeshedPart, pts: np.ndarray, allowed: float, depth: np.ndarray | None = None):
    """Gouge-check one polyline (``depth`` its per-move depth when known); lift what would
    cut (returns points, lift, the deepest a move then cuts)."""
    if len(pts) < 2:
        return pts, 0.0, -np.inf
    if depth is None:
        depth = move_gouge(part.height, pts)
    if depth.max() <= allowed:
        return pts, 0.0, float(depth.max())
    pts, lift, depth = lift_moves(part.height, pts, depth, REFINE_SHARE * allowed)
    if depth.max() > allowed:
        raise NoSafePathError(f"toolpath: no safe path: a waterline move still cuts {depth.max():.3g} deep")
    return pts, float(lift.max()), float(depth.max())


def _follow(part: MeshedPart, contour: ContourPoints, z: float, piece: np.ndarray, depth: np.ndarray, allowed: float,
            shortest: float):
    """``piece`` (tip height ``z`` + the contours' margin above the waterline's own ``z``)
    with every chord cutting deeper than ``allowed`` split at the exact contour point
    near its middle, round after round, so a chord whose middle lay on the contour while
    the contour left it between (a notch) follows it.  Chords no longer than ``shortest``
    are not split; the rounds are bounded before they start by the halvings that bring
    the longest chord down to ``shortest`` (plus ``SPLIT_SLACK``).  Returns the piece and
    its per-move depth."""
    longest = float(np.linalg.norm(np.diff(piece[:, :2], axis=0), axis=1).max())
    rounds = math.ceil(math.log2(max(longest / shortest, 1.0))) + SPLIT_SLACK
    for _ in range(rounds):
        length = np.linalg.norm(np.diff(piece[:, :2], axis=0), axis=1)
        bad = np.flatnonzero((depth > allowed) & (length > shortest))
        if not len(bad):
            break
        xy = contour.split(z, piece[:, :2], bad)
        piece = np.column_stack([xy, np.full(len(xy), piece[0, 2])])
        depth = move_gouge(part.height, piece)
    return piece, depth


def near_box(part: MeshedPart, tool: Tool, box) -> np.ndarray:
    """The triangles of ``part`` within two radii of ``tool`` (grown by the mesh's
    deflection) of the (x, y) ``box`` ``[[x0, y0], [x1, y1]]``: every triangle the tool
    standing over the box can touch."""
    tri, box = part.grid.triangles, np.asarray(box, float)
    reach = 2 * (tool.radius + part.deflection)
    near = (np.all(tri[:, :, :2].min(axis=1) <= box[1] + reach, axis=1)
            & np.all(tri[:, :, :2].max(axis=1) >= box[0] - reach, axis=1))
    return tri[near]


def _waterline_pieces(part: MeshedPart, tool: Tool, steep_angle: float, spacing: float, tolerance: float, bottom: float,
                      box: np.ndarray | None = None, keep=None, highest: float = math.inf, left: float = 0.0,
                      clear: float = 0.0):
    """The steep pieces of the waterline contours of ``tool`` round ``part``, levels from
    the top of its steep triangles (slope ≥ ``steep_angle``, no higher than ``highest``)
    down to ``bottom``, ``spacing`` the distance of neighbouring levels along the walls.
    With an (x, y) ``box`` ``[[x0, y0], [x1, y1]]`` only the triangles within two tool
    radii of it are contoured (so the contours are exact for the tool standing over the
    box), and ``keep(xy, z)`` (True where a contour point at tip height ``z`` is wanted)
    narrows the steep pieces further; ``left``: the stock a floor may still hold when the
    contours run (a roughing's); ``clear``: how far the job holds a holder disc above the
    stock (the cusps its model cannot see, :func:`surfmod.cam.job.machine`).  Returns
    ``(pieces, info)``: pieces per level (top first), each ``(points (N, 3), deepest)``
    (closed ones with their first point repeated; the deepest any of its moves cuts,
    judged on the drop-cutter heights), and a report dict."""
    tri = part.grid.triangles if box is None else near_box(part, tool, box)
    _, slope = _slopes(tri)
    steep = slope >= steep_angle - STEEP_MARGIN
    info = {"levels": 0, "z_spacing": (0.0, 0.0), "contours": 0, "length": 0.0, "spacing": spacing, "lifted": 0.0}
    if not steep.any():
        return [], info
    chord = _chord(part, tool, tolerance)
    g = chord + part.deflection  # the tool keeps the mesh's whole deflection from it (walls amplify any gouge)
    levels = _levels(tri, slope, steep, spacing, min(float(tri[steep, :, 2].max()), highest), bottom,
                     tool.corner + tool.radius)
    foot = g + 0.5 * tolerance
    # below a floor's height less the holder's (its lowest disc wider than the end) the
    # holder would stand on that floor and the job leaves those contours out: a contour
    # just above (by ``clear`` too), on a clear floor and on one holding ``left``, cuts the
    # wall down to there
    wider = [h for r, h, _ in tool.body if r > tool.radius]
    holder = [foot + m + clear - wider[0] for m in sorted({0.0, left})] if wider else []
    levels = _with_floors(levels, tri, slope, bottom, [foot] + holder)
    if not len(levels):
        return [], info
    grown = tool.cutter.grown(g)
    # fibers half a radius apart, spread up to a radius (a contour round any feature is
    # a tool wide, so fibers a radius apart still meet it) where a big part's fibers over
    # all its levels would pass the waterline's cap; beyond that the scallop (which spaces
    # the levels) or the tool must change, and the refusal names the command's --scallop
    sampling = sampling_within(tri, grown.radius, tool.radius / 2, levels - g, tool.radius, grown.corner)
    if sampling is None:
        most = fiber_pairs(tri, grown.radius, tool.radius, levels - g, grown.corner)
        raise SurfmodError(f"scallop: the waterline's {len(levels)} levels {spacing:.3g} mm apart on this part's "
                           f"{len(tri):,} triangles pass its cap even with fibers a tool radius apart "
                           f"(about {most:.3g} fiber-triangle pairs); choose a larger scallop or a larger finishing "
                           f"tool")
    if sampling > tool.radius / 2:
        info["sampling"] = sampling
    bar = part.meter.bar  # the finishing's bar names the waterline's level while it runs
    desc = bar.desc if bar is not None else ""
    loops, fibers = waterline(tri, grown, levels - g, sampling=sampling, tolerance=chord, bar=bar, fibers=True)
    if bar is not None:
        bar.set_description_str(desc)
    contour = None  # built at the first gouging chord (most parts have none)
    allowed = tolerance - part.deflection + part.lift
    w = 0.25 * spacing
    bottom_z = bottom
    out, lifted, count, length, split = [], 0.0, 0, 0.0, 0
    for z, level in zip(levels, loops):
        pieces = []
        for loop in level:
            xy = loop[:, :2]
            tangent = np.roll(xy, -1, axis=0) - np.roll(xy, 1, axis=0)
            tangent /= np.maximum(np.linalg.norm(tangent, axis=1), 1e-300)[:, None]
            outward = np.column_stack([tangent[:, 1], -tangent[:, 0]])  # the material lies on the left
            h_in = np.nan_to_num(part.height(xy - w * outward), nan=bottom_z)
            h_out = np.nan_to_num(part.height(xy + w * outward), nan=bottom_z)
            cl_slope = np.degrees(np.arctan2(np.maximum(h_in - h_out, 0.0), 2 * w))
            wanted = cl_slope >= steep_angle - STEEP_MARGIN
            if keep is not None:
                wanted &= keep(xy, z)
            if not wanted.any():
                continue
            for piece in _pieces(np.column_stack([xy, np.full(len(xy), z)]), wanted):
                if len(piece) < 2:
                    continue
                depth = move_gouge(part.height, piece)
                if depth.max() > allowed:  # a chord crosses a notch its middle missed: follow the contour
                    if contour is None:
                        contour = ContourPoints(tri, grown, 1.5 * sampling, fibers)  # the waterline's own
                    piece, depth = _follow(part, contour, z - g, piece, depth, allowed, chord)
                    split += 1
                piece, lift, deepest = _judge(part, piece, allowed, depth)
                lifted = max(lifted, lift)
                pieces.append((piece, deepest))
                count += 1
                length += float(np.linalg.norm(np.diff(piece, axis=0), axis=1).sum())
        out.append(pieces)
    gaps = -np.diff(levels)
    info.update(levels=len(levels), z_spacing=(float(gaps.min()) if len(gaps) else 0.0,
                                               float(gaps.max()) if len(gaps) else 0.0),
                contours=count, length=length, lifted=lifted, split=split, top=float(levels[0]), bottom=float(levels[-1]),
                margin=g)
    return out, info


def contour_spacing(part: MeshedPart, tool: Tool, scallop: float, tolerance: float, stepover: float | None):
    """The distance of neighbouring contours along a wall for cusps within ``scallop``
    (``stepover`` for a tool without a corner), and whether that holds the scallop
    (:func:`_budget`): the contours keep a chord + the deflection from the mesh, give or
    take a chord, and the mesh lies within the deflection of the faces."""
    budget, held = _budget(scallop, 2 * part.deflection + 2 * _chord(part, tool, tolerance))
    return (tool.cutter.cusp_spacing(budget) if tool.corner > 0 else stepover), held


def contour_moves(out: Moves, part: MeshedPart, tool: Tool, top, safe: float, steep_angle: float, spacing: float,
                  tolerance: float, bottom: float, **where) -> dict:
    """The steep pieces of the waterline contours (:func:`_waterline_pieces`, ``where``
    its ``box``, ``keep`` and ``highest``) appended to ``out`` level by level, linked
    (:func:`_order_pieces`) and left above the stock ``top(xy)`` gives; returns their report."""
    levels, info = _waterline_pieces(part, tool, steep_angle, spacing, tolerance, bottom, **where)
    if any(levels):
        info["links"] = _order_pieces(out, levels, part, tool, top, safe, tolerance, 1.5 * spacing)
        _leave(out, float(top(out.last[None, :2])[0]), safe)
    return info


def judge_links(part: MeshedPart, out: Moves, allowed: float, what: str, first: int = 0) -> np.ndarray:
    """Every move in ``out`` from its run ``first`` on (the contours' links, entries and
    retracts among them) judged on the drop-cutter heights, but the moves inside runs
    judged as they were made (``out.judged``: the contours' pieces; the rasters before
    ``first``): the depth of each move judged here and the deepest of each run skipped,
    or ``NoSafePathError`` naming the first deepest.  (Judging the pieces again took 5 of
    the 280 mm mould's 140 s.)"""
    if len(out.points) <= first:
        return np.full(1, -np.inf)
    runs = out.points[first:]
    pts = np.concatenate(runs)
    again = np.ones(len(pts) - 1, bool)
    start = np.r_[0, np.cumsum([len(r) for r in runs])]
    known = []
    for k, run in enumerate(runs, start=first):
        if k in out.judged:
            again[start[k - first]:start[k - first] + len(run) - 1] = False  # the moves within the run
            known.append(out.judged[k])
    moves = np.flatnonzero(again)
    depth = move_gouge(part.height, pts, moves)
    if len(depth) and depth.max() > allowed:
        k = int(moves[np.argmax(depth)])
        raise NoSafePathError(f"toolpath: no safe path: {what} move {k + 1} cuts {depth.max():.3g} deep")
    return np.r_[depth, known, -np.inf]


def _link_clear(part: MeshedPart, a, b, allowed: float, step: float) -> np.ndarray | None:
    """The straight move a -> b sampled ``step`` apart, if it stays clear of the part."""
    n = int(np.ceil(np.linalg.norm(b[:2] - a[:2]) / step)) + 1
    pts = a + np.linspace(0, 1, n + 1)[:, None] * (b - a)
    if move_gouge(part.height, pts).max() > REFINE_SHARE * allowed:
        return None
    return pts[1:]


def _budget(scallop: float, margin: float):
    """The cusp height passes are spaced for: the scallop less ``margin``, and whether that
    holds the scallop (a mesh coarser than the scallop, as some faces of real parts cannot be
    meshed finer than their own tolerance, gets half the scallop and no promise).

    >>> [tuple(round(v, 6) for v in _budget(0.05, m)) for m in (0.02, 0.2)]
    [(0.03, 1), (0.025, 0)]
    """
    if scallop - margin >= scallop / 4:
        return scallop - margin, True
    return scallop / 2, False  # no promise either way: not a raster ten times denser for nothing


def _order_pieces(out: Moves, levels, part: MeshedPart, tool: Tool, top: _StockTop, safe: float, tolerance: float,
                 max_down: float):
    """Append the pieces level by level (top first), each level's nearest first, linked
    along the part where short and clear, else up and over."""
    allowed = tolerance - part.deflection + part.lift
    links = 0
    for pieces in levels:
        todo = [pc for pc, _ in pieces]
        deepest = [d for _, d in pieces]
        while todo:
            # the first piece is entered from the clearance height over its own start
            here = out.last if out.points else np.array([todo[0][0, 0], todo[0][0, 1], safe])
            best, best_d, best_k = None, np.inf, 0
            for j, pc in enumerate(todo):
                closed = len(pc) > 2 and np.all(pc[0] == pc[-1])
                cand = pc[:-1] if closed else pc[:1]
                d = np.linalg.norm(cand[:, :2] - here[:2], axis=1)
                k = int(np.argmin(d))
                if d[k] < best_d:
                    best, best_d, best_k = j, float(d[k]), k
            pc, judged = todo.pop(best), deepest.pop(best)
            if len(pc) > 2 and np.all(pc[0] == pc[-1]) and best_k:
                pc = np.vstack([pc[best_k:-1], pc[:best_k + 1]])
            drop_z = here[2] - pc[0, 2]
            path = None
            if here[2] < safe and best_d <= tool.radius and -1e-9 <= drop_z <= max_down:
                path = _link_clear(part, here, pc[0], allowed, tool.radius / 8)
            if path is not None:
                out.add(path, PLUNGE if drop_z > 1e-9 else FEED)
                links += 1
            else:
                if here[2] < safe:
                    _leave(out, float(top(here[None, :2])[0]), safe)
                _enter(out, pc[0], float(top(pc[:1, :2])[0]), part, tool, safe, allowed)
            out.add(pc[1:], FEED, judged)  # its moves from pc[1] on were judged as it was made
    return links


def _raster_passes(part: MeshedPart, tool: Tool, scallop: float, steep_angle: float | None, direction: str,
                   lo: float, hi: float):
    """Cross positions of the raster's passes for cusps of ``scallop`` across the ground
    between them: each next pass ``s · cos φ`` further, ``φ`` the steepest cross slope of
    the part's triangles below ``steep_angle`` (all of them when None) within the tool's
    radius of the two passes, from ``lo`` to ``hi``.  Returns ``(positions, steepest φ in degrees)``."""
    tri = part.grid.triangles
    n, slope = _slopes(tri)
    shallow = slope < (90.0 if steep_angle is None else steep_angle)
    axis = 1 if direction == "x" else 0
    cross = np.minimum(np.degrees(np.arctan2(np.abs(n[shallow, axis]), n[shallow, 2])), 89.0)
    t_lo, t_hi = tri[shallow, :, axis].min(axis=1), tri[shallow, :, axis].max(axis=1)
    circ = tool.cutter.cusp_spacing(scallop)
    R = tool.radius
    out, steepest = [float(lo)], 0.0
    while out[-1] < hi - 1e-9:
        y = out[-1]
        near = (t_hi >= y - R) & (t_lo <= y + circ + 2.0 * tool.core + R)
        phi = float(cross[near].max()) if near.any() else 0.0
        steepest = max(steepest, phi)
        gap = tool.cutter.pass_gap(circ, phi)
        out.append(min(y + min(gap, tool.diameter), hi))
    return np.array(out), steepest


# ----------------------------------------------------------------------------------------------
# rest

def height_field(tri: np.ndarray, x: np.ndarray, y: np.ndarray, block: int = 2_000_000) -> np.ndarray:
    """Highest triangle over each node of the grid ``x`` × ``y`` (-inf where none).

    >>> tri = np.array([[[0, 0, 1], [2, 0, 1], [0, 2, 3]]], float)
    >>> height_field(tri, np.array([0.5, 3.0]), np.array([0.5])).tolist()
    [[1.5], [-inf]]
    """
    top = np.full((len(x), len(y)), -np.inf)
    lo, hi = tri[:, :, :2].min(axis=1), tri[:, :, :2].max(axis=1)
    i0, i1 = np.searchsorted(x, lo[:, 0] - 1e-12), np.searchsorted(x, hi[:, 0] + 1e-12, "right")
    j0, j1 = np.searchsorted(y, lo[:, 1] - 1e-12), np.searchsorted(y, hi[:, 1] + 1e-12, "right")
    ni, nj = np.maximum(i1 - i0, 0), np.maximum(j1 - j0, 0)
    counts = ni * nj
    edges = np.r_[0, np.cumsum(counts)]
    s0 = 0
    while s0 < len(counts):
        # triangles in blocks of at most `block` (triangle, node) pairs
        s_next = max(int(np.searchsorted(edges, edges[s0] + block, "right")) - 1, s0 + 1)
        ids = np.arange(s0, min(s_next, len(counts)))
        s0 = s_next
        c = counts[ids]
        t = np.repeat(ids, c)
        local = np.arange(c.sum()) - np.repeat(np.cumsum(c) - c, c)
        ii = i0[t] + local // np.maximum(nj[t], 1)
        jj = j0[t] + local % np.maximum(nj[t], 1)
        A, v0, v1 = tri[t, 0], tri[t, 1] - tri[t, 0], tri[t, 2] - tri[t, 0]
        den = v0[:, 0] * v1[:, 1] - v1[:, 0] * v0[:, 1]
        good = np.abs(den) > 1e-300
        den = np.where(good, den, 1.0)
        wx, wy = x[ii] - A[:, 0], y[jj] - A[:, 1]
        l1 = (wx * v1[:, 1] - v1[:, 0] * wy) / den
        l2 = (v0[:, 0] * wy - wx * v0[:, 1]) / den
        inside = good & (l1 >= -1e-12) & (l2 >= -1e-12) & (l1 + l2 <= 1 + 1e-12)
        z = A[:, 2] + l1 * v0[:, 2] + l2 * v1[:, 2]
        np.maximum.at(top, (ii[inside], jj[inside]), z[inside])
    return top


def rest_left(part: MeshedPart, tool: Tool, floor: float, threshold: float, spacing: float | None = None) -> dict:
    """Where ``tool`` cannot reach the part's top-visible surface by more than
    ``threshold``: ``area`` (mm²), ``max_depth`` (vertical, mm), ``box``
    ``[[x0, y0], [x1, y1]]`` (None when nowhere), ``regions``, the grid ``spacing`` and
    ``map`` ``(x, y, rest)``: the nodes and the height of the rest over each (NaN off the part).
    ``floor``: the lowest the tool may go where it touches nothing (the stock's bottom)."""
    tri = part.grid.triangles
    lo, hi = part.box
    h = float(spacing) if spacing else max(tool.radius / REST_PER_RADIUS, float(np.max(hi[:2] - lo[:2])) / REST_CELLS)
    x = np.arange(lo[0], hi[0] + 0.5 * h, h)
    y = np.arange(lo[1], hi[1] + 0.5 * h, h)
    top = height_field(tri, x, y)
    m = int(math.floor(tool.radius / h))
    px = lo[0] + h * np.arange(-m, len(x) + m)
    py = lo[1] + h * np.arange(-m, len(y) + m)
    PX, PY = np.meshgrid(px, py, indexing="ij")
    cl = part.height(np.column_stack([PX.ravel(), PY.ravel()])).reshape(PX.shape)
    cl = np.maximum(np.nan_to_num(cl, nan=floor), floor)
    reach = np.full(top.shape, np.inf)
    di, dj = np.mgrid[-m:m + 1, -m:m + 1]
    d = h * np.hypot(di, dj)
    ok = d <= tool.radius
    for a, b, f in zip(di[ok], dj[ok], tool.profile(d[ok])):
        np.minimum(reach, cl[m + a:m + a + len(x), m + b:m + b + len(y)] + f, out=reach)
    rest = np.where(np.isfinite(top), reach - top, -np.inf)
    mask = rest > threshold
    out = {"area": float(mask.sum() * h * h), "max_depth": float(rest[mask].max()) if mask.any() else 0.0,
           "box": None, "regions": 0, "spacing": h, "threshold": threshold,
           "map": (x, y, np.where(np.isfinite(rest), rest, np.nan))}
    if mask.any():
        ii, jj = np.nonzero(mask)
        out["box"] = [[float(x[ii.min()]), float(y[jj.min()])], [float(x[ii.max()]), float(y[jj.max()])]]
        out["regions"] = int(ndimage.label(mask, structure=np.ones((3, 3)))[1])
    return out


# ----------------------------------------------------------------------------------------------

def finish(part: MeshedPart, tool: Tool, *, scallop: float | None, stepover: float | None, direction: str,
           steep_angle: float | None, tolerance: float, stock: np.ndarray, safe: float, rest: Leftover | None):
    """The finishing :class:`~surfmod.cam.roughing.Motion` (the raster, then waterline
    pieces on the steep regions, cut once the floors beside them are clear) and its
    report; the contours go down to the stock's bottom (how deep the tool may go is its
    shank's and holder's to say: the job holds every move against them,
    :mod:`surfmod.cam.holder`)."""
    margin = part.lift + part.deflection  # what exactness costs the scallop (see the module doc)
    held = True
    if scallop is not None:
        budget, held = _budget(scallop, margin)
    else:
        budget = None
    # the raster runs beyond the part's box until a pass's contact reaches the rim: on ground
    # falling by θ towards it the tool touches its core plus c sin θ uphill of its axis
    _, slope = _slopes(part.grid.triangles)
    shallow = slope[slope < (90.0 if steep_angle is None else steep_angle)]
    theta = float(shallow.max()) if len(shallow) else 0.0
    overhang = tool.core + tool.corner * math.sin(math.radians(theta)) if theta > 1e-6 else 0.0
    bounds = (part.box[0, :2] - overhang, part.box[1, :2] + overhang)
    if budget is not None:
        axis = 1 if direction == "x" else 0
        across, phi = _raster_passes(part, tool, budget, steep_angle, direction, bounds[0][axis], bounds[1][axis])
        step_xy = float(np.diff(across).max()) if len(across) > 1 else tool.radius
    else:
        across, step_xy, phi = None, stepover, 0.0
    top = _StockTop(part, tool, rest, stock, safe)
    # the raster first: its work is estimated (and refused above the part's meter) before
    # any drop of the finishing, the contours' included
    path = raster_path(part, tool, step_xy, tool.radius / 4, direction, bounds, tolerance, part.meter.bar,
                       across=across, meter=part.meter)
    out = Moves()
    allowed = tolerance - part.deflection + part.lift
    # the raster before the contours: the floors are clear when a contour's holder comes
    # down beside them, so the walls are cut down to the holder's limit over a clear floor
    add_raster(out, path.points, top, part, tool, safe, allowed, "the raster's entry")
    wl_info, depth = None, np.full(1, -np.inf)
    if steep_angle is not None:
        if scallop is not None:
            spacing, wl_held = contour_spacing(part, tool, scallop, tolerance, stepover)
            held = held and wl_held
        else:
            spacing = stepover
        first = len(out.points)
        wl_info = contour_moves(out, part, tool, top, safe, steep_angle, spacing, tolerance, float(stock[0, 2]),
                                left=0.0 if rest is None else rest.on_floors + tolerance,
                                clear=(scallop if scallop is not None else path.scallop) + tolerance)
        depth = judge_links(part, out, allowed, "finishing", first)  # the raster was judged as it was made
    motion = out.motion()
    threshold = scallop if scallop is not None else max(tool.scallop_for_stepover(step_xy), tolerance)
    report = {"stepover": path.stepover, "scallop": scallop if scallop is not None else path.scallop,
              "scallop_held": held, "deflection": part.deflection,
              "gouge": max(float(depth.max()) - part.lift, path.gouge),
              "lifted": max(path.lifted, (wl_info or {}).get("lifted", 0.0)),
              "tolerance": tolerance, "toolpath": path, "steep_angle": steep_angle,
              "raster": {"stepover": path.stepover, "least_stepover": float(np.diff(_path_across(path)).min())
                         if path.n_passes > 1 else 0.0, "passes": path.n_passes, "length": path.length,
                         "cross_slope": phi, "margin": margin, "overhang": overhang},
              "waterline": wl_info,
              "rest": rest_left(part, tool, float(stock[0, 2]), threshold)}
    return motion, report


def recut(part: MeshedPart, tool: Tool, boxes, *, stepover: float, direction: str, tolerance: float,
          stock: np.ndarray, safe: float, rest: Leftover | None, over: float = 1.0, raster=None):
    """Cross passes over the regions a finishing left too much on: a drop-cutter raster
    across ``direction`` over each box ``(x0, y0, x1, y1)`` grown by the tool radius, each
    entered and left as the finishing's raster is.  Returns the :class:`Motion` (from and
    back to the clearance height) and the number of passes; a box the tool touches nowhere
    is skipped.  Walls and the fillets a tool leaves along them that run parallel to the
    raster are crossed by these passes, so their cusps stand a stepover apart across them.

    ``over`` is how many times the residual found passed its bound: the passes stand
    closer by its square root (down to a quarter).  A cusp on concave ground grows as
    ``s²/(8(ρ - c))`` (see the module), unbounded where the ground is the tool's own
    closing: over a hole a ball dips into (Analysis Situs' nist_ctc_02, ball r 26 over
    holes of r 7.5) passes at the finishing's spacing left 1.91 mm against 0.29, cross
    passes at 0.71 of it still 0.32.

    With the finishing's ``raster`` (its :class:`~surfmod.cam.toolpath.Toolpath`), passes
    along ``direction`` between its passes over each box are added too, each gap split in
    ``max(2, ceil(2 sqrt(over)))``.  Where a raster pass turns from shallow ground up a
    wall it runs up, the ground the tool leaves beside the turn is its ball's side (HEAD_BACK beside its seam's step: the surface the
    tool reaches there slopes 43 degrees, formed by one ball position at a corner of the
    drop-cutter surface).  There the rest grows with the passes' distance from that
    position: linearly for cross passes (they miss it along the wall's slope), only
    quadratically for passes along the raster (they miss it sideways)."""
    other = "y" if direction == "x" else "x"
    top = _StockTop(part, tool, rest, stock, safe)
    allowed = tolerance - part.deflection + part.lift
    axis = 1 if direction == "x" else 0
    between = None
    if raster is not None and raster.n_passes > 1:
        # each gap split in n: the rest there falls with the square of the passes' distance
        n = max(2, math.ceil(2.0 * math.sqrt(over)))
        done = _path_across(raster)
        between = (done[:-1, None] + np.diff(done)[:, None] * np.arange(1, n) / n).ravel()
    out, passes = Moves(), 0
    for x0, y0, x1, y1 in _merged(np.asarray(boxes, float).reshape(-1, 4), tool.radius):
        bounds = np.array([[x0, y0], [x1, y1]])
        # passes closer by cos 45°: the cusps hold on slopes across them up to the
        # waterline's threshold (the finishing's raster adapts its spacing; these do not)
        runs = [(other, stepover * RECUT_SHARE / min(max(math.sqrt(over), 1.0), 4.0), None)]
        if between is not None:
            inside = between[(between >= bounds[0, axis]) & (between <= bounds[1, axis])]
            if len(inside):
                runs.append((direction, stepover, inside))
        for way, step, across in runs:
            try:
                path = raster_path(part, tool, step, tool.radius / 4, way, bounds, tolerance, across=across)
            except SurfmodError as exc:
                if str(exc).startswith("bounds:"):
                    continue  # the tool touches no face there
                raise
            add_raster(out, path.points, top, part, tool, safe, allowed, "a cross pass's entry")
            passes += path.n_passes
    return out.motion(), passes


def reach_contours(part: MeshedPart, tool: Tool, groups, *, spacing: float, steep_angle: float, tolerance: float,
                   safe: float, stock: np.ndarray | None = None, rest: Leftover | None = None, top=None):
    """One waterline level per group ``(z, moves)`` of :func:`surfmod.cam.holder.reach_levels`
    (where the job's holder check left contours out, the lowest height the shank and holder
    let the tool cut there), its steep pieces kept within the tool's radius, and the rise,
    of the moves left out; linked, entered and left as the finishing's contours (the stock
    over them from ``stock`` and ``rest``, or ``top``: a rest operation's, from its stock
    model).  Returns the :class:`Motion` (from and back to the clearance height)."""
    top = _StockTop(part, tool, rest, stock, safe) if top is None else top
    out = Moves()
    for z, moves in groups:
        ends = moves[:, :, :2]
        n = np.maximum(np.ceil(np.linalg.norm(ends[:, 1] - ends[:, 0], axis=1) / (tool.radius / 4)), 1).astype(int)
        t = np.concatenate([np.linspace(0.0, 1.0, k + 1) for k in n])
        xy = np.repeat(ends[:, 0], n + 1, axis=0) + t[:, None] * np.repeat(ends[:, 1] - ends[:, 0], n + 1, axis=0)
        reach = tool.radius + z - float(moves[:, 0, 2].min())
        tree = cKDTree(xy)

        def keep(p, _z, tree=tree, reach=reach):
            return tree.query(p, distance_upper_bound=reach)[0] <= reach

        contour_moves(out, part, tool, top, safe, steep_angle, spacing, tolerance, z, highest=z, keep=keep,
                      box=[xy.min(axis=0) - reach, xy.max(axis=0) + reach])
    judge_links(part, out, tolerance - part.deflection + part.lift, "finishing")
    return out.motion()


def _merged(boxes: np.ndarray, grow: float) -> list:
    """The boxes grown by ``grow``, overlapping ones merged into their common box until
    none overlap (each merge removes a box, so at most ``len(boxes)`` rounds)."""
    out = [b + [-grow, -grow, grow, grow] for b in boxes]
    merged = True
    while merged:
        merged = False
        for i in range(len(out)):
            for j in range(i + 1, len(out)):
                a, b = out[i], out[j]
                if a[0] <= b[2] and b[0] <= a[2] and a[1] <= b[3] and b[1] <= a[3]:
                    out[i] = np.r_[np.minimum(a[:2], b[:2]), np.maximum(a[2:], b[2:])]
                    del out[j]
                    merged = True
                    break
            if merged:
                break
    return out


def _path_across(path) -> np.ndarray:
    """The cross positions of a raster's passes."""
    axis = 1 if path.direction == "x" else 0
    on = path.pass_index >= 0
    first = np.r_[True, path.pass_index[on][1:] != path.pass_index[on][:-1]]
    return path.points[on][first, axis]


def summary_lines(report: dict) -> list[str]:
    """The finishing report as lines for the ``surfmod machine`` summary.

    >>> summary_lines({"rest": {"box": None, "threshold": 0.05}})
    ['rest: the tool reaches everywhere within 0.05 mm']
    """
    lines = []
    r = report.get("raster")
    if r:
        lines.append(f"raster: {r['passes']} passes {r['least_stepover']:.4g}-{r['stepover']:.4g} mm apart (cross "
                     f"slopes up to {r['cross_slope']:.1f} deg), length {r['length']:.0f} mm")
    w = report.get("waterline")
    if w and w["levels"]:
        z0, z1 = round(w["bottom"], 3) + 0.0, round(w["top"], 3) + 0.0  # no "-0"
        lines.append(f"waterline on slopes >= {report['steep_angle']:g} deg: {w['levels']} levels "
                     f"{w['z_spacing'][0]:.3g}-{w['z_spacing'][1]:.3g} mm apart (z {z0:g} to {z1:g}), "
                     f"{w['contours']} contours, length {w['length']:.0f} mm"
                     + (f", {w['split']} chords split at the contour where they would cut the part"
                        if w.get("split") else "")
                     + (f", {w['at_reach']} more level(s) where the holder kept contours out, at the lowest "
                        "it lets the tool cut" if w.get("at_reach") else "")
                     + (f"; fibers {w['sampling']:.3g} mm apart, spread from half the tool radius to fit the "
                        "waterline's cap" if w.get("sampling") else ""))
    elif w is not None:
        lines.append(f"waterline: no slopes >= {report['steep_angle']:g} deg")
    if not report.get("scallop_held", True):
        lines.append(f"scallop not held: the mesh's deflection {report['deflection']:.3g} mm (the faces' own "
                     f"tolerance) is too large for {report['scallop']:g}; passes spaced for half of it")
    again = report.get("recut")
    if again:
        lines.append(f"re-cut: the scallop was broken in {again['regions']} region(s) (up to {again['before']:.3g} mm): "
                     f"{again['passes']} cross passes, length {again['length']:.0f} mm")
    rest = report.get("rest")
    if rest:
        if rest["box"] is None:
            lines.append(f"rest: the tool reaches everywhere within {rest['threshold']:.3g} mm")
        else:
            (x0, y0), (x1, y1) = rest["box"]
            lines.append(f"rest not reached (more than {rest['threshold']:.3g} mm, left for a smaller tool): "
                         f"area {rest['area']:.4g} mm^2, max depth {rest['max_depth']:.4g} mm, "
                         f"{rest['regions']} region(s) in x {x0:.4g}..{x1:.4g}, y {y0:.4g}..{y1:.4g}")
    return lines
