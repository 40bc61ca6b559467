"""Z-level roughing (:func:`rough`): clearing a block of stock down to the part plus an allowance.

Each level's regions are cleared by contour-parallel rings, entered by ramps or helices
(never a straight plunge) and linked above the stock.  Every cutter location stands on the
exact drop-cutter height of the tool grown by the allowance and every move is checked
between its ends: roughing never cuts into the part plus the allowance, beyond the mesh's
deflection.  See :doc:`/guide/cam` (section "Roughing").
"""

from __future__ import annotations

from dataclasses import dataclass

import contourpy
import numpy as np
from scipy import ndimage

from ..errors import SurfmodError
from .cutters import Cutter
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
#: Where the tool may stand at a level z: the exact height at most z + FREE_EPS; its
#: boundary found to 3 cells / 2**BISECTIONS.
FREE_EPS = 1e-7
BISECTIONS = 8
#: Smallest helix (radius, in tool radii) into a region too small to ramp along its ring,
#: and points per helix turn.
MIN_HELIX = 0.05
HELIX_POINTS = 24
#: Splitting rounds for moves that cut between their ends (each halves the moves cut).
SPLIT_ROUNDS = 12
#: How deep (grid cells) inside the region where the tool stood at a level a point must
#: lie for that level to have cleared the tool's disc round it with a cell to spare (the
#: boundary ring up to two cells inside, the grid's distance up to a cell off, and a cell
#: of margin: the verifier measures rapids with the tool grown by its own stock cell, a
#: quarter of the finishing stepover, commonly finer than this grid's third of the roughing's).
ENTRY_CELLS = 4.0


@dataclass(frozen=True)
class Motion:
    """Cutter locations ``points (N, 3)`` and how the tool moves to each ``kind (N,)``:
    ``RAPID`` (G0), ``FEED`` (G1 at the cutting feed), ``PLUNGE`` (G1 at the plunge/ramp
    feed)."""

    points: np.ndarray
    kind: np.ndarray


class Moves:
    """Cutter locations gathered run by run with their move kinds, then one :class:`Motion`
    (roughing and finishing both build their operations with it)."""

    def __init__(self):
        self.points, self.kinds = [], []
        #: run index -> the deepest its own moves cut, for runs judged as they were made
        #: (the finishing's contours): :func:`~surfmod.cam.finishing.judge_links` skips them
        self.judged = {}

    def add(self, pts, kind, deepest: float | None = None):
        pts = np.atleast_2d(np.asarray(pts, float))
        self.points.append(pts)
        self.kinds.append(np.full(len(pts), kind, np.int8))
        if deepest is not None:
            self.judged[len(self.points) - 1] = deepest

    @property
    def last(self):
        return self.points[-1][-1] if self.points else None

    def motion(self) -> Motion:
        if not self.points:
            return Motion(np.zeros((0, 3)), np.zeros(0, np.int8))
        return Motion(np.concatenate(self.points), np.concatenate(self.kinds))


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


def rough(part_grid: TriangleGrid, lift: float, grown: Cutter, tool: Tool, allowance: float, stock: np.ndarray,
          stepdown: float, stepover: float, clearance: float, step: float | None = None, progress=None,
          deflection: float = 0.0):
    """The roughing :class:`Motion` of ``tool`` over ``part_grid`` (the part's triangles
    bucketed for the ``grown`` tool, heights raised by ``lift`` for the mesh deflection)
    inside the ``stock`` box ``[[x0, y0, z0], [x1, y1, z1]]``, and a report dict.  Rings
    on the boundary stand ``deflection`` (the mesh's chordal deviation) further off the
    part, so the tool keeps the allowance from the exact faces too."""
    R = tool.radius
    step = min(R / 4, stepover / 2) if step is None else step
    safe = float(stock[1, 2] + clearance)
    bottom = float(stock[0, 2])

    def height(xy):
        h = drop(part_grid, grown, np.asarray(xy, float).reshape(-1, 2))
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
    values, which, counts = np.unique(np.round(inner, 6), return_inverse=True, return_counts=True)
    # the level at the floor's highest node (rounding must not leave any of it above the level)
    highest = np.full(len(values), -np.inf)
    np.maximum.at(highest, which.ravel(), inner.ravel())
    for v, c in zip(highest, counts):
        if c * cell * cell >= np.pi * R * R and low < v < top and min(abs(v - lv) for lv in levels) > 1e-3:
            levels.append(float(v))
    levels = sorted(set(levels), reverse=True)
    if low >= top:
        levels = []

    out = Moves()
    out.add([[stock[0, 0], stock[0, 1], safe]], RAPID)
    in_box = (X >= lo_box[0]) & (X <= hi_box[0]) & (Y >= lo_box[1]) & (Y <= hi_box[1])
    previous = top
    left = []
    # nodes of regions left uncut: the levels below them are left too (their entries
    # would start in material the level above did not remove)
    blocked = np.zeros(H.shape, bool)
    # per node, the lowest level whose rings cleared the tool's disc round it (with
    # ENTRY_CELLS to spare): an entry may come down rapidly to just above it
    cleared = np.full(H.shape, top)
    for z in levels:
        zc = z + FREE_EPS
        free = H <= zc
        if not free[in_box].any():
            previous = z
            continue
        if free.all():  # nothing of the part at this level: rings of the stock box, outside in
            dist = ndimage.distance_transform_edt(in_box) * cell
            top_d = float(dist[in_box].max())
            rings_at = cell + stepover * np.arange(int(max(top_d - cell, 0.0) / stepover) + 1)
            gen = contourpy.contour_generator(xs, ys, dist.T, line_type=contourpy.LineType.Separate)
            rings = [(line, True) for d in rings_at for line in gen.lines(float(d))]
        else:
            dist = ndimage.distance_transform_edt(free) * cell
            top_d = float(dist[in_box & free].max())
            # rings of the distance field `stepover` apart, far side first (the grid's
            # distance lies at most a cell beyond the true one), then the boundary itself:
            # where the tool may stand, to a fraction of a cell (every region of the level
            # has one, however small)
            rings_at = (stepover * np.arange(1, int(top_d / stepover) + 1))[::-1]
            gen = contourpy.contour_generator(xs, ys, dist.T, line_type=contourpy.LineType.Separate)
            rings = [(line, False) for d in rings_at for line in gen.lines(float(d))]
            rings += [(line, False) for line in _boundary(xs, ys, H, zc, dist, height, cell, R, deflection)]
        level = _Level(z, previous, safe, height, step, stepover, stock, lo_box, hi_box, xs, ys, dist, cell, R,
                       cleared)
        labels = None
        for line, whole_box in rings:
            closed = len(line) > 2 and np.allclose(line[0], line[-1])
            pieces, whole = ([line], True) if whole_box else _clip(line, lo_box, hi_box)
            for piece in pieces:
                nodes = level.nodes(piece)
                if blocked[nodes].any():
                    gone = level.left(piece)
                else:
                    gone = _cut_piece(out, piece, closed and whole, level)
                if gone is None:
                    continue
                if labels is None:
                    labels = ndimage.label(free)[0]
                hit = np.unique(labels[nodes])
                blocked |= np.isin(labels, hit[hit > 0])
                # one report per region: the levels below deepen it
                same = [g for g in left if np.linalg.norm(np.subtract(g["centre"], gone["centre"])) < R]
                if same:
                    same[0].update(z=min(same[0]["z"], gone["z"]), area=max(same[0]["area"], gone["area"]))
                else:
                    left.append(gone)
        # a level with no part in it ringed the whole grown box (no stock beyond it)
        inside = np.ones(H.shape, bool) if free.all() else dist >= ENTRY_CELLS * cell
        cleared[inside & ~blocked] = z
        previous = z
        if progress is not None:
            progress.update(0)
    out.add([[out.last[0], out.last[1], safe]], RAPID)
    ceiling = float(part_grid.triangles[..., 2].max()) + lift + allowance
    motion = _verify(out.motion(), height, ceiling)
    return motion, {"levels": levels, "cell": cell, "low": low, "left": left}


def _boundary(xs, ys, H, zc, dist, height, cell, R, deflection=0.0):
    """Rings on the boundary of where the tool may stand at a level (``H <= zc``): the
    grid's isolines of ``H`` resampled at ``cell / 2``, each point moved onto the exact
    boundary by bisection along its normal and then ``cell² / 16 R`` (plus the mesh's
    ``deflection``) inside (a chord
    between two points of a boundary that curves round the part, a flat end's offset of
    radius ``R`` at least, dips at most ``cell² / 32 R`` beyond it); points still beyond
    (sharper curves, a ball's small sections) go further in, up to a cell."""
    gen = contourpy.contour_generator(xs, ys, H.T, line_type=contourpy.LineType.Separate)
    lines = [np.asarray(line, float) for line in gen.lines(zc) if len(line) >= 2]
    if not lines:
        return []
    margin = cell * cell / (16 * R) + deflection
    shapes, normals, closed = [], [], []
    for line in lines:
        ring = len(line) > 2 and np.allclose(line[0], line[-1])
        pts = _resample(line, cell / 2, ring)
        # normals (central differences), turned towards the free side: up the distance field
        nxt = np.vstack([pts[1:], pts[1:2]]) if ring else np.vstack([pts[1:], pts[-1:]])
        prv = np.vstack([pts[-2:-1], pts[:-1]]) if ring else np.vstack([pts[:1], pts[:-1]])
        t = nxt - prv
        n = np.column_stack([-t[:, 1], t[:, 0]]) / np.maximum(np.hypot(t[:, 0], t[:, 1]), 1e-300)[:, None]
        shapes.append(pts)
        normals.append(n)
        closed.append(ring)
    pts, n = np.concatenate(shapes), np.concatenate(normals)
    up = _sample(dist, xs, ys, cell, pts + 0.5 * cell * n) >= _sample(dist, xs, ys, cell, pts - 0.5 * cell * n)
    n[~up] *= -1
    # each point onto the exact boundary along its normal (the grid's isoline lies within
    # a cell of it), then the margin in; all rings of the level at once
    lo, hi = pts + 1.5 * cell * n, pts - 1.5 * cell * n
    h = height(np.vstack([lo, hi]))
    ok = np.flatnonzero((h[:len(pts)] <= zc) & (h[len(pts):] > zc))
    lo, hi = lo[ok], hi[ok]
    for _ in range(BISECTIONS):
        mid = 0.5 * (lo + hi)
        f = height(mid) <= zc
        lo[f], hi[~f] = mid[f], mid[~f]
    pts[ok] = lo
    out = pts + margin * n
    bad = np.flatnonzero(height(out) > zc)
    push = 2 * margin
    while bad.size and push <= cell:
        trial = pts[bad] + push * n[bad]
        good = height(trial) <= zc
        out[bad[good]] = trial[good]
        bad = bad[~good]
        push *= 2
    if bad.size:
        # at a sharp corner of the region (where two walls' offsets meet) the normal
        # misleads: up the distance field instead
        gx, gy = np.gradient(dist, cell)
        g = np.column_stack([_sample(gx, xs, ys, cell, pts[bad]), _sample(gy, xs, ys, cell, pts[bad])])
        g /= np.maximum(np.hypot(g[:, 0], g[:, 1]), 1e-300)[:, None]
        push = margin
        while bad.size and push <= 2 * cell:
            trial = pts[bad] + push * g
            good = height(trial) <= zc
            out[bad[good]] = trial[good]
            bad, g = bad[~good], g[~good]
            push *= 2
    # points no push brought to where the tool may stand are dropped (lifting them
    # would climb the wall): the region round them is narrower than the push
    keep = np.ones(len(out), bool)
    keep[bad] = False
    rings = []
    for ring, ok, c in zip(np.split(out, np.cumsum([len(p) for p in shapes])[:-1]),
                           np.split(keep, np.cumsum([len(p) for p in shapes])[:-1]), closed):
        if c:
            ring, ok = ring[:-1], ok[:-1]
        ring = ring[ok]
        if c and len(ring) >= 1:
            # a closed ring stays closed (three points at least), however little is left of it
            ring = np.vstack([ring] + [ring[:1]] * max(1, 3 - len(ring)))
        if len(ring) >= 2:
            rings.append(ring)
    return rings


def left_summary(left) -> str:
    """One line naming the regions roughing left uncut (``report["left"]``), or ``""``.

    >>> left_summary([{"z": -4.0, "top": -2.5, "centre": (10.0, 5.0), "area": 31.4, "ring": None}])
    'left uncut (too small to enter without a plunge): 31 mm² at (10.0, 5.0), z -2.5 to -4'
    """
    if not left:
        return ""
    parts = [f"{g['area']:.0f} mm² at ({g['centre'][0]:.1f}, {g['centre'][1]:.1f}), z {g['top']:.4g} to {g['z']:.4g}"
             for g in left]
    return "left uncut (too small to enter without a plunge): " + "; ".join(parts)


def _sample(field, xs, ys, cell, pts):
    """Bilinear interpolation of a grid ``field`` at ``pts`` (clamped to the grid)."""
    return ndimage.map_coordinates(field, [(pts[:, 0] - xs[0]) / cell, (pts[:, 1] - ys[0]) / cell], order=1,
                                   mode="nearest")


@dataclass
class _Level:
    """What cutting one level needs: its height ``z``, the level above, the clearance
    height, the exact height function, the stock and its grown box, the grid and the
    distance to where the tool may not stand."""

    z: float
    previous: float
    safe: float
    height: object
    step: float
    stepover: float
    stock: np.ndarray
    lo_box: np.ndarray
    hi_box: np.ndarray
    xs: np.ndarray
    ys: np.ndarray
    dist: np.ndarray
    cell: float
    R: float
    cleared: np.ndarray

    def nodes(self, pts):
        """Grid nodes nearest the points (index arrays)."""
        i = np.clip(np.round((pts[:, 0] - self.xs[0]) / self.cell).astype(int), 0, len(self.xs) - 1)
        j = np.clip(np.round((pts[:, 1] - self.ys[0]) / self.cell).astype(int), 0, len(self.ys) - 1)
        return i, j

    def entry(self, pts):
        """The height an entry may come down to rapidly at each point (half a unit above
        it): the highest of the lowest levels that cleared the four nodes round it."""
        fx = np.clip((pts[:, 0] - self.xs[0]) / self.cell, 0, len(self.xs) - 1)
        fy = np.clip((pts[:, 1] - self.ys[0]) / self.cell, 0, len(self.ys) - 1)
        i0, j0 = np.floor(fx).astype(int), np.floor(fy).astype(int)
        i1, j1 = np.minimum(i0 + 1, len(self.xs) - 1), np.minimum(j0 + 1, len(self.ys) - 1)
        c = self.cleared
        return np.maximum(np.maximum(c[i0, j0], c[i1, j0]), np.maximum(c[i0, j1], c[i1, j1]))

    def left(self, pts):
        """The report of a region left uncut round the ring ``pts``: its (deepest) level
        ``z``, the level above ``top`` (the stock stays from there down), its centre, the
        (x, y) area of stock it leaves at most (the ring's area grown by the tool
        radius) and the ring."""
        seg = np.linalg.norm(np.diff(pts, axis=0), axis=1)
        ring = pts[:-1] if len(pts) > 2 and np.allclose(pts[0], pts[-1]) else pts
        x, y = ring[:, 0], ring[:, 1]
        inner = 0.5 * abs(float(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1))))
        area = inner + float(seg.sum()) * self.R + np.pi * self.R ** 2
        return {"z": float(self.z), "top": float(self.previous), "centre": tuple(float(v) for v in ring.mean(axis=0)),
                "area": area, "ring": pts.copy()}


def _cut_piece(out: Moves, piece, closed: bool, lv: _Level):
    """Cut one ring (closed) or piece of a ring (open, its ends on the grown stock box);
    returns the report of the region when the tool cannot enter it without a plunge."""
    z, height = lv.z, lv.height
    pts = _resample(piece, lv.step, closed)
    path = np.column_stack([pts, np.full(len(pts), z)])
    path[:, 2] = np.maximum(path[:, 2], height(pts))
    last = out.last
    if closed:
        # from the end of the ring before at this level, when near and the way there is
        # where the tool may stand: start the ring at its point nearest, no entry needed
        if last is not None and abs(last[2] - z) < 1e-9:
            k = int(np.argmin(np.linalg.norm(pts[:-1] - last[:2], axis=1)))
            if (np.linalg.norm(pts[k] - last[:2]) <= 1.5 * lv.stepover
                    and _level_clear(height, last[:2], pts[k], z, lv.step)):
                ring = np.vstack([path[k:-1], path[:k + 1]])
                out.add(ring, FEED)
                return None
        # ramp along the ring from just above the lowest level that cleared round its
        # start (the ring starts where that level is lowest), going round as needed
        over = lv.entry(pts[:-1])
        k = 0 if over[0] <= over.min() else int(np.argmin(over))
        if k:
            pts = np.vstack([pts[k:-1], pts[:k + 1]])
            path = np.vstack([path[k:-1], path[:k + 1]])
        L = float(np.linalg.norm(np.diff(pts, axis=0), axis=1).sum())
        start_z = float(over[k]) + 0.5
        drop_z = start_z - z
        turns = min(int(np.ceil(drop_z / np.tan(np.radians(RAMP_ANGLE)) / max(L, 1e-9))), MAX_RAMP_TURNS)
        if L * turns >= drop_z / np.tan(np.radians(MAX_RAMP_ANGLE)):
            ramp = np.vstack([pts[:-1]] * turns + [pts[:1]])
        else:
            # a ring too short to ramp along (a small region): a helix round its centre as
            # wide as the region allows, else the region is left (reported)
            c = pts[:-1].mean(axis=0)
            rho = min(float(_sample(lv.dist, lv.xs, lv.ys, lv.cell, c[None])[0]) - 1.5 * lv.cell, lv.R / 2)
            start_z = float(lv.entry((c + [max(rho, 0.0), 0.0])[None])[0]) + 0.5
            drop_z = start_z - z
            helix_turns = int(np.ceil(drop_z / np.tan(np.radians(RAMP_ANGLE)) / (2 * np.pi * max(rho, 1e-9))))
            helix_turns = min(helix_turns, MAX_RAMP_TURNS)
            if rho < MIN_HELIX * lv.R or 2 * np.pi * rho * helix_turns < drop_z / np.tan(np.radians(MAX_RAMP_ANGLE)):
                return lv.left(pts)
            t = np.linspace(0.0, 1.0, HELIX_POINTS * helix_turns + 1)
            ang = 2 * np.pi * helix_turns * t
            ramp = c + rho * np.column_stack([np.cos(ang), np.sin(ang)])
            # then across to the ring, inside the circle the helix cleared, and round it
        s = np.r_[0, np.cumsum(np.linalg.norm(np.diff(ramp, axis=0), axis=1))]
        rz = np.maximum(start_z - drop_z * s / s[-1], height(ramp))
        _link(out, np.array([ramp[0, 0], ramp[0, 1], lv.safe]), lv.safe)
        out.add([[ramp[0, 0], ramp[0, 1], max(start_z, rz[0])]], RAPID)
        out.add(np.column_stack([ramp, rz])[1:], PLUNGE)
        out.add(path if not np.allclose(ramp[-1], pts[0]) else path[1:], FEED)
        return None
    # open piece, its ends on the stock's grown side: lead in from outside the stock
    p0 = path[0, :2]
    out_dir = np.where(p0 <= lv.lo_box + 1e-6, -1.0, np.where(p0 >= lv.hi_box - 1e-6, 1.0, 0.0))
    if not out_dir.any():
        out_dir = np.sign(p0 - lv.stock[:, :2].mean(axis=0))
    lead = p0 + out_dir * (lv.stepover + 1.0)
    lead_z = float(max(z, height(lead[None])[0]))
    near = (last is not None and abs(last[2] - z) < 1e-9
            and np.linalg.norm(last[:2] - p0) <= 1.5 * lv.stepover
            and _level_clear(height, last[:2], p0, z, lv.step))
    if near:
        out.add(path, FEED)
        return None
    _link(out, np.array([lead[0], lead[1], lv.safe]), lv.safe)
    out.add([[lead[0], lead[1], lead_z]], RAPID)
    out.add(path, FEED)
    return None


def _level_clear(height, a, b, z, step) -> bool:
    n = int(np.ceil(np.linalg.norm(b - a) / step)) + 1
    t = np.linspace(0, 1, n + 1)[:, None]
    return bool(np.all(height(a + t * (b - a)) <= z + 1e-9))


def _link(out: Moves, target, safe):
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
