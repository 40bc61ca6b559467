"""Measured chordal deviation of triangles from an exact surface: sample points of each
triangle (edge points and interior, corners excluded) projected onto the surface by
Gauss-Newton from their parameter-space correspondents.  Shared by the adaptive
tessellator of surfmod surfaces and the measurement of BRepMesh triangulations."""

from __future__ import annotations

import numpy as np


def _barycentric(n: int) -> np.ndarray:
    """Barycentric sample points of a triangle on an ``n``-division grid, corners excluded."""
    i, j = np.meshgrid(np.arange(n + 1), np.arange(n + 1), indexing="ij")
    keep = (i + j) <= n
    b = np.stack([i[keep], j[keep], n - i[keep] - j[keep]], axis=1) / n
    return b[(b == 1.0).sum(axis=1) == 0]


COARSE = _barycentric(4)  # 12 points: edge points and interior
DENSE = _barycentric(6)  # 25 points


def project_distances(d1, points, uv, bounds, iterations: int = 6, threshold: float = 0.0, d0=None) -> np.ndarray:
    """Distance from ``points`` (N, 3) to a surface, by Gauss-Newton from the parameter
    guesses ``uv`` (N, 2), clipped to ``bounds = (u0, u1, v0, v1)``.

    ``d1(u, v)`` returns ``(N, >=2, >=2, 3)`` derivatives (``d0`` optionally positions
    only).  Every iterate is a point of the surface, so the smallest distance seen is an
    upper bound of the true distance (for the guarantee, over-estimating is the safe
    side).  Points whose bound is ``<= threshold`` (at first or after an iteration) are
    not iterated further: below the threshold the bound is all that is asked.

    >>> import numpy as np, surfmod as sm
    >>> s = sm.plane((0, 0, 0), (1, 0, 0), (0, 1, 0))
    >>> d = project_distances(lambda u, v: s._derivatives(u, v, 1),
    ...     np.array([[0.2, 0.7, 0.5]]), np.array([[0.0, 0.0]]), (0, 1, 0, 1))
    >>> float(d[0])
    0.5
    """
    u0, u1, v0, v1 = bounds
    u = np.clip(uv[:, 0], u0, u1)
    v = np.clip(uv[:, 1], v0, v1)
    first = d0(u, v) if d0 is not None else d1(u, v)[:, 0, 0]
    best = np.linalg.norm(points - first, axis=1)
    act = np.nonzero(best > threshold)[0]
    step_u, step_v = 0.25 * (u1 - u0), 0.25 * (v1 - v0)
    ua, va = u[act], v[act]
    for _ in range(iterations):
        if act.size == 0:
            break
        ders = d1(ua, va)
        r = points[act] - ders[:, 0, 0]
        best[act] = np.minimum(best[act], np.linalg.norm(r, axis=1))
        su, sv = ders[:, 1, 0], ders[:, 0, 1]
        # the Gram matrix of (Su, Sv, r) per point in one product: a, b, c and the gradient
        gram = np.matmul(np.stack([su, sv, r], axis=1), np.stack([su, sv], axis=2))
        a, b, c, g1, g2 = gram[:, 0, 0], gram[:, 0, 1], gram[:, 1, 1], gram[:, 2, 0], gram[:, 2, 1]
        det = a * c - b * b
        det = det + 1e-14 * (a + c) ** 2 + np.finfo(float).tiny
        du = np.clip((c * g1 - b * g2) / det, -step_u, step_u)
        dv = np.clip((a * g2 - b * g1) / det, -step_v, step_v)
        un = np.clip(ua + du, u0, u1)
        vn = np.clip(va + dv, v0, v1)
        # Gauss-Newton is quadratic near the foot point: once the 3-D step is below 1e-3 of
        # the distance, the distance is known to ~1e-6 relative and the point is done
        step3 = np.linalg.norm((un - ua)[:, None] * su + (vn - va)[:, None] * sv, axis=1)
        moving = (step3 > 1e-3 * best[act]) & (best[act] > threshold)
        # converged points already have their distance in ``best``
        act, ua, va = act[moving], un[moving], vn[moving]
    if act.size:
        last = d0(ua, va) if d0 is not None else d1(ua, va)[:, 0, 0]
        best[act] = np.minimum(best[act], np.linalg.norm(points[act] - last, axis=1))
    return best


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


