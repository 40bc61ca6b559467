"""Shared pieces of the interop converters: optional imports, NURBS data of surfmod
objects, and building surfmod objects from plain arrays."""

from __future__ import annotations

import numpy as np

from ..construct.from_edge import from_edge
from ..curve import Curve
from ..errors import SurfmodError
from ..nets.bspline import BSplineCurve, BSplineSurface
from ..readback import from_face
from ..surface import Surface

def nurbs_of(obj, name: str = "obj"):
    """The exact B-spline/NURBS form of a surfmod surface or curve (or build123d
    Face/Edge): ``("surface" | "curve", BSplineSurface | BSplineCurve)``."""
    if not isinstance(obj, (Surface, Curve)) and hasattr(obj, "wrapped"):
        kind = type(obj).__name__
        obj = from_face(obj) if kind == "Face" else from_edge(obj) if kind in ("Edge", "Wire") else obj
    if isinstance(obj, Curve):
        c = obj.to_bspline()
        return "curve", BSplineCurve._trusted(c.control_points, c.degree, c.knots, c.weights)
    if isinstance(obj, Surface):
        for attr in ("to_bspline", "to_nurbs"):
            if hasattr(obj, attr):
                s = getattr(obj, attr)()
                return "surface", BSplineSurface._trusted(s.control_points, s.degree, s.knots, s.weights)
        from ..occ.geom import as_bspline_surface, read_bspline_surface

        data = read_bspline_surface(as_bspline_surface(obj.geom()))
        s = BSplineSurface(data["control_points"], data["degree"], data["knots"], data["weights"])
        (u0, u1), (v0, v1) = obj.domain
        return "surface", s.segment((u0, u1), (v0, v1))
    raise SurfmodError(
        f"{name}: expected a surfmod surface or curve (or a build123d Face/Edge), got {type(obj).__name__}"
    )


def from_homogeneous(h: np.ndarray, rational: bool):
    """Cartesian points and weights (or None) from homogeneous ``(..., 4)`` data."""
    h = np.asarray(h, dtype=float)
    if not rational:
        return h[..., :3], None
    w = h[..., 3]
    if np.any(w <= 0):
        raise SurfmodError("weights: all weights must be > 0")
    return h[..., :3] / w[..., None], w
