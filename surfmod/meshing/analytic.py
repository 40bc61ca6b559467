"""Closed-form distances from points to planes, spheres, cylinders, cones and tori (as
OCCT defines them, untrimmed), for many surfaces at once: each point names its surface,
so the faces of a whole part are measured in a few array passes instead of a few per
face.

The foot point of a point on a surface of revolution lies in the point's meridian plane,
where the cone and the torus show *two* profiles (the generatrix line and the circle
mirrored through the axis, both parts of OCCT's surface: a cone goes on past its apex, a
spindle torus' tube crosses the axis): the distance is the smaller of the two.
"""

from __future__ import annotations

import numpy as np

#: Kinds of :func:`distances`' surfaces (``occ.mesh.analytic_parameters`` reads them).
PLANE, SPHERE, CYLINDER, CONE, TORUS = range(5)


def distances(kinds: np.ndarray, frames: np.ndarray, sizes: np.ndarray, points: np.ndarray,
              owner: np.ndarray) -> np.ndarray:
    """Distance from each point to its surface ``owner[i]``: ``kinds (F,)`` (the kinds
    above), ``frames (F, 2, 3)`` (origin, unit axis), ``sizes (F, 2)`` (sphere and
    cylinder: radius; cone: reference radius, semi-angle; torus: major, minor radius).

    >>> import numpy as np
    >>> d = distances(np.array([PLANE, CYLINDER]), np.array([[[0, 0, 0], [0, 0, 1]]] * 2, float),
    ...               np.array([[0, 0], [2, 0]], float), np.array([[1, 1, 3.0], [0, 3, 5]]), np.array([0, 1]))
    >>> d.tolist()
    [3.0, 1.0]
    """
    kind = kinds[owner]
    rel = points - frames[owner, 0]
    z = frames[owner, 1]
    h = np.einsum("ij,ij->i", rel, z)
    out = np.abs(h)  # planes
    a, b = sizes[owner, 0], sizes[owner, 1]
    sphere = kind == SPHERE
    if sphere.any():
        out[sphere] = np.abs(np.linalg.norm(rel[sphere], axis=1) - a[sphere])
    round_ = kind >= CYLINDER
    if round_.any():
        hr, ar, br, kr = h[round_], a[round_], b[round_], kind[round_]
        radial = np.linalg.norm(rel[round_] - hr[:, None] * z[round_], axis=1)
        got = np.abs(radial - ar)  # cylinders
        cone = kr == CONE
        if cone.any():
            # profile lines through (+-r0, 0) with directions (+-sin a, cos a), in (radial, h)
            rad, hc, r0 = radial[cone], hr[cone], ar[cone]
            sa, ca = np.sin(br[cone]), np.cos(br[cone])
            got[cone] = np.minimum(np.abs((rad - r0) * ca - hc * sa), np.abs((rad + r0) * ca + hc * sa))
        torus = kr == TORUS
        if torus.any():
            rad, ht, big, small = radial[torus], hr[torus], ar[torus], br[torus]
            got[torus] = np.minimum(np.abs(np.hypot(rad - big, ht) - small), np.abs(np.hypot(rad + big, ht) - small))
        out[round_] = got
    return out
