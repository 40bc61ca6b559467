"""Closest-point projection of many points (or a sampled curve) onto a surface.

Vectorized over all points at once: every point starts from its few nearest samples of
a parameter grid (a grid that resolves every knot span), then a projected Newton
iteration on ``f(u, v) = |S(u, v) - P|^2 / 2`` runs on all starts together.  The domain
is a box constraint: a parameter at its bound whose gradient points outward is held
there and the other one is solved alone (the constrained step), so points whose closest
point lies on an edge or at a corner converge too.  The best start wins.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from .. import checks
from ..errors import SurfmodError
from ..surface import Surface


class Projection(NamedTuple):
    """Closest points: parameters ``u``, ``v``, the surface ``point`` and the ``distance``.

    >>> import surfmod as sm
    >>> pr = sm.project([(0, 0, 5)], sm.sphere(2.0))
    >>> [round(float(x), 12) for x in (pr.distance[0], pr.point[0][2])]
    [3.0, 2.0]
    """

    u: np.ndarray
    v: np.ndarray
    point: np.ndarray
    distance: np.ndarray


def seed_parameters(s: Surface, direction: int, per_span: int = 4, minimum: int = 24, maximum: int = 96) -> np.ndarray:
    """Sample parameters along one direction: ``minimum`` equal steps over the domain
    (so long spans are not starved when short spans hold most knots), every knot, and
    ``per_span`` samples inside each knot span while that stays under ``maximum``."""
    lo, hi = s.domain[direction]
    even = np.linspace(lo, hi, minimum + 1)
    knots = getattr(s, "knots", None)
    if knots is None:
        return even
    k = np.asarray(knots[direction])
    k = np.unique(np.concatenate([[lo, hi], k[(k > lo) & (k < hi)]]))
    if (len(k) - 1) * per_span > maximum:
        return np.unique(np.concatenate([np.linspace(lo, hi, maximum + 1), k]))
    fine = [np.linspace(a, b, per_span, endpoint=False) for a, b in zip(k[:-1], k[1:])]
    return np.unique(np.concatenate(fine + [even, k]))


def nearest_samples(points: np.ndarray, samples: np.ndarray, count: int, chunk: int = 2_000_000) -> np.ndarray:
    """Indices ``(N, count)`` of the ``count`` nearest ``samples`` to each point (chunked)."""
    count = min(count, len(samples))
    out = np.empty((len(points), count), dtype=int)
    step = max(1, chunk // max(1, len(samples)))
    s2 = np.einsum("ij,ij->i", samples, samples)
    for a in range(0, len(points), step):  # loop over memory chunks, not points
        p = points[a : a + step]
        d2 = s2[None, :] - 2 * p @ samples.T
        idx = np.argpartition(d2, count - 1, axis=1)[:, :count] if count < len(samples) else np.argsort(d2, axis=1)
        out[a : a + step] = idx
    return out


def nearest_triangles(points, tri_pts, count: int, chunk: int = 1_000_000):
    """For each point the ``count`` grid triangles whose (approximate) closest point is
    nearest: ``(idx (N, count), barycentric (N, count, 3))``.  The closest point of a
    triangle is its plane projection with barycentric coordinates clipped to the
    triangle (exact inside, a good seed near edges)."""
    a, b, c = tri_pts[:, 0], tri_pts[:, 1], tri_pts[:, 2]
    e0, e1 = b - a, c - a
    d00, d01, d11 = (np.einsum("ij,ij->i", x, y) for x, y in ((e0, e0), (e0, e1), (e1, e1)))
    det = np.maximum(d00 * d11 - d01**2, 1e-300)
    count = min(count, len(tri_pts))
    idx = np.empty((len(points), count), dtype=int)
    bary = np.empty((len(points), count, 3))
    step = max(1, chunk // max(1, len(tri_pts)))
    for s0 in range(0, len(points), step):  # memory chunks, not points
        p = points[s0 : s0 + step]
        r = p[:, None, :] - a[None]
        r0, r1 = np.einsum("ntj,tj->nt", r, e0), np.einsum("ntj,tj->nt", r, e1)
        beta = np.clip((d11 * r0 - d01 * r1) / det, 0, 1)
        gamma = np.clip((d00 * r1 - d01 * r0) / det, 0, 1)
        tot = beta + gamma
        over = tot > 1
        safe = np.where(over, tot, 1.0)
        beta, gamma = beta / safe, gamma / safe
        q = a[None] + beta[..., None] * e0[None] + gamma[..., None] * e1[None]
        d2 = np.einsum("ntj,ntj->nt", q - p[:, None], q - p[:, None])
        best = np.argpartition(d2, count - 1, axis=1)[:, :count] if count < d2.shape[1] else np.argsort(d2, axis=1)
        rows = np.arange(len(p))[:, None]
        idx[s0 : s0 + step] = best
        bg = np.stack([beta[rows, best], gamma[rows, best]], axis=-1)
        bary[s0 : s0 + step] = np.concatenate([1 - bg.sum(-1, keepdims=True), bg], axis=-1)
    return idx, bary


def crease_boxes(s: Surface, direction: int, t: np.ndarray):
    """Per-parameter bounds ``(lo, hi)``: the piece between C0 knot lines (multiplicity
    >= degree) that holds ``t``.  Across such a crease the distance has a kink that
    Newton cannot settle on, so each start works in its own smooth piece and a minimum on
    the crease becomes a constrained (boundary) minimum."""
    lo, hi = s.domain[direction]
    knots, degree = getattr(s, "knots", None), getattr(s, "degree", None)
    if knots is None or degree is None:
        return np.full(t.shape, lo), np.full(t.shape, hi)
    values, mult = np.unique(np.asarray(knots[direction]), return_counts=True)
    creases = values[(mult >= degree[direction]) & (values > lo) & (values < hi)]
    breaks = np.concatenate([[lo], creases, [hi]])
    piece = np.clip(np.searchsorted(breaks, t, side="right") - 1, 0, len(breaks) - 2)
    return breaks[piece], breaks[piece + 1]


def newton_closest(s: Surface, points: np.ndarray, u: np.ndarray, v: np.ndarray, iterations: int = 60):
    """Projected Newton on ``|S - P|^2 / 2`` from starts ``(u, v)`` (flat arrays, one per
    point row of ``points``), each kept inside its smooth piece (:func:`crease_boxes`).
    Returns refined ``(u, v)``."""
    (du0, du1), (dv0, dv1) = s.domain
    spanu, spanv = du1 - du0, dv1 - dv0
    u, v = u.astype(float).copy(), v.astype(float).copy()
    box_u, box_v = crease_boxes(s, 0, u), crease_boxes(s, 1, v)
    active = np.ones(u.shape, bool)
    for _ in range(iterations):
        idx = np.nonzero(active)[0]
        if idx.size == 0:
            break
        uu, vv, pp = u[idx], v[idx], points[idx]
        u0, u1, v0, v1 = box_u[0][idx], box_u[1][idx], box_v[0][idx], box_v[1][idx]
        d = s._derivatives(uu, vv, 2)
        S, Su, Sv = d[:, 0, 0], d[:, 1, 0], d[:, 0, 1]
        r = S - pp
        gu, gv = np.einsum("ij,ij->i", r, Su), np.einsum("ij,ij->i", r, Sv)
        a, b, c = (np.einsum("ij,ij->i", x, y) for x, y in ((Su, Su), (Su, Sv), (Sv, Sv)))
        huu = a + np.einsum("ij,ij->i", r, d[:, 2, 0])
        huv = b + np.einsum("ij,ij->i", r, d[:, 1, 1])
        hvv = c + np.einsum("ij,ij->i", r, d[:, 0, 2])
        tiny = 1e-300 + 1e-14 * (a + c) ** 2
        indefinite = (huu <= 0) | (hvv <= 0) | (huu * hvv - huv**2 <= tiny)
        huu, huv, hvv = np.where(indefinite, a, huu), np.where(indefinite, b, huv), np.where(indefinite, c, hvv)
        huu = np.maximum(huu, 1e-300 + 1e-14 * (a + c))
        hvv = np.maximum(hvv, 1e-300 + 1e-14 * (a + c))
        det = np.maximum(huu * hvv - huv**2, tiny)
        du = (-gu * hvv + gv * huv) / det
        dv = (-gv * huu + gu * huv) / det
        # constrained step: a parameter held at its bound when the descent leaves the domain
        fix_u = ((uu <= u0) & (gu > 0)) | ((uu >= u1) & (gu < 0))
        fix_v = ((vv <= v0) & (gv > 0)) | ((vv >= v1) & (gv < 0))
        du = np.where(fix_u, 0.0, np.where(fix_v, -gu / huu, du))
        dv = np.where(fix_v, 0.0, np.where(fix_u, -gv / hvv, dv))
        # no jumps across the whole patch in one step
        du = np.clip(du, -0.25 * spanu, 0.25 * spanu)
        dv = np.clip(dv, -0.25 * spanv, 0.25 * spanv)
        f0 = np.einsum("ij,ij->i", r, r)
        nu, nv = np.clip(uu + du, u0, u1), np.clip(vv + dv, v0, v1)
        trial = np.arange(idx.size)
        step = 1.0
        for _ in range(8):  # backtracking on the points whose distance grew
            rn = s._derivatives(nu[trial], nv[trial], 0)[:, 0, 0] - pp[trial]
            worse = np.einsum("ij,ij->i", rn, rn) > f0[trial] * (1 + 1e-12) + 1e-300
            trial = trial[worse]
            if trial.size == 0:
                break
            step /= 4
            nu[trial] = np.clip(uu[trial] + step * du[trial], u0[trial], u1[trial])
            nv[trial] = np.clip(vv[trial] + step * dv[trial], v0[trial], v1[trial])
        # no decrease even for a tiny step: converged to round-off, stay
        nu[trial], nv[trial] = uu[trial], vv[trial]
        moved = np.maximum(np.abs(nu - uu) / spanu, np.abs(nv - vv) / spanv)
        u[idx], v[idx] = nu, nv
        # quadratic convergence: a step below 1e-10 leaves an error ~1e-20
        active[idx] = moved > 1e-10
    return u, v


def closest_points(s: Surface, points: np.ndarray, seeds: int = 8):
    """``(u, v, point, distance)`` flat arrays for ``(N, 3)`` points (trusted input)."""
    us, vs = seed_parameters(s, 0), seed_parameters(s, 1)
    g = s.grid(us, vs)
    uu, vv = np.meshgrid(us, vs, indexing="ij")
    # two triangles per grid cell, with their corner parameters
    i, j = np.meshgrid(np.arange(len(us) - 1), np.arange(len(vs) - 1), indexing="ij")
    i, j = i.ravel(), j.ravel()
    ij = lambda a, b: np.stack([a, b], axis=-1)  # noqa: E731
    corners = np.concatenate(
        [np.stack([ij(i, j), ij(i + 1, j), ij(i + 1, j + 1)], 1), np.stack([ij(i, j), ij(i + 1, j + 1), ij(i, j + 1)], 1)], 0
    )
    tri_pts = g[corners[:, :, 0], corners[:, :, 1]]  # (T, 3 corners, 3)
    tri_uv = np.stack([uu[corners[:, :, 0], corners[:, :, 1]], vv[corners[:, :, 0], corners[:, :, 1]]], -1)
    near, bary = nearest_triangles(points, tri_pts, seeds)  # (N, K), (N, K, 3)
    k = near.shape[1]
    start = np.einsum("nkc,nkcd->nkd", bary, tri_uv[near])
    rep = np.repeat(points, k, axis=0)
    u, v = newton_closest(s, rep, start[..., 0].ravel(), start[..., 1].ravel())
    pts = s._derivatives(u, v, 0)[:, 0, 0]
    dist = np.linalg.norm(pts - rep, axis=1).reshape(-1, k)
    best = np.argmin(dist, axis=1)
    pick = np.arange(len(points)) * k + best
    return u[pick], v[pick], pts[pick], dist[np.arange(len(points)), best]


def _as_points(points_or_curve, samples):
    from ..curve import Curve

    if isinstance(points_or_curve, Curve):
        t0, t1 = points_or_curve.domain
        return points_or_curve.points(np.linspace(t0, t1, samples))
    if hasattr(points_or_curve, "wrapped") and hasattr(points_or_curve, "position_at"):
        # a build123d Edge / Wire: sampled uniformly in its normalized parameter
        from build123d import PositionMode

        ts = np.linspace(0.0, 1.0, samples)
        return np.array([tuple(points_or_curve.position_at(t, PositionMode.PARAMETER)) for t in ts])
    return checks.finite_array(points_or_curve, "points_or_curve", last=3)


def project(points_or_curve, s: Surface, *, samples: int = 65, seeds: int = 8) -> Projection:
    """Closest points on ``s`` to many points at once (or to ``samples`` points of a curve).

    ``points_or_curve``: a point ``(3,)``, points ``(..., 3)``, a surfmod curve or a
    build123d ``Edge``/``Wire`` (sampled at ``samples`` equally spaced parameters).
    Returns ``Projection(u, v, point, distance)`` with the points' leading shape.  The
    closest point may lie on the boundary of the domain (a constrained minimum).

    >>> import surfmod as sm
    >>> s = sm.plane((0, 0, 0), (1, 0, 0), (0, 1, 0))
    >>> pr = sm.project([(0.25, 0.5, 2.0), (3.0, 0.5, 0.0)], s)
    >>> pr.u, pr.v, pr.distance
    (array([0.25, 1.  ]), array([0.5, 0.5]), array([2., 2.]))
    """
    if not isinstance(s, Surface):
        raise SurfmodError(f"s: expected a surfmod Surface, got {type(s).__name__}")
    samples = checks.count(samples, "samples", minimum=2)
    seeds = checks.count(seeds, "seeds", minimum=1)
    pts = _as_points(points_or_curve, samples)
    shape = pts.shape[:-1]
    flat = pts.reshape(-1, 3)
    if flat.shape[0] == 0:
        empty = np.empty(shape)
        return Projection(empty, empty.copy(), np.empty(shape + (3,)), empty.copy())
    u, v, p, d = closest_points(s, flat, seeds)
    return Projection(u.reshape(shape), v.reshape(shape), p.reshape(shape + (3,)), d.reshape(shape))
