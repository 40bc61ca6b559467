"""Compiled (numba) seeding for closest-point projection: for each point, the nearest
triangles of a sampled grid and the bottoms of the sampled distance, by branch and bound.

Imported lazily by :mod:`surfmod.ops.project` (``import surfmod`` does not load numba).
Per point the kernel computes the squared distances to all samples once (a vectorized
pass), then visits the grid cells with a cheap lower bound -- the nearest corner's
distance minus the cell's diameter -- and evaluates the two triangles of a cell only
when that bound beats the current ``k``-th best foot distance.  The cells around the
nearest sample go first, so the bound prunes almost everything else.  The result is the
exact ``k`` nearest triangles (by clipped-foot distance) rather than a ranking of
bounding spheres.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from .nearest import row_diameters, triangle_tables  # noqa: F401  (the kernel's tables, in NumPy)


@njit(cache=True, inline="always", error_model="numpy")
def _foot(px, py, pz, g, i, j, e, gram, cross, t):
    """Clipped barycentric foot of the point on triangle ``t`` (0 or 1) of cell ``(i, j)``:
    ``(squared distance, beta, gamma)`` (the formula of the NumPy seeding)."""
    ax, ay, az = px - g[i, j, 0], py - g[i, j, 1], pz - g[i, j, 2]
    e0, e1 = 2 * t, 2 * t + 1
    r0 = ax * e[i, j, e0, 0] + ay * e[i, j, e0, 1] + az * e[i, j, e0, 2]
    r1 = ax * e[i, j, e1, 0] + ay * e[i, j, e1, 1] + az * e[i, j, e1, 2]
    d00, d11, d01 = gram[i, j, e0], gram[i, j, e1], cross[i, j, t]
    det = max(d00 * d11 - d01 * d01, 1e-300)
    beta = min(max((d11 * r0 - d01 * r1) / det, 0.0), 1.0)
    gamma = min(max((d00 * r1 - d01 * r0) / det, 0.0), 1.0)
    over = max(beta + gamma, 1.0)
    beta /= over
    gamma /= over
    fx = beta * e[i, j, e0, 0] + gamma * e[i, j, e1, 0] - ax
    fy = beta * e[i, j, e0, 1] + gamma * e[i, j, e1, 1] - ay
    fz = beta * e[i, j, e0, 2] + gamma * e[i, j, e1, 2] - az
    return fx * fx + fy * fy + fz * fz, beta, gamma


@njit(cache=True, inline="always", error_model="numpy")
def _insert(dist, key, vals, d, k, v0, v1, v2, count):
    """Insert ``(d, k, (v0, v1, v2))`` into the sorted top list; returns the new count."""
    size = dist.size
    if count == size and d >= dist[size - 1]:
        return count
    for s in range(count):  # the same triangle already listed (the first cells go twice)
        if key[s] == k:
            return count
    pos = count if count < size else size - 1
    while pos > 0 and dist[pos - 1] > d:
        if pos < size:
            dist[pos] = dist[pos - 1]
            key[pos] = key[pos - 1]
            vals[pos, 0], vals[pos, 1], vals[pos, 2] = vals[pos - 1, 0], vals[pos - 1, 1], vals[pos - 1, 2]
        pos -= 1
    dist[pos] = d
    key[pos] = k
    vals[pos, 0], vals[pos, 1], vals[pos, 2] = v0, v1, v2
    return min(count + 1, size)


@njit(cache=True, inline="always", error_model="numpy")
def _is_bottom(d2, i, j, d):
    """No neighbour of sample ``(i, j)`` (of eight) is nearer than ``d``; the neighbours
    along the row go first, as they reject most samples at once."""
    nu, nv = d2.shape[0], d2.shape[1]
    if j > 0 and d2[i, j - 1] < d:
        return False
    if j < nv - 1 and d2[i, j + 1] < d:
        return False
    j0, j1 = max(j - 1, 0), min(j + 1, nv - 1)
    if i > 0:
        for jj in range(j0, j1 + 1):
            if d2[i - 1, jj] < d:
                return False
    if i < nu - 1:
        for jj in range(j0, j1 + 1):
            if d2[i + 1, jj] < d:
                return False
    return True


@njit(cache=True, error_model="numpy")
def seed_kernel(points, g, us, vs, e, gram, cross, diam, row_diam, seeds, n_basins, out):
    """Starts ``out (N, seeds + n_basins, 2)``: the ``seeds`` nearest triangles entered at
    their clipped feet, then the ``n_basins`` deepest bottoms of the sampled distance
    (samples no farther than their eight neighbours); short lists repeat their first."""
    nu, nv = g.shape[0], g.shape[1]
    d2 = np.empty((nu, nv))
    row_min = np.empty(nu)
    top_d, top_k, top_v = np.empty(seeds), np.empty(seeds, np.int64), np.empty((seeds, 3))
    bot_d, bot_k, bot_v = np.empty(n_basins), np.empty(n_basins, np.int64), np.empty((n_basins, 3))
    for a in range(points.shape[0]):
        px, py, pz = points[a, 0], points[a, 1], points[a, 2]
        best, bi, bj = np.inf, 0, 0
        for i in range(nu):
            for j in range(nv):
                dx, dy, dz = g[i, j, 0] - px, g[i, j, 1] - py, g[i, j, 2] - pz
                d2[i, j] = dx * dx + dy * dy + dz * dz
        for i in range(nu):
            low = np.inf
            for j in range(nv):
                if d2[i, j] < low:
                    low = d2[i, j]
                    if low < best:
                        best, bi, bj = low, i, j
            row_min[i] = low
        count = 0
        # the cells around the nearest sample first: a tight bound from the start
        for ci in range(max(bi - 1, 0), min(bi + 1, nu - 2) + 1):
            for cj in range(max(bj - 1, 0), min(bj + 1, nv - 2) + 1):
                for t in range(2):
                    d, beta, gamma = _foot(px, py, pz, g, ci, cj, e, gram, cross, t)
                    count = _insert(top_d, top_k, top_v, d, (ci * (nv - 1) + cj) * 2 + t, ci, beta, gamma, count)
        worst = np.sqrt(top_d[seeds - 1]) if count == seeds else np.inf
        for ci in range(nu - 1):
            # a whole row of cells whose nearest sample is out of reach is skipped at once
            reach = worst + row_diam[ci]
            if min(row_min[ci], row_min[ci + 1]) > reach * reach:
                continue
            for cj in range(nv - 1):
                reach = worst + diam[ci, cj]
                if min(min(d2[ci, cj], d2[ci + 1, cj]), min(d2[ci + 1, cj + 1], d2[ci, cj + 1])) > reach * reach:
                    continue
                for t in range(2):
                    d, beta, gamma = _foot(px, py, pz, g, ci, cj, e, gram, cross, t)
                    count = _insert(top_d, top_k, top_v, d, (ci * (nv - 1) + cj) * 2 + t, ci, beta, gamma, count)
                worst = np.sqrt(top_d[seeds - 1]) if count == seeds else np.inf
        for s in range(count):
            kk = top_k[s]
            t = kk % 2
            cell = kk // 2
            ci, cj = cell // (nv - 1), cell % (nv - 1)
            beta, gamma = top_v[s, 1], top_v[s, 2]
            w0 = 1.0 - beta - gamma
            if t == 0:  # corners (i,j), (i+1,j), (i+1,j+1)
                out[a, s, 0] = w0 * us[ci] + beta * us[ci + 1] + gamma * us[ci + 1]
                out[a, s, 1] = w0 * vs[cj] + beta * vs[cj] + gamma * vs[cj + 1]
            else:  # corners (i,j), (i+1,j+1), (i,j+1)
                out[a, s, 0] = w0 * us[ci] + beta * us[ci + 1] + gamma * us[ci]
                out[a, s, 1] = w0 * vs[cj] + beta * vs[cj + 1] + gamma * vs[cj + 1]
        for s in range(count, seeds):
            out[a, s, 0], out[a, s, 1] = out[a, 0, 0], out[a, 0, 1]
        # valley bottoms
        nb = 0
        for i in range(nu):
            for j in range(nv):
                d = d2[i, j]
                if nb == n_basins and d >= bot_d[n_basins - 1]:
                    continue
                # the row neighbours reject most samples: tested here, without a call
                if (j > 0 and d2[i, j - 1] < d) or (j < nv - 1 and d2[i, j + 1] < d):
                    continue
                if _is_bottom(d2, i, j, d):
                    nb = _insert(bot_d, bot_k, bot_v, d, i * nv + j, i, j, 0.0, nb)
        if nb == 0:
            bot_v[0, 0], bot_v[0, 1] = bi, bj
            nb = 1
        for s in range(n_basins):
            src = s if s < nb else 0
            out[a, seeds + s, 0] = us[int(bot_v[src, 0])]
            out[a, seeds + s, 1] = vs[int(bot_v[src, 1])]
