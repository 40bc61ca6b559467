"""Drop-cutter against a triangle soup, vectorized over (cutter location, triangle) pairs.

The tool is an end mill with an endless shank of its own radius above the tip: a ball
end (sphere of radius ``r`` centred ``r`` above the tip), a flat end (a disc at the
tip) or a bull nose (a flat core of radius ``a = r - c`` rounded by a torus of corner
radius ``c``).  Dropped along -Z at the cutter location ``(x, y)``, it stops at the lowest tip
height where no triangle point lies inside it.  Since the shank is as wide as the end,
every triangle point within horizontal distance ``r`` of the axis bounds the tip from
below, so the shank is included without extra work (the "full cutter").

Per pair the exact contact with the triangle's three vertices, three edges and its
facet is solved in closed form (as OpenCAMLib does), then the highest contact wins:

* ball: vertex ``z + sqrt(r² - d²)``; edge: the higher root of the quadratic for the
  centre on the cylinder of radius ``r`` round the edge's line, kept when the contact
  falls inside the edge; facet: the centre at ``r`` along the upward unit normal, kept
  when the contact point ``(x, y) - r·n_xy`` lies inside the triangle;
* flat: vertex ``z`` within the disc; edge: the higher end of the edge's piece inside
  the disc; facet: the disc's rim point uphill along the plane's gradient, when inside;
* bull: vertex ``z - f(d)`` with the profile ``f(d) = 0`` on the core (``d ≤ a``) and
  ``c - sqrt(c² - (d - a)²)`` on the torus; facet: the torus's ring point ``a`` uphill of
  the axis, pushed out by ``c`` along the normal (the ball's rule for ``a = 0``, the flat
  end's for ``c = 0``); edge: along the edge ``z(u) - f(d(u))`` is concave (``f`` convex
  and increasing, ``d`` convex), so its maximum is the one root of the decreasing
  derivative, found by bisection to rounding (the torus-line contact is a quartic;
  OpenCAMLib also solves it numerically).

Candidate pairs come from a uniform (x, y) grid of cell size ~``r/2`` holding, for each
cell, every triangle whose (x, y) box grown by ``r`` meets it.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from ..errors import SurfmodError

# Pairs evaluated per block: bounds the memory of the (pairs, 7) candidate arrays.
PAIRS_PER_BLOCK = 250_000
# Barycentric slack for "contact inside the triangle": neighbouring triangles share the
# edge anyway, so a hair of overlap never adds a wrong contact.
INSIDE_SLACK = 1e-12


class TriangleGrid:
    """Triangles ``(M, 3, 3)`` bucketed on an (x, y) grid for queries of tool radius ``radius``.

    Each cell lists the triangles whose (x, y) box grown by the radius meets it.

    >>> import numpy as np
    >>> tri = np.array([[[0, 0, 1], [4, 0, 1], [0, 4, 1]]], float)
    >>> grid = TriangleGrid(tri, 0.5)
    >>> start, stop = grid.segments(np.array([[1.0, 1.0], [9.0, 9.0]]))
    >>> (stop - start).tolist()
    [1, 0]
    """

    def __init__(self, triangles: np.ndarray, radius: float):
        self.triangles = np.ascontiguousarray(triangles, dtype=float)
        self.radius = float(radius)
        # structure of arrays (12, M): a, b, c (x, y, z each), upward unit normal
        self.soa = np.ascontiguousarray(np.vstack([self.triangles.reshape(-1, 9).T,
                                                   _upward_normals(self.triangles).T]))
        self.top = self.triangles[:, :, 2].max(axis=1)
        lo = self.triangles[:, :, :2].min(axis=1) - self.radius
        hi = self.triangles[:, :, :2].max(axis=1) + self.radius
        self.lo, self.hi = lo, hi
        self.origin = lo.min(axis=0)
        span = hi.max(axis=0) - self.origin
        # cells of half a radius (a location's candidates then cover (2.5 r)², not (3 r)²),
        # but never more than ~4000 along a side (tiny tools on huge parts would otherwise
        # spread big planar triangles over millions of cells)
        self.cell = max(self.radius / 2, float(span.max()) / 4000.0)
        self.shape = (np.floor(span / self.cell).astype(np.int64) + 1)
        i0 = np.floor((lo - self.origin) / self.cell).astype(np.int64)
        i1 = np.floor((hi - self.origin) / self.cell).astype(np.int64)
        nx, ny = i1[:, 0] - i0[:, 0] + 1, i1[:, 1] - i0[:, 1] + 1
        counts = nx * ny
        tri_id = np.repeat(np.arange(len(counts)), counts)
        local = np.arange(counts.sum()) - np.repeat(np.cumsum(counts) - counts, counts)
        ix = i0[tri_id, 0] + local % nx[tri_id]
        iy = i0[tri_id, 1] + local // nx[tri_id]
        cell_id = ix * self.shape[1] + iy
        order = np.argsort(cell_id, kind="stable")
        self._cells = cell_id[order]
        self._tris = tri_id[order]

    def _cell_ids(self, xy: np.ndarray) -> np.ndarray:
        ij = np.floor((xy - self.origin) / self.cell).astype(np.int64)
        ok = np.all((ij >= 0) & (ij < self.shape), axis=1)
        return np.where(ok, ij[:, 0] * self.shape[1] + ij[:, 1], -1)

    def segments(self, xy: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``(start, stop)`` of each location's cell list (empty outside the grid)."""
        cell_id = self._cell_ids(xy)
        start = np.searchsorted(self._cells, cell_id, "left")
        stop = np.where(cell_id >= 0, np.searchsorted(self._cells, cell_id, "right"), start)
        return start, stop

    def pairs(self, xy: np.ndarray, start: np.ndarray, stop: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``(location index, triangle index)`` pairs of the list entries ``start:stop`` of
        each location whose (x, y) box grown by the radius holds the location."""
        n = np.maximum(stop - start, 0)
        qi = np.repeat(np.arange(len(xy)), n)
        offset = np.arange(n.sum()) - np.repeat(np.cumsum(n) - n, n)
        ti = self._tris[np.repeat(start, n) + offset]
        p = xy[qi]
        keep = np.all((p >= self.lo[ti]) & (p <= self.hi[ti]), axis=1)
        return qi[keep], ti[keep]


def _upward_normals(tri: np.ndarray) -> np.ndarray:
    """Unit normals with n_z ≥ 0 (the tool comes from above: a facet's upper side counts)."""
    n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    n *= np.where(n[:, 2:3] < 0, -1.0, 1.0)
    length = np.linalg.norm(n, axis=1, keepdims=True)
    return n / np.where(length > 0, length, 1.0)


def _inside_xy(t, px, py):
    """Is (px, py) inside the (x, y) projection of each triangle ``t`` (rows of the
    structure-of-arrays gather, see :meth:`TriangleGrid.gather`)?"""
    ax, ay = t[0], t[1]
    v0x, v0y, v1x, v1y = t[3] - ax, t[4] - ay, t[6] - ax, t[7] - ay
    v2x, v2y = px - ax, py - ay
    den = v0x * v1y - v1x * v0y
    ok = den != 0
    den = np.where(ok, den, 1.0)
    l1 = (v2x * v1y - v1x * v2y) / den
    l2 = (v0x * v2y - v2x * v0y) / den
    return ok & (l1 >= -INSIDE_SLACK) & (l2 >= -INSIDE_SLACK) & (l1 + l2 <= 1 + INSIDE_SLACK)


def _plane_z(t, px, py):
    nz = np.where(t[11] > 0, t[11], 1.0)
    return t[2] - (t[9] * (px - t[0]) + t[10] * (py - t[1])) / nz


def _ball_features(qx, qy, t, r: float):
    """Tip heights of a ball at (qx, qy) against each triangle's 3 vertices, 3 edges and
    facet (-inf where that feature is not touched), as 7 arrays, and the 7 contact points."""
    heights, contacts = [], []
    r2 = r * r
    for j in range(3):
        px, py, pz = t[3 * j], t[3 * j + 1], t[3 * j + 2]
        wx, wy = qx - px, qy - py
        m = wx * wx + wy * wy
        heights.append(np.where(m <= r2, pz + np.sqrt(np.maximum(r2 - m, 0.0)) - r, -np.inf))
        contacts.append((px, py, pz))
        # edge p -> p + e: centre (q, p_z + s) at distance r from the edge's line
        k3 = 3 * ((j + 1) % 3)
        ex, ey, ez = t[k3] - px, t[k3 + 1] - py, t[k3 + 2] - pz
        k = wx * ex + wy * ey
        A = ex * ex + ey * ey
        L2 = A + ez * ez
        disc = k * k * ez * ez - A * (L2 * m - k * k - r2 * L2)
        ok = (A > 1e-14 * L2) & (disc >= 0)
        s = (k * ez + np.sqrt(np.where(ok, disc, 0.0))) / np.where(ok, A, 1.0)
        u = (k + s * ez) / np.where(L2 > 0, L2, 1.0)
        ok &= (u >= 0) & (u <= 1)
        heights.append(np.where(ok, pz + s - r, -np.inf))
        u = np.clip(u, 0, 1)
        contacts.append((px + u * ex, py + u * ey, pz + u * ez))
    cx, cy = qx - r * t[9], qy - r * t[10]
    z = _plane_z(t, cx, cy)
    ok = (t[11] > 1e-12) & _inside_xy(t, cx, cy)
    heights.append(np.where(ok, z + r * t[11] - r, -np.inf))
    contacts.append((cx, cy, z))
    return heights, contacts


def _flat_features(qx, qy, t, r: float):
    """As :func:`_ball_features` for a flat end of radius ``r`` (a disc at the tip)."""
    heights, contacts = [], []
    r2 = r * r
    for j in range(3):
        px, py, pz = t[3 * j], t[3 * j + 1], t[3 * j + 2]
        dx, dy = px - qx, py - qy
        C = dx * dx + dy * dy - r2
        heights.append(np.where(C <= 0, pz, -np.inf))
        contacts.append((px, py, pz))
        # edge: the parameter interval inside the disc, |p_xy + u e_xy - q|² ≤ r²
        k3 = 3 * ((j + 1) % 3)
        ex, ey, ez = t[k3] - px, t[k3 + 1] - py, t[k3 + 2] - pz
        A = ex * ex + ey * ey
        B = ex * dx + ey * dy
        disc = B * B - A * C
        ok = (A > 0) & (disc >= 0)
        root = np.sqrt(np.where(ok, disc, 0.0))
        Ad = np.where(ok, A, 1.0)
        u0, u1 = (-B - root) / Ad, (-B + root) / Ad
        ok &= (u1 >= 0) & (u0 <= 1)
        u = np.clip(np.where(ez >= 0, u1, u0), 0, 1)  # the higher end of the piece inside the disc
        heights.append(np.where(ok, pz + u * ez, -np.inf))
        contacts.append((px + u * ex, py + u * ey, pz + u * ez))
    slope = np.hypot(t[9], t[10])
    # uphill direction of the plane is -n_xy; a level facet is touched under the axis
    scale = np.where(slope > 1e-15, r / np.where(slope > 0, slope, 1.0), 0.0)
    cx, cy = qx - scale * t[9], qy - scale * t[10]
    z = _plane_z(t, cx, cy)
    ok = (t[11] > 1e-12) & _inside_xy(t, cx, cy)
    heights.append(np.where(ok, z, -np.inf))
    contacts.append((cx, cy, z))
    return heights, contacts


#: Bisection steps for the bull's edge contact: the parameter to 2^-36 of the edge, the
#: height (second order in it at an interior maximum) to rounding.
BULL_EDGE_STEPS = 36


def _bull_profile(d, a: float, c: float):
    """Height of the bull's surface above its tip at distance ``d`` from the axis (inf
    beyond the radius), and its slope ``df/dd``."""
    t = np.maximum(d - a, 0.0)
    root = np.sqrt(np.maximum(c * c - t * t, 0.0))
    inside = d <= a + c
    f = np.where(inside, c - root, np.inf)
    slope = np.where(t <= 0, 0.0, np.where(root > 0, t / np.where(root > 0, root, 1.0), np.inf))
    return f, slope


@njit(cache=True, error_model="numpy")
def _bull_edge_kernel(dx, dy, ex, ey, ez, A, B, lo, hi, a, c, steps, u):
    """Bisection per pair on the sign of ``ez - f'(d(u)) d'(u)`` (decreasing in ``u``)."""
    for i in range(len(u)):
        left, right = lo[i], hi[i]
        for _ in range(steps):
            mid = 0.5 * (left + right)
            px, py = dx[i] + mid * ex[i], dy[i] + mid * ey[i]
            d = np.sqrt(px * px + py * py)
            t = d - a
            if t <= 0.0 or d == 0.0:
                rising = ez[i] > 0.0
            else:
                root2 = c * c - t * t
                if root2 <= 0.0:
                    rate = (mid * A[i] + B[i]) / d
                    rising = rate < 0.0 or (rate == 0.0 and ez[i] > 0.0)
                else:
                    rising = ez[i] > t / np.sqrt(root2) * (mid * A[i] + B[i]) / d
            if rising:
                left = mid
            else:
                right = mid
        u[i] = 0.5 * (left + right)


def _bull_edge_argmax(rows, default, lo, hi, dx, dy, ex, ey, ez, A, B, a: float, c: float):
    """Edge parameter ``u`` in ``[lo, hi]`` maximizing the concave ``u ez - f(d(u))`` at
    ``rows`` (``default`` elsewhere): bisection on the sign of the decreasing derivative
    (compiled: a scalar loop per pair)."""
    u = default.copy()
    if not rows.size:
        return u
    got = np.empty(rows.size)
    _bull_edge_kernel(*(np.ascontiguousarray(w[rows], dtype=np.float64) for w in (dx, dy, ex, ey, ez, A, B, lo, hi)),
                      float(a), float(c), BULL_EDGE_STEPS, got)
    u[rows] = got
    return u


def _bull_features(qx, qy, t, r: float, c: float):
    """As :func:`_ball_features` for a bull nose of radius ``r`` and corner radius ``c``."""
    a = r - c
    heights, contacts = [], []
    r2 = r * r
    for j in range(3):
        px, py, pz = t[3 * j], t[3 * j + 1], t[3 * j + 2]
        dx, dy = px - qx, py - qy
        f, _ = _bull_profile(np.sqrt(dx * dx + dy * dy), a, c)
        heights.append(np.where(np.isfinite(f), pz - f, -np.inf))
        contacts.append((px, py, pz))
        # edge p + u e: the piece inside the radius, then the maximum of the concave height
        k3 = 3 * ((j + 1) % 3)
        ex, ey, ez = t[k3] - px, t[k3 + 1] - py, t[k3 + 2] - pz
        A = ex * ex + ey * ey
        B = ex * dx + ey * dy
        C = dx * dx + dy * dy - r2
        disc = B * B - A * C
        ok = (A > 1e-14 * (A + ez * ez)) & (disc >= 0)
        root = np.sqrt(np.where(ok, disc, 0.0))
        Ad = np.where(ok, A, 1.0)
        lo = np.clip((-B - root) / Ad, 0.0, 1.0)
        hi = np.clip((-B + root) / Ad, 0.0, 1.0)
        ok &= hi > lo
        # a piece wholly on the core (d convex: both ends within a) is highest at an end
        core = (np.hypot(dx + lo * ex, dy + lo * ey) <= a) & (np.hypot(dx + hi * ex, dy + hi * ey) <= a)
        u = _bull_edge_argmax(np.flatnonzero(ok & ~core), np.where(ez > 0, hi, lo), lo, hi,
                              dx, dy, ex, ey, ez, A, B, a, c)
        ddx, ddy = dx + u * ex, dy + u * ey
        f, _ = _bull_profile(np.sqrt(ddx * ddx + ddy * ddy), a, c)
        heights.append(np.where(ok & np.isfinite(f), pz + u * ez - f, -np.inf))
        contacts.append((px + u * ex, py + u * ey, pz + u * ez))
    slope = np.hypot(t[9], t[10])
    scale = np.where(slope > 1e-15, a / np.where(slope > 0, slope, 1.0), 0.0)
    cx, cy = qx - scale * t[9] - c * t[9], qy - scale * t[10] - c * t[10]
    z = _plane_z(t, cx, cy)
    ok = (t[11] > 1e-12) & _inside_xy(t, cx, cy)
    heights.append(np.where(ok, z + c * t[11] - c, -np.inf))
    contacts.append((cx, cy, z))
    return heights, contacts


def _features(kind: str, corner: float):
    """The feature function ``(qx, qy, t, r)`` of a tool kind."""
    if kind == "ball":
        return _ball_features
    if kind == "flat":
        return _flat_features
    return lambda qx, qy, t, r: _bull_features(qx, qy, t, r, corner)


def _reach(grid: TriangleGrid, kind: str, q: np.ndarray, ti: np.ndarray, corner: float = 0.0) -> np.ndarray:
    """Upper bound of the tip height each triangle can give: its highest vertex, lifted
    (ball) by how far the ball can rise over the nearest point of its (x, y) box."""
    gap = np.maximum(np.maximum(grid.lo[ti] + grid.radius - q, q - grid.hi[ti] + grid.radius), 0.0)
    d2 = (gap**2).sum(axis=1)
    r2 = grid.radius**2
    if kind == "ball":
        return np.where(d2 <= r2, grid.top[ti] + np.sqrt(np.maximum(r2 - d2, 0.0)) - grid.radius, -np.inf)
    if kind == "bull":  # no point nearer than the box can lift the tip more than the profile there
        f, _ = _bull_profile(np.sqrt(d2), grid.radius - corner, corner)
        return np.where(d2 <= r2, grid.top[ti] - np.minimum(f, corner), -np.inf)
    return np.where(d2 <= r2, grid.top[ti], -np.inf)


def _per_location_max(qi: np.ndarray, values: np.ndarray, n: int) -> np.ndarray:
    """Max of ``values`` per location index ``qi`` (sorted), -inf where none."""
    out = np.full(n, -np.inf)
    if len(qi):
        first = np.r_[0, np.nonzero(np.diff(qi))[0] + 1]
        out[qi[first]] = np.maximum.reduceat(values, first)
    return out


def _best(grid: TriangleGrid, kind: str, xy: np.ndarray, start: np.ndarray, stop: np.ndarray, corner: float = 0.0):
    """Highest tip height ``(N,)`` (-inf if none), its contact ``(N, 3)`` and the index of
    the touched triangle ``(N,)`` (-1 if none) over the
    cell-list entries ``start:stop`` of each location, in blocks of about
    ``PAIRS_PER_BLOCK`` pairs.  Pairs whose upper bound (:func:`_reach`) is below a height
    already reached at their location are skipped."""
    features = _features(kind, corner)
    z = np.full(len(xy), -np.inf)
    touch = np.full((len(xy), 3), np.nan)
    touched = np.full(len(xy), -1, dtype=np.int64)
    block = np.cumsum(np.maximum(stop - start, 0)) // PAIRS_PER_BLOCK
    starts = np.r_[0, np.nonzero(np.diff(block))[0] + 1]
    for s0, s1 in zip(starts, np.r_[starts[1:], len(xy)]):
        q_block = xy[s0:s1]
        qi, ti = grid.pairs(q_block, start[s0:s1], stop[s0:s1])
        reach = _reach(grid, kind, q_block[qi], ti, corner)
        live = np.isfinite(reach)
        qi, ti, reach = qi[live], ti[live], reach[live]
        if not len(qi):
            continue
        # first the triangles right under each location (its (x, y) inside their box): their
        # best contact bounds from below what every other triangle must be able to beat
        q = q_block[qi]
        early = np.all((q >= grid.lo[ti] + grid.radius) & (q <= grid.hi[ti] - grid.radius), axis=1)
        q = q[early]
        heights, _ = features(q[:, 0], q[:, 1], grid.soa[:, ti[early]], grid.radius)
        bound = _per_location_max(qi[early], np.max(heights, axis=0), len(q_block))
        late = ~early & (reach >= bound[qi])
        pick = early | late
        qi, ti = qi[pick], ti[pick]
        q = q_block[qi]
        heights, _ = features(q[:, 0], q[:, 1], grid.soa[:, ti], grid.radius)
        best = np.max(heights, axis=0)
        top = _per_location_max(qi, best, len(q_block))
        hit = np.flatnonzero(best == top[qi])
        _, winner = np.unique(qi[hit], return_index=True)
        winner = hit[winner]
        rows = s0 + qi[winner]
        z[rows] = best[winner]
        # contacts of the winning pairs only
        qw = q[winner]
        heights, contacts = features(qw[:, 0], qw[:, 1], grid.soa[:, ti[winner]], grid.radius)
        feature = np.argmax(heights, axis=0)
        touch[rows] = np.array(contacts)[feature, :, np.arange(len(winner))]
        touched[rows] = ti[winner]
    return z, touch, touched


def drop(grid: TriangleGrid, kind: str, xy: np.ndarray, *, contacts: bool = False, triangles: bool = False,
         corner: float = 0.0):
    """Tip heights ``(N,)`` (NaN where the tool touches nothing) of the ``kind`` (``"ball"``,
    ``"flat"`` or ``"bull"`` of corner radius ``corner``) end mill of the grid's radius
    dropped at ``xy`` (N, 2); with
    ``contacts`` also the contact points ``(N, 3)``, with ``triangles`` also the index of
    the touched triangle ``(N,)`` (-1 where none).

    >>> import numpy as np
    >>> tri = np.array([[[-5, -5, 2], [5, -5, 2], [0, 5, 2]]], float)
    >>> drop(TriangleGrid(tri, 1.0), "ball", np.array([[0.0, 0.0], [20.0, 0.0]])).tolist()
    [2.0, nan]
    """
    if kind not in ("ball", "flat", "bull"):
        raise SurfmodError(f"tool: kind must be 'ball', 'flat' or 'bull', got {kind!r}")
    if kind == "bull" and not 0.0 < corner < grid.radius:
        raise SurfmodError(f"corner_radius: must be > 0 and < the radius {grid.radius:g}, got {corner!r}")
    xy = np.asarray(xy, dtype=float).reshape(-1, 2)
    start, stop = grid.segments(xy)
    z, touch, touched = _best(grid, kind, xy, start, stop, corner)
    z[~np.isfinite(z)] = np.nan
    return (z,) + ((touch,) if contacts else ()) + ((touched,) if triangles else ()) if contacts or triangles else z
