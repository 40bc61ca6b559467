"""Waterline (constant-Z) contours of an end mill round a triangle soup.

At tip height ``z`` the tool (an end mill with a shank of its own radius up to infinity:
flat, ball, or bull = flat core of radius ``R - r`` rounded by a torus of corner radius
``r``) may stand at the (x, y) positions where it meets no triangle; the waterline is
the boundary of the positions where it does.  That set is, per triangle, convex (the
tool and the triangle are convex), so along any horizontal line ("fiber") each triangle
forbids one interval of positions, whose ends are solved in closed form from the
triangle's features, as OpenCAMLib's push-cutter does:

* a vertex (or a point where an edge crosses height ``z`` or ``z + r``) forbids a disc
  of the tool's radius at that height;
* an edge's part above ``z + r`` (r the corner radius; the whole edge above ``z`` for a
  flat end) forbids the band within ``R`` of its (x, y) projection: the fiber meets the
  two offset lines;
* an edge's part between ``z`` and ``z + r`` is touched by the ball (the centre line
  meets the cylinder of radius ``R`` round the edge: a quadratic) or by the torus (the
  core circle's centre meets the ellipse where that cylinder of radius ``r`` cuts the
  plane ``z + r``, offset by ``R - r``: roots bracketed on the ellipse's angle, then
  bisected);
* a facet is touched by the tool's support point along its normal (linear in the
  position along the fiber), kept when that point falls inside the triangle.

Every candidate is a position where the tool touches the triangle, so the interval is
the smallest and largest of them.  The contours come from a grid of fibers of spacing
``sampling``: node states (inside or outside) and the exact crossing on every grid edge
whose nodes differ, joined cell by cell (marching squares, the material kept on the
left) into closed loops; then every chord whose midpoint lies farther than
``tolerance`` from the true contour (measured along a fiber normal to the chord) gets
that exact point inserted, until none does.

Work is bounded before it starts: the number of (fiber, triangle) pairs from the grid
and the triangles' boxes is estimated and refused above ``MAX_PAIRS``; refinement stops
after ``MAX_REFINE`` rounds (each halves the chord error's scale).
"""

from __future__ import annotations

import math

import numpy as np

from ..errors import SurfmodError
from .drop_cutter import TriangleGrid

MAX_PAIRS = 200_000_000  # (fiber, triangle) pairs over all levels: beyond this, coarsen sampling
PAIRS_PER_BLOCK = 400_000
MAX_REFINE = 30
TORUS_SAMPLES = 48  # angle samples bracketing the torus-edge roots (at most 4 per edge)


def _tool_shape(tool):
    kind = getattr(tool, "kind", None)
    if kind not in ("ball", "flat", "bull"):
        raise SurfmodError(f"tool: kind must be 'ball', 'flat' or 'bull', got {kind!r}")
    R = float(getattr(tool, "radius", float("nan")))
    if not R > 0:
        raise SurfmodError(f"tool: radius must be > 0, got {R}")
    if kind == "ball":
        return kind, R, R
    if kind == "flat":
        return kind, R, 0.0
    r = float(getattr(tool, "corner_radius", 0.0))
    if not 0 < r < R:
        raise SurfmodError(f"tool: corner radius must be in (0, radius {R:g}), got {r}")
    return kind, R, r


# ----------------------------------------------------------------------------------------------
# per (fiber, triangle) pair: the interval of positions where the tool meets the triangle

def _profile_radius(h, R, rc):
    """Tool radius at height ``h`` ≥ 0 above the tip (R above the corner)."""
    core = R - rc
    hc = np.clip(h, 0.0, rc)
    return np.where(h >= rc, R, core + np.sqrt(np.maximum(rc * rc - (rc - hc) ** 2, 0.0)))


class _Span:
    """Running min / max of candidate positions per pair."""

    def __init__(self, n):
        self.lo = np.full(n, np.inf)
        self.hi = np.full(n, -np.inf)

    def add(self, t, ok):
        t = np.where(ok, t, np.nan)
        self.lo = np.fmin(self.lo, t)
        self.hi = np.fmax(self.hi, t)


def _disc(span, px, py, radius, ok, ox, oy, dx, dy):
    wx, wy = px - ox, py - oy
    along = wx * dx + wy * dy
    off = wx * dy - wy * dx
    g = radius * radius - off * off
    ok = ok & (g >= 0)
    root = np.sqrt(np.where(ok, g, 0.0))
    span.add(along - root, ok)
    span.add(along + root, ok)


def intervals(tri, ox, oy, dx, dy, z, kind: str, R: float, rc: float):
    """``(t0, t1)`` per pair: positions ``o + t d`` along each pair's fiber (unit ``d``,
    horizontal, tip height ``z``) where the tool meets the pair's triangle ``tri``
    ``(P, 3, 3)``; ``t0 = inf, t1 = -inf`` where it never does."""
    n = len(ox)
    span = _Span(n)
    core = R - rc
    for j in range(3):
        p, q = tri[:, j], tri[:, (j + 1) % 3]
        h0 = p[:, 2] - z
        _disc(span, p[:, 0], p[:, 1], _profile_radius(h0, R, rc), h0 >= 0, ox, oy, dx, dy)
        e = q - p
        ez = e[:, 2]
        flat_edge = np.abs(ez) < 1e-300
        safe_ez = np.where(flat_edge, 1.0, ez)
        # crossings of the heights z and z + rc: points whose disc is the profile's there
        for level, radius in ((0.0, core), (rc, R)) if rc > 0 else ((0.0, R),):
            u = (level - h0) / safe_ez
            ok = ~flat_edge & (u > 0) & (u < 1)
            _disc(span, p[:, 0] + u * e[:, 0], p[:, 1] + u * e[:, 1], radius, ok, ox, oy, dx, dy)
        # the edge's parameter range above z + rc (cylinder) and within [z, z + rc) (end)
        ua, ub = _above(h0, ez, flat_edge, rc)
        _offset_lines(span, p, e, ua, ub, R, ox, oy, dx, dy)
        if rc > 0:
            uc, ud = _between(h0, ez, flat_edge, rc)
            if kind == "ball":
                _ball_edge(span, p, e, uc, ud, z, R, ox, oy, dx, dy)
            else:
                _torus_edge(span, p, e, uc, ud, z, R, rc, ox, oy, dx, dy)
    _facet(span, tri, z, kind, R, rc, ox, oy, dx, dy)
    return span.lo, span.hi


def _above(h0, ez, flat_edge, level):
    """Parameter range ``[ua, ub]`` of each edge where its height above z is ≥ level
    (empty: ua > ub)."""
    safe = np.where(flat_edge, 1.0, ez)
    u = (level - h0) / safe
    ua = np.where(flat_edge, np.where(h0 >= level, 0.0, 2.0), np.where(ez > 0, np.maximum(u, 0), 0.0))
    ub = np.where(flat_edge, np.where(h0 >= level, 1.0, -1.0), np.where(ez > 0, 1.0, np.minimum(u, 1)))
    return ua, ub


def _between(h0, ez, flat_edge, rc):
    a0, b0 = _above(h0, ez, flat_edge, 0.0)
    a1, b1 = _above(h0, ez, flat_edge, rc)
    # [z, z + rc) is the range above 0 minus the range above rc: one piece since the edge is straight
    lo = np.where(ez > 0, a0, np.where(ez < 0, np.maximum(a0, b1), a0))
    hi = np.where(ez > 0, np.minimum(b0, a1), np.where(ez < 0, b0, np.where(flat_edge & (h0 >= rc), -1.0, b0)))
    return lo, hi


def _offset_lines(span, p, e, ua, ub, R, ox, oy, dx, dy):
    ex, ey = e[:, 0], e[:, 1]
    L = np.hypot(ex, ey)
    ok0 = (ub >= ua) & (L > 0)
    Ls = np.where(L > 0, L, 1.0)
    nx, ny = -ey / Ls, ex / Ls
    det = -dx * ey + ex * dy  # of [d, -e] (columns)
    ok0 &= np.abs(det) > 1e-14 * Ls
    det = np.where(ok0, det, 1.0)
    for side in (1.0, -1.0):
        bx = p[:, 0] + side * R * nx - ox
        by = p[:, 1] + side * R * ny - oy
        t = (bx * -ey + ex * by) / det
        u = (dx * by - dy * bx) / det
        span.add(t, ok0 & (u >= ua) & (u <= ub))


def _ball_edge(span, p, e, uc, ud, z, R, ox, oy, dx, dy):
    Le = np.linalg.norm(e, axis=1)
    ok0 = (ud >= uc) & (Le > 0)
    L = np.where(Le > 0, Le, 1.0)
    ux, uy, uz = e[:, 0] / L, e[:, 1] / L, e[:, 2] / L
    wx, wy, wz = ox - p[:, 0], oy - p[:, 1], z + R - p[:, 2]
    De = dx * ux + dy * uy
    we = wx * ux + wy * uy + wz * uz
    a = 1.0 - De * De
    b = wx * dx + wy * dy - we * De
    c = wx * wx + wy * wy + wz * wz - we * we - R * R
    disc = b * b - a * c
    ok0 &= (a > 1e-14) & (disc >= 0)
    a = np.where(ok0, a, 1.0)
    root = np.sqrt(np.where(ok0, disc, 0.0))
    for t in ((-b - root) / a, (-b + root) / a):
        u = (we + t * De) / L
        span.add(t, ok0 & (u >= uc) & (u <= ud))


def _torus_edge(span, p, e, uc, ud, z, R, rc, ox, oy, dx, dy):
    """Torus end against the edge's part between z and z + rc: the core circle's centre
    (at height z + rc) lies at distance R - rc from the ellipse in which the cylinder of
    radius rc round the edge's line cuts that plane.  Roots of the fiber's offset from
    that ellipse's offset curve are bracketed on the ellipse angle and bisected."""
    ok0 = ud >= uc
    _torus_level_edge(span, p, e, uc, ud, z, R, rc, ox, oy, dx, dy, ok0)
    idx = np.flatnonzero(ok0 & (np.abs(e[:, 2]) > 1e-12 * np.linalg.norm(e, axis=1)))
    if not len(idx):
        return
    P, E = p[idx], e[idx]
    Ox, Oy, Dx, Dy = ox[idx], oy[idx], dx[idx], dy[idx]
    L = np.linalg.norm(E, axis=1)
    a = E / L[:, None]
    # the edge line meets the plane z + rc at the ellipse centre
    s0 = (z + rc - P[:, 2]) / a[:, 2]
    cx, cy = P[:, 0] + s0 * a[:, 0], P[:, 1] + s0 * a[:, 1]
    # ellipse: semi-axis rc across the line's horizontal direction, rc / |a_z| along it
    hxy = np.hypot(a[:, 0], a[:, 1])
    tilted = hxy > 1e-15
    ux = np.where(tilted, a[:, 0] / np.where(tilted, hxy, 1.0), 1.0)
    uy = np.where(tilted, a[:, 1] / np.where(tilted, hxy, 1.0), 0.0)
    A = rc / np.abs(a[:, 2])  # along (ux, uy)
    B = np.full_like(A, rc)  # along (-uy, ux)
    core = R - rc

    th = np.linspace(0.0, 2 * np.pi, TORUS_SAMPLES + 1)[None, :].repeat(len(idx), 0)
    f = _curve_at(th, *(k[:, None] for k in (cx, cy, A, B, ux, uy, Ox, Oy, Dx, Dy)), core)[0]
    sign = np.signbit(f)
    cross = sign[:, :-1] != sign[:, 1:]
    rows, cols = np.nonzero(cross)
    if not len(rows):
        return
    lo, hi = th[rows, cols], th[rows, cols + 1]
    sub = idx[rows]

    def curve_rows(t):
        keep = (cx, cy, A, B, ux, uy, Ox, Oy, Dx, Dy)
        return _curve_at(t, *(k[rows] for k in keep), core)

    flo = curve_rows(lo)[0]
    for _ in range(44):  # 2π/48 / 2^44: 1e-14 rad
        mid = 0.5 * (lo + hi)
        fm = curve_rows(mid)[0]
        same = np.signbit(fm) == np.signbit(flo)
        lo = np.where(same, mid, lo)
        flo = np.where(same, fm, flo)
        hi = np.where(same, hi, mid)
    _, t, qx, qy = curve_rows(0.5 * (lo + hi))
    # the contact's edge parameter: the ellipse point's foot on the edge line
    Pr, ar = P[rows], a[rows]
    foot = ((qx - Pr[:, 0]) * ar[:, 0] + (qy - Pr[:, 1]) * ar[:, 1] + (z + rc - Pr[:, 2]) * ar[:, 2]) / L[rows]
    good = (foot >= uc[sub]) & (foot <= ud[sub])
    # scatter into the span of the pairs (several roots per pair: fmin/fmax per root)
    lo_t = np.full(len(span.lo), np.inf)
    hi_t = np.full(len(span.lo), -np.inf)
    np.minimum.at(lo_t, sub[good], t[good])
    np.maximum.at(hi_t, sub[good], t[good])
    span.lo = np.minimum(span.lo, lo_t)
    span.hi = np.maximum(span.hi, hi_t)


def _curve_at(th, cx, cy, A, B, ux, uy, Ox, Oy, Dx, Dy, core):
    c, s = np.cos(th), np.sin(th)
    qx = cx + A * c * ux - B * s * uy
    qy = cy + A * c * uy + B * s * ux
    gx, gy = c / A, s / B
    g = np.hypot(gx, gy)
    nx = (gx * ux - gy * uy) / g
    ny = (gx * uy + gy * ux) / g
    fx, fy = qx + core * nx - Ox, qy + core * ny - Oy
    return fx * Dy - fy * Dx, fx * Dx + fy * Dy, qx, qy


def _torus_level_edge(span, p, e, uc, ud, z, R, rc, ox, oy, dx, dy, ok0):
    """A level edge at height h in [0, rc): the band within the profile's radius there
    of its (x, y) projection (offset lines of that radius)."""
    level = ok0 & (np.abs(e[:, 2]) <= 1e-12 * np.linalg.norm(e, axis=1))
    if not level.any():
        return
    h = p[:, 2] - z
    rho = _profile_radius(h, R, rc)
    ex, ey = e[:, 0], e[:, 1]
    Ls = np.where(np.hypot(ex, ey) > 0, np.hypot(ex, ey), 1.0)
    nx, ny = -ey / Ls, ex / Ls
    det = -dx * ey + ex * dy
    ok = level & (np.abs(det) > 1e-14 * Ls)
    det = np.where(ok, det, 1.0)
    for side in (1.0, -1.0):
        bx = p[:, 0] + side * rho * nx - ox
        by = p[:, 1] + side * rho * ny - oy
        t = (bx * -ey + ex * by) / det
        u = (dx * by - dy * bx) / det
        span.add(t, ok & (u >= 0) & (u <= 1))


def _facet(span, tri, z, kind, R, rc, ox, oy, dx, dy):
    a, b, c = tri[:, 0], tri[:, 1], tri[:, 2]
    n = np.cross(b - a, c - a)
    n *= np.where(n[:, 2:3] < 0, -1.0, 1.0)
    ln = np.linalg.norm(n, axis=1)
    n = n / np.where(ln > 0, ln, 1.0)[:, None]
    nx, ny, nz = n[:, 0], n[:, 1], n[:, 2]
    sxy = np.hypot(nx, ny)
    ok = (nz > 1e-12) & (sxy > 1e-15)
    sx = np.where(ok, nx / np.where(sxy > 0, sxy, 1.0), 0.0)
    sy = np.where(ok, ny / np.where(sxy > 0, sxy, 1.0), 0.0)
    # support point of the tool along -n, relative to the tip at (o + t d, z)
    if kind == "ball":
        px, py, pz = -R * nx, -R * ny, R - R * nz
    elif kind == "flat":
        px, py, pz = -R * sx, -R * sy, np.zeros_like(nz)
    else:
        px, py, pz = -(R - rc) * sx - rc * nx, -(R - rc) * sy - rc * ny, rc - rc * nz
    rate = nx * dx + ny * dy
    ok &= np.abs(rate) > 1e-15
    s0x, s0y, s0z = ox + px - a[:, 0], oy + py - a[:, 1], z + pz - a[:, 2]
    t = -(nx * s0x + ny * s0y + nz * s0z) / np.where(ok, rate, 1.0)
    cx, cy = ox + t * dx + px, oy + t * dy + py
    v0x, v0y, v1x, v1y = b[:, 0] - a[:, 0], b[:, 1] - a[:, 1], c[:, 0] - a[:, 0], c[:, 1] - a[:, 1]
    den = v0x * v1y - v1x * v0y
    ok &= den != 0
    den = np.where(ok, den, 1.0)
    wx, wy = cx - a[:, 0], cy - a[:, 1]
    l1 = (wx * v1y - v1x * wy) / den
    l2 = (v0x * wy - wx * v0y) / den
    span.add(t, ok & (l1 >= 0) & (l2 >= 0) & (l1 + l2 <= 1))


# ----------------------------------------------------------------------------------------------
# fibers against the mesh

class _Fibers:
    """The part's triangles for fiber queries at one tool: bucketed for short fibers."""

    def __init__(self, triangles, kind, R, rc, reach):
        self.tri = triangles
        self.kind, self.R, self.rc = kind, R, rc
        self.top = triangles[:, :, 2].max(axis=1)
        self.grid = TriangleGrid(triangles, R + reach)
        self.lo = triangles[:, :, :2].min(axis=1)
        self.hi = triangles[:, :, :2].max(axis=1)

    def lines(self, at, axis: int, z):
        """Merged components ``(start, end)`` along each grid line: the lines
        ``coordinate[axis] = at[k]``, running along the other axis (positions measured
        along it)."""
        other = 1 - axis
        tri = self.tri
        lo = tri[:, :, axis].min(axis=1) - self.R
        hi = tri[:, :, axis].max(axis=1) + self.R
        live = np.flatnonzero(self.top >= z)
        k0 = np.searchsorted(at, lo[live], "left")
        k1 = np.searchsorted(at, hi[live], "right")
        n = np.maximum(k1 - k0, 0)
        ti = np.repeat(live, n)
        li = np.repeat(k0, n) + np.arange(n.sum()) - np.repeat(np.cumsum(n) - n, n)
        o = np.zeros((len(ti), 2))
        o[:, axis] = at[li]
        d = np.zeros((len(ti), 2))
        d[:, other] = 1.0
        t0, t1 = np.empty(len(ti)), np.empty(len(ti))
        for s0 in range(0, len(ti), PAIRS_PER_BLOCK):
            s1 = s0 + PAIRS_PER_BLOCK
            t0[s0:s1], t1[s0:s1] = intervals(tri[ti[s0:s1]], o[s0:s1, 0], o[s0:s1, 1], d[s0:s1, 0], d[s0:s1, 1],
                                             z, self.kind, self.R, self.rc)
        hit = t0 <= t1
        c_line, c_lo, c_hi = _components(li[hit], t0[hit], t1[hit])
        bounds = np.searchsorted(c_line, np.arange(len(at) + 1))
        return [(c_lo[bounds[k]:bounds[k + 1]], c_hi[bounds[k]:bounds[k + 1]]) for k in range(len(at))]

    def query(self, o, d, z, reach):
        """Per fiber (the segment ``o ± reach d``: origin (F, 2), unit direction (F, 2),
        ``reach`` (F,) at most the grid's): pair arrays (fiber index, t0, t1)."""
        start, stop = self.grid.segments(o)
        out_q, out_lo, out_hi = [], [], []
        block = np.cumsum(np.maximum(stop - start, 0)) // PAIRS_PER_BLOCK
        cuts = np.r_[0, np.nonzero(np.diff(block))[0] + 1, len(o)]
        for s0, s1 in zip(cuts[:-1], cuts[1:]):
            qi, ti = self.grid.pairs(o[s0:s1], start[s0:s1], stop[s0:s1])
            qg = qi + s0
            # the triangle's box grown by R must meet the fiber's box, and reach above z
            ext = np.abs(d[qg]) * reach[qg, None] + self.R
            keep = (self.top[ti] >= z) & np.all((o[qg] + ext >= self.lo[ti]) & (o[qg] - ext <= self.hi[ti]), axis=1)
            qg, ti = qg[keep], ti[keep]
            lo, hi = intervals(self.tri[ti], o[qg, 0], o[qg, 1], d[qg, 0], d[qg, 1], z, self.kind, self.R, self.rc)
            hit = lo <= hi
            out_q.append(qg[hit]), out_lo.append(lo[hit]), out_hi.append(hi[hit])
        return np.concatenate(out_q), np.concatenate(out_lo), np.concatenate(out_hi)


def _components(qi, lo, hi):
    """Merged forbidden intervals per fiber: ``(fiber, start, end)`` of each component of
    the union of the pairs' intervals, sorted by fiber then start."""
    if not len(qi):
        return qi, lo, hi
    order = np.lexsort((lo, qi))
    qi, lo, hi = qi[order], lo[order], hi[order]
    first = np.r_[True, qi[1:] != qi[:-1]]
    starts = np.flatnonzero(first)
    counts = np.diff(np.r_[starts, len(qi)])
    # running end within each fiber: a segmented maximum, vectorised across fibers and
    # looped over the largest per-fiber pair count (bounded by the pairs themselves)
    run = hi.copy()
    for k in range(1, int(counts.max())):
        rows = starts[counts > k] + k
        run[rows] = np.maximum(run[rows], run[rows - 1])
    new = first.copy()
    new[1:] |= lo[1:] > run[:-1]
    heads = np.flatnonzero(new)
    return qi[heads], lo[heads], np.maximum.reduceat(hi, heads)


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
    of the one holding the inside node, else the nearest boundary within the edge."""
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
    else:
        got, ok = a, np.zeros(len(a), bool)
    out[differ] = np.where(ok, got, 0.5 * (a + b))  # a tangency seen by one line only: refined later
    return out


def _grid_contours(fib: _Fibers, z, x, y):
    """Closed loops (arrays of (x, y)) of the forbidden region's boundary found on the grid."""
    nx, ny = len(x), len(y)
    rows = fib.lines(y, 1, z)  # per row j: components along x
    cols = fib.lines(x, 0, z)  # per column i: components along y
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


def waterline(part, tool, z_levels, *, sampling: float | None = None, tolerance: float | None = None):
    """Waterline contours of ``tool`` round ``part`` at each tip height in ``z_levels``:
    a list (one entry per level) of closed loops ``(N, 3)`` in part coordinates (the
    first point not repeated), the material on the left of the direction of travel
    (counter-clockwise round islands, clockwise inside pockets).

    ``part``: triangles ``(M, 3, 3)`` (e.g. from :func:`surfmod.occ.triangulation.part_triangles`);
    ``tool``: anything with ``kind`` (``"ball"``, ``"flat"``, ``"bull"``), ``radius`` and
    (bull) ``corner_radius``, such as :class:`surfmod.Tool`.  ``sampling``: spacing of the
    fiber grid that finds the loops (default a quarter of the radius; features of the
    tool-offset narrower than it may be missed); ``tolerance``: how far a chord's middle
    may lie from the exact contour (default 1e-6 of the part's size).

    >>> import numpy as np
    >>> from types import SimpleNamespace
    >>> box = np.array([[[0, 0, 0], [10, 0, 0], [10, 10, 0]], [[0, 0, 0], [10, 10, 0], [0, 10, 0]]], float)
    >>> (loop,), = waterline(box, SimpleNamespace(kind="flat", radius=1.0), [0.0])
    >>> bool(np.allclose(loop[:, :2].min(axis=0), -1.0, atol=1e-9)), float(loop[0, 2])
    (True, 0.0)
    """
    kind, R, rc = _tool_shape(tool)
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
    fib = _Fibers(tri, kind, R, rc, 1.5 * h)
    # bound the work: each triangle meets the grid lines within R of its box (both
    # directions); refinement fibers add about as many again
    span = np.maximum(tri[:, :, :2].max(axis=1) - tri[:, :, :2].min(axis=1), 0) + 2 * R
    per_level = 2.0 * float((span / h + 1).sum())
    if per_level * len(levels) > MAX_PAIRS:
        raise SurfmodError(f"sampling: {sampling} gives ~{per_level * len(levels):.3g} fiber-triangle pairs "
                           f"over {len(levels)} levels (limit {MAX_PAIRS:.0e}); choose a coarser sampling")
    out = []
    for z in levels:
        loops = _grid_contours(fib, z, x, y)
        if loops:
            loops = _refine(fib, z, loops, tol, 1.5 * h)
        out.append([np.column_stack([p, np.full(len(p), z)]) for p in loops])
    return out
