"""geomdl (NURBS-Python) ⇄ surfmod: ``to_geomdl``, ``from_geomdl``.

geomdl's ``BSpline.Surface``/``Curve`` hold Cartesian control points, its
``NURBS.Surface``/``Curve`` homogeneous ones (``ctrlptsw``); surface points are stored
flat with ``v`` running fastest.  A polynomial surfmod object becomes a ``BSpline``
object, a rational one a ``NURBS`` object, so the kind survives the round trip.
geomdl normalizes knot vectors to [0, 1] by default; the objects made here keep the
knots as they are (``normalize_kv=False``).
"""

from __future__ import annotations

import numpy as np

from ..errors import SurfmodError
from ..nets.bspline import BSplineCurve, BSplineSurface, homogeneous
from ..extras import require
from .common import from_homogeneous, nurbs_of


def to_geomdl(obj):
    """A geomdl curve or surface with the same degrees, knots, control points and weights.

    >>> import surfmod as sm, numpy as np
    >>> s = sm.BSplineSurface(np.mgrid[0:3, 0:4, 0:1].transpose(1, 2, 3, 0)[:, :, 0, :] * 1.0, (2, 3))
    >>> g = sm.to_geomdl(s)
    >>> (g.degree_u, g.degree_v), np.allclose(g.evaluate_single((0.3, 0.6)), s.points(0.3, 0.6))
    ((2, 3), True)
    """
    require("geomdl", "interop", "to_geomdl")
    from geomdl import NURBS, BSpline

    kind, b = nurbs_of(obj)
    if kind == "curve":
        c = (NURBS if b.rational else BSpline).Curve(normalize_kv=False)
        c.degree = b.degree
        if b.rational:
            c.ctrlptsw = homogeneous(b.control_points, b.weights).tolist()
        else:
            c.ctrlpts = b.control_points.tolist()
        c.knotvector = b.knots.tolist()
        return c
    n, m = b.control_points.shape[:2]
    s = (NURBS if b.rational else BSpline).Surface(normalize_kv=False)
    s.degree_u, s.degree_v = b.degree
    flat = homogeneous(b.control_points, b.weights).reshape(n * m, -1)
    s.set_ctrlpts(flat.tolist(), n, m)
    s.knotvector_u = b.knots[0].tolist()
    s.knotvector_v = b.knots[1].tolist()
    return s


def from_geomdl(obj):
    """A surfmod ``BSplineCurve``/``BSplineSurface`` from a geomdl curve or surface.

    >>> import surfmod as sm
    >>> c = sm.BSplineCurve([(0, 0, 0), (1, 2, 0), (3, 0, 1)], 2)
    >>> sm.from_geomdl(sm.to_geomdl(c)).control_points.tolist() == c.control_points.tolist()
    True
    """
    require("geomdl", "interop", "from_geomdl")
    from geomdl import abstract

    rational = hasattr(obj, "ctrlptsw")
    if isinstance(obj, abstract.Curve):
        if obj.dimension not in (2, 3):
            raise SurfmodError(f"obj: geomdl curve of dimension {obj.dimension}; expected 2 or 3")
        pts, w = _cartesian(obj.ctrlptsw if rational else obj.ctrlpts, rational, obj.dimension)
        return BSplineCurve(pts, obj.degree, obj.knotvector, w)
    if isinstance(obj, abstract.Surface):
        n, m = obj.ctrlpts_size_u, obj.ctrlpts_size_v
        pts, w = _cartesian(obj.ctrlptsw if rational else obj.ctrlpts, rational, obj.dimension)
        return BSplineSurface(pts.reshape(n, m, 3), (obj.degree_u, obj.degree_v),
                              (obj.knotvector_u, obj.knotvector_v), None if w is None else w.reshape(n, m))
    raise SurfmodError(f"obj: expected a geomdl curve or surface, got {type(obj).__name__}")


def _cartesian(values, rational, dim):
    arr = np.asarray(values, dtype=float)
    if dim == 2:  # planar geomdl geometry: z = 0
        arr = np.insert(arr, 2, 0.0, axis=-1)
    if not rational:
        return arr[..., :3], None
    return from_homogeneous(arr, True)
