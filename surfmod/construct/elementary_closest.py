"""Closest points on the elementary surfaces in closed form: planes, cylinders, cones,
spheres and tori (OCCT's, and the 3-point parallelogram), the one home of these formulas.

:func:`plane` ... :func:`cone` (and :func:`parallelogram`) give the parameters of the
closest point of a bounded patch of the surface's own parametrization (OCCT's
``Extrema_ExtPElS``); :func:`distances` and :func:`triangle_distances` the distance to the
untrimmed surfaces, for many surfaces at once.  On the axis the angle nearest 0 in the box
is chosen.  NumPy only: a projection never waits for numba.
See :doc:`/guide/surfaces` (section "Closest points").
"""

from __future__ import annotations

import math

import numpy as np

TWO_PI = 2.0 * math.pi
#: Kinds of :func:`distances`' surfaces (:func:`surfmod.meshing.analytic_distance.parameters`
#: reads them from OCCT).
KINDS = PLANE, SPHERE, CYLINDER, CONE, TORUS = range(5)
#: samples per block of :func:`triangle_distances`: a block's temporaries take a few MiB
#: whatever the part (5M triangles of 25 samples would take GiBs at once); smaller blocks
#: were slower on a part's 300k samples, larger ones no faster
BLOCK_SAMPLES = 1 << 16


def closest_angle(theta: np.ndarray, a0: float, a1: float) -> np.ndarray:
    """The angle of ``[a0, a1]`` nearest to ``theta`` on the circle (``theta`` taken mod 2 pi).

    >>> closest_angle(np.array([0.5, 3.0, -0.1, 6.0]), 0.0, 1.0).tolist()
    [0.5, 1.0, 0.0, 0.0]
    """
    t = a0 + np.mod(theta - a0, TWO_PI)  # in [a0, a0 + 2 pi)
    if a1 - a0 >= TWO_PI:
        return t
    # outside the arc: the nearer end going either way round (both gaps add to 2 pi - span)
    return np.where(t <= a1, t, np.where(t - a1 <= a0 + TWO_PI - t, a1, a0))


def _polar(local: np.ndarray):
    x, y, z = local[:, 0], local[:, 1], local[:, 2]
    return np.hypot(x, y), np.arctan2(y, x), z


def plane(local, box):
    """``(u, v)`` on ``O + u X + v Y``: the in-plane coordinates clipped to the box."""
    (u0, u1), (v0, v1) = box
    return np.clip(local[:, 0], u0, u1), np.clip(local[:, 1], v0, v1)


def cylinder(local, box):
    """``(u, v)`` on ``O + R (cos u X + sin u Y) + v Z``."""
    (u0, u1), (v0, v1) = box
    _, theta, z = _polar(local)
    return closest_angle(theta, u0, u1), np.clip(z, v0, v1)


def sphere(local, box):
    """``(u, v)`` on ``O + R cos v (cos u X + sin u Y) + R sin v Z``, ``v`` in ``[-pi/2, pi/2]``.

    With ``u`` fixed the distance falls as ``w cos v + z sin v`` grows (``w = rho cos(u - t)``),
    a cosine of ``v - atan2(z, w)``: the latitude of the box closest to that angle wins.
    """
    (u0, u1), (v0, v1) = box
    rho, theta, z = _polar(local)
    u = closest_angle(theta, u0, u1)
    return u, closest_angle(np.arctan2(z, rho * np.cos(u - theta)), v0, v1)


def torus(local, box, major: float):
    """``(u, v)`` on ``O + (R + r cos v)(cos u X + sin u Y) + r sin v Z`` (``r < R``).

    With ``u`` fixed the point seen in the meridian half-plane is ``(w, z)``,
    ``w = rho cos(u - t)``; the closest point of the tube circle around ``(R, 0)`` is in
    the direction ``atan2(z, w - R)``, the closest angle of the box to it wins.
    """
    (u0, u1), (v0, v1) = box
    rho, theta, z = _polar(local)
    u = closest_angle(theta, u0, u1)
    w = rho * np.cos(u - theta)
    return u, closest_angle(np.arctan2(z, w - major), v0, v1)


def cone(local, box, radius: float, semi_angle: float):
    """``(u, v)`` on ``O + (R + v sin a)(cos u X + sin u Y) + v cos a Z``.

    One candidate per nappe of the box (``R + v sin a >= 0``, the best ``u`` facing the
    point, and ``<= 0``, facing away); the nearer one is returned.
    """
    (u0, u1), (v0, v1) = box
    rho, theta, z = _polar(local)
    sa, ca = math.sin(semi_angle), math.cos(semi_angle)
    apex = -radius / sa
    # the v-intervals of the box on either side of the apex: (R + v sin a) >= 0, then <= 0
    ahead = (max(v0, apex), v1) if sa > 0 else (v0, min(v1, apex))
    behind = (v0, min(v1, apex)) if sa > 0 else (max(v0, apex), v1)
    best = None
    for (lo, hi), facing in ((ahead, theta), (behind, theta + math.pi)):
        if lo > hi:
            continue
        u = closest_angle(facing, u0, u1)
        c, s = np.cos(u - theta), np.sin(u - theta)
        # |S - P|^2 = v^2 + 2 v (R sin a - rho cos(u - t) sin a - z cos a) + const
        v = np.clip(rho * c * sa + z * ca - radius * sa, lo, hi)
        # the squared distance as a sum of squares (no cancellation near the surface)
        d2 = (radius + v * sa - rho * c) ** 2 + (rho * s) ** 2 + (v * ca - z) ** 2
        if best is None:
            best = (u, v, d2)
        else:
            nearer = d2 < best[2]
            best = (np.where(nearer, u, best[0]), np.where(nearer, v, best[1]), np.minimum(d2, best[2]))
    return best[0], best[1]


def parallelogram(points: np.ndarray, origin: np.ndarray, e1: np.ndarray, e2: np.ndarray):
    """``(s, t)`` in ``[0, 1]²`` of the closest points of ``origin + s e1 + t e2`` to ``(N, 3)`` points.

    The foot on the carrier plane has the coordinates of the dual basis, ``s = d . f1``,
    ``t = d . f2`` with ``f1 = (e2 x n) / (e1 . (e2 x n))`` (no normal equations: their
    conditioning is the square of a skewed pair's); a foot outside the square means the
    closest point is on the boundary (the squared distance is convex), the nearest of the
    four edges' clipped feet.

    >>> s, t = parallelogram(np.array([[0.5, 0.5, 3.0], [3.0, -1.0, 0.0]]), np.zeros(3), np.array([2.0, 0, 0]),
    ...                      np.array([1.0, 1, 0]))
    >>> s.tolist(), t.tolist()   # a foot inside; the corner (1, 0) nearest to a point beyond it
    ([0.0, 1.0], [0.5, 0.0])
    """
    n = np.cross(e1, e2)
    n /= np.linalg.norm(n)
    f1, f2 = np.cross(e2, n), np.cross(n, e1)
    f1, f2 = f1 / (e1 @ f1), f2 / (e2 @ f2)
    d = points - origin
    s, t = d @ f1, d @ f2
    out = ~((s >= 0) & (s <= 1) & (t >= 0) & (t <= 1))
    if out.any():
        q = d[out]
        best = np.full(len(q), np.inf)
        bs, bt = np.empty(len(q)), np.empty(len(q))
        # the edges t = 0, t = 1 (along e1) and s = 0, s = 1 (along e2), with the fixed side
        for start, along, fixed, run_is_s in ((0, e1, 0.0, True), (e2, e1, 1.0, True),
                                               (0, e2, 0.0, False), (e1, e2, 1.0, False)):
            w = np.clip((q - start) @ along / (along @ along), 0.0, 1.0)
            d2 = np.sum((start + w[:, None] * along - q) ** 2, axis=1)
            nearer = d2 < best
            best = np.where(nearer, d2, best)
            bs = np.where(nearer, w if run_is_s else fixed, bs)
            bt = np.where(nearer, fixed if run_is_s else w, bt)
        s, t = s.copy(), t.copy()
        s[out], t[out] = bs, bt
    return s, t


def distances(kinds: np.ndarray, frames: np.ndarray, sizes: np.ndarray, points: np.ndarray,
              owner: np.ndarray) -> np.ndarray:
    """Distance from each point to its untrimmed surface ``owner[i]``: ``kinds (F,)`` (the
    kinds above), ``frames (F, 2, 3)`` (origin, unit axis), ``sizes (F, 2)`` (sphere and
    cylinder: radius; cone: reference radius, semi-angle; torus: major, minor radius).

    >>> d = distances(np.array([PLANE, CYLINDER]), np.array([[[0, 0, 0], [0, 0, 1]]] * 2, float),
    ...               np.array([[0, 0], [2, 0]], float), np.array([[1, 1, 3.0], [0, 3, 5]]), np.array([0, 1]))
    >>> d.tolist()
    [3.0, 1.0]
    """
    kinds, frames, sizes = _tables(kinds, frames, sizes)
    points, owner = np.asarray(points, float), np.asarray(owner, np.int64)
    out = np.empty(len(points))
    of_kind = kinds[owner]
    for kind in range(len(KINDS)):
        at = np.nonzero(of_kind == kind)[0]
        if at.size == 0:
            continue
        f = owner[at]
        axis = frames[f, 1]
        r = points[at] - frames[f, 0]
        h = np.einsum("ij,ij->i", r, axis)
        p = None if kind == PLANE else r - h[:, None] * axis  # a plane's distance is the height alone
        out[at] = _distance(kind, h, None if p is None else np.einsum("ij,ij->i", p, p), sizes[f].T)
    return out


def triangle_distances(kinds: np.ndarray, frames: np.ndarray, sizes: np.ndarray, nodes: np.ndarray,
                       triangles: np.ndarray, faces: np.ndarray, bary: np.ndarray) -> np.ndarray:
    """Max distance per triangle over its barycentric samples ``bary (K, 3)`` (points
    ``bary @ corners`` of ``nodes (N, 3)`` indexed by ``triangles (T, 3)``), from the
    untrimmed surface of its face: ``faces (F, 3)`` rows ``(surface, first triangle, end
    triangle)``; a triangle of no row gets 0.  Returns ``(T,)``.

    A sample's height along the axis is the samples' mix of its corners' heights, and its
    squared distance from the axis the quadratic form of the corners' offsets from it
    (their six dot products): per triangle nine numbers, then two small matrix products
    give every sample's pair, not a dozen passes over the samples' coordinates.

    >>> nodes = np.array([[1.0, 0, 0], [0, 1, 0], [-1, 0, 0]])  # on a unit cylinder about z
    >>> d = triangle_distances(np.array([CYLINDER]), np.array([[[0, 0, 0], [0, 0, 1.0]]]),
    ...                        np.array([[1.0, 0]]), nodes, np.array([[0, 1, 2]]), np.array([[0, 0, 1]]),
    ...                        np.array([[1 / 3, 1 / 3, 1 / 3]]))
    >>> round(float(d[0]), 12)  # the centroid (0, 1/3, 0) is 2/3 inside
    0.666666666667
    """
    kinds, frames, sizes = _tables(kinds, frames, sizes)
    faces, bary = np.asarray(faces, np.int64).reshape(-1, 3), np.asarray(bary, float)
    nodes, triangles = np.asarray(nodes, float), np.asarray(triangles, np.int64)
    out = np.zeros(len(triangles))
    counts = faces[:, 2] - faces[:, 1]
    # the triangles of every row in turn: each row's first, stepped by one
    tri = np.repeat(faces[:, 1] - np.cumsum(counts) + counts, counts) + np.arange(counts.sum())
    surface = np.repeat(faces[:, 0], counts)
    of_kind = kinds[surface]
    pairs = ((0, 0), (1, 1), (2, 2), (0, 1), (0, 2), (1, 2))
    # the weights of the six products in |w0 p0 + w1 p1 + w2 p2|^2: (6, K)
    mix = np.array([bary[:, i] * bary[:, j] * (1.0 if i == j else 2.0) for i, j in pairs])
    step = max(1, BLOCK_SAMPLES // max(1, len(bary)))
    for kind in range(len(KINDS)):
        every = np.nonzero(of_kind == kind)[0]
        for a in range(0, len(every), step):  # loop over memory blocks, not triangles
            at, f = tri[every[a : a + step]], surface[every[a : a + step]]
            axis = frames[f, 1][:, None]
            r = nodes[triangles[at]] - frames[f, 0][:, None]  # (n, 3 corners, 3)
            h = np.einsum("ncd,nd->nc", r, frames[f, 1])
            p = r - h[..., None] * axis
            gram = np.stack([np.einsum("nd,nd->n", p[:, i], p[:, j]) for i, j in pairs], axis=1)
            q = np.maximum(gram @ mix, 0.0)  # round-off may take a point on the axis below 0
            out[at] = _distance(kind, h @ bary.T, q, sizes[f].T[..., None]).max(axis=1, initial=0.0)
    return out


def _tables(kinds, frames, sizes):
    return (np.asarray(kinds, np.int64), np.asarray(frames, float).reshape(-1, 2, 3),
            np.asarray(sizes, float).reshape(-1, 2))


def _distance(kind: int, h: np.ndarray, q: np.ndarray | None, size: np.ndarray) -> np.ndarray:
    """Distance to surfaces of one kind from points at height ``h`` along the axis and at
    squared distance ``q`` from it (unused for planes); ``size (2, ...)`` broadcasts
    against them (see :func:`distances`)."""
    if kind == PLANE:
        return np.abs(h)
    if kind == SPHERE:
        return np.abs(np.sqrt(q + h * h) - size[0])
    radial = np.sqrt(q)
    if kind == CYLINDER:
        return np.abs(radial - size[0])
    if kind == CONE:
        # profile lines through (+-r0, 0) with directions (+-sin a, cos a), in (radial, h)
        sa, ca = np.sin(size[1]), np.cos(size[1])
        return np.minimum(np.abs((radial - size[0]) * ca - h * sa), np.abs((radial + size[0]) * ca + h * sa))
    return np.minimum(np.abs(np.hypot(radial - size[0], h) - size[1]), np.abs(np.hypot(radial + size[0], h) - size[1]))
