"""Shadows under parallel light (:func:`shadow`): the outline of a surface projected along a
direction onto a plane, from its projected boundary and silhouettes, outer loops
counter-clockwise and holes clockwise in the plane's frame.
See :doc:`/guide/surfaces` (section "Intersections and shadows").
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .. import checks
from ..errors import SurfmodError
from ..surface import Surface, require_surface
from . import marching
from .intersect import IntersectionProblem, as_plane, implicit_seeds, plane_frame, seeded_size
from .closest import nearest_samples, seed_parameters


class Silhouette(IntersectionProblem):
    """Unknowns ``(u, v)``; ``F = (Su x Sv) . L``."""

    def __init__(self, s, light, tolerance):
        super().__init__(list(s.domain), seeded_size(s), tolerance)
        self.s, self.light = s, light

    def evaluate(self, X):
        d = self.s._derivatives(X[:, 0], X[:, 1], 2)
        su, sv = d[:, 1, 0], d[:, 0, 1]
        F = (np.cross(su, sv) @ self.light)[:, None]
        fu = (np.cross(d[:, 2, 0], sv) + np.cross(su, d[:, 1, 1])) @ self.light
        fv = (np.cross(d[:, 1, 1], sv) + np.cross(su, d[:, 0, 2])) @ self.light
        dP = np.stack([su, sv], axis=-1)
        return F, np.stack([fu, fv], axis=-1)[:, None, :], d[:, 0, 0], dP


@dataclass(frozen=True, eq=False)
class Shadow:
    """The shadow of a surface on a plane.

    ``outline``: closed polylines ``(N, 3)`` on the plane bounding the shadow (shadow on
    the left seen from the plane normal; outer loops counter-clockwise, holes clockwise);
    ``boundary`` and ``silhouettes``: the projected patch boundary and light-grazing
    curves the outline is made of; ``frame = (origin, xdir, ydir, normal)`` of the plane;
    ``area``: the shadow's area (from the outline loops); ``complete`` is False when
    some outline pieces could not be chained into closed loops (then ``outline`` and
    ``area`` are partial; this happens at grazing light on wavy surfaces).

    >>> import surfmod as sm, numpy as np
    >>> sh = sm.shadow(sm.sphere(1.0).translated((0, 0, 3)), (0, 0, -1), ((0, 0, 0), (0, 0, 1)))
    >>> sh.complete, bool(abs(sh.area - np.pi) < 1e-3)   # a disc of radius 1
    (True, True)
    """

    outline: list
    boundary: list
    silhouettes: list
    frame: tuple
    area: float
    complete: bool = True

    def to_2d(self, points) -> np.ndarray:
        """Plane coordinates ``(..., 2)`` of points on the plane."""
        o, x, y, _ = self.frame
        p = np.asarray(points, dtype=float) - o
        return np.stack([p @ x, p @ y], axis=-1)


def _boundary_polylines(s: Surface, density: int = 8):
    """The four domain edges, sampled at every knot and ``density`` points per span (at
    least 200 per edge), collapsed edges dropped."""
    (u0, u1), (v0, v1) = s.domain
    us = seed_parameters(s, 0, per_span=density, minimum=200, maximum=400)
    vs = seed_parameters(s, 1, per_span=density, minimum=200, maximum=400)
    edges = [s.points(us, v0), s.points(u1, vs), s.points(us[::-1], v1), s.points(u0, vs[::-1])]
    size = seeded_size(s)
    return [e for e in edges if np.linalg.norm(np.ptp(e, axis=0)) > 1e-9 * size]


def _covered(s: Surface, to2d, queries: np.ndarray, tol: float, seeds: int = 6, iterations: int = 40):
    """Whether each 2-D query point is in the projected image of ``s`` (vectorized Newton
    on ``proj(S(u, v)) = q`` from the nearest projected grid samples)."""
    (u0, u1), (v0, v1) = s.domain
    us, vs = seed_parameters(s, 0, 6, 32, 128), seed_parameters(s, 1, 6, 32, 128)
    g2 = to2d(s.grid(us, vs)).reshape(-1, 2)
    uu, vv = (a.ravel() for a in np.meshgrid(us, vs, indexing="ij"))
    pad = lambda a: np.c_[a, np.zeros(len(a))]  # noqa: E731
    near = nearest_samples(pad(queries), pad(g2), seeds)
    k = near.shape[1]
    q = np.repeat(queries, k, axis=0)
    u, v = uu[near].ravel(), vv[near].ravel()
    active = np.ones(len(u), bool)
    for _ in range(iterations):
        idx = np.nonzero(active)[0]
        if idx.size == 0:
            break
        d = s._derivatives(u[idx], v[idx], 1)
        r = to2d(d[:, 0, 0]) - q[idx]
        a, b = to2d(d[:, 1, 0], vector=True), to2d(d[:, 0, 1], vector=True)
        det = a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]
        det = np.where(np.abs(det) < 1e-300, 1e-300, det)
        du = -(b[:, 1] * r[:, 0] - b[:, 0] * r[:, 1]) / det
        dv = -(-a[:, 1] * r[:, 0] + a[:, 0] * r[:, 1]) / det
        du = np.clip(du, -0.25 * (u1 - u0), 0.25 * (u1 - u0))
        dv = np.clip(dv, -0.25 * (v1 - v0), 0.25 * (v1 - v0))
        nu, nv = np.clip(u[idx] + du, u0, u1), np.clip(v[idx] + dv, v0, v1)
        active[idx] = np.maximum(np.abs(nu - u[idx]) / (u1 - u0), np.abs(nv - v[idx]) / (v1 - v0)) > 1e-13
        u[idx], v[idx] = nu, nv
    res = np.linalg.norm(to2d(s._derivatives(u, v, 0)[:, 0, 0]) - q, axis=1).reshape(-1, k)
    return np.any(res <= tol, axis=1)


def _split_segments(polylines2d):
    """All polyline segments split at their mutual crossings: ``(M, 2, 2)``."""
    segs = np.concatenate([np.stack([p[:-1], p[1:]], axis=1) for p in polylines2d if len(p) > 1])
    a, b = segs[:, 0], segs[:, 1]
    d = b - a
    # pairwise crossing parameters
    cross = d[:, None, 0] * d[None, :, 1] - d[:, None, 1] * d[None, :, 0]
    ab = a[None, :, :] - a[:, None, :]
    with np.errstate(divide="ignore", invalid="ignore"):
        t = (ab[..., 0] * d[None, :, 1] - ab[..., 1] * d[None, :, 0]) / cross
        s = (ab[..., 0] * d[:, None, 1] - ab[..., 1] * d[:, None, 0]) / cross
    eps = 1e-12
    hit = np.isfinite(t) & (t > eps) & (t < 1 - eps) & (s >= -eps) & (s <= 1 + eps)
    out = []
    for i in range(len(segs)):  # loop over segments (arrangement), not evaluation points
        ts = np.concatenate([[0.0], np.sort(t[i][hit[i]]), [1.0]])
        p = a[i] + ts[:, None] * d[i]
        out.append(np.stack([p[:-1], p[1:]], axis=1))
    pieces = np.concatenate(out)
    keep = np.linalg.norm(pieces[:, 1] - pieces[:, 0], axis=1) > 0
    return pieces[keep]


def _chain(pieces, size, gap: float = 2e-3):
    """Chain oriented pieces (start -> end) into closed loops: each piece continues with
    the unused piece starting nearest to its end (within ``gap * size``: silhouettes
    meet the projected boundary tangentially, so their polylines only nearly touch)."""
    starts = pieces[:, 0]
    used = np.zeros(len(pieces), bool)
    loops = []
    for i in range(len(pieces)):  # loop over pieces (topology), not evaluation points
        if used[i]:
            continue
        loop = [pieces[i][0]]
        j = i
        while True:
            used[j] = True
            end = pieces[j][1]
            loop.append(end)
            dist = np.linalg.norm(starts - end, axis=1)
            dist[used] = np.inf
            dist[i] = np.linalg.norm(end - loop[0])  # back to the first piece: closed
            j = int(np.argmin(dist))
            if not dist[j] <= gap * size or j == i:
                break
        loop = np.array(loop)
        if len(loop) >= 4 and np.linalg.norm(loop[0] - loop[-1]) <= gap * size:
            loop[-1] = loop[0]
            loops.append(loop)
    return loops


def shadow(obj: Surface, light_direction, plane, *, max_angle: float = 2.5) -> Shadow:
    """The shadow of ``obj`` cast by parallel light along ``light_direction`` onto
    ``plane`` (``(origin, normal)``, a build123d ``Plane`` or the carrier of a ``PlaneSurface`` / ``ThreePointPlane``).

    >>> import surfmod as sm
    >>> s = sm.plane((0, 0, 1), (2, 0, 1), (0, 1, 1))
    >>> sh = sm.shadow(s, (0, 0, -1), ((0, 0, 0), (0, 0, 1)))
    >>> round(sh.area, 12), len(sh.outline)
    (2.0, 1)
    """
    obj = require_surface(obj, "obj")
    light = checks.direction(light_direction, "light_direction")
    origin, normal = as_plane(plane, "plane")
    if abs(light @ normal) < 1e-9:
        raise SurfmodError("light_direction: parallel to the plane, the shadow is undefined")
    angle = checks.positive(max_angle, "max_angle")
    o, xdir, ydir, n = plane_frame(origin, normal)

    def proj(p):
        """``P - ((P - o).n / (L.n)) L``: along the light onto the plane."""
        return p - (((p - origin) @ normal) / (light @ normal))[..., None] * light

    def to2d(p, vector=False):
        q = (p - (((p @ n) / (light @ n))[..., None]) * light) if vector else proj(p) - o
        return np.stack([q @ xdir, q @ ydir], axis=-1)

    size = seeded_size(obj)
    boundary3 = _boundary_polylines(obj)
    problem = Silhouette(obj, light, 1e-12 * size)
    seeds = implicit_seeds(problem, obj)
    traced = marching.trace_all(problem, seeds, size / 40, angle)
    sil3 = [problem.evaluate(X)[2] for X, _ in traced]
    boundary = [checks.frozen(proj(b)) for b in boundary3]
    silhouettes = [checks.frozen(proj(c)) for c in sil3]
    curves2 = [to2d(p) for p in boundary3 + sil3]
    allp = np.concatenate(curves2)
    size2 = float(np.linalg.norm(np.ptp(allp, axis=0)))  # the shadow's own size
    pieces = _split_segments(curves2)
    mid = pieces.mean(axis=1)
    d = pieces[:, 1] - pieces[:, 0]
    left = np.stack([-d[:, 1], d[:, 0]], axis=1) / np.linalg.norm(d, axis=1, keepdims=True)
    eps = 1e-3 * size2
    cov = _covered(obj, to2d, np.concatenate([mid + eps * left, mid - eps * left]), 1e-6 * eps)
    covered_left, covered_right = cov[: len(mid)], cov[len(mid) :]
    keep = covered_left ^ covered_right  # a shadow edge has shadow on exactly one side
    oriented = np.where(covered_right[keep][:, None, None], pieces[keep][:, ::-1], pieces[keep])
    loops2 = _chain(oriented, size2)
    chained = sum(float(np.sum(np.linalg.norm(np.diff(p, axis=0), axis=1))) for p in loops2)
    kept = float(np.sum(np.linalg.norm(oriented[:, 1] - oriented[:, 0], axis=1)))
    # pieces left over are slivers doubled along the tangency of silhouette and boundary
    complete = kept - chained <= 0.03 * max(kept, 1e-300)
    area = float(sum(0.5 * np.sum(p[:-1, 0] * p[1:, 1] - p[1:, 0] * p[:-1, 1]) for p in loops2))
    outline = [checks.frozen(o + p[:, :1] * xdir + p[:, 1:] * ydir) for p in loops2]
    return Shadow(outline, boundary, silhouettes, (o, xdir, ydir, n), area, bool(complete))
