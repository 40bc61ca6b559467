"""Drop-cutter against a triangle soup, compiled: one scalar loop per cutter location over its
candidate triangles (:func:`drop`).

The soup is the part's faces meshed by BRepMesh and measured against them
(:func:`part_triangles`).  A location's height is the lowest tip height where no triangle
point lies inside the tool and its shank, the highest of the closed-form contacts with the
vertices, edges and facets of the triangles a :class:`TriangleGrid` cell lists, walked from
the highest bound down.  See :doc:`/guide/cam` (section "Drop-cutter").
"""

from __future__ import annotations

import numpy as np
from numba import njit

from ..errors import SurfmodError
from ..meshing.brep import tessellate_shape
from .cutters import Ball, Cutter, Flat

# Barycentric slack for "contact inside the triangle": neighbouring triangles share the
# edge anyway, so a hair of overlap never adds a wrong contact.
INSIDE_SLACK = 1e-12
BALL, FLAT = Ball.code, Flat.code  # the cutters' numbers, globals frozen into the compiled code


class TriangleGrid:
    """Triangles ``(M, 3, 3)`` bucketed on an (x, y) grid for queries of tool radius ``radius``.

    Each cell lists the triangles whose (x, y) box grown by the radius meets it, highest
    top first.

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
        self.rows = triangle_rows(self.triangles)
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
        # each cell's list from its highest triangle down (of equal tops the first): a drop
        # stops at the first triangle whose top is below the height already found
        order = np.argsort(-self.top, kind="stable")
        self._cells, self._tris = _cell_lists(i0, i1, order, int(self.shape[1]), int(self.shape.prod()))
        self._offsets = np.searchsorted(self._cells, np.arange(int(self.shape.prod()) + 1))  # each cell's first
        self._order = order
        self._drops: dict = {}  # corner radius -> the drops' cell lists (:meth:`_drop_lists`)

    @property
    def listed(self) -> np.ndarray:
        """The triangle of each cell-list entry (the lists one after the other, as
        :meth:`segments` indexes them)."""
        return self._tris

    def _cell_ids(self, xy: np.ndarray) -> np.ndarray:
        ij = np.floor((xy - self.origin) / self.cell).astype(np.int64)
        ok = np.all((ij >= 0) & (ij < self.shape), axis=1)
        return np.where(ok, ij[:, 0] * self.shape[1] + ij[:, 1], -1)

    def segments(self, xy: np.ndarray, above: float | None = None) -> tuple[np.ndarray, np.ndarray]:
        """``(start, stop)`` of each location's cell list (empty outside the grid); with
        ``above``, only its head of triangles whose top reaches ``above`` (give or take
        2e-6 of the height range: callers test the tops themselves).

        >>> tri = np.array([[[0, 0, 1], [4, 0, 1], [0, 4, 1]], [[0, 0, 3], [4, 0, 3], [0, 4, 3]]], float)
        >>> grid = TriangleGrid(tri, 0.5)
        >>> [(b - a).tolist() for a, b in (grid.segments(np.array([[1.0, 1.0]]), z) for z in (0.0, 2.0, 4.0))]
        [[2], [1], [0]]
        """
        cell_id = self._cell_ids(xy)
        inside = np.maximum(cell_id, 0)
        start = self._offsets[inside]
        stop = np.where(cell_id >= 0, self._offsets[inside + 1], start)
        if above is None:
            return start, stop
        # each list runs from its highest top down: one search on (cell, fall from the top)
        # finds where the tops pass below ``above``
        if not hasattr(self, "_fall"):
            lo, hi = float(self.top.min()), float(self.top.max())
            self._scale = 0.5 / max(hi - lo, 1e-300)
            self._fall = self._cells + (hi - self.top[self._tris]) * self._scale
        fall = (float(self.top.max()) - above) * self._scale + 1e-6
        fall = -0.25 if fall < 0 else min(fall, 0.75)  # above every top: none; below every one: the whole list
        head = np.searchsorted(self._fall, cell_id + fall, "right")
        return start, np.clip(head, start, stop)

    def pairs(self, xy: np.ndarray, start: np.ndarray, stop: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``(location index, triangle index)`` pairs of the list entries ``start:stop`` of
        each location whose (x, y) box grown by the radius holds the location (the
        waterline's fibers query the grid this way)."""
        n = np.maximum(stop - start, 0)
        qi = np.repeat(np.arange(len(xy)), n)
        offset = np.arange(n.sum()) - np.repeat(np.cumsum(n) - n, n)
        ti = self._tris[np.repeat(start, n) + offset]
        p = xy[qi]
        keep = np.all((p >= self.lo[ti]) & (p <= self.hi[ti]), axis=1)
        return qi[keep], ti[keep]

    def _drop_lists(self, corner: float):
        """The cell lists a drop of a cutter of corner radius ``corner`` walks: each
        cell's triangles that some location of the cell can touch, ordered by the highest
        tip height any location of the cell can get from them (the triangle's top lowered
        by the cutter's profile at the distance between the cell and the triangle's box,
        :func:`_cell_bounds`), highest first; and each triangle's place in the top-down
        order of :attr:`listed` (a drop's tie-break).  ``(offsets per cell, triangles,
        bounds, rank)``, built on the first drop and kept.  Without a corner (a flat end)
        the profile is level and the bound the top itself: the top-down lists serve as
        they are."""
        lists = self._drops.get(corner)
        if lists is None:
            rank = np.empty(len(self.top), np.int64)
            rank[self._order] = np.arange(len(self.top))
            if corner == 0.0:
                lists = self._drops[corner] = (self._offsets, self._tris, self.top[self._tris], rank)
                return lists
            box = np.ascontiguousarray(np.column_stack([self.lo + self.radius, self.hi - self.radius]))
            slack = 1e-9 * (float(np.abs(self.origin).sum()) + self.cell * float(self.shape.max()) + self.radius)
            offsets, tris, bounds = _cell_bounds(self._cells, self._tris, box, self.top, self.origin, self.cell,
                                                 int(self.shape[1]), int(self.shape.prod()), slack, self.radius,
                                                 corner)
            lists = self._drops[corner] = (offsets, tris, bounds, rank)
        return lists

    def entries(self, xy: np.ndarray) -> int:
        """How many cell-list entries the locations ``xy`` (N, 2) walk: the work of a drop
        (each entry costs a box test, most of them nothing more), known before it is done."""
        start, stop = self.segments(np.asarray(xy, dtype=float).reshape(-1, 2))
        return int(np.maximum(stop - start, 0).sum())


@njit(cache=True)
def _cell_lists(i0, i1, order, ny, n_cells):
    """The cells' lists one after the other: the cell and the triangle of each entry, the
    triangles whose cells span ``i0``..``i1`` listed in each in the sequence ``order``
    (a counting sort by cell: one pass to count, one to place)."""
    start = np.zeros(n_cells + 1, np.int64)
    for t in order:
        for ix in range(i0[t, 0], i1[t, 0] + 1):
            for iy in range(i0[t, 1], i1[t, 1] + 1):
                start[ix * ny + iy + 1] += 1
    for k in range(n_cells):
        start[k + 1] += start[k]
    cells, tris = np.empty(start[n_cells], np.int64), np.empty(start[n_cells], np.int64)
    for t in order:
        for ix in range(i0[t, 0], i1[t, 0] + 1):
            for iy in range(i0[t, 1], i1[t, 1] + 1):
                c = ix * ny + iy
                cells[start[c]], tris[start[c]] = c, t
                start[c] += 1
    return cells, tris


@njit(cache=True, error_model="numpy")
def _cell_bounds(cells, tris, box, top, origin, cell, ny, n_cells, slack, r, c):
    """The drop lists of :meth:`TriangleGrid._drop_lists` from the top-down lists
    (``cells``, ``tris``; ``box``: each triangle's own (x, y) box, x0 y0 x1 y1).  A
    triangle's bound in a cell is its top less the cutter's profile (a ball's is the bull's
    of a corner as large as the radius) at the least distance ``d`` between the cell's
    square and its box, the bound
    :func:`_drop_triangle` takes at a location from the location's own distance, which is
    never less; stored as float32 rounded up.  A triangle whose box lies farther than
    ``r`` from the whole cell (the grid lists it for its box grown by ``r``, corners
    included) touches no location of it and is left out; both tests have a hair of
    slack (``slack`` on the cell's sides, 1e-9 relative on the distance), so rounding in
    the cell of a location never drops a touch."""
    offsets = np.zeros(n_cells + 1, np.int64)
    keep = np.zeros(len(tris), np.bool_)
    bound = np.empty(len(tris))
    r2 = r * r
    for k in range(len(tris)):
        ci, t = cells[k], tris[k]
        x0 = origin[0] + (ci // ny) * cell - slack
        y0 = origin[1] + (ci % ny) * cell - slack
        gx = max(max(box[t, 0] - (x0 + cell + 2 * slack), x0 - box[t, 2]), 0.0)
        gy = max(max(box[t, 1] - (y0 + cell + 2 * slack), y0 - box[t, 3]), 0.0)
        d2 = gx * gx + gy * gy
        if d2 > r2 * (1.0 + 1e-9):
            continue
        keep[k] = True
        offsets[ci + 1] += 1
        # the bull's profile (a ball's is its corner of the full radius), as _drop_triangle's
        bound[k] = top[t] - min(_bull_profile(np.sqrt(d2), r - c, c), c)
    for ci in range(n_cells):
        offsets[ci + 1] += offsets[ci]
    out_tris = np.empty(offsets[n_cells], np.int32)
    out_bound = np.empty(offsets[n_cells], np.float32)
    fill = offsets[:-1].copy()
    for k in range(len(tris)):
        if keep[k]:
            ci = cells[k]
            j = fill[ci]
            out_tris[j] = tris[k]
            b = np.float32(bound[k])
            out_bound[j] = b if b >= bound[k] else np.nextafter(b, np.float32(np.inf))
            fill[ci] = j + 1
    for ci in range(n_cells):  # each cell's list from its highest bound down
        a, b = offsets[ci], offsets[ci + 1]
        if b - a > 1:
            order = np.argsort(-out_bound[a:b])
            out_tris[a:b] = out_tris[a:b][order]
            out_bound[a:b] = out_bound[a:b][order]
    return offsets, out_tris, out_bound


def triangle_rows(tri: np.ndarray) -> np.ndarray:
    """One row of 12 per triangle for the compiled kernels: a, b, c (x, y, z each), then
    the upward unit normal.

    >>> triangle_rows(np.array([[[0, 0, 0], [1, 0, 0], [0, 1, 1]]], float))[0, 9:].round(4).tolist()
    [0.0, -0.7071, 0.7071]
    """
    tri = np.asarray(tri, dtype=float)
    return np.ascontiguousarray(np.hstack([tri.reshape(-1, 9), upward_normals(tri)]))


def upward_normals(tri: np.ndarray) -> np.ndarray:
    """Unit normals with n_z ≥ 0 (the tool comes from above: a facet's upper side counts)."""
    n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    n *= np.where(n[:, 2:3] < 0, -1.0, 1.0)
    length = np.linalg.norm(n, axis=1, keepdims=True)
    return n / np.where(length > 0, length, 1.0)


@njit(cache=True, inline="always", error_model="numpy")
def _inside_xy(t, px, py):
    """Is (px, py) inside the (x, y) projection of the triangle row ``t``?"""
    ax, ay = t[0], t[1]
    v0x, v0y, v1x, v1y = t[3] - ax, t[4] - ay, t[6] - ax, t[7] - ay
    v2x, v2y = px - ax, py - ay
    den = v0x * v1y - v1x * v0y
    if den == 0.0:
        return False
    l1 = (v2x * v1y - v1x * v2y) / den
    l2 = (v0x * v2y - v2x * v0y) / den
    return l1 >= -INSIDE_SLACK and l2 >= -INSIDE_SLACK and l1 + l2 <= 1.0 + INSIDE_SLACK


@njit(cache=True, inline="always", error_model="numpy")
def _plane_z(t, px, py):
    nz = t[11] if t[11] > 0.0 else 1.0
    return t[2] - (t[9] * (px - t[0]) + t[10] * (py - t[1])) / nz


@njit(cache=True, inline="always", error_model="numpy")
def _keep(best, contact, h, x, y, z):
    """Keep the feature ``h`` at ``(x, y, z)`` when it is strictly higher (the first of equals wins)."""
    if h > best:
        contact[0], contact[1], contact[2] = x, y, z
        return h
    return best


@njit(cache=True, error_model="numpy")
def _ball(qx, qy, t, r, contact):
    """Tip height of a ball at (qx, qy) on the triangle row ``t`` (-inf if untouched), the
    highest of its 3 vertices, 3 edges and facet; the contact point goes to ``contact``."""
    best = -np.inf
    r2 = r * r
    for j in range(3):
        px, py, pz = t[3 * j], t[3 * j + 1], t[3 * j + 2]
        wx, wy = qx - px, qy - py
        m = wx * wx + wy * wy
        if m <= r2:
            best = _keep(best, contact, pz + np.sqrt(max(r2 - m, 0.0)) - r, px, py, pz)
        # edge p -> p + e: centre (q, p_z + s) at distance r from the edge's line
        k3 = 3 * ((j + 1) % 3)
        ex, ey, ez = t[k3] - px, t[k3 + 1] - py, t[k3 + 2] - pz
        k = wx * ex + wy * ey
        A = ex * ex + ey * ey
        L2 = A + ez * ez
        disc = k * k * ez * ez - A * (L2 * m - k * k - r2 * L2)
        if A > 1e-14 * L2 and disc >= 0.0:
            s = (k * ez + np.sqrt(disc)) / A
            u = (k + s * ez) / (L2 if L2 > 0.0 else 1.0)
            if 0.0 <= u <= 1.0:
                best = _keep(best, contact, pz + s - r, px + u * ex, py + u * ey, pz + u * ez)
    cx, cy = qx - r * t[9], qy - r * t[10]
    if t[11] > 1e-12 and _inside_xy(t, cx, cy):
        z = _plane_z(t, cx, cy)
        best = _keep(best, contact, z + r * t[11] - r, cx, cy, z)
    return best


@njit(cache=True, error_model="numpy")
def _flat(qx, qy, t, r, contact):
    """As :func:`_ball` for a flat end of radius ``r`` (a disc at the tip)."""
    best = -np.inf
    r2 = r * r
    for j in range(3):
        px, py, pz = t[3 * j], t[3 * j + 1], t[3 * j + 2]
        dx, dy = px - qx, py - qy
        C = dx * dx + dy * dy - r2
        if C <= 0.0:
            best = _keep(best, contact, pz, px, py, pz)
        # edge: the parameter interval inside the disc, |p_xy + u e_xy - q|² ≤ r²
        k3 = 3 * ((j + 1) % 3)
        ex, ey, ez = t[k3] - px, t[k3 + 1] - py, t[k3 + 2] - pz
        A = ex * ex + ey * ey
        B = ex * dx + ey * dy
        disc = B * B - A * C
        if A > 0.0 and disc >= 0.0:
            root = np.sqrt(disc)
            u0, u1 = (-B - root) / A, (-B + root) / A
            if u1 >= 0.0 and u0 <= 1.0:
                u = min(max(u1 if ez >= 0.0 else u0, 0.0), 1.0)  # the higher end of the piece inside the disc
                best = _keep(best, contact, pz + u * ez, px + u * ex, py + u * ey, pz + u * ez)
    # uphill direction of the plane is -n_xy; a level facet is touched under the axis
    slope = np.hypot(t[9], t[10])
    scale = r / slope if slope > 1e-15 else 0.0
    cx, cy = qx - scale * t[9], qy - scale * t[10]
    if t[11] > 1e-12 and _inside_xy(t, cx, cy):
        z = _plane_z(t, cx, cy)
        best = _keep(best, contact, z, cx, cy, z)
    return best


#: Bisection steps for the bull's edge contact: the parameter to 2^-36 of the edge, the
#: height (second order in it at an interior maximum) to rounding.
BULL_EDGE_STEPS = 36


@njit(cache=True, inline="always", error_model="numpy")
def _bull_profile(d, a, c):
    """Height of the bull's surface above its tip at distance ``d`` from the axis (inf
    beyond the radius)."""
    if d > a + c:
        return np.inf
    t = max(d - a, 0.0)
    return c - np.sqrt(max(c * c - t * t, 0.0))


@njit(cache=True, error_model="numpy")
def _bull_edge_u(dx, dy, ex, ey, ez, A, B, left, right, a, c):
    """Edge parameter in ``[left, right]`` maximizing the concave ``u ez - f(d(u))``:
    bisection on the sign of its decreasing derivative ``ez - f'(d(u)) d'(u)``."""
    for _ in range(BULL_EDGE_STEPS):
        mid = 0.5 * (left + right)
        px, py = dx + mid * ex, dy + mid * ey
        d = np.sqrt(px * px + py * py)
        t = d - a
        if t <= 0.0 or d == 0.0:
            rising = ez > 0.0
        else:
            root2 = c * c - t * t
            if root2 <= 0.0:
                rate = (mid * A + B) / d
                rising = rate < 0.0 or (rate == 0.0 and ez > 0.0)
            else:
                rising = ez > t / np.sqrt(root2) * (mid * A + B) / d
        if rising:
            left = mid
        else:
            right = mid
    return 0.5 * (left + right)


@njit(cache=True, error_model="numpy")
def _bull(qx, qy, t, r, c, contact):
    """As :func:`_ball` for a bull nose of radius ``r`` and corner radius ``c``."""
    a = r - c
    best = -np.inf
    r2 = r * r
    for j in range(3):
        px, py, pz = t[3 * j], t[3 * j + 1], t[3 * j + 2]
        dx, dy = px - qx, py - qy
        f = _bull_profile(np.sqrt(dx * dx + dy * dy), a, c)
        if f < np.inf:
            best = _keep(best, contact, pz - f, px, py, pz)
        # edge p + u e: the piece inside the radius, then the maximum of the concave height
        k3 = 3 * ((j + 1) % 3)
        ex, ey, ez = t[k3] - px, t[k3 + 1] - py, t[k3 + 2] - pz
        A = ex * ex + ey * ey
        B = ex * dx + ey * dy
        C = dx * dx + dy * dy - r2
        disc = B * B - A * C
        if not (A > 1e-14 * (A + ez * ez) and disc >= 0.0):
            continue
        root = np.sqrt(disc)
        lo = min(max((-B - root) / A, 0.0), 1.0)
        hi = min(max((-B + root) / A, 0.0), 1.0)
        if not hi > lo:
            continue
        # a piece wholly on the core (d convex: both ends within a) is highest at an end
        if np.hypot(dx + lo * ex, dy + lo * ey) <= a and np.hypot(dx + hi * ex, dy + hi * ey) <= a:
            u = hi if ez > 0.0 else lo
        else:
            u = _bull_edge_u(dx, dy, ex, ey, ez, A, B, lo, hi, a, c)
        ddx, ddy = dx + u * ex, dy + u * ey
        f = _bull_profile(np.sqrt(ddx * ddx + ddy * ddy), a, c)
        if f < np.inf:
            best = _keep(best, contact, pz + u * ez - f, px + u * ex, py + u * ey, pz + u * ez)
    slope = np.hypot(t[9], t[10])
    scale = a / slope if slope > 1e-15 else 0.0
    cx, cy = qx - scale * t[9] - c * t[9], qy - scale * t[10] - c * t[10]
    if t[11] > 1e-12 and _inside_xy(t, cx, cy):
        z = _plane_z(t, cx, cy)
        best = _keep(best, contact, z + c * t[11] - c, cx, cy, z)
    return best


@njit(cache=True, inline="always", error_model="numpy")
def _drop_triangle(code, qx, qy, rows, ti, lo, hi, top, r, c, best, contact):
    """Tip height of the cutter ``code`` at (qx, qy) on the triangle ``rows[ti]`` (the one
    choice of a cutter's routine here), or -inf when it cannot beat ``best``: no higher
    than the triangle's top, lifted (ball) or lowered (bull) by the profile over the
    nearest point of its (x, y) box (``lo``, ``hi``: the box grown by ``r``)."""
    gx = max(max(lo[0] + r - qx, qx - hi[0] + r), 0.0)
    gy = max(max(lo[1] + r - qy, qy - hi[1] + r), 0.0)
    d2 = gx * gx + gy * gy
    r2 = r * r
    reach = -np.inf if d2 > r2 else top
    if code == BALL:
        if d2 <= r2:
            reach = top + np.sqrt(max(r2 - d2, 0.0)) - r
        return -np.inf if reach < best else _ball(qx, qy, rows[ti], r, contact)
    if code == FLAT:
        return -np.inf if reach < best else _flat(qx, qy, rows[ti], r, contact)
    if d2 <= r2:  # no point nearer than the box can lift the tip more than the profile there
        reach = top - min(_bull_profile(np.sqrt(d2), r - c, c), c)
    return -np.inf if reach < best else _bull(qx, qy, rows[ti], r, c, contact)


#: how far (relative to the height and the location's size) a computed contact may pass
#: its triangle's top or box bound by rounding (7e-13 seen on a 280 mm mould): the walk
#: prunes only below the best height less this, so it finds the exact maximum whatever
#: height it starts from
PRUNE_SLACK = 1e-9


@njit(cache=True, error_model="numpy")
def _drop_kernel(code, xy, cell_id, offsets, tris, bounds, rank, rows, lo, hi, top, r, c, z, touch, touched):
    """Per location: the highest tip height over its cell's drop list, its contact and
    triangle (of equal heights the one first in the top-down order, ``rank``).

    The list runs from the highest bound down (:meth:`TriangleGrid._drop_lists`: no
    triangle lifts the tip above its bound anywhere in the cell, and
    :func:`_drop_triangle`'s tighter bound at the location skips most of the rest before
    any contact is solved), so the walk stops at the first bound below the height found:
    on a fine mesh most of a list is never read.  The previous location's triangle is tried
    first (its height on a raster's next location prunes most of the walk at once); the
    bounds are widened by :data:`PRUNE_SLACK`, so the result is the maximum over every
    triangle, whichever was tried first."""
    contact = np.empty(3)
    warm = -1
    for i in range(len(xy)):
        qx, qy = xy[i, 0], xy[i, 1]
        best, winner, bound = -np.inf, -1, -np.inf
        tried = -1
        if warm >= 0 and lo[warm, 0] <= qx <= hi[warm, 0] and lo[warm, 1] <= qy <= hi[warm, 1]:
            tried = warm
            h = _drop_triangle(code, qx, qy, rows, warm, lo[warm], hi[warm], top[warm], r, c, -np.inf, contact)
            if h > best:
                best, winner = h, warm
                bound = h - PRUNE_SLACK * (abs(h) + abs(qx) + abs(qy) + r)
                touch[i, 0], touch[i, 1], touch[i, 2] = contact[0], contact[1], contact[2]
        cell = cell_id[i]
        if cell >= 0:
            for k in range(offsets[cell], offsets[cell + 1]):
                if bounds[k] < bound:
                    break
                ti = tris[k]
                if ti == tried or not (lo[ti, 0] <= qx <= hi[ti, 0] and lo[ti, 1] <= qy <= hi[ti, 1]):
                    continue
                h = _drop_triangle(code, qx, qy, rows, ti, lo[ti], hi[ti], top[ti], r, c, bound, contact)
                if h > best or (h == best and winner >= 0 and rank[ti] < rank[winner]):
                    best, winner = h, ti
                    bound = h - PRUNE_SLACK * (abs(h) + abs(qx) + abs(qy) + r)
                    touch[i, 0], touch[i, 1], touch[i, 2] = contact[0], contact[1], contact[2]
        z[i] = best
        touched[i] = winner
        warm = winner if winner >= 0 else warm


def drop(grid: TriangleGrid, cutter: Cutter, xy: np.ndarray, *, contacts: bool = False, triangles: bool = False):
    """Tip heights ``(N,)`` (NaN where the tool touches nothing) of ``cutter`` (of the
    grid's radius) dropped at ``xy`` (N, 2); with ``contacts`` also the contact points
    ``(N, 3)``, with ``triangles`` also the index of the touched triangle ``(N,)`` (-1
    where none).

    >>> import numpy as np
    >>> from surfmod.cam.cutters import Ball
    >>> tri = np.array([[[-5, -5, 2], [5, -5, 2], [0, 5, 2]]], float)
    >>> drop(TriangleGrid(tri, 1.0), Ball(1.0), np.array([[0.0, 0.0], [20.0, 0.0]])).tolist()
    [2.0, nan]
    """
    if cutter.radius != grid.radius:
        raise SurfmodError(f"cutter: radius {cutter.radius:g} differs from the grid's {grid.radius:g}")
    xy = np.asarray(xy, dtype=float).reshape(-1, 2)
    offsets, tris, bounds, rank = grid._drop_lists(float(cutter.corner))
    z, touch = np.empty(len(xy)), np.full((len(xy), 3), np.nan)
    touched = np.empty(len(xy), dtype=np.int64)
    _drop_kernel(cutter.code, np.ascontiguousarray(xy), grid._cell_ids(xy), offsets, tris, bounds, rank, grid.rows,
                 grid.lo, grid.hi, grid.top, grid.radius, float(cutter.corner), z, touch, touched)
    z[~np.isfinite(z)] = np.nan
    return (z,) + ((touch,) if contacts else ()) + ((touched,) if triangles else ()) if contacts or triangles else z


def part_triangles(shape, deflection: float, angular: float = 0.35, *, face_index: bool = False):
    """``(triangles (M, 3, 3), deflection)``: all faces of ``shape`` meshed at the linear
    ``deflection`` (model units) and ``angular`` deflection (radians), in global
    coordinates, and the largest deviation of any triangle from its exact face (at least
    the requested deflection).  The mesh is :func:`surfmod.meshing.brep.tessellate_shape`'s:
    BRepMesh's triangles measured against the exact faces and refined where they stray
    (BRepMesh leaves twisted ruled B-spline faces, e.g. face 78 of trimesh_featuretype,
    25 times its deflection away and says so), so the deviation is measured, not
    BRepMesh's own estimate; only what the model itself is off by (its edges' declared
    tolerance) stays above the request.  A face left without triangles raises
    ``SurfmodError`` (the tool would not see it).  With ``face_index`` a third item: the
    faces (``faces_of`` order) and each triangle's index into them ``(M,)``."""
    from ..occ.topo import faces_of, wrapped

    if wrapped(shape) is None:
        raise SurfmodError(f"obj: expected an OCCT shape, got {type(shape).__name__}")
    faces = faces_of(shape)
    if not faces:
        raise SurfmodError("obj: has no faces to machine")
    mesh = tessellate_shape(shape, float(deflection), angular=angular)
    unmeshed = mesh.info["faces_not_meshed"]
    if unmeshed:
        raise SurfmodError(f"obj: BRepMesh could not triangulate {len(unmeshed)} face(s); a tool path over them "
                           f"cannot be checked")
    triangles = mesh.vertices[mesh.faces]
    measured = max(float(deflection), float(mesh.info["max_deviation"]))
    if face_index:
        owner = np.concatenate([labels for _, _, labels in mesh.info["stl_groups"]])
        return triangles, measured, (faces, owner)
    return triangles, measured
