"""OCCT's planes, spheres, cylinders, cones and tori read as the ``(kind, frame, sizes)``
that the closed-form distances of :mod:`surfmod.construct.elementary_closest` take, also
where a surface of revolution is one of those (a circle or line in a plane through the
axis)."""

from __future__ import annotations

import numpy as np

from ..construct.conics import Conic
from ..construct.curves import Line
from ..construct.elementary import ConicalSurface, CylindricalSurface, PlaneSurface, SphericalSurface, ToroidalSurface
from ..construct.elementary_closest import CONE, CYLINDER, PLANE, SPHERE, TORUS
from ..construct.revolution import RevolutionSurface
from ..errors import SurfmodError
from ..readback.readers import read_surface

_KINDS = {PlaneSurface: PLANE, SphericalSurface: SPHERE, CylindricalSurface: CYLINDER, ConicalSurface: CONE,
          ToroidalSurface: TORUS}
#: OCCT surface types :func:`parameters` reads (the others are none of the kinds).
_READ = ("Geom_Plane", "Geom_SphericalSurface", "Geom_CylindricalSurface", "Geom_ConicalSurface",
         "Geom_ToroidalSurface", "Geom_SurfaceOfRevolution")


def parameters(surf) -> tuple | None:
    """``(kind, frame (2, 3), sizes (2,))`` of an OCCT plane, sphere, cylinder, cone or
    torus as :func:`~surfmod.construct.elementary_closest.distances` takes them (also of a
    surface of revolution that is one of those, see :func:`revolved`), ``None`` for any
    other surface: read from the surfmod surface :func:`surfmod.readback.read_surface`
    gives.

    >>> import build123d as bd
    >>> from surfmod.occ.topo import face_surface
    >>> kind, frame, sizes = parameters(face_surface(bd.Face.make_rect(2, 3))[0])
    >>> kind == PLANE, sizes
    (True, (0.0, 0.0))
    """
    from ..occ.geom import surface_type

    if surface_type(surf) not in _READ:
        return None
    try:  # the bounds give no sizes here: any box will do
        s = read_surface(surf, (0.0, 1.0, 0.0, 1.0))
    except SurfmodError:  # a revolved curve the reader does not know
        return None
    if isinstance(s, RevolutionSurface):  # of a circle or line in a plane through the axis
        return revolved(s.axis_origin, s.axis_direction, s.profile)
    kind = _KINDS[type(s)]
    sizes = (0.0, 0.0) if kind == PLANE else (s.major, s.minor) if kind == TORUS else \
        (s.radius, s.semi_angle) if kind == CONE else (s.radius, 0.0)
    return kind, (s.origin, s.z_dir), sizes


def revolved(origin, axis, curve, rtol: float = 1e-12):
    """``(kind, frame, sizes)`` of the surface a circle or line sweeps about the axis
    ``(origin, unit axis)`` when it lies in a plane through the axis (to ``rtol`` of its
    size): a torus (a sphere when the circle's centre is on the axis), a cone, a
    cylinder or a plane, the same point sets as OCCT's surface of revolution;
    ``None`` for any other basis curve (``curve``: the surfmod curve
    :func:`surfmod.readback.read_curve` gives).

    >>> import numpy as np, surfmod as sm
    >>> circle = sm.Circle((3, 0, 1), (0, -1, 0), 0.5)
    >>> kind, frame, sizes = revolved(np.zeros(3), np.array([0, 0, 1.0]), circle)
    >>> kind == TORUS, frame[0].tolist(), sizes
    (True, [0.0, 0.0, 1.0], (3.0, 0.5))
    """
    origin, axis = np.asarray(origin, float), np.asarray(axis, float)
    if isinstance(curve, Conic):
        centre, x, y, a, b = curve.center, curve.x_dir, curve.y_dir, curve.a, curve.b
        if a != b:
            return None  # an ellipse
        normal = np.cross(x, y)
        offset = centre - origin
        scale = 1.0 + np.linalg.norm(offset) + a
        if abs(normal @ axis) > rtol or abs(offset @ normal) > rtol * scale:
            return None
        foot = origin + (offset @ axis) * axis
        big = float(np.linalg.norm(centre - foot))
        if big <= rtol * scale:
            return SPHERE, (foot, axis), (float(a), 0.0)
        return TORUS, (foot, axis), (big, float(a))
    if isinstance(curve, Line):
        point, direction = np.asarray(curve.origin, float), np.asarray(curve.direction, float)
        offset = point - origin
        scale = 1.0 + np.linalg.norm(offset)
        if abs(offset @ np.cross(axis, direction)) > rtol * scale:
            return None  # skew to the axis: a hyperboloid
        along = direction @ axis
        if along < 0:
            direction, along = -direction, -along
        foot = origin + (offset @ axis) * axis
        radial = point - foot
        r0 = float(np.linalg.norm(radial))
        outward = direction @ (radial / r0) if r0 > rtol * scale else float(np.linalg.norm(direction - along * axis))
        if along <= rtol:
            return PLANE, (foot, axis), (0.0, 0.0)  # a line across the axis sweeps a plane
        if abs(outward) <= rtol:
            return CYLINDER, (foot, axis), (r0, 0.0)
        return CONE, (foot, axis), (r0, float(np.arctan2(outward, along)))
    return None
