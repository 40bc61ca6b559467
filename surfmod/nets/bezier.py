"""Bézier curves and patches (Bernstein basis), rational when weighted.

A Bézier patch of degree ``(n-1, m-1)`` is the B-spline on the clamped knots
``[0]*n + [1]*n``; it shares the B-spline evaluator and maps onto OCCT's
``Geom_BezierSurface`` (degree at most 25, OCCT's own limit).
"""

from __future__ import annotations

import numpy as np

from .. import checks, transforms
from ..errors import SurfmodError
from ..eval.basis import clamped_bezier_knots
from . import knots as kn
from .bspline import BSplineCurve, BSplineSurface, cartesian

MAX_DEGREE = 25  # Geom_BezierSurface::MaxDegree()


class BezierCurve(BSplineCurve):
    """A Bézier curve on ``[0, 1]``.

    >>> import surfmod as sm
    >>> sm.BezierCurve([(0, 0, 0), (1, 2, 0), (2, 0, 0)]).points(0.5)
    array([1., 1., 0.])
    """

    occt_construct = "Geom_BezierCurve"

    def __init__(self, points, weights=None):
        pts = checks.finite_array(points, "points", ndim=2, last=3)
        if not 2 <= pts.shape[0] <= MAX_DEGREE + 1:
            raise SurfmodError(f"points: need 2 to {MAX_DEGREE + 1} control points, got {pts.shape[0]}")
        w = checks.weights_for(weights, pts.shape[:1])
        self._set(pts, pts.shape[0] - 1, clamped_bezier_knots(pts.shape[0] - 1), w)

    @classmethod
    def _trusted(cls, pts, w=None):
        obj = cls._construct_fast()
        BSplineCurve._set(obj, pts, pts.shape[0] - 1, clamped_bezier_knots(pts.shape[0] - 1), w)
        return obj

    def geom(self):
        from ..occ.geom import bezier_curve

        return bezier_curve(self.control_points, self.weights)

    def transformed(self, matrix):
        m = transforms.affine(matrix)
        return BezierCurve._trusted(transforms.apply(m, self.control_points), self.weights)

    def to_bspline(self) -> BSplineCurve:
        return BSplineCurve._trusted(self.control_points, self.degree, self.knots, self.weights)


class BezierSurface(BSplineSurface):
    """A Bézier patch on ``[0, 1] x [0, 1]``; degree ``(n-1, m-1)`` from the ``(n, m, 3)`` net.

    >>> import numpy as np, surfmod as sm
    >>> net = np.zeros((3, 3, 3)); net[..., 0], net[..., 1] = np.mgrid[0:3, 0:3]
    >>> net[1, 1, 2] = 4.0
    >>> sm.BezierSurface(net).points(0.5, 0.5)
    array([1., 1., 1.])
    """

    occt_construct = "Geom_BezierSurface"

    def __init__(self, control_points, weights=None):
        net = checks.control_net(control_points)
        n, m = net.shape[:2]
        if max(n, m) > MAX_DEGREE + 1:
            raise SurfmodError(
                f"control_points: Bézier degree is at most {MAX_DEGREE} (net at most "
                f"{MAX_DEGREE + 1} x {MAX_DEGREE + 1}), got {n} x {m}"
            )
        w = checks.weights_for(weights, (n, m))
        self._set_bezier(net, w)

    def _set_bezier(self, net, w):
        n, m = net.shape[:2]
        BSplineSurface._set(self, net, (n - 1, m - 1), (clamped_bezier_knots(n - 1), clamped_bezier_knots(m - 1)), w)

    @classmethod
    def _trusted(cls, net, weights=None):
        obj = cls._construct_fast()
        BezierSurface._set_bezier(obj, np.asarray(net, dtype=float), weights)
        return obj

    def geom(self):
        from ..occ.geom import bezier_surface

        return bezier_surface(self.control_points, self.weights)

    def transformed(self, matrix) -> "BezierSurface":
        m = transforms.affine(matrix)
        return BezierSurface._trusted(transforms.apply(m, self.control_points), self.weights)

    def to_bspline(self) -> BSplineSurface:
        return BSplineSurface._trusted(self.control_points, self.degree, self.knots, self.weights)


# -- Bézier extraction -----------------------------------------------------------------------
def _pieces(knots: np.ndarray, degree: int, hpoints: np.ndarray):
    """``[((t0, t1), hpoints_piece), ...]``: every non-empty knot span raised to full
    multiplicity, leaving ``degree + 1`` homogeneous points per span (along axis 0)."""
    breaks = np.unique(knots[degree : hpoints.shape[0] + 1])
    return [
        ((float(t0), float(t1)), kn.segment(knots, degree, hpoints, t0, t1)[1])
        for t0, t1 in zip(breaks[:-1], breaks[1:])
    ]


def bezier_pieces(curve: BSplineCurve) -> list[tuple[tuple[float, float], BezierCurve]]:
    """Bézier extraction of a B-spline curve: one exact Bézier piece per non-empty knot span.

    >>> import surfmod as sm
    >>> c = sm.BSplineCurve([(0, 0, 0), (1, 1, 0), (2, 0, 0), (3, 1, 0)], 2)
    >>> [(span, piece.degree) for span, piece in bezier_pieces(c)]
    [((0.0, 0.5), 2), ((0.5, 1.0), 2)]
    >>> bool(np.allclose(bezier_pieces(c)[1][1].points(0.0), c.points(0.5), atol=1e-15))
    True
    """
    return [
        (span, BezierCurve._trusted(*cartesian(h, curve.rational)))
        for span, h in _pieces(curve.knots, curve.degree, curve._homogeneous)
    ]


def bezier_patches(surface: BSplineSurface) -> list[tuple[tuple[float, float], tuple[float, float], BezierSurface]]:
    """Bézier extraction of a B-spline surface: one exact Bézier patch per pair of
    non-empty knot spans, ``[((u0, u1), (v0, v1), BezierSurface), ...]`` (u-major order).

    >>> import surfmod as sm
    >>> net = np.stack([*np.meshgrid(np.arange(4.0), np.arange(3.0), indexing="ij"), np.zeros((4, 3))], -1)
    >>> [(u, v) for u, v, _ in bezier_patches(sm.BSplineSurface(net, (2, 2)))]
    [((0.0, 0.5), (0.0, 1.0)), ((0.5, 1.0), (0.0, 1.0))]
    """
    p, q = surface.degree
    patches = []
    for ur, hu in _pieces(surface.knots[0], p, surface._homogeneous):
        for vr, hv in _pieces(surface.knots[1], q, hu.transpose(1, 0, 2)):
            pts, w = cartesian(hv.transpose(1, 0, 2), surface.rational)
            patches.append((ur, vr, BezierSurface._trusted(pts, w)))
    return patches
