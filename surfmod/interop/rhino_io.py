"""rhino3dm (OpenNURBS) ⇄ surfmod: ``to_rhino``, ``from_rhino`` and ``.3dm`` files.

OpenNURBS stores orders (degree + 1), control vertices in homogeneous form and knot
vectors *without* the two superfluous end knots of the textbook (full) vector, which
never influence the spline on its domain.  Writing drops them; reading restores them by
repeating the neighbouring knot, so clamped vectors come back identical and unclamped
ones give the same spline.
"""

from __future__ import annotations

import os

import numpy as np

from ..atomic import atomic_path, target_path
from ..errors import SurfmodError
from ..nets.bspline import BSplineCurve, BSplineSurface
from ..extras import require
from .common import from_homogeneous, nurbs_of


def to_rhino(obj, path=None):
    """A rhino3dm ``NurbsCurve``/``NurbsSurface`` with the same data; with ``path``,
    ``obj`` may be a list and everything is written to that ``.3dm`` file (atomically)
    and the list of rhino3dm objects is returned.

    >>> import surfmod as sm, numpy as np
    >>> c = sm.BSplineCurve([(0, 0, 0), (1, 2, 0), (3, 0, 1)], 2)
    >>> rc = sm.to_rhino(c)
    >>> p = rc.PointAt(0.5)
    >>> rc.Order, bool(np.allclose([p.X, p.Y, p.Z], c.points(0.5)))
    (3, True)
    """
    if path is not None:
        return export_3dm(obj, path)
    r3 = require("rhino3dm", "interop", "to_rhino")
    kind, b = nurbs_of(obj)
    if kind == "curve":
        n = len(b.control_points)
        c = r3.NurbsCurve(3, b.rational, b.degree + 1, n)
        w = np.ones(n) if b.weights is None else b.weights
        for i, (p, wi) in enumerate(zip(b.control_points, w)):
            c.Points[i] = r3.Point4d(*(p * wi if b.rational else p), float(wi))
        for i, k in enumerate(b.knots[1:-1]):
            c.Knots[i] = float(k)
        return c
    n, m = b.control_points.shape[:2]
    s = r3.NurbsSurface.Create(3, b.rational, b.degree[0] + 1, b.degree[1] + 1, n, m)
    w = np.ones((n, m)) if b.weights is None else b.weights
    for i in range(n):  # plain loops: rhino3dm sets one control vertex per call
        for j in range(m):
            p = b.control_points[i, j] * (w[i, j] if b.rational else 1.0)
            s.Points[i, j] = r3.Point4d(*p, float(w[i, j]))
    for i, k in enumerate(b.knots[0][1:-1]):
        s.KnotsU[i] = float(k)
    for i, k in enumerate(b.knots[1][1:-1]):
        s.KnotsV[i] = float(k)
    return s


def _full(knots):
    inner = np.asarray(knots, dtype=float)
    return np.concatenate([[inner[0]], inner, [inner[-1]]])


def from_rhino(obj):
    """A surfmod curve or surface from rhino3dm geometry (``NurbsCurve``,
    ``NurbsSurface``, or anything with ``ToNurbsCurve``/``ToNurbsSurface``), or every
    curve and surface of a ``.3dm`` file (a path: returns a list).

    >>> import surfmod as sm
    >>> c = sm.BSplineCurve([(0, 0, 0), (1, 2, 0), (3, 0, 1)], 2)
    >>> sm.from_rhino(sm.to_rhino(c)).knots.tolist()
    [0.0, 0.0, 0.0, 1.0, 1.0, 1.0]
    """
    r3 = require("rhino3dm", "interop", "from_rhino")
    if isinstance(obj, (str, os.PathLike)):
        return read_3dm(obj)

    if not isinstance(obj, (r3.NurbsCurve, r3.NurbsSurface)):
        for attr in ("ToNurbsSurface", "ToNurbsCurve"):
            if hasattr(obj, attr):
                obj = getattr(obj, attr)()
                break
        else:
            raise SurfmodError(f"obj: expected rhino3dm NURBS geometry or a .3dm path, got {type(obj).__name__}")
    if isinstance(obj, r3.NurbsCurve):
        if obj.IsPeriodic:
            raise SurfmodError("obj: periodic rhino3dm curves are not read (clamp them in Rhino first)")
        n = len(obj.Points)
        h = np.array([[q.X, q.Y, q.Z, q.W] for q in (obj.Points[i] for i in range(n))])
        pts, w = from_homogeneous(h, obj.IsRational)
        return BSplineCurve(pts, obj.Order - 1, _full([obj.Knots[i] for i in range(len(obj.Knots))]), w)
    n, m = obj.Points.CountU, obj.Points.CountV
    h = np.array([[[q.X, q.Y, q.Z, q.W] for q in (obj.Points[i, j] for j in range(m))] for i in range(n)])
    pts, w = from_homogeneous(h, obj.IsRational)
    ku = _full([obj.KnotsU[i] for i in range(len(obj.KnotsU))])
    kv = _full([obj.KnotsV[i] for i in range(len(obj.KnotsV))])
    return BSplineSurface(pts, (obj.OrderU - 1, obj.OrderV - 1), (ku, kv), w)


def export_3dm(objects, path) -> list:
    """Write surfmod curves/surfaces to a Rhino ``.3dm`` file, atomically; returns the
    rhino3dm objects written.

    >>> import surfmod as sm, tempfile, os
    >>> path = os.path.join(tempfile.mkdtemp(), "c.3dm")
    >>> _ = export_3dm([sm.BSplineCurve([(0, 0, 0), (1, 2, 0), (3, 0, 1)], 2)], path)
    >>> len(read_3dm(path))
    1
    """
    r3 = require("rhino3dm", "interop", "export_3dm")

    target = target_path(path, "path", (".3dm",))
    items = list(objects) if isinstance(objects, (list, tuple)) else [objects]
    if not items:
        raise SurfmodError("objects: nothing to export")
    model = r3.File3dm()
    made = [to_rhino(obj) for obj in items]
    for geom in made:
        model.Objects.Add(geom)
    with atomic_path(target) as tmp:
        if not model.Write(str(tmp), 0):
            raise SurfmodError(f"path: rhino3dm could not write {target}")
    return made


def read_3dm(path) -> list:
    """Every NURBS curve and surface of a ``.3dm`` file as surfmod objects (Breps give
    their faces' surfaces)."""
    r3 = require("rhino3dm", "interop", "read_3dm")
    if not os.path.isfile(os.fspath(path)):
        raise SurfmodError(f"path: no such file {path}")
    model = r3.File3dm.Read(os.fspath(path))
    if model is None:
        raise SurfmodError(f"path: {path} is not a readable .3dm file")
    out = []
    for item in model.Objects:
        geom = item.Geometry
        if isinstance(geom, r3.Brep):
            out.extend(from_rhino(f.ToNurbsSurface()) for f in geom.Faces)
        elif isinstance(geom, (r3.NurbsCurve, r3.NurbsSurface)) or any(
            hasattr(geom, attr) for attr in ("ToNurbsSurface", "ToNurbsCurve")
        ):
            out.append(from_rhino(geom))
    return out
