"""Waterline (constant-Z) contours of an end mill round a triangle soup (:func:`waterline`).

Fibers on a grid meet the triangles (:mod:`surfmod.cam.fiber_contact`), marching squares
joins their crossings into loops, extra fibers cross every pit (:func:`pit_lines`), and
chords are refined onto the exact contour.  The (fiber, triangle) pairs are counted from
the index before any is met (:func:`fiber_pairs`, at most :data:`MAX_PAIRS`).
See :doc:`/guide/cam` (section "Waterline").
"""

from __future__ import annotations

import numpy as np
from numba import njit
from scipy.spatial import cKDTree

from ..errors import SurfmodError
from .cutters import Cutter
from .drop_cutter import TriangleGrid
from .fiber_contact import pair_intervals, profile_radius

MAX_PAIRS = 200_000_000  # (fiber, triangle) pairs over all levels: beyond this, coarsen sampling
PAIRS_PER_BLOCK = 400_000
MAX_REFINE = 30
#: a pit: the tool's positions against steep triangles (slope over 30°) gathered within
#: three fiber cells whose wall normals, weighted by area, cancel to under this share
PIT_BALANCE = 0.5
#: times a pit's middle is moved to the middle of the positions near it
PIT_SHIFTS = 3


def fiber_pairs(tri: np.ndarray, radius: float, sampling: float, levels, corner: float = 0.0,
                pits: tuple | None = None) -> float:
    """The (fiber, triangle) pairs :func:`waterline` meets at the tip heights ``levels``
    with fibers ``sampling`` apart, for a tool of ``radius`` and corner radius ``corner``.

    The triangles are indexed by height and by grid line: at a level z only those
    reaching into [z, z + corner) are met (the band: the tool's rounded end can touch
    them there), each with the grid lines within ``radius`` of its box in both directions;
    a triangle wholly above z + corner is met once, at the first level below it, and its
    shank intervals carried down; one wholly below z is not met at all.  (The refinement's
    fibers, a few per contour point, each meet the triangles within reach of it: work that
    follows the contours found, bounded by :data:`MAX_REFINE` rounds.)  The fibers
    through pits (:func:`pit_lines`) count too; ``pits`` gives them where the caller has
    them already.

    >>> tri = np.array([[[0, 0, 0], [1, 0, 0], [0, 1, 0]]], float)
    >>> fiber_pairs(tri, 0.5, 0.5, [0.0, -1.0, -2.0], 0.5)  # (5 + 5) lines: in the band at 0, joined at -1
    20.0
    >>> fiber_pairs(tri, 0.5, 0.5, [1.0, 2.0], 0.5)  # every level above the triangle: none
    0.0
    """
    z = np.sort(np.atleast_1d(np.asarray(levels, dtype=float)))
    lo, hi = tri[:, :, :2].min(axis=1), tri[:, :, :2].max(axis=1)
    span = np.maximum(hi - lo, 0) + 2 * radius
    lines = (span / sampling + 1).sum(axis=1)
    for axis, at in enumerate(pit_lines(tri, radius, sampling) if pits is None else pits):
        lines += np.searchsorted(at, hi[:, axis] + radius, "right") - np.searchsorted(at, lo[:, axis] - radius)
    top, bottom = tri[:, :, 2].max(axis=1), tri[:, :, 2].min(axis=1)
    # levels in (bottom - corner, top]: the band; any level at or below bottom - corner: joined once
    band = np.searchsorted(z, top, "right") - np.searchsorted(z, bottom - corner, "right")
    joined = np.searchsorted(z, bottom - corner, "right") > 0
    return float((lines * (band + joined)).sum())


def sampling_within(tri: np.ndarray, radius: float, sampling: float, levels, most: float,
                    corner: float = 0.0) -> float | None:
    """``sampling``, or the finest spacing up to ``most`` at which :func:`waterline`'s
    fibers fit :data:`MAX_PAIRS` at the tip heights ``levels`` (the pairs fall as the
    spacing grows); None when even ``most`` does not fit.

    >>> tri = np.array([[[0, 0, 0], [1, 0, 0], [0, 1, 0]]], float)
    >>> sampling_within(tri, 0.5, 0.5, [0.0, -1.0], 2.0)
    0.5
    """
    def count(h):
        return fiber_pairs(tri, radius, h, levels, corner)

    if count(sampling) <= MAX_PAIRS:
        return sampling
    if count(most) > MAX_PAIRS:
        return None
    lo, hi = sampling, most
    for _ in range(40):  # bisection on a monotone count: 40 halvings reach 1e-12 of the bracket
        mid = 0.5 * (lo + hi)
        lo, hi = (lo, mid) if count(mid) <= MAX_PAIRS else (mid, hi)
    return hi


def pit_lines(tri: np.ndarray, radius: float, sampling: float) -> tuple[np.ndarray, np.ndarray]:
    """The x and the y of one more fiber each through every pit of the tool's positions:
    where the tool standing against the steep triangles (its axis ``radius`` out along
    their horizontal normal) gathers within three cells of ``sampling``, less than a
    ``sampling`` from its middle (root mean square), from walls facing every way (their
    area-weighted normals cancel to under :data:`PIT_BALANCE`), as in a hole a little wider
    than the tool.  The fibers cross at the weighted middle of those
    positions, so a node of the grid lies in the pit; a middle whose positions within a
    spacing no longer balance (moved onto one wall) is no pit, and fibers closer than a
    millionth of the spacing are one.

    >>> a = np.linspace(2 * np.pi, 0, 33)[:-1]  # a hole of radius 1.1, 1 deep: 64 triangles facing in
    >>> rim = np.column_stack([1.1 * np.cos(a) + 5, 1.1 * np.sin(a) - 2])
    >>> nxt = np.roll(rim, -1, axis=0)
    >>> wall = [[[*p, 0], [*q, 0], [*q, 1]] for p, q in zip(rim, nxt)] + [[[*p, 0], [*q, 1], [*p, 1]] for p, q in zip(rim, nxt)]
    >>> [np.round(v, 6).tolist() for v in pit_lines(np.array(wall, float), 1.0, 0.5)]
    [[5.0], [-2.0]]
    """
    tri = np.asarray(tri, float)
    n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    flat = np.hypot(n[:, 0], n[:, 1])  # twice the area times the normal's horizontal share
    steep = flat > 0.5 * np.linalg.norm(n, axis=1)
    if not steep.any():
        return np.zeros(0), np.zeros(0)
    w, nh = flat[steep], n[steep, :2] / flat[steep, None]
    at = tri[steep, :, :2].mean(axis=1) + radius * nh
    cell = np.floor((at - at.min(axis=0)) / sampling).astype(np.int64) + 1
    width = int(cell[:, 1].max()) + 2  # a row of cells, its neighbours' included
    keys, inv = np.unique(cell[:, 0] * width + cell[:, 1], return_inverse=True)
    sums = np.zeros((len(keys), 6))  # weight, weighted normal (2), position (2) and its square
    np.add.at(sums, inv.ravel(), np.column_stack([w, w[:, None] * nh, w[:, None] * at, w * (at * at).sum(axis=1)]))
    # each occupied cell with its eight neighbours: a pit straddling cells is whole in one
    window = sums.copy()
    for step in (-width - 1, -width, -width + 1, -1, 1, width - 1, width, width + 1):
        k = np.minimum(np.searchsorted(keys, keys + step), len(keys) - 1)
        found = keys[k] == keys + step
        window[found] += sums[k[found]]
    middle = window[:, 3:5] / window[:, :1]
    spread = window[:, 5] / window[:, 0] - (middle * middle).sum(axis=1)  # the positions' variance
    # balanced, and narrow: a pit as wide as the spacing holds a node of the grid already
    pit = np.flatnonzero((np.hypot(window[:, 1], window[:, 2]) < PIT_BALANCE * window[:, 0])
                         & (spread < sampling ** 2))
    # the windows round one pit overlap: the heaviest (holding all of it) speaks for those
    # within a spacing of its middle; each pass keeps one and drops at least itself
    kept, order = [], pit[np.argsort(-window[pit, 0], kind="stable")]
    while len(order):
        kept.append(middle[order[0]])
        order = order[np.hypot(*(middle[order] - middle[order[0]]).T) >= sampling]
    kept = np.reshape(kept, (-1, 2))
    # the window's middle leans towards other walls in it: moved to the weighted middle of
    # the positions within half a spacing of it, a few times (a pit narrower than the
    # spacing is then all that is left round it)
    tree = cKDTree(at)
    for _ in range(PIT_SHIFTS):
        for k, near in enumerate(tree.query_ball_point(kept, 0.5 * sampling)):
            if near:
                kept[k] = np.average(at[near], axis=0, weights=w[near])
    # a window balanced by walls a few cells apart can be moved onto one wall's positions:
    # a fiber there runs along that wall's offset and finds nothing a grid line does not;
    # a pit is still balanced among the positions within a spacing of its middle
    near = tree.query_ball_point(kept, sampling)
    pit = [bool(k) and np.hypot(*(w[k, None] * nh[k]).sum(axis=0)) < PIT_BALANCE * w[k].sum() for k in near]
    kept = kept[np.asarray(pit, bool)]
    # pits mirrored across the part give one fiber, not two a rounding apart
    return tuple(_distinct(kept[:, axis], 1e-6 * sampling) for axis in (0, 1))


def _distinct(values, gap):
    """``values`` sorted, each no closer than ``gap`` to the one before it (the first of a
    run kept)."""
    v = np.unique(values)
    return v[np.r_[True, np.diff(v) > gap]] if len(v) else v


# ----------------------------------------------------------------------------------------------
# fibers against the mesh

class _Shank:
    """Per grid line of one direction, the merged intervals forbidden by the triangles
    wholly above ``floor``.  A triangle above a level's corner height z + rc meets the tool
    with the shank alone, in the band within R of its (x, y) shadow: the same at every
    lower level, so it is met once and carried down (on a part that is mostly above the
    level, most triangles are), not once per level."""

    def __init__(self):
        self.floor = np.inf
        self.comp = (np.zeros(0, np.int64), np.zeros(0), np.zeros(0))


class _Fibers:
    """The part's triangles for fiber queries at one tool: bucketed for short fibers."""

    def __init__(self, triangles, cutter: Cutter, reach):
        self.tri = triangles
        self.cutter, self.R, self.rc = cutter, cutter.radius, cutter.corner
        self.top = triangles[:, :, 2].max(axis=1)
        self.bottom = triangles[:, :, 2].min(axis=1)
        self.grid = TriangleGrid(triangles, self.R + reach)
        self.lo = triangles[:, :, :2].min(axis=1)
        self.hi = triangles[:, :, :2].max(axis=1)
        self.boxes = np.ascontiguousarray(np.column_stack([self.lo, self.hi, self.top]))
        self.pairs = 0  # (fiber, triangle) pairs met so far on the grid lines: what fiber_pairs estimates
        self.refined = 0  # and by the refinement's fibers

    def lines(self, at, axis: int, z, shank: "_Shank"):
        """Merged components ``(start, end)`` along each grid line: the lines
        ``coordinate[axis] = at[k]``, running along the other axis (positions measured
        along it).  ``shank`` carries the components of the triangles wholly above
        ``z + rc`` from the level above (levels must come top first); only the triangles
        new to it and those reaching into [z, z + rc) are met here."""
        corner = z + self.rc
        joined = np.flatnonzero((self.bottom >= corner) & (self.bottom < shank.floor))
        shank.floor = corner
        if len(joined):
            shank.comp = _components(*(np.concatenate(pair) for pair in zip(shank.comp, self._hits(at, axis, z, joined))))
        band = np.flatnonzero((self.top >= z) & (self.bottom < corner))
        c_line, c_lo, c_hi = _components(*(np.concatenate(pair) for pair in zip(shank.comp, self._hits(at, axis, z, band))))
        bounds = np.searchsorted(c_line, np.arange(len(at) + 1))
        return [(c_lo[bounds[k]:bounds[k + 1]], c_hi[bounds[k]:bounds[k + 1]]) for k in range(len(at))]

    def _hits(self, at, axis: int, z, which):
        """``(line, t0, t1)`` of every grid line that the triangles ``which`` forbid an
        interval of (the lines within R of a triangle's box)."""
        lo = self.lo[which, axis] - self.R
        hi = self.hi[which, axis] + self.R
        k0 = np.searchsorted(at, lo, "left")
        k1 = np.searchsorted(at, hi, "right")
        n = np.maximum(k1 - k0, 0)
        ti = np.repeat(which, n)
        li = np.repeat(k0, n) + np.arange(n.sum()) - np.repeat(np.cumsum(n) - n, n)
        o = np.zeros((len(ti), 2))
        o[:, axis] = at[li]
        d = np.zeros((len(ti), 2))
        d[:, 1 - axis] = 1.0
        self.pairs += len(ti)
        t0, t1 = pair_intervals(self.grid.rows, ti, o[:, 0], o[:, 1], d[:, 0], d[:, 1], z, self.cutter)
        hit = t0 <= t1
        return li[hit], t0[hit], t1[hit]

    def query(self, o, d, z, reach):
        """Per fiber (the segment ``o ± reach d``: origin (F, 2), unit direction (F, 2),
        ``reach`` (F,) at most the grid's): pair arrays (fiber index, t0, t1)."""
        start, stop = self.grid.segments(o, above=z)  # triangles wholly below z cannot meet the tool
        out_q, out_lo, out_hi = [], [], []
        block = np.cumsum(np.maximum(stop - start, 0)) // PAIRS_PER_BLOCK
        cuts = np.r_[0, np.nonzero(np.diff(block))[0] + 1, len(o)]
        for s0, s1 in zip(cuts[:-1], cuts[1:]):
            qg, ti = _segment_pairs(self.grid.listed, self.boxes, float(z), self.R, self.rc, o[s0:s1], d[s0:s1],
                                    reach[s0:s1], start[s0:s1], stop[s0:s1])
            qg += s0
            self.refined += len(ti)
            lo, hi = pair_intervals(self.grid.rows, ti, o[qg, 0], o[qg, 1], d[qg, 0], d[qg, 1], z, self.cutter)
            hit = lo <= hi
            out_q.append(qg[hit]), out_lo.append(lo[hit]), out_hi.append(hi[hit])
        return np.concatenate(out_q), np.concatenate(out_lo), np.concatenate(out_hi)


@njit(cache=True)
def _segment_pairs(tris, boxes, z, R, rc, o, d, reach, start, stop):
    """``(fiber, triangle)`` of the cell-list entries ``start:stop`` of each fiber (the
    segment ``o ± reach d``) that the tool at tip height ``z`` can touch: the triangle's top
    reaches ``z``, and its (x, y) box comes within the tool's radius at that top (R above
    the corner ``rc``, :func:`~surfmod.cam.fiber_contact.profile_radius` below) of the
    segment's box and of the disc of radius ``reach`` round ``o`` (``boxes``: a row per
    triangle, x0 y0 x1 y1 top, so that an entry reads one cache line).  No point of a
    triangle lies farther than that radius from where the tool touches it, so the pairs
    dropped have no interval on the segment; on a wall most triangles within R of a fiber
    stand low beside it, where the ball's end is narrow.  Only the pairs kept are returned
    (on a metre part the lists hold thousands of triangles per fiber, of which a few dozen
    are kept).  The boxes grown by R lie inside the ones the grid listed the triangles for
    (``reach`` is at most the grid's), so that is not tested."""
    n = 0
    for q in range(len(o)):
        n += max(stop[q] - start[q], 0)
    qi = np.empty(n, np.int64)
    ti = np.empty(n, np.int64)
    n = 0
    for q in range(len(o)):
        ox, oy, s = o[q, 0], o[q, 1], reach[q]
        ax, ay = abs(d[q, 0]) * s, abs(d[q, 1]) * s
        for e in range(start[q], stop[q]):
            t = tris[e]
            b = boxes[t]
            if b[4] < z:
                continue
            r = profile_radius(b[4] - z, R, rc) * (1.0 + 1e-9) + 1e-12  # a hair over: rounding never drops a touch
            gx = max(b[0] - ox, ox - b[2], 0.0)  # the box's distance from o along x and y
            gy = max(b[1] - oy, oy - b[3], 0.0)
            if gx <= ax + r and gy <= ay + r and gx * gx + gy * gy <= (s + r) * (s + r):
                qi[n] = q
                ti[n] = t
                n += 1
    return qi[:n], ti[:n]


def _components(qi, lo, hi):
    """Merged forbidden intervals per fiber: ``(fiber, start, end)`` of each component of
    the union of the pairs' intervals, sorted by fiber then start."""
    if not len(qi):
        return qi, lo, hi
    heads, ends = _merge(qi, lo, hi)
    return qi[heads], lo[heads], ends


@njit(cache=True)
def _merge(qi, lo, hi):
    """The first pair of each component (an index into the pairs) and the component's end,
    in order of fiber then start: the pairs bucketed by fiber, each bucket sorted by start
    and swept with the running end (compiled: a grid line crossing a part meets thousands
    of triangles)."""
    n = int(qi.max()) + 1
    first = np.zeros(n + 1, np.int64)
    for i in range(len(qi)):
        first[qi[i] + 1] += 1
    for k in range(n):
        first[k + 1] += first[k]
    fill = first[:-1].copy()
    order = np.empty(len(qi), np.int64)
    for i in range(len(qi)):
        order[fill[qi[i]]] = i
        fill[qi[i]] += 1
    heads = np.empty(len(qi), np.int64)
    ends = np.empty(len(qi))
    m = 0
    for k in range(n):
        bucket = order[first[k]:first[k + 1]]
        for i in bucket[np.argsort(lo[bucket])]:
            if m == 0 or qi[i] != qi[heads[m - 1]] or lo[i] > ends[m - 1]:
                heads[m] = i
                ends[m] = hi[i]
                m += 1
            elif hi[i] > ends[m - 1]:
                ends[m - 1] = hi[i]
    return heads[:m], ends[:m]


def _union_nearest(n, qi, lo, hi):
    """Per fiber: the point of its forbidden union's boundary nearest t = 0 (NaN if none)."""
    best = np.full(n, np.nan)
    c_fib, c_lo, c_hi = _components(qi, lo, hi)
    if not len(c_fib):
        return best
    cand = np.where(np.abs(c_lo) <= np.abs(c_hi), c_lo, c_hi)
    o2 = np.lexsort((np.abs(cand), c_fib))
    firsts = o2[np.r_[True, c_fib[o2][1:] != c_fib[o2][:-1]]]
    best[c_fib[firsts]] = cand[firsts]
    return best


# ----------------------------------------------------------------------------------------------
# contours

def _line_crossings(t, state, c_lo, c_hi):
    """Along one grid line with nodes at ``t`` and their ``state``: the crossing on each
    edge (i, i+1) whose states differ (NaN elsewhere) from the line's components: the end
    of the one holding the inside node, else the nearest boundary within the edge.  With
    no boundary within the edge the line sees one state all along it, and the node whose
    state it contradicts is the crossing: the states come from the rows, and a row (or
    this line) tangent to the contour there, e.g. a fiber along a straight wall's offset,
    sees the node a rounding off the other side."""
    out = np.full(len(t) - 1, np.nan)
    differ = np.flatnonzero(state[:-1] != state[1:])
    if not len(differ):
        return out
    a, b = t[differ], t[differ + 1]
    leaving = state[differ]
    if len(c_lo):
        # in -> out: the last component end within (a, b]; out -> in: the first start in [a, b)
        k_end = np.searchsorted(c_hi, b, "right") - 1
        end = np.where(k_end >= 0, c_hi[np.maximum(k_end, 0)], -np.inf)
        k_start = np.searchsorted(c_lo, a, "left")
        start = np.where(k_start < len(c_lo), c_lo[np.minimum(k_start, len(c_lo) - 1)], np.inf)
        got = np.where(leaving, end, start)
        ok = (got >= a) & (got <= b)
        # the line's own state at a: inside a component starting at or before it
        k_a = np.searchsorted(c_lo, a, "right") - 1
        inside_a = (k_a >= 0) & (c_hi[np.maximum(k_a, 0)] >= a)
    else:
        got, ok, inside_a = a, np.zeros(len(a), bool), np.zeros(len(a), bool)
    out[differ] = np.where(ok, got, np.where(inside_a != leaving, a, b))
    return out


def _grid_contours(fib: _Fibers, z, x, y, shanks):
    """Closed loops (arrays of (x, y)) of the forbidden region's boundary found on the grid
    (``shanks``: the rows' and the columns' :class:`_Shank`, levels top first)."""
    nx, ny = len(x), len(y)
    rows = fib.lines(y, 1, z, shanks[0])  # per row j: components along x
    cols = fib.lines(x, 0, z, shanks[1])  # per column i: components along y
    state = np.zeros((nx, ny), bool)
    for j, (c_lo, c_hi) in enumerate(rows):
        if len(c_lo):
            k = np.searchsorted(c_lo, x, "right") - 1
            state[:, j] = (k >= 0) & (c_hi[np.maximum(k, 0)] >= x)
    n_x = (nx - 1) * ny
    cross = np.full((n_x + nx * (ny - 1), 2), np.nan)
    xe = np.full((nx - 1, ny), np.nan)
    for j, (c_lo, c_hi) in enumerate(rows):
        xe[:, j] = _line_crossings(x, state[:, j], c_lo, c_hi)
    ye = np.full((nx, ny - 1), np.nan)
    for i, (c_lo, c_hi) in enumerate(cols):
        ye[i] = _line_crossings(y, state[i], c_lo, c_hi)
    Yx = np.broadcast_to(y, (nx - 1, ny))
    cross[:n_x] = np.column_stack([xe.ravel(), Yx.ravel()])
    Xy = np.broadcast_to(x[:, None], (nx, ny - 1))
    cross[n_x:] = np.column_stack([Xy.ravel(), ye.ravel()])
    # marching squares, material on the left; corners CCW: (i,j) (i+1,j) (i+1,j+1) (i,j+1)
    ci, cj = np.meshgrid(np.arange(nx - 1), np.arange(ny - 1), indexing="ij")
    ci, cj = ci.ravel(), cj.ravel()
    corners = np.stack([state[ci, cj], state[ci + 1, cj], state[ci + 1, cj + 1], state[ci, cj + 1]], axis=1)
    edges = np.stack([ci * ny + cj,                      # bottom: x-edge (i, j)
                      n_x + (ci + 1) * (ny - 1) + cj,    # right: y-edge (i+1, j)
                      ci * ny + cj + 1,                  # top: x-edge (i, j+1), walked backwards
                      n_x + ci * (ny - 1) + cj], axis=1)  # left: y-edge (i, j), walked backwards
    succ = np.full(len(cross), -1)
    live = np.flatnonzero(corners.any(axis=1) & ~corners.all(axis=1))
    cs = corners[live]
    for k in range(4):
        is_exit = cs[:, k] & ~cs[:, (k + 1) % 4]
        # the run of inside corners ending at corner k entered at the nearest edge behind
        # it (a run stops at an outside corner: saddles stay separated)
        found = np.zeros(len(live), bool)
        entry_edge = np.full(len(live), -1)
        for back_step in range(1, 4):
            m = (k - back_step) % 4
            take = is_exit & ~found & ~cs[:, m] & cs[:, (m + 1) % 4]
            entry_edge[take] = m
            found |= take | (is_exit & ~cs[:, m])
        sel = np.flatnonzero(is_exit & (entry_edge >= 0))
        succ[edges[live[sel], k]] = edges[live[sel], entry_edge[sel]]
    loops = []
    seen = np.zeros(len(succ), bool)
    for s in np.flatnonzero(succ >= 0):
        if seen[s]:
            continue
        loop = []
        cur = s
        while cur >= 0 and not seen[cur]:
            seen[cur] = True
            loop.append(cur)
            cur = succ[cur]
        if cur == s and len(loop) >= 3:
            loops.append(cross[np.array(loop)])
    return loops


def _refine(fib: _Fibers, z, loops, tolerance, reach):
    """Insert the exact contour point at every chord's middle that lies off it by more
    than ``tolerance`` (found along a fiber normal to the chord), round after round;
    a chord found within tolerance is not asked again."""
    done = [np.zeros(len(p), bool) for p in loops]
    for _ in range(MAX_REFINE):
        sizes = [len(p) for p in loops]
        pts = np.vstack(loops)
        ok = np.concatenate(done)
        nxt = np.vstack([np.roll(p, -1, axis=0) for p in loops])
        mid = 0.5 * (pts + nxt)
        chord = nxt - pts
        length = np.linalg.norm(chord, axis=1)
        normal = np.column_stack([-chord[:, 1], chord[:, 0]]) / np.where(length > 0, length, 1.0)[:, None]
        idx = np.flatnonzero(~ok & (length > tolerance))
        if not len(idx):
            break
        # the contour leaves a chord by at most half its length (at a corner)
        span = np.minimum(np.maximum(length[idx], 4 * tolerance), reach)
        qi, lo, hi = fib.query(mid[idx], normal[idx], z, span)
        seen = (lo <= span[qi]) & (hi >= -span[qi])
        qi, lo, hi = qi[seen], np.maximum(lo[seen], -span[qi[seen]]), np.minimum(hi[seen], span[qi[seen]])
        best = _union_nearest(len(idx), qi, lo, hi)
        off = np.zeros(len(pts))
        off[idx] = np.where(np.isfinite(best) & (np.abs(best) < span), best, 0.0)
        insert = np.abs(off) > tolerance
        ok[idx] = ~insert[idx]
        if not insert.any():
            break
        new_pts = mid + off[:, None] * normal
        out, flags, k = [], [], 0
        for size in sizes:
            p, q, ins, f = pts[k:k + size], new_pts[k:k + size], insert[k:k + size], ok[k:k + size]
            merged = np.empty((size + ins.sum(), 2))
            mflag = np.zeros(len(merged), bool)
            pos = np.arange(size) + np.r_[0, np.cumsum(ins)[:-1]]
            merged[pos] = p
            mflag[pos] = f
            merged[pos[ins] + 1] = q[ins]
            out.append(merged)
            flags.append(mflag)
            k += size
        loops, done = out, flags
    return loops


class ContourPoints:
    """Exact waterline points of one tool round a part, to split chords of its contours
    (e.g. where a drop-cutter check finds a chord crossing a notch of the contour that its
    midpoint missed).  ``reach``: how far from a chord's middle a point is looked for.

    >>> import numpy as np
    >>> from surfmod.cam.cutters import Flat
    >>> box = np.array([[[0, 0, 0], [10, 0, 0], [10, 10, 0]], [[0, 0, 0], [10, 10, 0], [0, 10, 0]]], float)
    >>> cp = ContourPoints(box, Flat(1.0), 6.0)
    >>> cp.split(0.0, np.array([[-1.0, 5.0], [5.0, -1.0]]), np.array([0])).round(6).tolist()  # cuts a corner
    [[-1.0, 5.0], [-0.707107, -0.707107], [5.0, -1.0]]
    """

    def __init__(self, part, tool, reach: float, fibers: "_Fibers | None" = None):
        """``fibers``: those :func:`waterline` returned for the same triangles and tool at
        a sampling of ``reach / 1.5`` (its fibers reach that far), reused, not built again."""
        cutter = getattr(tool, "cutter", tool)
        tri = np.asarray(part, dtype=float)
        if tri.ndim != 3 or tri.shape[1:] != (3, 3) or not len(tri):
            raise SurfmodError(f"part: expected triangles (M, 3, 3), got shape {tri.shape}")
        if not reach > 0:
            raise SurfmodError(f"reach: must be > 0, got {reach}")
        self.fib, self.reach = fibers or _Fibers(tri, cutter, float(reach)), float(reach)

    def split(self, z: float, pts: np.ndarray, which: np.ndarray) -> np.ndarray:
        """The polyline ``pts`` (N, 2) with each chord ``i`` in ``which`` (from ``pts[i]`` to
        ``pts[i + 1]``) split at the contour point at tip height ``z`` nearest its middle
        along the fiber normal to it (the middle itself where none lies within the chord's
        length, or ``reach``, of it)."""
        pts = np.asarray(pts, float)
        if pts.ndim != 2 or pts.shape[1] != 2:
            raise SurfmodError(f"pts: expected (N, 2) points, got shape {pts.shape}")
        which = np.unique(np.asarray(which, np.int64))
        if not len(which):
            return pts
        if which[0] < 0 or which[-1] >= len(pts) - 1:
            raise SurfmodError(f"which: chord indices must lie in [0, {len(pts) - 2}], got {which[0]}..{which[-1]}")
        a, b = pts[which], pts[which + 1]
        mid, chord = 0.5 * (a + b), b - a
        length = np.linalg.norm(chord, axis=1)
        normal = np.column_stack([-chord[:, 1], chord[:, 0]]) / np.where(length > 0, length, 1.0)[:, None]
        span = np.minimum(np.maximum(length, 1e-12), self.reach)
        qi, lo, hi = self.fib.query(mid, normal, z, span)
        seen = (lo <= span[qi]) & (hi >= -span[qi])
        qi, lo, hi = qi[seen], np.maximum(lo[seen], -span[qi[seen]]), np.minimum(hi[seen], span[qi[seen]])
        best = _union_nearest(len(which), qi, lo, hi)
        off = np.where(np.isfinite(best) & (np.abs(best) < span), best, 0.0)
        return np.insert(pts, which + 1, mid + off[:, None] * normal, axis=0)


def waterline(part, tool, z_levels, *, sampling: float | None = None, tolerance: float | None = None, bar=None,
              fibers: bool = False):
    """Waterline contours of ``tool`` round ``part`` at each tip height in ``z_levels``:
    a list (one entry per level) of closed loops ``(N, 3)`` in part coordinates (the
    first point not repeated), the material on the left of the direction of travel
    (counter-clockwise round islands, clockwise inside pockets).

    ``part``: triangles ``(M, 3, 3)`` (e.g. from :func:`surfmod.cam.drop_cutter.part_triangles`);
    ``tool``: a :class:`surfmod.Tool` or a :class:`~surfmod.cam.cutters.Cutter`.
    ``sampling``: spacing of the fiber grid that finds the loops (default a quarter of the
    radius; features of the tool-offset narrower than it may be missed); ``tolerance``:
    how far a chord's middle may lie from the exact contour (default 1e-6 of the part's
    size); ``bar``: a tqdm bar whose description counts the levels done.  With ``fibers``
    the result is ``(contours, fibers)``, the :class:`_Fibers` that found them (their
    ``pairs`` counts the fiber-triangle pairs met, against the estimate :func:`fiber_pairs`
    checked first; :class:`ContourPoints` reuses them).

    >>> import numpy as np
    >>> from surfmod.cam.cutters import Flat
    >>> box = np.array([[[0, 0, 0], [10, 0, 0], [10, 10, 0]], [[0, 0, 0], [10, 10, 0], [0, 10, 0]]], float)
    >>> (loop,), = waterline(box, Flat(1.0), [0.0])
    >>> bool(np.allclose(loop[:, :2].min(axis=0), -1.0, atol=1e-9)), float(loop[0, 2])
    (True, 0.0)
    """
    cutter = getattr(tool, "cutter", tool)
    R = cutter.radius
    tri = np.asarray(part, dtype=float)
    if tri.ndim != 3 or tri.shape[1:] != (3, 3) or not len(tri):
        raise SurfmodError(f"part: expected triangles (M, 3, 3), got shape {tri.shape}")
    if not np.all(np.isfinite(tri)):
        raise SurfmodError("part: triangles hold NaN or inf")
    levels = np.atleast_1d(np.asarray(z_levels, dtype=float))
    if levels.ndim != 1 or not np.all(np.isfinite(levels)):
        raise SurfmodError("z_levels: expected finite heights")
    pts = tri.reshape(-1, 3)
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    size = float(np.max(hi - lo)) or 1.0
    h = R / 4 if sampling is None else float(sampling)
    if not h > 0:
        raise SurfmodError(f"sampling: must be > 0, got {sampling}")
    tol = 1e-6 * size if tolerance is None else float(tolerance)
    if not tol > 0:
        raise SurfmodError(f"tolerance: must be > 0, got {tolerance}")
    tol = max(tol, 1e-12 * size)  # below this the contour's own rounding
    # the grid: the part's box grown by the radius and two cells, all outside
    x = np.arange(lo[0] - R - 2 * h, hi[0] + R + 2 * h + h, h)
    y = np.arange(lo[1] - R - 2 * h, hi[1] + R + 2 * h + h, h)
    px, py = pit_lines(tri, R, h)
    x, y = np.union1d(x, px), np.union1d(y, py)
    fib = _Fibers(tri, cutter, 1.5 * h)
    pairs = fiber_pairs(tri, R, h, levels, cutter.corner, (px, py))
    if pairs > MAX_PAIRS:
        raise SurfmodError(f"sampling: {sampling} gives ~{pairs:.3g} fiber-triangle pairs "
                           f"over {len(levels)} levels (limit {MAX_PAIRS:.0e}); choose a coarser sampling")
    out = [None] * len(levels)
    shanks = (_Shank(), _Shank())
    for i, k in enumerate(np.argsort(-levels, kind="stable")):  # top first: the shank intervals carry down
        if bar is not None:
            bar.set_description_str(f"  waterline level {i + 1}/{len(levels)}")
        z = levels[k]
        loops = _grid_contours(fib, z, x, y, shanks)
        if loops:
            loops = _refine(fib, z, loops, tol, 1.5 * h)
        out[k] = [np.column_stack([p, np.full(len(p), z)]) for p in loops]
    return (out, fib) if fibers else out
