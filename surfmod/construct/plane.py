"""The plane through three points, ``S(u, v) = P0 + u (P1 - P0) + v (P2 - P0)``."""

from __future__ import annotations

import numpy as np

from .. import checks
from ..errors import SurfmodError
from ..nets.bspline import BSplineSurface
from .elementary_closest import parallelogram

#: how far (relative to the net's size) the fourth control point may sit from the
#: parallelogram of the other three for the closed-form projection (a rounding, no more)
PARALLELOGRAM_SLACK = 1e-13


class ThreePointPlane(BSplineSurface):
    """A bilinear (degree 1 x 1) B-spline that is exactly the lecture's plane.

    OCCT's ``Geom_Plane`` is parametrized by an orthonormal frame, so it matches
    ``P0 + u(P1-P0) + v(P2-P0)`` only for orthonormal edge vectors; the degree-1
    ``Geom_BSplineSurface`` matches it for any three points.

    >>> import surfmod as sm
    >>> p = sm.plane((0, 0, 0), (2, 0, 0), (1, 1, 0))   # skewed edges: still exact
    >>> p.points(0.5, 1.0)
    array([2., 1., 0.])
    """

    occt_construct = "Geom_BSplineSurface (degree 1 x 1)"

    @property
    def origin(self) -> np.ndarray:
        return self.control_points[0, 0]

    @property
    def normal(self) -> np.ndarray:
        n = np.cross(self.control_points[1, 0] - self.origin, self.control_points[0, 1] - self.origin)
        return n / np.linalg.norm(n)

    def _closest_parameters(self, points):
        """Closest points in closed form (:func:`~surfmod.construct.elementary_closest.parallelogram`)
        when the net is the parallelogram :func:`plane` makes (``None`` otherwise: a net
        given to the class directly is projected like any B-spline)."""
        net = self.control_points
        if net.shape[:2] != (2, 2) or self.degree != (1, 1) or (self.rational and np.ptp(self.weights) > 0):
            return None
        e1, e2 = net[1, 0] - net[0, 0], net[0, 1] - net[0, 0]
        size = max(np.abs(e1).max(), np.abs(e2).max())
        if (np.abs(net[1, 1] - net[1, 0] - e2).max() > PARALLELOGRAM_SLACK * size
                or np.linalg.norm(np.cross(e1, e2)) <= 1e-12 * size * size):
            return None
        s, t = parallelogram(points, net[0, 0], e1, e2)
        (u0, u1), (v0, v1) = self.domain
        return u0 + s * (u1 - u0), v0 + t * (v1 - v0)

    def transformed(self, matrix) -> "ThreePointPlane":
        """An affine image of a plane is a plane: same class, mapped control points."""
        out = BSplineSurface.transformed(self, matrix)
        obj = ThreePointPlane._trusted(out.control_points, out.degree, out.knots, None)
        return obj

    def implicit(self, xyz) -> np.ndarray:
        """Signed distance ``F(x) = n . (x - P0)``; zero on the plane."""
        return (np.asarray(xyz, dtype=float) - self.origin) @ self.normal


def plane(p0, p1, p2) -> ThreePointPlane:
    """The plane through three points, parametrized ``P0 + u(P1-P0) + v(P2-P0)`` on [0, 1]^2.

    >>> import surfmod as sm
    >>> s = sm.plane((0, 0, 0), (2, 0, 0), (0, 1, 1))
    >>> s.points(0.5, 1.0)
    array([1., 1., 1.])
    """
    a, b, c = checks.point(p0, "p0"), checks.point(p1, "p1"), checks.point(p2, "p2")
    e1, e2 = b - a, c - a
    scale = max(np.linalg.norm(e1), np.linalg.norm(e2), 1e-300)
    if np.linalg.norm(e1) <= 1e-12 * max(scale, 1.0):
        raise SurfmodError("p1: coincides with p0, the three points do not span a plane")
    if np.linalg.norm(np.cross(e1, e2)) <= 1e-12 * scale * scale:
        raise SurfmodError("p2: collinear with p0 and p1, the three points do not span a plane")
    net = np.array([[a, c], [b, b + e2]])
    k = np.array([0.0, 0.0, 1.0, 1.0])
    obj = ThreePointPlane._trusted(net, (1, 1), (k, k), None)
    return obj
