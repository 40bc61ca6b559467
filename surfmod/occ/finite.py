"""Is every number of a shape's geometry finite?  Poles, weights and values of its ``Geom``
surfaces and curves, and its ``BRepBndLib`` box (the STEP reader's last check).

A damaged STEP file can hold ``inf`` or ``nan`` in a control point that OCCT's reader
accepts; the bounding box, built from edges and bounds, need not see it, and a later
evaluation of that span crashes inside OCCT (SIGSEGV in ``BRepAdaptor``).  So the reader's
worker looks at the numbers themselves: the poles and weights of every B-spline or Bézier
surface, 3-D curve and p-curve, and a few evaluated points of every other surface and curve
(an analytic surface's numbers are its placement and radii, which its points carry).
"""

from __future__ import annotations

import math

import OCP.Geom as G
import OCP.Geom2d as G2
from OCP.Bnd import Bnd_Box
from OCP.BRep import BRep_Tool
from OCP.BRepBndLib import BRepBndLib
from OCP.BRepTools import BRepTools
from OCP.TopAbs import TopAbs_EDGE, TopAbs_FACE
from OCP.TopoDS import TopoDS

from ..errors import SurfmodError
from .bindings import box_limits
from .geom import downcast_surface
from .guard import kernel
from .topo import explore

# where no B-spline form holds the numbers, these fractions of the range are evaluated
_FRACTIONS = (0.0, 0.5, 1.0)


def _basis(geom, module, attribute: str):
    """Through trimming and offset wrappers (``attribute``: ``BasisSurface`` or
    ``BasisCurve``) to the geometry that holds the numbers."""
    for _ in range(8):  # nesting is shallow in any file; bounded anyway
        geom = downcast_surface(geom, module)
        inner = getattr(geom, attribute, None)
        if inner is None:
            return geom
        geom = inner()
    return downcast_surface(geom, module)


def _finite_xyz(p, limit: float) -> bool:
    return all(math.isfinite(c) and abs(c) <= limit for c in p.Coord())


def _poles_ok(geom, limit: float) -> bool:
    """The control points (and weights) of a B-spline/Bézier curve or surface."""
    if hasattr(geom, "NbUPoles"):
        nu, nv = geom.NbUPoles(), geom.NbVPoles()
        for i in range(1, nu + 1):
            for j in range(1, nv + 1):
                if not _finite_xyz(geom.Pole(i, j), limit) or not math.isfinite(geom.Weight(i, j)):
                    return False
        return True
    for i in range(1, geom.NbPoles() + 1):
        if not _finite_xyz(geom.Pole(i), limit) or not math.isfinite(geom.Weight(i)):
            return False
    return True


def _has_poles(geom) -> bool:
    return hasattr(geom, "NbUPoles") or hasattr(geom, "NbPoles")


def _surface_ok(surf, bounds, limit: float) -> bool:
    surf = _basis(surf, G, "BasisSurface")
    if _has_poles(surf):
        return _poles_ok(surf, limit)
    # a swept surface (revolution, extrusion) carries the numbers of its profile curve
    profile = getattr(surf, "BasisCurve", None)
    if profile is not None:
        curve = _basis(profile(), G, "BasisCurve")
        if _has_poles(curve) and not _poles_ok(curve, limit):
            return False
    u0, u1, v0, v1 = bounds
    if not all(math.isfinite(b) for b in bounds):
        return False
    return all(
        _finite_xyz(surf.Value(u0 + a * (u1 - u0), v0 + b * (v1 - v0)), limit) for a in _FRACTIONS for b in _FRACTIONS
    )


def _curve_ok(curve, t0: float, t1: float, limit: float, module) -> bool:
    curve = _basis(curve, module, "BasisCurve")
    if _has_poles(curve):
        return _poles_ok(curve, limit)
    if not (math.isfinite(t0) and math.isfinite(t1)):
        return False
    return all(_finite_xyz(curve.Value(t0 + a * (t1 - t0)), limit) for a in _FRACTIONS)


def first_non_finite(shape, limit: float) -> str | None:
    """``None`` when every number is finite and within ``limit``, else what is not
    (``"face 3"``, ``"edge 12"``, ``"p-curve of edge 4 on face 2"``)."""
    for fi, face in enumerate(map(TopoDS.Face, explore(shape, TopAbs_FACE)), 1):
        surf = BRep_Tool.Surface_s(face)
        if surf is not None and not _surface_ok(surf, BRepTools.UVBounds_s(face), limit):
            return f"face {fi}"
        for ei, edge in enumerate(map(TopoDS.Edge, explore(face, TopAbs_EDGE)), 1):
            pcurve, t0, t1 = BRep_Tool.CurveOnSurface_s(edge, face, 0.0, 0.0), *BRep_Tool.Range_s(edge)
            if pcurve is not None and not _curve_ok(pcurve, t0, t1, math.inf, G2):
                return f"p-curve of edge {ei} on face {fi}"
    for ei, edge in enumerate(map(TopoDS.Edge, explore(shape, TopAbs_EDGE)), 1):
        curve = None if BRep_Tool.Degenerated_s(edge) else BRep_Tool.Curve_s(edge, 0.0, 0.0)
        if curve is not None and not _curve_ok(curve, *BRep_Tool.Range_s(edge), limit, G):
            return f"edge {ei}"
    return None


def check_numbers(shape, path, max_coordinate: float) -> None:
    """Raise ``SurfmodError`` naming ``path`` when ``shape`` holds no geometry, or NaN,
    infinite or out-of-range numbers (beyond ``max_coordinate``): its bounding box first,
    then every number (:func:`first_non_finite`)."""
    with kernel("BRepBndLib"):
        box = Bnd_Box()
        BRepBndLib.Add_s(shape, box, False)  # from the geometry, not a triangulation
        if box.IsVoid():
            raise SurfmodError(f"path: {path} contains no geometry")
        corners = box_limits(box)
    if not all(math.isfinite(c) for c in corners):
        raise SurfmodError(f"path: {path} has NaN or infinite coordinates")
    size = max(abs(c) for c in corners)
    if size > max_coordinate:
        raise SurfmodError(
            f"path: {path} has coordinates up to {size:.3g}, beyond the limit {max_coordinate:.3g} "
            "(max_coordinate=)"
        )
    # the box is built from edges and bounds: a control point of inf inside a face is
    # not in it, and evaluating that span later crashes OCCT
    with kernel("geometry check"):
        where = first_non_finite(shape, max_coordinate)
    if where is not None:
        raise SurfmodError(
            f"path: {path} has NaN, infinite or out-of-range numbers in the geometry of {where} "
            f"(limit {max_coordinate:.3g}, max_coordinate=)"
        )
