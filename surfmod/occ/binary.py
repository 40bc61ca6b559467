"""B-spline curves and B-spline / Bézier surfaces read through OCCT's binary writers
(``BinTools_CurveSet``, ``BinTools_Curve2dSet``, ``BinTools_SurfaceSet``), parsed with NumPy.

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

from ..errors import SurfmodError
from .guard import kernel

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
