"""Adaptive cell refinement of a surfmod surface (``sm.tessellate(..., method="adaptive")``).

Cells live on an integer lattice, so splitting is exact, and each is triangulated with the
corners of its finer neighbours on its sides: no T-junctions, hence no cracks.
See :doc:`/guide/meshing` (section "Tessellation of a surface").
"""

from __future__ import annotations

import numpy as np

from ..errors import SurfmodError
from ..eval.basis import knots_inside
from ..surface import model_size
from .deviation import COARSE, DENSE, triangle_deviations
from .domain import domain_sides

#: Lattice steps per start cell, as a power of two (depth limit of the refinement).
LEVELS = 22

class _Lattice:
    """Integer lattice over the domain: start cells of size ``2**LEVELS``."""

    def __init__(self, ub: np.ndarray, vb: np.ndarray):
        self.ub, self.vb = ub, vb
        self.step = 1 << LEVELS
        self.X = (len(ub) - 1) * self.step
        self.Y = (len(vb) - 1) * self.step

    def _map(self, x, breaks):
        k = np.minimum(x // self.step, len(breaks) - 2)
        return breaks[k] + (x - k * self.step) / self.step * (breaks[k + 1] - breaks[k])

    def uv(self, x, y) -> np.ndarray:
        return np.stack([self._map(x, self.ub), self._map(y, self.vb)], axis=-1)


def _breaks(s, direction: int) -> np.ndarray:
    lo, hi = s.domain[direction]
    knots = getattr(s, "knots", None)
    k = knots_inside(knots[direction], lo, hi) if knots is not None else np.empty(0)
    return np.concatenate([[lo], k[(k - lo > 1e-12 * (hi - lo)) & (hi - k > 1e-12 * (hi - lo))], [hi]])


def _start_counts(s, tolerance: float, scale: float = 1.0, samples: int = 33) -> tuple[int, int]:
    """Uniform start divisions ``(n_u, n_v)`` for a surface without knots (analytic
    surfaces: sphere, torus, ...): the fewest equal chords that the most curved iso-curve
    row needs, so that refinement does not have to round a count up to a power of two.

    Along an iso-curve of curvature ``k`` a chord of length ``h`` sags ``k h^2 / 8``;
    where the other direction is curved as much the same way (elliptic points), a
    triangle's interior deviates about
    twice its edges', hence ``k h^2 / 4``.  The count is a lower bound of what the
    tolerance needs (the rows are refined further where it is not enough); ``scale``
    divides it by ``sqrt(scale)`` (a coarser start that dyadic refinement completes).
    """
    (u0, u1), (v0, v1) = s.domain
    us, vs = np.linspace(u0, u1, samples), np.linspace(v0, v1, samples)
    d = s.grid_derivatives(us, vs, 2)
    su, sv, suu, svv = d[:, :, 1, 0], d[:, :, 0, 1], d[:, :, 2, 0], d[:, :, 0, 2]
    lu, lv = np.linalg.norm(su, axis=-1), np.linalg.norm(sv, axis=-1)
    tiny = np.finfo(float).tiny
    # no curvature counted where a speed vanishes (a pole), and no 0/0 computed there
    ku = np.divide(np.linalg.norm(np.cross(su, suu), axis=-1), lu**3, out=np.zeros_like(lu), where=lu > 0)
    kv = np.divide(np.linalg.norm(np.cross(sv, svv), axis=-1), lv**3, out=np.zeros_like(lv), where=lv > 0)
    n = np.cross(su, sv)
    same = np.einsum("...i,...i->...", n, suu) * np.einsum("...i,...i->...", n, svv) > 0  # elliptic point
    cu = scale * np.where(same, 4.0 + 4.0 * (1.0 - np.minimum(1.0, kv / np.maximum(ku, tiny))), 8.0)
    cv = scale * np.where(same, 4.0 + 4.0 * (1.0 - np.minimum(1.0, ku / np.maximum(kv, tiny))), 8.0)
    du, dv = (u1 - u0) / (samples - 1), (v1 - v0) / (samples - 1)
    rate_u = np.sqrt(ku / (cu * tolerance)) * lu  # chords per unit u
    rate_v = np.sqrt(kv / (cv * tolerance)) * lv
    nu = np.trapezoid(rate_u, dx=du, axis=0).max()  # integrate along u, worst v row
    nv = np.trapezoid(rate_v, dx=dv, axis=1).max()
    cap = 4096
    return int(min(cap, max(2, np.floor(0.999 * nu) + 1))), int(min(cap, max(2, np.floor(0.999 * nv) + 1)))


class Refiner:
    def __init__(self, s, tolerance: float, max_triangles: int, start_scale: float = 1.0, bar=None):
        self.bar = bar  # a tqdm bar ticked once per refinement pass, or None
        self.s, self.tol, self.max_triangles = s, tolerance, max_triangles
        (u0, u1), (v0, v1) = s.domain
        self.bounds = (u0, u1, v0, v1)
        self.size = model_size(s, samples=17)
        ub, vb = _breaks(s, 0), _breaks(s, 1)
        if getattr(s, "knots", None) is None:
            nu, nv = _start_counts(s, tolerance, start_scale)
            ub = np.linspace(ub[0], ub[-1], nu + 1)
            vb = np.linspace(vb[0], vb[-1], nv + 1)
        self.lat = _Lattice(ub, vb)
        self.sides = domain_sides(s, self.size)
        _, self.closed_u, self.closed_v = self.sides
        st = self.lat.step
        i, j = np.meshgrid(np.arange(len(self.lat.ub) - 1), np.arange(len(self.lat.vb) - 1), indexing="ij")
        self.x0, self.y0 = (i.ravel() * st).astype(np.int64), (j.ravel() * st).astype(np.int64)
        self.x1, self.y1 = self.x0 + st, self.y0 + st
        self.err = np.full(self.x0.size, np.nan)
        self.sig = np.full((self.x0.size, 4), -1, dtype=np.int64)
        self.iterations = 0

    def d1(self, u, v):
        return self.s._derivatives(u, v, 1)

    def d0(self, u, v):
        return self.s._derivatives(u, v, 0)[:, 0, 0]

    # lattice points -> positions
    def _key(self, x, y):
        return x * (self.lat.Y + 1) + y

    def triangulate(self):
        """Triangles of all cells as lattice corner coordinates ``(T, 3, 2)`` and their
        cell index ``(T,)``, plus the hanging-node signature per cell."""
        x0, x1, y0, y1 = self.x0, self.x1, self.y0, self.y1
        px = np.concatenate([x0, x1, x1, x0])
        py = np.concatenate([y0, y0, y1, y1])
        X, Y = self.lat.X, self.lat.Y
        if self.closed_u:
            px, py = np.concatenate([px, np.where(px == 0, X, 0)[(px == 0) | (px == X)]]), np.concatenate(
                [py, py[(px == 0) | (px == X)]]
            )
        if self.closed_v:
            sel = (py == 0) | (py == Y)
            px, py = np.concatenate([px, px[sel]]), np.concatenate([py, np.where(py[sel] == 0, Y, 0)])
        pts = np.unique(np.stack([px, py], axis=1), axis=0)
        pkeys = self._key(pts[:, 0], pts[:, 1])  # sorted, as np.unique sorts (x, y)
        ppos = self._positions(pts)

        def lookup(q):
            return ppos[np.searchsorted(pkeys, self._key(q[:, 0], q[:, 1]))]

        W = self.lat.X + 1
        H = self.lat.Y + 1
        kh = np.sort(pts[:, 1] * W + pts[:, 0])  # rows: (y, x)
        kv = np.sort(pts[:, 0] * H + pts[:, 1])  # columns: (x, y)

        def count(keys, a, b):
            lo = np.searchsorted(keys, a, "right")
            hi = np.searchsorted(keys, b, "left")
            return lo, hi - lo

        bl, bn = count(kh, y0 * W + x0, y0 * W + x1)
        tl, tn = count(kh, y1 * W + x0, y1 * W + x1)
        ll, ln = count(kv, x0 * H + y0, x0 * H + y1)
        rl, rn = count(kv, x1 * H + y0, x1 * H + y1)
        sig = np.stack([bn, rn, tn, ln], axis=1)
        simple = sig.sum(axis=1) == 0

        # simple cells: two triangles, shorter 3-D diagonal
        idx = np.nonzero(simple)[0]
        a = np.stack([x0[idx], y0[idx]], 1)
        b = np.stack([x1[idx], y0[idx]], 1)
        c = np.stack([x1[idx], y1[idx]], 1)
        d = np.stack([x0[idx], y1[idx]], 1)
        pa, pb, pc, pd = (lookup(q) for q in (a, b, c, d))
        ac = np.linalg.norm(pa - pc, axis=1) <= np.linalg.norm(pb - pd, axis=1)
        t1 = np.where(ac[:, None, None], np.stack([a, b, c], 1), np.stack([a, b, d], 1))
        t2 = np.where(ac[:, None, None], np.stack([a, c, d], 1), np.stack([b, c, d], 1))
        tris = [t1, t2]
        owner = [idx, idx]

        # cells with hanging nodes: ear clipping of the cell polygon
        hx = kh % W
        vy = kv % H
        for k in np.nonzero(~simple)[0]:
            poly = [(x0[k], y0[k])]
            poly += [(xx, y0[k]) for xx in hx[bl[k] : bl[k] + bn[k]]]
            poly.append((x1[k], y0[k]))
            poly += [(x1[k], yy) for yy in vy[rl[k] : rl[k] + rn[k]]]
            poly.append((x1[k], y1[k]))
            poly += [(xx, y1[k]) for xx in hx[tl[k] : tl[k] + tn[k]][::-1]]
            poly.append((x0[k], y1[k]))
            poly += [(x0[k], yy) for yy in vy[ll[k] : ll[k] + ln[k]][::-1]]
            poly = np.array(poly, dtype=np.int64)
            out = ear_clip(poly, lookup(poly))
            tris.append(out)
            owner.append(np.full(len(out), k))
        return np.concatenate(tris).astype(np.int64), np.concatenate(owner), sig

    def _positions(self, lattice_xy: np.ndarray) -> np.ndarray:
        if len(lattice_xy) == 0:
            return np.zeros((0, 3))
        uv = self.lat.uv(lattice_xy[:, 0], lattice_xy[:, 1])
        return self.s._derivatives(uv[:, 0], uv[:, 1], 0)[:, 0, 0]

    def measure(self, tris: np.ndarray, bary, threshold=None, accurate_max=True) -> np.ndarray:
        flat = tris.reshape(-1, 2)
        uv = self.lat.uv(flat[:, 0], flat[:, 1])
        pos = self.s._derivatives(uv[:, 0], uv[:, 1], 0)[:, 0, 0]
        return triangle_deviations(
            self.d1, pos.reshape(-1, 3, 3), uv.reshape(-1, 3, 2), self.bounds, bary, threshold, self.d0, accurate_max
        )

    def split(self, cells: np.ndarray):
        """Split the given cells along u, v or both, by the chord sagitta per direction."""
        x0, x1, y0, y1 = (a[cells] for a in (self.x0, self.x1, self.y0, self.y1))
        xm, ym = (x0 + x1) // 2, (y0 + y1) // 2

        def sag(xa, ya, xb, yb, xc, yc):
            pa = self._positions(np.stack([xa, ya], 1))
            pb = self._positions(np.stack([xb, yb], 1))
            pc = self._positions(np.stack([xc, yc], 1))
            return np.linalg.norm((pa + pb) / 2 - pc, axis=1)

        # sagitta of the u-chords (bottom, middle, top row) and of the v-chords
        eu = np.maximum.reduce([sag(x0, y, x1, y, xm, y) for y in (y0, ym, y1)])
        ev = np.maximum.reduce([sag(x, y0, x, y1, x, ym) for x in (x0, xm, x1)])
        can_u, can_v = (x1 - x0) >= 2, (y1 - y0) >= 2
        # k-d refinement: split across the direction whose chords sag more (both on a tie,
        # e.g. a twisted cell with straight edges); measured best for triangle count
        su = (eu > ev) | (eu == ev)
        sv = (ev > eu) | (eu == ev)
        su, sv = (su & can_u) | (sv & ~can_v & can_u), (sv & can_v) | (su & ~can_u & can_v)
        stuck = ~su & ~sv
        keep = np.ones(self.x0.size, bool)
        keep[cells[~stuck]] = False
        new = []
        for flag_u, flag_v in ((True, True), (True, False), (False, True)):
            m = (su == flag_u) & (sv == flag_v) & ~stuck
            if not np.any(m):
                continue
            a0, a1, b0, b1, am, bm = x0[m], x1[m], y0[m], y1[m], xm[m], ym[m]
            xs = [(a0, am), (am, a1)] if flag_u else [(a0, a1)]
            ys = [(b0, bm), (bm, b1)] if flag_v else [(b0, b1)]
            for xa, xb in xs:
                for ya, yb in ys:
                    new.append((xa, xb, ya, yb))
        self.x0 = np.concatenate([self.x0[keep]] + [n[0] for n in new])
        self.x1 = np.concatenate([self.x1[keep]] + [n[1] for n in new])
        self.y0 = np.concatenate([self.y0[keep]] + [n[2] for n in new])
        self.y1 = np.concatenate([self.y1[keep]] + [n[3] for n in new])
        added = self.x0.size - int(keep.sum())
        self.err = np.concatenate([self.err[keep], np.full(added, np.nan)])
        self.sig = np.concatenate([self.sig[keep], np.full((added, 4), -1, dtype=np.int64)])
        return int(stuck.sum())

    def _refuse_beyond_cap(self, bad: np.ndarray) -> None:
        """Refuse before splitting when even the fewest cells the refinement can end with
        exceed the cap: a split halves a cell's chords, so its sag falls at best fourfold
        (a smooth surface; less at a crease), and a cell off by ``e`` becomes at least
        ``2^ceil(log4(e / tol))`` cells."""
        splits = np.ceil(np.log(np.maximum(self.err[bad] / self.tol, 1.0)) / np.log(4.0))
        fewest = self.x0.size - bad.size + float(np.sum(2.0 ** np.maximum(splits, 1.0)))
        if 2 * fewest > self.max_triangles:
            raise SurfmodError(
                f"tolerance: {self.tol:g} needs more than {2 * fewest:,.0f} triangles, above the limit "
                f"max_triangles={self.max_triangles:,} (found after {self.iterations} refinement passes)"
            )

    def run(self):
        stuck_total = 0
        dense_pass = False
        while True:
            self.iterations += 1
            if self.bar is not None:
                self.bar.update()
            if 2 * self.x0.size > self.max_triangles:
                raise SurfmodError(
                    f"tolerance: {self.tol:g} needs more than {self.max_triangles:,} triangles (limit max_triangles)"
                )
            tris, owner, sig = self.triangulate()
            dirty = np.isnan(self.err) | np.any(sig != self.sig, axis=1)
            self.sig = sig
            if dense_pass:
                dev = self.measure(tris, DENSE, threshold=self.tol)
                cell_err = np.zeros(self.x0.size)
                np.maximum.at(cell_err, owner, dev)
                self.err = cell_err
            else:
                sel = dirty[owner]
                dev = self.measure(tris[sel], COARSE, threshold=self.tol, accurate_max=False)
                cell_err = np.where(dirty, 0.0, self.err)
                cell_err[dirty] = 0.0
                np.maximum.at(cell_err, owner[sel], dev)
                self.err = cell_err
            bad = np.nonzero(self.err > self.tol)[0]
            if bad.size == 0 or self.iterations > 200:
                if dense_pass or self.iterations > 200:
                    return tris, dev, stuck_total
                dense_pass = True
                continue
            dense_pass = False
            self._refuse_beyond_cap(bad)
            stuck = self.split(bad)
            stuck_total = max(stuck_total, stuck)
            if stuck == bad.size:  # nothing could be split any more
                tris, owner, _ = self.triangulate()
                return tris, self.measure(tris, DENSE), stuck_total


def ear_clip(poly: np.ndarray, pos: np.ndarray) -> np.ndarray:
    """Triangulate a convex cell polygon (CCW lattice points, collinear points on its
    sides) into ``n - 2`` non-degenerate triangles, clipping the ear with the shortest
    3-D diagonal first."""
    ids = list(range(len(poly)))
    out = []
    while len(ids) > 3:
        best, best_len = None, np.inf
        n = len(ids)
        for k in range(n):
            a, b, c = ids[k - 1], ids[k], ids[(k + 1) % n]
            cross = (poly[b, 0] - poly[a, 0]) * (poly[c, 1] - poly[a, 1]) - (poly[b, 1] - poly[a, 1]) * (
                poly[c, 0] - poly[a, 0]
            )
            if cross <= 0:
                continue
            # the rest must keep an area (not collapse onto the line of one side)
            rest = poly[ids[:k] + ids[k + 1 :]]
            area2 = np.dot(rest[:, 0], np.roll(rest[:, 1], -1)) - np.dot(rest[:, 1], np.roll(rest[:, 0], -1))
            if area2 <= 0:
                continue
            length = float(np.sum((pos[a] - pos[c]) ** 2))
            if length < best_len:
                best, best_len = k, length
        if best is None:  # cannot happen for a convex polygon; keep what we have
            break
        n = len(ids)
        out.append((ids[best - 1], ids[best], ids[(best + 1) % n]))
        del ids[best]
    out.append(tuple(ids))
    return poly[np.array(out)]
