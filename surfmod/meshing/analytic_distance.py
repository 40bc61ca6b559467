"""Closed-form distances from points to planes, spheres, cylinders, cones and tori (as
OCCT defines them, untrimmed), for many surfaces at once: each point names its surface,
so the faces of a whole part are measured in a few array passes instead of a few per
face.

The foot point of a point on a surface of revolution lies in the point's meridian plane,
where the cone and the torus show *two* profiles (the generatrix line and the circle
mirrored through the axis, both parts of OCCT's surface: a cone goes on past its apex, a
spindle torus' tube crosses the axis): the distance is the smaller of the two.

Compiled (numba): a point costs a few arithmetic operations, which in NumPy would be
a dozen array passes.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from ..construct.conics import Conic
from ..construct.curves import Line
from ..construct.elementary import ConicalSurface, CylindricalSurface, PlaneSurface, SphericalSurface, ToroidalSurface
from ..construct.revolution import RevolutionSurface
from ..errors import SurfmodError
from ..readback.readers import read_surface

#: Kinds of :func:`distances`' surfaces (:func:`parameters` reads them).
PLANE, SPHERE, CYLINDER, CONE, TORUS = range(5)
_KINDS = {PlaneSurface: PLANE, SphericalSurface: SPHERE, CylindricalSurface: CYLINDER, ConicalSurface: CONE,
          ToroidalSurface: TORUS}
#: OCCT surface types :func:`parameters` reads (the others are none of the kinds).
_READ = ("Geom_Plane", "Geom_SphericalSurface", "Geom_CylindricalSurface", "Geom_ConicalSurface",
         "Geom_ToroidalSurface", "Geom_SurfaceOfRevolution")


def parameters(surf) -> tuple | None:
    """``(kind, frame (2, 3), sizes (2,))`` of an OCCT plane, sphere, cylinder, cone or
    torus as :func:`distances` takes them (also of a surface of revolution that is one of
    those, see :func:`revolved`), ``None`` for any other surface: read from the surfmod
    surface :func:`surfmod.readback.read_surface` gives.

    >>> import build123d as bd
    >>> from surfmod.occ.topo import face_surface
    >>> kind, frame, sizes = parameters(face_surface(bd.Face.make_rect(2, 3))[0])
    >>> kind == PLANE, sizes
    (True, (0.0, 0.0))
    """
    from ..occ.geom import surface_type

    if surface_type(surf) not in _READ:
        return None
    try:  # the bounds give no sizes here: any box will do
        s = read_surface(surf, (0.0, 1.0, 0.0, 1.0))
    except SurfmodError:  # a revolved curve the reader does not know
        return None
    if isinstance(s, RevolutionSurface):  # of a circle or line in a plane through the axis
        return revolved(s.axis_origin, s.axis_direction, s.profile)
    kind = _KINDS[type(s)]
    sizes = (0.0, 0.0) if kind == PLANE else (s.major, s.minor) if kind == TORUS else \
        (s.radius, s.semi_angle) if kind == CONE else (s.radius, 0.0)
    return kind, (s.origin, s.z_dir), sizes


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
    out = np.empty(len(points))
    _point_distances(*_tables(kinds, frames, sizes), np.ascontiguousarray(points, float),
                     np.ascontiguousarray(owner, np.int64), out)
    return out


def triangle_distances(kinds: np.ndarray, frames: np.ndarray, sizes: np.ndarray, nodes: np.ndarray,
                       triangles: np.ndarray, faces: np.ndarray, bary: np.ndarray) -> np.ndarray:
    """Max distance per triangle over its barycentric samples ``bary (K, 3)`` (points
    ``bary @ corners`` of ``nodes (N, 3)`` indexed by ``triangles (T, 3)``), from the
    surface of its face: ``faces (F, 3)`` rows ``(surface, first triangle, end
    triangle)``.  Returns ``(T,)``.

    >>> import numpy as np
    >>> nodes = np.array([[1.0, 0, 0], [0, 1, 0], [-1, 0, 0]])  # on a unit cylinder about z
    >>> d = triangle_distances(np.array([CYLINDER]), np.array([[[0, 0, 0], [0, 0, 1.0]]]),
    ...                        np.array([[1.0, 0]]), nodes, np.array([[0, 1, 2]]), np.array([[0, 0, 1]]),
    ...                        np.array([[1 / 3, 1 / 3, 1 / 3]]))
    >>> round(float(d[0]), 12)  # the centroid (0, 1/3, 0) is 2/3 inside
    0.666666666667
    """
    out = np.zeros(len(triangles))
    _triangle_distances(*_tables(kinds, frames, sizes), np.ascontiguousarray(nodes, float),
                        np.ascontiguousarray(triangles, np.int64), np.ascontiguousarray(faces, np.int64),
                        np.ascontiguousarray(bary, float), out)
    return out


def _tables(kinds, frames, sizes):
    return (np.ascontiguousarray(kinds, np.int64), np.ascontiguousarray(frames, float).reshape(-1, 2, 3),
            np.ascontiguousarray(sizes, float).reshape(-1, 2))


@njit(cache=True, error_model="numpy")
def _distance(kind, frame, size, x, y, z):
    """Distance from ``(x, y, z)`` to one surface (see :func:`distances`)."""
    rx, ry, rz = x - frame[0, 0], y - frame[0, 1], z - frame[0, 2]
    h = rx * frame[1, 0] + ry * frame[1, 1] + rz * frame[1, 2]
    if kind == PLANE:
        return abs(h)
    if kind == SPHERE:
        return abs(np.sqrt(rx * rx + ry * ry + rz * rz) - size[0])
    px, py, pz = rx - h * frame[1, 0], ry - h * frame[1, 1], rz - h * frame[1, 2]
    radial = np.sqrt(px * px + py * py + pz * pz)
    if kind == CYLINDER:
        return abs(radial - size[0])
    if kind == CONE:
        # profile lines through (+-r0, 0) with directions (+-sin a, cos a), in (radial, h)
        sa, ca = np.sin(size[1]), np.cos(size[1])
        return min(abs((radial - size[0]) * ca - h * sa), abs((radial + size[0]) * ca + h * sa))
    return min(abs(np.hypot(radial - size[0], h) - size[1]), abs(np.hypot(radial + size[0], h) - size[1]))


@njit(cache=True, error_model="numpy")
def _point_distances(kinds, frames, sizes, points, owner, out):
    for i in range(points.shape[0]):
        f = owner[i]
        out[i] = _distance(kinds[f], frames[f], sizes[f], points[i, 0], points[i, 1], points[i, 2])


@njit(cache=True, error_model="numpy")
def _triangle_distances(kinds, frames, sizes, nodes, triangles, faces, bary, out):
    for r in range(faces.shape[0]):
        f = faces[r, 0]
        kind, frame, size = kinds[f], frames[f], sizes[f]
        for t in range(faces[r, 1], faces[r, 2]):
            i, j, k = triangles[t, 0], triangles[t, 1], triangles[t, 2]
            worst = 0.0
            for s in range(bary.shape[0]):
                w0, w1, w2 = bary[s, 0], bary[s, 1], bary[s, 2]
                worst = max(worst, _distance(kind, frame, size, w0 * nodes[i, 0] + w1 * nodes[j, 0] + w2 * nodes[k, 0],
                                             w0 * nodes[i, 1] + w1 * nodes[j, 1] + w2 * nodes[k, 1],
                                             w0 * nodes[i, 2] + w1 * nodes[j, 2] + w2 * nodes[k, 2]))
            out[t] = worst


def revolved(origin, axis, curve, rtol: float = 1e-12):
    """``(kind, frame, sizes)`` of the surface a circle or line sweeps about the axis
    ``(origin, unit axis)`` when it lies in a plane through the axis (to ``rtol`` of its
    size): a torus (a sphere when the circle's centre is on the axis), a cone, a
    cylinder or a plane, the same point sets as OCCT's surface of revolution;
    ``None`` for any other basis curve (``curve``: the surfmod curve
    :func:`surfmod.readback.read_curve` gives).

    >>> import numpy as np, surfmod as sm
    >>> circle = sm.Circle((3, 0, 1), (0, -1, 0), 0.5)
    >>> kind, frame, sizes = revolved(np.zeros(3), np.array([0, 0, 1.0]), circle)
    >>> kind == TORUS, frame[0].tolist(), sizes
    (True, [0.0, 0.0, 1.0], (3.0, 0.5))
    """
    origin, axis = np.asarray(origin, float), np.asarray(axis, float)
    if isinstance(curve, Conic):
        centre, x, y, a, b = curve.center, curve.x_dir, curve.y_dir, curve.a, curve.b
        if a != b:
            return None  # an ellipse
        normal = np.cross(x, y)
        offset = centre - origin
        scale = 1.0 + np.linalg.norm(offset) + a
        if abs(normal @ axis) > rtol or abs(offset @ normal) > rtol * scale:
            return None
        foot = origin + (offset @ axis) * axis
        big = float(np.linalg.norm(centre - foot))
        if big <= rtol * scale:
            return SPHERE, (foot, axis), (float(a), 0.0)
        return TORUS, (foot, axis), (big, float(a))
    if isinstance(curve, Line):
        point, direction = np.asarray(curve.origin, float), np.asarray(curve.direction, float)
        offset = point - origin
        scale = 1.0 + np.linalg.norm(offset)
        if abs(offset @ np.cross(axis, direction)) > rtol * scale:
            return None  # skew to the axis: a hyperboloid
        along = direction @ axis
        if along < 0:
            direction, along = -direction, -along
        foot = origin + (offset @ axis) * axis
        radial = point - foot
        r0 = float(np.linalg.norm(radial))
        outward = direction @ (radial / r0) if r0 > rtol * scale else float(np.linalg.norm(direction - along * axis))
        if along <= rtol:
            return PLANE, (foot, axis), (0.0, 0.0)  # a line across the axis sweeps a plane
        if abs(outward) <= rtol:
            return CYLINDER, (foot, axis), (r0, 0.0)
        return CONE, (foot, axis), (r0, float(np.arctan2(outward, along)))
    return None
