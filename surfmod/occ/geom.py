"""Build OCCT ``Geom_*`` curves and surfaces from surfmod data, and read them back."""

from __future__ import annotations

import numpy as np

from OCP.Geom import Geom_BezierCurve, Geom_BezierSurface, Geom_BSplineCurve, Geom_BSplineSurface

from . import arrays
from .binary import bspline_curves, spline_surface
from .guard import kernel
import OCP.Geom as G


def bspline_surface(net, degree, knots, weights=None) -> Geom_BSplineSurface:
    """``Geom_BSplineSurface`` with the same poles, weights, flat knots and degrees."""
    (p, q), (ku, kv) = degree, knots
    uk, um = arrays.knots_and_mults(ku)
    vk, vm = arrays.knots_and_mults(kv)
    poles = arrays.points_2d(net)
    with kernel("Geom_BSplineSurface"):
        if weights is None:
            return Geom_BSplineSurface(poles, uk, vk, um, vm, p, q, False, False)
        return Geom_BSplineSurface(poles, arrays.reals_2d(weights), uk, vk, um, vm, p, q, False, False)


def bezier_surface(net, weights=None) -> Geom_BezierSurface:
    poles = arrays.points_2d(net)
    with kernel("Geom_BezierSurface"):
        if weights is None:
            return Geom_BezierSurface(poles)
        return Geom_BezierSurface(poles, arrays.reals_2d(weights))


def bspline_curve(points, degree, knots, weights=None) -> Geom_BSplineCurve:
    k, mults = arrays.knots_and_mults(knots)
    poles = arrays.points_1d(points)
    with kernel("Geom_BSplineCurve"):
        if weights is None:
            return Geom_BSplineCurve(poles, k, mults, degree, False)
        return Geom_BSplineCurve(poles, arrays.reals_1d(weights), k, mults, degree, False)


def bezier_curve(points, weights=None) -> Geom_BezierCurve:
    poles = arrays.points_1d(points)
    with kernel("Geom_BezierCurve"):
        if weights is None:
            return Geom_BezierCurve(poles)
        return Geom_BezierCurve(poles, arrays.reals_1d(weights))


def read_bspline_surface(surf: Geom_BSplineSurface) -> dict:
    """Poles, weights (None if polynomial), flat knots and degrees of a B-spline surface.

    Periodic surfaces are read through a non-periodic copy (same shape, OCCT converts).
    The data come through OCCT's binary writer in one piece (:mod:`surfmod.occ.binary`).

    >>> import numpy as np, surfmod as sm
    >>> net = np.zeros((3, 4, 3)); net[..., 0], net[..., 1] = np.mgrid[0:3, 0:4]
    >>> d = read_bspline_surface(sm.BSplineSurface(net, (2, 3), ([0] * 3 + [1] * 3, [0] * 4 + [1] * 4)).geom())
    >>> d["control_points"].shape, d["degree"], d["knots"][1].tolist()
    ((3, 4, 3), (2, 3), [0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 1.0])
    """
    with kernel("reading Geom_BSplineSurface"):
        if surf.IsUPeriodic() or surf.IsVPeriodic():
            surf = surf.Copy()  # OCP returns the derived type (no DownCast in OCP)
            if surf.IsUPeriodic():
                surf.SetUNotPeriodic()
            if surf.IsVPeriodic():
                surf.SetVNotPeriodic()
    data = spline_surface(surf)
    return {key: data[key] for key in ("control_points", "weights", "knots", "degree")}


def read_bezier_surface(surf: Geom_BezierSurface) -> dict:
    """Poles and weights (None if polynomial) of a Bézier surface (binary, as above)."""
    data = spline_surface(surf)
    return {"control_points": data["control_points"], "weights": data["weights"]}


def read_bspline_curve(curve: Geom_BSplineCurve) -> dict:
    """Poles ``(n, 3)``, weights (None if polynomial), flat knots and degree of a
    ``Geom_BSplineCurve`` or of a ``Geom2d_BSplineCurve`` (a p-curve: its poles get
    z = 0, so the surfmod evaluator reads both); a periodic curve is unwrapped.  The
    data come through OCCT's binary writer in one piece (:mod:`surfmod.occ.binary`).

    >>> import surfmod as sm
    >>> d = read_bspline_curve(sm.BSplineCurve([(0, 0, 0), (1, 2, 0), (3, 1, 1)], 2, [0, 0, 0, 1, 1, 1]).geom())
    >>> d["points"].shape, d["weights"], d["degree"]
    ((3, 3), None, 2)
    """
    with kernel("reading Geom_BSplineCurve"):
        if curve.IsPeriodic():
            curve = curve.Copy()  # OCP returns the derived type (no DownCast in OCP)
            curve.SetNotPeriodic()
        planar = type(curve).__name__.startswith("Geom2d")
    return _padded(bspline_curves([curve], 2 if planar else 3)[0])


def _padded(data: dict) -> dict:
    """A :func:`surfmod.occ.binary.bspline_curves` record as :func:`read_bspline_curve`
    returns it: 2-D poles get z = 0."""
    points = data["points"]
    if points.shape[1] == 2:
        points = np.column_stack([points, np.zeros(len(points))])
    return {"points": points, "weights": data["weights"], "knots": data["knots"], "degree": data["degree"]}


def read_bspline_curves_2d(curves: list) -> list[dict]:
    """:func:`read_bspline_curve` of many non-periodic ``Geom2d_BSplineCurve`` (the
    B-spline p-curves of a face) through one binary table."""
    return [_padded(d) for d in bspline_curves(curves, 2)]


def surface_type(surf) -> str:
    """OCCT dynamic type name of a Geom_Surface handle, e.g. ``Geom_BSplineSurface``."""
    return surf.DynamicType().Name()


def downcast_surface(surf):
    """The most derived Python wrapper of a ``Geom_Surface`` handle."""
    cls = getattr(G, surface_type(surf), None)
    if cls is None or not hasattr(cls, "DownCast"):
        return surf
    down = cls.DownCast(surf)
    return down if down is not None else surf


def iso_curve(surf, direction: int, value: float):
    """OCCT's exact iso-parametric curve: ``UIso(value)`` (direction 0: u fixed, a curve
    in v) or ``VIso(value)`` (direction 1)."""
    with kernel("Geom_Surface.UIso/VIso"):
        return surf.UIso(float(value)) if direction == 0 else surf.VIso(float(value))
