"""Gallery entries for the synthetic surfaces (issue 3): plane, Bézier, B-spline, NURBS,
uniform cubic B-spline, Hermite bicubic."""

from __future__ import annotations

import numpy as np

from ..construct.plane import plane
from ..nets.bezier import BezierSurface
from ..nets.bspline import BSplineSurface
from ..nets.hermite import HermiteBicubic
from . import entry


def wavy_net(n: int, m: int, amplitude: float = 0.6) -> np.ndarray:
    """A reproducible (n, m, 3) net over [0, 10] x [0, 8] with a smooth bump pattern."""
    x, y = np.meshgrid(np.linspace(0, 10, n), np.linspace(0, 8, m), indexing="ij")
    z = amplitude * (np.sin(x * 0.9) * np.cos(y * 0.7) * 2 + 0.3 * x)
    return np.stack([x, y, z], axis=-1)


@entry("plane", "plane through three points", "sm.plane(p0, p1, p2)")
def _plane():
    return plane((0, 0, 0), (10, 0, 1), (2, 8, 0))


@entry("bezier", "Bézier patch (Bernstein)", "sm.BezierSurface(net)")
def _bezier():
    return BezierSurface(wavy_net(6, 5))


@entry("bezier_rational", "rational Bézier patch", "sm.BezierSurface(net, weights)")
def _bezier_rational():
    w = 1.0 + 0.5 * np.add.outer(np.sin(np.arange(4)), np.cos(np.arange(4))) ** 2
    return BezierSurface(wavy_net(4, 4), w)


@entry("bspline", "B-spline surface (non-uniform)", "sm.BSplineSurface(net, (3, 2), knots)")
def _bspline():
    ku = [0, 0, 0, 0, 0.2, 0.5, 0.5, 1, 1, 1, 1]
    kv = [0, 0, 0, 0.3, 0.6, 1, 1, 1]
    return BSplineSurface(wavy_net(7, 5), (3, 2), (ku, kv))


@entry("nurbs", "NURBS surface", "sm.BSplineSurface(net, (3, 3), weights=w)")
def _nurbs():
    w = np.ones((6, 6))
    w[2:4, 2:4] = 4.0
    w[0, :] = 0.5
    return BSplineSurface(wavy_net(6, 6), (3, 3), weights=w)


@entry("uniform_cubic", "uniform cubic B-spline (matrix form)", "sm.BSplineSurface.uniform_cubic(net)")
def _uniform_cubic():
    return BSplineSurface.uniform_cubic(wavy_net(7, 6))


@entry("hermite", "Hermite bicubic patch", "sm.HermiteBicubic(corners, du, dv, twist)")
def _hermite():
    corners = np.array([[[0, 0, 0], [0, 6, 1]], [[8, 0, 1], [8, 6, 0]]], dtype=float)
    du = np.array([[[8, 0, 4], [8, 0, -2]], [[8, 0, -4], [8, 0, 2]]], dtype=float)
    dv = np.array([[[0, 6, 3], [0, 6, -3]], [[0, 6, 0], [0, 6, 2]]], dtype=float)
    twist = np.array([[[0, 0, 5], [0, 0, -5]], [[0, 0, 0], [0, 0, 3]]], dtype=float)
    return HermiteBicubic(corners, du, dv, twist)
