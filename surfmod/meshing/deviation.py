"""Measured chordal deviation of triangles from an exact surface: sample points of each
triangle (edge points and interior, corners excluded) projected onto the surface by
Gauss-Newton from their parameter-space correspondents.  Shared by the adaptive
tessellator of surfmod surfaces and the measurement of BRepMesh triangulations."""

from __future__ import annotations

import numpy as np

from ..ops.closest import project_distances


def _barycentric(n: int) -> np.ndarray:
    """Barycentric sample points of a triangle on an ``n``-division grid, corners excluded."""
    i, j = np.meshgrid(np.arange(n + 1), np.arange(n + 1), indexing="ij")
    keep = (i + j) <= n
    b = np.stack([i[keep], j[keep], n - i[keep] - j[keep]], axis=1) / n
    return b[(b == 1.0).sum(axis=1) == 0]


COARSE = _barycentric(4)  # 12 points: edge points and interior
DENSE = _barycentric(6)  # 25 points


def triangle_deviations(d1, positions, uvs, bounds, bary=COARSE, threshold=None, d0=None, accurate_max=True):
    """Measured max deviation per triangle: ``positions`` (T, 3, 3), ``uvs`` (T, 3, 2)
    (B-spline faces of real parts go through the compiled
    :func:`surfmod.eval.packed.triangle_deviations_compiled` instead).

    Samples whose parameter-space bound is already at most ``threshold`` are not
    projected (their bound suffices to pass).  With ``accurate_max``, the samples within
    30 % of the running maximum are also projected until the maximum is a projected
    value: an accurate maximum at a fraction of the cost of projecting every sample.
    """
    if len(positions) == 0:
        return np.zeros(0)
    q = np.matmul(bary, positions).reshape(-1, 3)
    g = np.matmul(bary, uvs).reshape(-1, 2)
    thr = np.inf if threshold is None else threshold
    d0v = d0(np.clip(g[:, 0], bounds[0], bounds[1]), np.clip(g[:, 1], bounds[2], bounds[3])) if d0 else None
    first = np.linalg.norm(q - d0v, axis=1) if d0v is not None else None
    if first is None:
        d = project_distances(d1, q, g, bounds, threshold=thr)
        done = d > thr
    else:
        d = first.copy()
        done = d > thr
        idx = np.nonzero(done)[0]
        if idx.size:
            # without accurate_max, a sample's bound need only come within the threshold
            stop = 0.0 if accurate_max else thr
            d[idx] = np.minimum(d[idx], project_distances(d1, q[idx], g[idx], bounds, threshold=stop, d0=d0))
    while accurate_max and d.size:
        cand = np.nonzero(~done & (d >= 0.9 * d.max()))[0]
        if cand.size == 0:
            break
        d[cand] = np.minimum(d[cand], project_distances(d1, q[cand], g[cand], bounds, d0=d0))
        done[cand] = True
    return d.reshape(len(positions), len(bary)).max(axis=1)
