"""Read OCCT / build123d faces and edges back into surfmod objects.

``from_face`` dispatches on the OCCT surface type of the face; the result is restricted
to the face's parameter bounds (same parametrization as OCCT), so
``crosscheck(from_face(f))`` compares like with like.
"""

from __future__ import annotations

from ..errors import SurfmodError

# OCCT type name -> reader(geom_surface, (u0, u1, v0, v1)) -> Surface
READERS: dict = {}


def reader(*type_names):
    """Register a reader for the named OCCT surface types."""

    def register(fn):
        for name in type_names:
            READERS[name] = fn
        return fn

    return register


def _restricted(surface, bounds):
    (du0, du1), (dv0, dv1) = surface.domain
    u0, u1, v0, v1 = bounds
    tol = 1e-9 * max(1.0, du1 - du0, dv1 - dv0)
    if abs(u0 - du0) <= tol and abs(u1 - du1) <= tol and abs(v0 - dv0) <= tol and abs(v1 - dv1) <= tol:
        return surface
    u0, u1 = max(u0, du0), min(u1, du1)
    v0, v1 = max(v0, dv0), min(v1, dv1)
    return surface.segment((u0, u1), (v0, v1))


@reader("Geom_BSplineSurface")
def _bspline(surf, bounds):
    from ..nets.bspline import BSplineSurface
    from ..occ.geom import read_bspline_surface

    data = read_bspline_surface(surf)
    s = BSplineSurface(data["control_points"], data["degree"], data["knots"], data["weights"])
    return _restricted(s, bounds)


@reader("Geom_BezierSurface")
def _bezier(surf, bounds):
    from ..nets.bezier import BezierSurface
    from ..occ.geom import read_bezier_surface

    data = read_bezier_surface(surf)
    return _restricted(BezierSurface(data["control_points"], data["weights"]), bounds)


def from_face(face):
    """A surfmod surface for a build123d ``Face`` or an OCP ``TopoDS_Face``.

    >>> import surfmod as sm, numpy as np
    >>> net = np.zeros((3, 3, 3)); net[..., 0], net[..., 1] = np.mgrid[0:3, 0:3]
    >>> s = sm.from_face(sm.BezierSurface(net).face())
    >>> type(s).__name__
    'BezierSurface'
    """
    from ..occ.geom import downcast_surface, surface_type
    from ..occ.topo import face_surface

    surf, bounds, _reversed = face_surface(face)
    name = surface_type(surf)
    read = READERS.get(name)
    if read is None:
        raise SurfmodError(f"face: unsupported OCCT surface type {name}")
    return read(downcast_surface(surf), tuple(float(b) for b in bounds))


def from_edge(edge):
    """A surfmod curve for a build123d ``Edge``/``Wire`` or OCP edge (exact B-spline form
    of the edge's 3-D curve over its parameter range).

    >>> import surfmod as sm, build123d as bd
    >>> c = sm.from_edge(bd.Edge.make_line((0, 0, 0), (3, 4, 0)))
    >>> c.points(c.domain[1])
    array([3., 4., 0.])
    """
    from ..nets.bspline import BSplineCurve
    from ..occ.geom import read_bspline_curve
    from ..occ.topo import shape_bspline

    data = read_bspline_curve(shape_bspline(edge))
    return BSplineCurve(data["points"], data["degree"], data["knots"], data["weights"])


def as_curve(value, name: str):
    """Accept a surfmod curve or a build123d Edge/Wire wherever a curve is taken."""
    from ..curve import Curve

    if isinstance(value, Curve):
        return value
    if hasattr(value, "wrapped") or type(value).__name__.startswith("TopoDS"):
        try:
            return from_edge(value)
        except SurfmodError as exc:
            raise SurfmodError(f"{name}: {exc}") from None
    raise SurfmodError(f"{name}: expected a surfmod curve or a build123d Edge/Wire, got {type(value).__name__}")


from . import readers_elementary  # noqa: E402,F401  (registers the analytic surface readers)
