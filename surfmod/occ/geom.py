"""Build OCCT ``Geom_*`` curves and surfaces from surfmod data, and read them back."""

from __future__ import annotations

import io

import numpy as np
from OCP.Geom import Geom_BezierCurve, Geom_BezierSurface, Geom_BSplineCurve, Geom_BSplineSurface

from . import arrays
from .guard import kernel


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
    OCCT serializes the surface in C++ (``BinTools_SurfaceSet``) and NumPy reads the
    buffer, where reading pole by pole costs Python calls per pole (the STEP parts'
    surfaces have hundreds of poles each); a buffer that does not parse as expected is
    read pole by pole instead."""
    from OCP.BinTools import BinTools_SurfaceSet

    with kernel("reading Geom_BSplineSurface"):
        if surf.IsUPeriodic() or surf.IsVPeriodic():
            surf = surf.Copy()  # OCP returns the derived type (no DownCast in OCP)
            if surf.IsUPeriodic():
                surf.SetUNotPeriodic()
            if surf.IsVPeriodic():
                surf.SetVNotPeriodic()
        table = BinTools_SurfaceSet()
        table.Add(surf)
        buffer = io.BytesIO()
        table.Write(buffer)
        read = _parse_bspline_surface(buffer.getvalue())
        return read if read is not None else _read_bspline_surface_by_pole(surf)


#: ``(knot, multiplicity)`` records of OCCT's binary format (little-endian, packed)
_KNOT_RECORD = np.dtype([("knot", "<f8"), ("mult", "<i4")])


def _parse_bspline_surface(data: bytes) -> dict | None:
    """One ``Geom_BSplineSurface`` as ``BinTools_SurfaceSet::Write`` stores it (a
    ``Surfaces 1`` line, type byte 9, four flag bytes (u/v rational, u/v periodic), the
    degrees as uint16, the pole and knot counts as int32, the poles row by row each
    followed by its weight when rational, then (knot, multiplicity) records in u and in
    v), or ``None`` when the bytes do not follow that layout."""
    end = data.find(b"\n")
    if end < 0 or data[:end].split() != [b"Surfaces", b"1"] or len(data) < end + 26 or data[end + 1] != 9:
        return None
    pos = end + 2
    rational = bool(data[pos] or data[pos + 1])
    p, q = (int(x) for x in np.frombuffer(data, "<u2", 2, pos + 4))
    n, m, nku, nkv = (int(x) for x in np.frombuffer(data, "<i4", 4, pos + 8))
    pos += 24
    dim = 4 if rational else 3
    if min(n, m, nku, nkv) < 1 or len(data) != pos + 8 * n * m * dim + _KNOT_RECORD.itemsize * (nku + nkv):
        return None
    poles = np.frombuffer(data, "<f8", n * m * dim, pos).reshape(n, m, dim)
    pos += 8 * n * m * dim
    u = np.frombuffer(data, _KNOT_RECORD, nku, pos)
    v = np.frombuffer(data, _KNOT_RECORD, nkv, pos + _KNOT_RECORD.itemsize * nku)
    ku, kv = np.repeat(u["knot"], u["mult"]), np.repeat(v["knot"], v["mult"])
    if len(ku) != n + p + 1 or len(kv) != m + q + 1:
        return None
    return {
        "control_points": poles[..., :3].astype(float),  # aligned, writable copies
        "weights": poles[..., 3].astype(float) if rational else None,
        "knots": (ku.astype(float), kv.astype(float)),
        "degree": (p, q),
    }


def _read_bspline_surface_by_pole(surf: Geom_BSplineSurface) -> dict:
    """:func:`read_bspline_surface` through OCCT's per-pole accessors (non-periodic surface)."""
    from OCP.TColgp import TColgp_Array2OfPnt
    from OCP.TColStd import TColStd_Array1OfReal, TColStd_Array2OfReal

    with kernel("reading Geom_BSplineSurface"):
        n, m = surf.NbUPoles(), surf.NbVPoles()
        poles = TColgp_Array2OfPnt(1, n, 1, m)
        surf.Poles(poles)
        net = arrays.pnts_to_numpy_2d(poles)
        weights = None
        if surf.IsURational() or surf.IsVRational():
            w = TColStd_Array2OfReal(1, n, 1, m)
            surf.Weights(w)
            weights = arrays.reals_to_numpy_2d(w)
        p, q = surf.UDegree(), surf.VDegree()
        ku = TColStd_Array1OfReal(1, n + p + 1)
        surf.UKnotSequence(ku)
        kv = TColStd_Array1OfReal(1, m + q + 1)
        surf.VKnotSequence(kv)
    return {
        "control_points": net,
        "weights": weights,
        "knots": (arrays.to_numpy_1d(ku), arrays.to_numpy_1d(kv)),
        "degree": (p, q),
    }


def read_bezier_surface(surf: Geom_BezierSurface) -> dict:
    with kernel("reading Geom_BezierSurface"):
        from OCP.TColgp import TColgp_Array2OfPnt
        from OCP.TColStd import TColStd_Array2OfReal

        n, m = surf.NbUPoles(), surf.NbVPoles()
        poles = TColgp_Array2OfPnt(1, n, 1, m)
        surf.Poles(poles)
        weights = None
        if surf.IsURational() or surf.IsVRational():
            w = TColStd_Array2OfReal(1, n, 1, m)
            surf.Weights(w)
            weights = arrays.reals_to_numpy_2d(w)
    return {"control_points": arrays.pnts_to_numpy_2d(poles), "weights": weights}


def read_bspline_curve(curve: Geom_BSplineCurve) -> dict:
    """Poles ``(n, 3)``, weights (None if polynomial), flat knots and degree of a
    ``Geom_BSplineCurve`` or of a ``Geom2d_BSplineCurve`` (a p-curve: its poles get
    z = 0, so the surfmod evaluator reads both); a periodic curve is unwrapped."""
    with kernel("reading Geom_BSplineCurve"):
        from OCP.TColgp import TColgp_Array1OfPnt, TColgp_Array1OfPnt2d
        from OCP.TColStd import TColStd_Array1OfReal

        if curve.IsPeriodic():
            curve = curve.Copy()  # OCP returns the derived type (no DownCast in OCP)
            curve.SetNotPeriodic()
        n, p = curve.NbPoles(), curve.Degree()
        planar = type(curve).__name__.startswith("Geom2d")
        poles = (TColgp_Array1OfPnt2d if planar else TColgp_Array1OfPnt)(1, n)
        curve.Poles(poles)
        weights = None
        if curve.IsRational():
            w = TColStd_Array1OfReal(1, n)
            curve.Weights(w)
            weights = arrays.to_numpy_1d(w)
        k = TColStd_Array1OfReal(1, n + p + 1)
        curve.KnotSequence(k)
        if planar:
            points = np.zeros((n, 3))
            points[:, :2] = [poles.Value(i).Coord() for i in range(1, n + 1)]
        else:
            points = arrays.pnts_to_numpy_1d(poles)
    return {"points": points, "weights": weights, "knots": arrays.to_numpy_1d(k), "degree": p}


def surface_type(surf) -> str:
    """OCCT dynamic type name of a Geom_Surface handle, e.g. ``Geom_BSplineSurface``."""
    return surf.DynamicType().Name()


def downcast_surface(surf):
    """The most derived Python wrapper of a ``Geom_Surface`` handle."""
    import OCP.Geom as G

    cls = getattr(G, surface_type(surf), None)
    if cls is None or not hasattr(cls, "DownCast"):
        return surf
    down = cls.DownCast(surf)
    return down if down is not None else surf
