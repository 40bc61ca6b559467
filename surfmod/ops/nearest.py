"""The seeding of closest-point projection (:mod:`surfmod.ops.seeding`) in NumPy, for
work too small to wait for numba: every triangle of the sampled grid for every point,
instead of the compiled branch and bound.  A first ``sm.project`` of a few hundred
points would otherwise spend seconds importing numba and loading the kernel (minutes
compiling it into an empty cache) on work NumPy does in milliseconds.

The starts are the kernel's: the ``seeds`` triangles with the nearest clipped feet
(the same formula, ties in the kernel's order of cells), entered at those feet, then the
``n_basins`` deepest bottoms of the sampled distance (samples no farther than their
eight neighbours); short lists repeat their first.

>>> import numpy as np
>>> us = vs = np.linspace(0, 1, 3)
>>> g = np.stack([*np.meshgrid(us, vs, indexing="ij"), np.zeros((3, 3))], axis=-1)
>>> e, gram, cross, _ = triangle_tables(g)
>>> seed_starts(np.array([[0.3, 0.6, 1.0]]), us, vs, g, e, gram, cross, 1, 1)[0].round(12).tolist()
[[0.3, 0.6], [0.5, 0.5]]
"""

from __future__ import annotations

import numpy as np

#: triangle-point pairs per block: the block's temporaries stay a few MiB
BLOCK_PAIRS = 1 << 17


def triangle_tables(g: np.ndarray):
    """Per-cell data of the grid ``g (nu, nv, 3)``: corners, edges and the 2x2 Gram
    matrices of the two triangles ``(i,j),(i+1,j),(i+1,j+1)`` and ``(i,j),(i+1,j+1),(i,j+1)``,
    and the cell diameters.  Arrays are ``(nu-1, nv-1, ...)``."""
    p00, p10, p11, p01 = g[:-1, :-1], g[1:, :-1], g[1:, 1:], g[:-1, 1:]
    e = np.stack([p10 - p00, p11 - p00, p11 - p00, p01 - p00], axis=2)  # (.., 4, 3): e0,e1 of tri 0, of tri 1
    gram = np.einsum("...ad,...ad->...a", e[..., [0, 1, 2, 3], :], e[..., [0, 1, 2, 3], :])
    cross = np.stack([np.einsum("...d,...d->...", e[..., 0, :], e[..., 1, :]),
                      np.einsum("...d,...d->...", e[..., 2, :], e[..., 3, :])], axis=-1)
    corners = (p00, p10, p11, p01)
    diam2 = np.zeros(p00.shape[:2])
    for a in range(4):
        for b in range(a + 1, 4):
            diff = corners[a] - corners[b]
            diam2 = np.maximum(diam2, np.einsum("...d,...d->...", diff, diff))
    return (np.ascontiguousarray(e), np.ascontiguousarray(gram), np.ascontiguousarray(cross),
            np.sqrt(diam2))


def row_diameters(diam: np.ndarray) -> np.ndarray:
    """The largest cell diameter of each row of cells (prunes whole rows at once)."""
    return np.ascontiguousarray(diam.max(axis=1))


def _unit_quotient(num, det):
    """``clip(num / det, 0, 1)`` for ``det > 0``, forming only the quotients inside
    ``(0, 1)``: a degenerate triangle (a pole's collapsed edge, ``det`` at its 1e-300
    floor) seen from a far point (1e60) would otherwise overflow to inf before the clip.

    >>> _unit_quotient(np.array([-1.0, 0.5, 1e60]), np.array([1.0, 1.0, 1e-300])).tolist()
    [0.0, 0.5, 1.0]
    """
    inside = (num > 0.0) & (num < det)
    q = np.divide(num, det, out=np.zeros(np.broadcast_shapes(np.shape(num), np.shape(det))), where=inside)
    return np.where(num >= det, 1.0, q)


def _feet(a, e0, e1, d00, d11, d01):
    """Squared distances and clipped barycentric ``(beta, gamma)`` of the feet of the
    points ``a`` (relative to each triangle's first corner, ``(B, C, 3)``) on the triangles
    spanned by ``e0``, ``e1``; the operations of :func:`surfmod.ops.seeding._foot`."""
    r0 = a[..., 0] * e0[:, 0] + a[..., 1] * e0[:, 1] + a[..., 2] * e0[:, 2]
    r1 = a[..., 0] * e1[:, 0] + a[..., 1] * e1[:, 1] + a[..., 2] * e1[:, 2]
    det = np.maximum(d00 * d11 - d01 * d01, 1e-300)
    beta = _unit_quotient(d11 * r0 - d01 * r1, det)
    gamma = _unit_quotient(d00 * r1 - d01 * r0, det)
    over = np.maximum(beta + gamma, 1.0)
    beta, gamma = beta / over, gamma / over
    f = [beta * e0[:, d] + gamma * e1[:, d] - a[..., d] for d in range(3)]
    return f[0] * f[0] + f[1] * f[1] + f[2] * f[2], beta, gamma


def _bottoms(d2):
    """Samples no farther than any of their eight neighbours: ``(B, nu, nv)`` bools."""
    padded = np.pad(d2, ((0, 0), (1, 1), (1, 1)), constant_values=np.inf)
    nu, nv = d2.shape[1:]
    ok = np.ones(d2.shape, bool)
    for di in (0, 1, 2):
        for dj in (0, 1, 2):
            if di != 1 or dj != 1:
                ok &= ~(padded[:, di : di + nu, dj : dj + nv] < d2)
    return ok


def _smallest(x, k: int) -> np.ndarray:
    """Per row the indices of the ``k`` smallest entries, in rising order (ties by index,
    as the kernel's insertion keeps them): a partition, then a sort of ``k`` entries."""
    if k < x.shape[1]:
        pick = np.argpartition(x, k - 1, axis=1)[:, :k]
    else:
        pick = np.broadcast_to(np.arange(x.shape[1]), x.shape).copy()
    vals = np.take_along_axis(x, pick, axis=1)
    order = np.lexsort((pick, vals), axis=1)
    return np.take_along_axis(pick, order, axis=1)


def seed_starts(points, us, vs, g, e, gram, cross, seeds: int, n_basins: int) -> np.ndarray:
    """Starts ``(N, seeds + n_basins, 2)`` in (u, v), as
    :func:`surfmod.ops.seeding.seed_kernel` makes them (tables of
    :func:`triangle_tables`)."""
    nu, nv = g.shape[:2]
    cells = (nu - 1) * (nv - 1)
    corner = g[:-1, :-1].reshape(cells, 3)
    edges, grams, crosses = e.reshape(cells, 4, 3), gram.reshape(cells, 4), cross.reshape(cells, 2)
    ci, cj = np.divmod(np.arange(cells), nv - 1)
    out = np.empty((len(points), seeds + n_basins, 2))
    take = min(seeds, 2 * cells)
    step = max(1, BLOCK_PAIRS // (2 * cells))
    for a0 in range(0, len(points), step):  # loop over memory blocks, not points
        pts = points[a0 : a0 + step]
        rel = pts[:, None, :] - corner[None]  # (B, C, 3)
        d = np.empty((len(pts), cells, 2))
        bg = np.empty((len(pts), cells, 2, 2))
        for t in range(2):
            d[..., t], bg[..., t, 0], bg[..., t, 1] = _feet(rel, edges[:, 2 * t], edges[:, 2 * t + 1], grams[:, 2 * t],
                                                             grams[:, 2 * t + 1], crosses[:, t])
        key = _smallest(d.reshape(len(pts), -1), take)  # key = 2 cell + t
        cell, t = np.divmod(key, 2)
        beta = bg.reshape(len(pts), -1, 2)[np.arange(len(pts))[:, None], key, 0]
        gamma = bg.reshape(len(pts), -1, 2)[np.arange(len(pts))[:, None], key, 1]
        i, j = ci[cell], cj[cell]
        w0 = 1.0 - beta - gamma
        first = t == 0  # corners (i,j), (i+1,j), (i+1,j+1); else (i,j), (i+1,j+1), (i,j+1)
        u = np.where(first, w0 * us[i] + beta * us[i + 1] + gamma * us[i + 1],
                     w0 * us[i] + beta * us[i + 1] + gamma * us[i])
        v = np.where(first, w0 * vs[j] + beta * vs[j] + gamma * vs[j + 1],
                     w0 * vs[j] + beta * vs[j + 1] + gamma * vs[j + 1])
        block = out[a0 : a0 + step]
        block[:, :take, 0], block[:, :take, 1] = u, v
        block[:, take:seeds] = block[:, :1]
        # valley bottoms of the sampled distance, deepest first (ties in raster order)
        diff = g[None] - pts[:, None, None, :]
        d2 = diff[..., 0] * diff[..., 0] + diff[..., 1] * diff[..., 1] + diff[..., 2] * diff[..., 2]
        flat = np.where(_bottoms(d2), d2, np.inf).reshape(len(pts), -1)
        order = _smallest(flat, min(n_basins, flat.shape[1]))
        found = np.take_along_axis(flat, order, axis=1) < np.inf
        nearest = np.argmin(d2.reshape(len(pts), -1), axis=1)
        order[:, 0] = np.where(found[:, 0], order[:, 0], nearest)  # none (NaN): the nearest sample
        found[:, 0] = True
        order = np.where(found, order, order[:, :1])
        bi, bj = np.divmod(order, nv)
        block[:, seeds:, 0], block[:, seeds:, 1] = us[bi], vs[bj]
    return out
