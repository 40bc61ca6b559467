"""Build OCCT ``Geom_*`` curves and surfaces from surfmod data, and read them back through
OCCT's binary writers (``BinTools_CurveSet``, ``BinTools_Curve2dSet``,
``BinTools_SurfaceSet``), parsed with NumPy.

OCCT writes a whole table of curves in C++ (little-endian, ``BinTools::PutReal`` etc.);
each B-spline record is ``uint8 type (7), bool rational, bool periodic, char16 degree,
int32 poles, int32 knots``, then per pole its coordinates (and weight, if rational) as
doubles, then per knot ``double value, int32 multiplicity``.  ``np.frombuffer`` reads the
poles and knots of many curves at C speed, where reading them through OCP costs one
Python call per pole and per knot.  The per-pole reading is the reference the tests hold
this to, bit for bit.  Surfaces are written the same way (``uint8 type (9: B-spline, 8:
Bézier), bool rational u, v, [bool periodic u, v], char16 degrees, [int32 poles u, v,
knots u, v]``, poles row by row with the weight after each pole when rational in either
direction, then the u and v knots).
"""

from __future__ import annotations

import io
import struct

import numpy as np
from OCP.BinTools import BinTools_Curve2dSet, BinTools_CurveSet, BinTools_SurfaceSet
from OCP.Geom import Geom_BezierCurve, Geom_BezierSurface, Geom_BSplineCurve, Geom_BSplineSurface
import OCP.Geom as G

from . import arrays
from ..errors import SurfmodError
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
    The data come through OCCT's binary writer in one piece (:func:`bspline_curves`,
    :func:`spline_surface`).

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
    data come through OCCT's binary writer in one piece (:func:`bspline_curves`,
    :func:`spline_surface`).

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
    """A :func:`bspline_curves` record as :func:`read_bspline_curve`
    returns it: 2-D poles get z = 0."""
    points = data["points"]
    if points.shape[1] == 2:
        points = np.column_stack([points, np.zeros(len(points))])
    return {"points": points, "weights": data["weights"], "knots": data["knots"], "degree": data["degree"]}


def surface_type(surf) -> str:
    """OCCT dynamic type name of a Geom_Surface handle, e.g. ``Geom_BSplineSurface``."""
    return surf.DynamicType().Name()


def downcast_surface(surf, module=G):
    """The most derived Python wrapper of a ``Geom_Surface`` handle (of a curve's too,
    a 2-D one with ``module`` ``OCP.Geom2d``)."""
    cls = getattr(module, surface_type(surf), None)
    down = cls.DownCast(surf) if cls is not None and hasattr(cls, "DownCast") else None
    return surf if down is None else down


def iso_curve(surf, direction: int, value: float):
    """OCCT's exact iso-parametric curve: ``UIso(value)`` (direction 0: u fixed, a curve
    in v) or ``VIso(value)`` (direction 1)."""
    with kernel("Geom_Surface.UIso/VIso"):
        return surf.UIso(float(value)) if direction == 0 else surf.VIso(float(value))


_BSPLINE = 7
_HEAD = struct.Struct("<BBBHii")  # type, rational, periodic, degree, poles, knots
_KNOT = np.dtype([("value", "<f8"), ("mult", "<i4")])


def bspline_curves(curves: list, dim: int) -> list[dict]:
    """Per ``Geom_BSplineCurve`` (``dim`` 3) or ``Geom2d_BSplineCurve`` (``dim`` 2):
    ``{"points" (n, dim), "weights" (n,) or None, "knots" (flat), "degree", "periodic"}``
    exactly as stored (a periodic curve keeps its periodic poles and knots).

    >>> import surfmod as sm
    >>> c = sm.BSplineCurve([(0, 0, 0), (1, 2, 0), (3, 1, 1)], 2, [0, 0, 0, 1, 1, 1]).geom()
    >>> d = bspline_curves([c], 3)[0]
    >>> d["degree"], d["knots"].tolist(), d["points"][1].tolist()
    (2, [0.0, 0.0, 0.0, 1.0, 1.0, 1.0], [1.0, 2.0, 0.0])
    """
    if not curves:
        return []
    table = BinTools_Curve2dSet() if dim == 2 else BinTools_CurveSet()
    with kernel("BinTools curve set"):
        index = [table.Add(c) for c in curves]  # the set keeps one entry per distinct curve
        buf = io.BytesIO()
        table.Write(buf)
    data = buf.getvalue()
    at = data.index(b"\n") + 1  # after the text header "Curves N" / "Curve2ds N"
    parsed = []
    for _ in range(max(index)):
        kind, rational, periodic, degree, n_poles, n_knots = _HEAD.unpack_from(data, at)
        if kind != _BSPLINE:
            raise SurfmodError(f"curve: expected B-spline curves, got OCCT binary curve type {kind}")
        at += _HEAD.size
        width = dim + bool(rational)
        poles = np.frombuffer(data, "<f8", n_poles * width, at).reshape(n_poles, width)
        at += 8 * n_poles * width
        knots = np.frombuffer(data, _KNOT, n_knots, at)
        at += _KNOT.itemsize * n_knots
        parsed.append({
            "points": np.array(poles[:, :dim]),
            "weights": np.array(poles[:, dim]) if rational else None,
            "knots": np.repeat(knots["value"], knots["mult"]),
            "degree": int(degree),
            "periodic": bool(periodic),
        })
    return [parsed[i - 1] for i in index]


_SURFACE_BEZIER, _SURFACE_BSPLINE = 8, 9
_SURFACE_HEAD = struct.Struct("<BBBBBHHiiii")  # type, rational u/v, periodic u/v, degrees, poles, knots
_BEZIER_HEAD = struct.Struct("<BBBHH")  # type, rational u/v, degrees


def spline_surface(surf) -> dict:
    """``{"control_points" (n, m, 3), "weights" (n, m) or None, "knots" (flat u, flat
    v) or None, "degree" (p, q), "periodic" (u, v)}`` of one ``Geom_BSplineSurface`` or
    ``Geom_BezierSurface`` (``knots`` None), exactly as stored.

    >>> import numpy as np, surfmod as sm
    >>> net = np.zeros((3, 4, 3)); net[..., 0], net[..., 1] = np.mgrid[0:3, 0:4]
    >>> d = spline_surface(sm.BezierSurface(net).geom())
    >>> d["control_points"].shape, d["degree"], d["knots"]
    ((3, 4, 3), (2, 3), None)
    """
    table = BinTools_SurfaceSet()
    with kernel("BinTools surface set"):
        table.Add(surf)
        buf = io.BytesIO()
        table.Write(buf)
    data = buf.getvalue()
    at = data.index(b"\n") + 1  # after the text header "Surfaces 1"
    kind = data[at]
    if kind == _SURFACE_BSPLINE:
        _, ur, vr, up, vp, p, q, n, m, nu, nv = _SURFACE_HEAD.unpack_from(data, at)
        at += _SURFACE_HEAD.size
    elif kind == _SURFACE_BEZIER:
        _, ur, vr, p, q = _BEZIER_HEAD.unpack_from(data, at)
        at += _BEZIER_HEAD.size
        up = vp = False
        n, m = p + 1, q + 1
    else:
        raise SurfmodError(f"surface: expected a B-spline or Bézier surface, got OCCT binary surface type {kind}")
    width = 3 + bool(ur or vr)
    poles = np.frombuffer(data, "<f8", n * m * width, at).reshape(n, m, width)
    at += 8 * n * m * width
    knots = None
    if kind == _SURFACE_BSPLINE:
        u = np.frombuffer(data, _KNOT, nu, at)
        v = np.frombuffer(data, _KNOT, nv, at + _KNOT.itemsize * nu)
        knots = (np.repeat(u["value"], u["mult"]), np.repeat(v["value"], v["mult"]))
    return {
        "control_points": np.array(poles[..., :3]),
        "weights": np.array(poles[..., 3]) if width == 4 else None,
        "knots": knots,
        "degree": (int(p), int(q)),
        "periodic": (bool(up), bool(vp)),
    }
