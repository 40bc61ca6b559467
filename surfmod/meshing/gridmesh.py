"""Structured anisotropic tessellation: a tensor grid of u- and v-lines placed by
equidistributing a chordal-error bound, then *verified* and refined where it fails.

The reported ``max_deviation`` is a measured one (the largest bounds projected); seams and
poles share their vertices, so spheres and tori are watertight.  A tolerance that cannot be
reached within ``max_triangles`` raises.  See :doc:`/guide/meshing` (section "Tessellation of
a surface").
"""

from __future__ import annotations

import numpy as np

from ..errors import SurfmodError
from ..nets.knots import span_samples
from ..ops.closest import crease_breaks, project_distances
from . import gridbounds
from .domain import shared_points

#: lattice divisions per cell side for verification (6: DENSE's 25 samples per triangle)
K = 6
#: lattice points per verification block (bounded memory)
BLOCK_POINTS = 1 << 18
#: lattice points from which a block is bounded by the compiled loops (gridbounds_compiled.py);
#: smaller ones in NumPy (gridbounds.py, the same values), which spares the first mesh
#: of a process numba's import and load
COMPILED_LATTICE = 1 << 16
#: refinement passes before giving up
MAX_PASSES = 40
#: verification passes spent on coarsening after the first passing grid
COARSEN_PASSES = 2
#: coarsen only when it would leave fewer than this fraction of the cells
COARSEN_GAIN = 0.9


def _sample_params(s, direction: int, breaks: np.ndarray, base: int = 48) -> np.ndarray:
    """Sample parameters for the density: ``base`` overall, at least 4 per knot span
    (2 per span beyond 256 spans, 1 beyond 1024: nets of scanned surfaces)."""
    lo, hi = (float(x) for x in s.domain[direction])
    knots = getattr(s, "knots", None)
    spans = np.unique(np.concatenate([breaks, np.asarray(knots[direction], float)])) if knots is not None else breaks
    spans = spans[(spans >= lo) & (spans <= hi)]
    n = max(1, len(spans) - 1)
    per = max(4 if n <= 256 else (2 if n <= 1024 else 1), int(np.ceil(base / n)))
    return np.unique(np.append(span_samples(spans, per), hi))


def _fundamental(d: np.ndarray):
    """``(E, G, L, M, N, regular)`` from ``(.., 3, 3, 3)`` partials."""
    su, sv = d[..., 1, 0, :], d[..., 0, 1, :]
    n = np.cross(su, sv)
    ln = np.linalg.norm(n, axis=-1)
    E, G = np.einsum("...i,...i->...", su, su), np.einsum("...i,...i->...", sv, sv)
    regular = ln > 1e-12 * np.maximum(E + G, np.finfo(float).tiny)
    n = n / np.where(regular, ln, 1.0)[..., None]
    L = np.abs(np.einsum("...i,...i->...", n, d[..., 2, 0, :]))
    M = np.abs(np.einsum("...i,...i->...", n, d[..., 1, 1, :]))
    N = np.abs(np.einsum("...i,...i->...", n, d[..., 0, 2, :]))
    zero = ~regular
    L[zero], M[zero], N[zero] = 0.0, 0.0, 0.0
    return E, G, L, M, N, regular


def _densities(s, tol: float, us: np.ndarray, vs: np.ndarray):
    """Lines per unit u needed at each u-sample (worst over v), per unit v at each
    v-sample (worst over u), and the largest normal curvature sampled; evaluated in
    blocks of u-rows (bounded memory on nets of thousands of spans)."""
    rate_u, rate_v, kmax = np.zeros(len(us)), np.zeros(len(vs)), 0.0
    rows = max(1, (1 << 16) // len(vs))
    for i0 in range(0, len(us), rows):
        ru, rv, km = _block_densities(s, tol, us[i0 : i0 + rows], vs)
        rate_u[i0 : i0 + rows] = ru.max(axis=1)
        rate_v = np.maximum(rate_v, rv.max(axis=0))
        kmax = max(kmax, km)
    return rate_u, rate_v, kmax


def _block_densities(s, tol: float, us: np.ndarray, vs: np.ndarray):
    """Lines per unit u and v needed at each sample (``(len(us), len(vs))`` each) and the
    largest normal curvature sampled."""
    d = s._grid_derivatives(us, vs, 2)
    E, G, L, M, N, regular = _fundamental(d)
    tiny = np.finfo(float).tiny
    r = np.where(regular, np.sqrt(G / np.where(regular, E, 1.0)), 1.0)  # |S_v| / |S_u|
    # the twist term 2|M| h_u h_v, shared between the directions for cells of equal sides
    lu, lv = L + M / r, N + M * r
    ku, kv = lu / np.maximum(E, tiny), lv / np.maximum(G, tiny)  # normal curvatures
    # where both directions bend, a triangle's interior sags by about the sum of both
    # chords' sagittas: each direction gets half the tolerance (c = 4) where the other
    # bends as much, more of it (c -> 8) as the other bends less.  Saddles are treated
    # like domes (their diagonal could sag less): measured on the benchmark surfaces,
    # this gave fewer triangles than c = 8 at saddles, after verification
    both = (L > 0) & (N > 0)
    cu = np.where(both, 4.0 + 4.0 * (1.0 - np.minimum(1.0, kv / np.maximum(ku, tiny))), 8.0)
    cv = np.where(both, 4.0 + 4.0 * (1.0 - np.minimum(1.0, ku / np.maximum(kv, tiny))), 8.0)
    rate_u = np.where(regular, np.sqrt(lu / (cu * tol)), 0.0)
    rate_v = np.where(regular, np.sqrt(lv / (cv * tol)), 0.0)
    # largest principal curvature is at most |L|/E + |N|/G + 2|M|/sqrt(EG) (bound of the
    # second fundamental form in an orthonormal frame)
    kmax = (L / np.maximum(E, tiny) + N / np.maximum(G, tiny) + 2 * M / np.sqrt(np.maximum(E * G, tiny)))[regular]
    return rate_u, rate_v, float(kmax.max(initial=0.0))


def equidistribute(params: np.ndarray, rate: np.ndarray, breaks: np.ndarray) -> np.ndarray:
    """Lines between ``breaks`` at equal steps of the integral of ``rate`` (sampled at
    ``params``): in each span the fewest intervals whose integral is at most 1.

    >>> equidistribute(np.linspace(0, 1, 5), np.full(5, 3.5), np.array([0.0, 1.0])).tolist()
    [0.0, 0.25, 0.5, 0.75, 1.0]
    """
    out = [breaks[:1]]
    for a, b in zip(breaks[:-1], breaks[1:]):
        t = np.unique(np.concatenate([[a, b], params[(params > a) & (params < b)]]))
        r = np.interp(t, params, rate)
        cum = np.concatenate([[0.0], np.cumsum(0.5 * (r[1:] + r[:-1]) * np.diff(t))])
        n = max(1, int(np.floor(0.999 * cum[-1])) + 1)
        if n == 1:
            out.append([b])
            continue
        targets = cum[-1] * np.arange(1, n) / n
        out.append(np.interp(targets, cum, t))
        out.append([b])
    lines = np.concatenate(out)
    return lines[np.concatenate([[True], np.diff(lines) > 0])]


def _lattice(lines: np.ndarray, lo: int, hi: int) -> np.ndarray:
    """Lattice parameters of cells ``lo..hi-1``: ``K`` per cell plus the closing line."""
    a, h = lines[lo:hi], np.diff(lines[lo : hi + 1])
    t = np.arange(K) / K
    return np.concatenate([(a[:, None] + t[None, :] * h[:, None]).ravel(), lines[hi : hi + 1]])


class GridMesh:
    """State of the tensor grid of one surface: the density model, the lines
    (``us``, ``vs``) and, after :meth:`verify`, per-cell errors, diagonals and vertices.

    >>> import surfmod as sm
    >>> g = GridMesh(sm.torus(3.0, 1.0), 0.05)
    >>> dev = g.verify()
    >>> g.err.shape == (len(g.us) - 1, len(g.vs) - 1), bool(g.err.max() == dev)
    (True, True)
    """

    def __init__(self, s, tol: float):
        self.s, self.tol = s, tol
        (u0, u1), (v0, v1) = s.domain
        self.bounds = (float(u0), float(u1), float(v0), float(v1))
        self.breaks = crease_breaks(s, 0), crease_breaks(s, 1)
        self.samples = _sample_params(s, 0, self.breaks[0]), _sample_params(s, 1, self.breaks[1])
        # per direction the worst density over the other one: the lines of a tensor grid
        # run through the whole domain
        rate_u, rate_v, kmax = _densities(s, tol, *self.samples)
        self.rates = [rate_u, rate_v]
        self.kmax = 1.5 * kmax  # margin: the sampled curvature is not a bound
        self.us = equidistribute(self.samples[0], self.rates[0], self.breaks[0])
        self.vs = equidistribute(self.samples[1], self.rates[1], self.breaks[1])
        self.corrections = 0

    def verify(self) -> float:
        """Verify the grid: per-cell deviation ``err`` ``(nu, nv)``, diagonals ``diag``
        (True: 00-11), the sagging of each cell's u- and v-sides (``eu``, ``ev``) and
        the vertices; returns the largest deviation (measured by projection at the
        samples over the tolerance or near the maximum, bounded elsewhere)."""
        us, vs = self.us, self.vs
        nu, nv = len(us) - 1, len(vs) - 1
        self.err, self.eu, self.ev = np.zeros((nu, nv)), np.zeros((nu, nv)), np.zeros((nu, nv))
        self.diag = np.zeros((nu, nv), bool)
        self.verts = np.empty((nu + 1, nv + 1, 3))
        rows = max(1, BLOCK_POINTS // ((K * nv + 1) * K))
        lat_v = _lattice(vs, 0, nv)
        blocks, cand, top = [], [], 0.0
        for i0 in range(0, nu, rows):
            i1 = min(nu, i0 + rows)
            lat_u = _lattice(us, i0, i1)
            S = np.ascontiguousarray(self.s._grid_derivatives(lat_u, lat_v, 0)[:, :, 0, 0])
            self.verts[i0 : i1 + 1] = S[::K, ::K]
            diag = self.diag[i0:i1]
            compiled = S.shape[0] * S.shape[1] >= COMPILED_LATTICE
            if compiled:
                from .gridbounds_compiled import diagonals_compiled, estimates_compiled  # numba: first large lattice

                diagonals_compiled(S, K, diag)
                est = np.empty(S.shape[:2])
                Q = np.empty_like(S)
                estimates_compiled(S, K, diag, self.kmax, est, Q)
            else:
                diag[...] = gridbounds.diagonals(S, K, diag.shape)
                est, Q = gridbounds.estimates(S, K, diag, self.kmax)
            top = max(top, float(est.max()))
            # candidates for projection: over the tolerance or near the running maximum
            idx = np.flatnonzero(est > min(self.tol, 0.9 * top))
            A, B = np.divmod(idx, est.shape[1])
            cand.append((len(blocks), idx, Q.reshape(-1, 3)[idx], np.stack([lat_u[A], lat_v[B]], 1)))
            blocks.append((i0, i1, est))
        self._project(blocks, cand, top)
        for i0, i1, est in blocks:
            parts = self.err[i0:i1], self.eu[i0:i1], self.ev[i0:i1]
            if est.size >= COMPILED_LATTICE:
                from .gridbounds_compiled import cell_maxima_compiled

                cell_maxima_compiled(est, K, *parts)
            else:
                for part, value in zip(parts, gridbounds.cell_maxima(est, K, parts[0].shape)):
                    part[...] = value
        return float(self.err.max(initial=0.0))

    def _project(self, blocks, cand, top: float) -> None:
        """When the grid passes, make its reported maximum a *measured* one: project the
        samples with the largest bounds onto the surface by Gauss-Newton, in rounds
        (bounds >= 0.98 of the maximum first, then down to the largest distance
        measured so far), until no sample left unprojected has a bound above the
        measured maximum.  A failing grid is refined without projecting (its bound is
        within a few per cent of the distance, so projections would rarely clear it)."""
        if top > self.tol or not cand:
            return
        est_all = np.concatenate([blocks[c[0]][2].ravel()[c[1]] for c in cand])
        q_all = np.concatenate([c[2] for c in cand])
        uv_all = np.concatenate([c[3] for c in cand])
        offsets = np.cumsum([0] + [len(c[1]) for c in cand])
        s = self.s
        done = np.zeros(len(est_all), bool)
        hi, measured = np.inf, 0.0
        lo = 0.98 * top
        while True:
            sel = np.flatnonzero(~done & (est_all >= lo) & (est_all < hi))
            if sel.size:
                dist = project_distances(
                    lambda u, v: s._derivatives(u, v, 1), q_all[sel], uv_all[sel], self.bounds,
                    d0=lambda u, v: s._derivatives(u, v, 0)[:, 0, 0],
                )
                est_all[sel] = np.minimum(est_all[sel], dist)
                done[sel] = True
                measured = max(measured, float(est_all[sel].max()))
            rest = est_all[~done]
            if rest.size == 0 or rest.max() <= measured:
                break
            hi, lo = lo, max(measured, 0.9 * lo)
        # write the measured distances back into the blocks' bounds
        for k, (bi, idx, _, _) in enumerate(cand):
            part = slice(offsets[k], offsets[k + 1])
            flat = blocks[bi][2].reshape(-1)
            flat[idx] = est_all[part]

    def refine(self) -> bool:
        """Refine the strips of failing cells in the direction whose sides sag (both when
        neither does: the error is inside); False if no cell fails.

        The first passes correct the density model: in a failing strip the density is
        raised to at least the strip's present one, times ``sqrt(err / tol)`` (chordal
        error goes with the square of the step), and all lines are placed again, so a
        count that was a little short grows a little instead of doubling.  Later passes
        insert the strips' midlines, which always terminates."""
        bad = self.err > self.tol
        if not bad.any():
            return False
        split_u = bad & (self.eu >= 0.6 * self.ev)
        split_v = bad & (self.ev >= 0.6 * self.eu)
        both = bad & ~split_u & ~split_v
        factor = np.sqrt(np.where(bad, self.err / self.tol, 1.0)) * 1.03
        if self.corrections < 3:
            self.corrections += 1
            for axis, mask in ((0, split_u | both), (1, split_v | both)):
                lines = self.us if axis == 0 else self.vs
                g = np.where(mask, factor, 1.0).max(axis=1 - axis)  # per strip
                if not np.any(g > 1.0):
                    continue
                params = self.samples[axis]
                strip = np.clip(np.searchsorted(lines, params, side="right") - 1, 0, len(lines) - 2)
                gs = g[strip]
                present = 1.0 / np.diff(lines)[strip]
                self.rates[axis] = np.where(gs > 1.0, np.maximum(self.rates[axis], present) * gs, self.rates[axis])
                new = equidistribute(params, self.rates[axis], self.breaks[axis])
                if axis == 0:
                    self.us = new
                else:
                    self.vs = new
            return True
        iu = np.unique(np.nonzero(split_u | both)[0])
        jv = np.unique(np.nonzero(split_v | both)[1])
        if iu.size:
            self.us = np.sort(np.concatenate([self.us, 0.5 * (self.us[iu] + self.us[iu + 1])]))
        if jv.size:
            self.vs = np.sort(np.concatenate([self.vs, 0.5 * (self.vs[jv] + self.vs[jv + 1])]))
        return True

    def coarsen(self) -> bool:
        """After a passing verification: lower the density of the strips whose cells all
        stay well inside the tolerance, by ``sqrt(err / tol)`` per strip (a cell's error
        grows at most by the square of the larger of its two strips' step ratios, so
        each cell stays within the tolerance to the model's accuracy), and place the
        lines again.  False (nothing changed) when that would save less than
        ``1 - COARSEN_GAIN`` of the cells: not worth the verification it costs."""
        new_lines, new_rates = [self.us, self.vs], list(self.rates)
        for axis in (0, 1):
            lines = new_lines[axis]
            worst = self.err.max(axis=1 - axis)  # per strip
            c = np.sqrt(np.maximum(worst, 1e-3 * self.tol) / self.tol) * 1.03
            if not np.any(c < 0.9):
                continue
            params = self.samples[axis]
            strip = np.clip(np.searchsorted(lines, params, side="right") - 1, 0, len(lines) - 2)
            cs = np.minimum(c[strip], 1.0)
            present = 1.0 / np.diff(lines)[strip]
            # the density the present strips realise, lowered where they have room
            new_rates[axis] = np.where(cs < 0.9, np.minimum(self.rates[axis], present) * np.maximum(cs, 0.5),
                                       self.rates[axis])
            new = equidistribute(params, new_rates[axis], self.breaks[axis])
            if len(new) < len(lines):
                new_lines[axis] = new
        cells = (len(new_lines[0]) - 1) * (len(new_lines[1]) - 1)
        if cells >= COARSEN_GAIN * (len(self.us) - 1) * (len(self.vs) - 1):
            return False
        self.us, self.vs = new_lines
        self.rates = new_rates
        return True

    def snapshot(self):
        return (self.us, self.vs, self.err, self.diag, self.verts)

    def restore(self, snap) -> None:
        self.us, self.vs, self.err, self.diag, self.verts = snap


def grid_tessellate(s, tol: float, max_triangles: int, sides, bar=None):
    """Tessellate ``s`` as a verified structured grid.  ``sides = (degenerate, closed_u,
    closed_v)`` from :func:`surfmod.meshing.domain.domain_sides`.  Returns
    ``(vertices, triangles, uv, max_deviation, passes)``.

    >>> import surfmod as sm
    >>> from surfmod.meshing.domain import domain_sides
    >>> s = sm.sphere(1.0)
    >>> v, f, uv, dev, passes = grid_tessellate(s, 0.01, 10_000, domain_sides(s, 2.0))
    >>> bool(dev <= 0.01), v.shape == (len(uv), 3)
    (True, True)
    """
    g = GridMesh(s, tol)
    passes, best, after_pass = 0, None, 0
    while True:
        passes += 1
        if bar is not None:
            bar.update()
        ntri = 2 * (len(g.us) - 1) * (len(g.vs) - 1)
        if best is not None and ntri >= best[0]:
            break  # a coarsening that had to be refined back: keep the best grid
        if ntri > max_triangles:
            raise SurfmodError(
                f"tolerance: {tol:g} needs more than {max_triangles:,} triangles on a structured grid "
                "(limit max_triangles)"
            )
        dev = g.verify()
        if best is not None:
            after_pass += 1
        if dev <= tol:
            best = (ntri, dev, g.snapshot())
            # try fewer lines where the strips have room (twice at most)
            if after_pass >= COARSEN_PASSES or not g.coarsen():
                break
            continue
        if best is not None and after_pass >= COARSEN_PASSES:
            break
        if passes >= MAX_PASSES or not g.refine():
            raise SurfmodError(
                f"tolerance: {tol:g} not reached: estimated {g.err.max():.3g} after {passes} refinement passes"
            )
    ntri, dev, snap = best
    g.restore(snap)
    verts, faces, uv = _assemble(g, sides)
    return verts, faces, uv, dev, passes


def _assemble(g: GridMesh, sides):
    """Vertices shared across seams and poles, two triangles per cell on its diagonal."""
    nu, nv = len(g.us) - 1, len(g.vs) - 1
    ci, cj = shared_points(*np.meshgrid(np.arange(nu + 1), np.arange(nv + 1), indexing="ij"), nu, nv, sides)
    key = ci * (nv + 1) + cj
    unique, first, inverse = np.unique(key.ravel(), return_index=True, return_inverse=True)
    vid = inverse.reshape(nu + 1, nv + 1)
    a, b, c, d = vid[:-1, :-1], vid[1:, :-1], vid[1:, 1:], vid[:-1, 1:]
    dg = g.diag
    t1 = np.where(dg[..., None], np.stack([a, b, c], -1), np.stack([a, b, d], -1))
    t2 = np.where(dg[..., None], np.stack([a, c, d], -1), np.stack([b, c, d], -1))
    faces = np.concatenate([t1.reshape(-1, 3), t2.reshape(-1, 3)])
    keep = (faces[:, 0] != faces[:, 1]) & (faces[:, 1] != faces[:, 2]) & (faces[:, 0] != faces[:, 2])
    flat_i, flat_j = ci.ravel()[first], cj.ravel()[first]
    uv = np.stack([g.us[flat_i], g.vs[flat_j]], axis=1)
    verts = g.verts[flat_i, flat_j]
    return verts, faces[keep], uv
