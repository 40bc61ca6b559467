"""OCCT ``Geom_*`` surfaces and curves read into surfmod objects in OCCT's own parametrization.

:func:`read_surface` dispatches on the OCCT type name: ``Geom_Plane``,
``Geom_CylindricalSurface``, ``Geom_ConicalSurface``, ``Geom_SphericalSurface``,
``Geom_ToroidalSurface`` (domain = the given bounds), ``Geom_BSplineSurface`` and
``Geom_BezierSurface`` (their whole knot range: no re-knotting, so evaluation is exactly
OCCT's), ``Geom_SurfaceOfRevolution`` and ``Geom_SurfaceOfLinearExtrusion`` (basis curves
read natively: lines, conics, B-splines, Béziers), ``Geom_RectangularTrimmedSurface``
(unwrapped) and ``Geom_OffsetSurface``.  The surface a reader returns is the *untrimmed*
surface; :class:`surfmod.readback.trimmed.TrimmedFace` adds the face's bounds and boundary.
"""

from __future__ import annotations

import numpy as np

from ..construct.conics import Conic, Hyperbola, Parabola
from ..construct.curves import Line
from ..construct.elementary import PlaneSurface, ConicalSurface, CylindricalSurface, SphericalSurface, ToroidalSurface
from ..construct.extrusion import TabulatedCylinder
from ..construct.offset_surface import OffsetSurface
from ..construct.revolution import RevolutionSurface
from ..errors import SurfmodError
from ..nets.bezier import BezierCurve, BezierSurface
from ..nets.bspline import BSplineCurve, BSplineSurface

# OCCT type name -> reader(downcast geom, (u0, u1, v0, v1)) -> Surface
READERS: dict = {}


def reader(*type_names):
    """Register a reader for the named OCCT surface types."""

    def register(fn):
        for name in type_names:
            READERS[name] = fn
        return fn

    return register


def read_surface(geom, bounds):
    """The untrimmed surfmod surface of an OCCT ``Geom_Surface`` handle; ``bounds``
    ``(u0, u1, v0, v1)`` give the domain of surfaces that have no natural one
    (planes, cylinders, cones, swept lines).

    >>> import surfmod as sm
    >>> s = read_surface(sm.sphere(2.0).geom(), (0.0, 1.0, 0.0, 0.5))
    >>> type(s).__name__, s.domain
    ('SphericalSurface', ((0.0, 1.0), (0.0, 0.5)))
    """
    from ..occ.geom import downcast_surface, surface_type

    name = surface_type(geom)
    read = READERS.get(name)
    if read is None:
        raise SurfmodError(f"face: unsupported OCCT surface type {name}")
    return read(downcast_surface(geom), tuple(float(b) for b in bounds))


def parameter_space(geom) -> tuple:
    """``(periodic, period, range)`` of an OCCT ``Geom_Surface`` as OCCT evaluates it:
    per direction whether it is periodic, its period (0 if not) and the parameter range
    ``((u0, u1), (v0, v1))`` of ``Bounds`` (infinite directions as OCCT's 2e100).

    >>> import surfmod as sm
    >>> periodic, period, _ = parameter_space(sm.sphere(1.0).geom())
    >>> periodic, round(period[0], 12)
    ((True, False), 6.28318530718)
    """
    u0, u1, v0, v1 = (float(b) for b in geom.Bounds())
    periodic = bool(geom.IsUPeriodic()), bool(geom.IsVPeriodic())
    period = (float(geom.UPeriod()) if periodic[0] else 0.0, float(geom.VPeriod()) if periodic[1] else 0.0)
    return periodic, period, ((u0, u1), (v0, v1))


def read_curve(curve, t_range):
    """A surfmod curve in OCCT's own parametrization of ``curve`` (a ``Geom_Curve``):
    lines and conics over ``t_range``, B-splines and Béziers over their whole knot range
    (evaluation outside it continues the end span, as OCCT does).

    >>> import surfmod as sm
    >>> c = read_curve(sm.Circle((0, 0, 0), (0, 0, 1), 2.0).geom(), (0.0, 1.0))
    >>> type(c).__name__, c.domain
    ('Arc', (0.0, 1.0))
    """
    from ..occ.analytic import read_curve as occ_read_curve

    t0, t1 = (float(t) for t in t_range)
    d = occ_read_curve(curve)
    kind = d["kind"]
    if kind == "line":
        return Line.through(d["origin"], d["direction"], (t0, t1))
    if kind in ("circle", "ellipse"):
        o, x, _, z = d["frame"]
        a, b = (d["radius"], d["radius"]) if kind == "circle" else (d["major"], d["minor"])
        return Conic._from_radians(o, z, x, a, b, (t0, t1))
    if kind == "parabola":
        o, x, _, z = d["frame"]
        return Parabola._make(o, z, x, (d["focal"],), (t0, t1))
    if kind == "hyperbola":
        o, x, _, z = d["frame"]
        return Hyperbola._make(o, z, x, (d["major"], d["minor"]), (t0, t1))
    if kind == "bspline":
        return BSplineCurve(d["points"], d["degree"], d["knots"], d["weights"])
    return BezierCurve(d["points"], d["weights"])


@reader("Geom_BSplineSurface")
def _bspline(surf, bounds):
    from ..occ.geom import read_bspline_surface

    data = read_bspline_surface(surf)
    net = np.asarray(data["control_points"], float)
    if np.isfinite(net).all():
        # OCCT's Geom_BSplineSurface has validated its knots, multiplicities and weights;
        # only the poles of a damaged file can be non-finite (refused below, named)
        return BSplineSurface._trusted(net, data["degree"], data["knots"], data["weights"])
    return BSplineSurface(net, data["degree"], data["knots"], data["weights"])


@reader("Geom_BezierSurface")
def _bezier(surf, bounds):
    from ..occ.geom import read_bezier_surface

    data = read_bezier_surface(surf)
    return BezierSurface(data["control_points"], data["weights"])


def _elementary(cls, params):
    def read(surf, bounds):
        from ..occ.analytic import read_elementary

        data = read_elementary(surf)
        u0, u1, v0, v1 = bounds
        return cls._trusted(data["frame"], params(data), (u0, u1), (v0, v1))

    return read


reader("Geom_Plane")(_elementary(PlaneSurface, lambda d: ()))
reader("Geom_CylindricalSurface")(_elementary(CylindricalSurface, lambda d: (d["radius"],)))
reader("Geom_ConicalSurface")(_elementary(ConicalSurface, lambda d: (d["radius"], d["semi_angle"])))
reader("Geom_SphericalSurface")(_elementary(SphericalSurface, lambda d: (d["radius"],)))
reader("Geom_ToroidalSurface")(_elementary(ToroidalSurface, lambda d: (d["major"], d["minor"])))


@reader("Geom_SurfaceOfRevolution")
def _revolution(surf, bounds):
    from ..occ.analytic import read_revolution

    data = read_revolution(surf)
    u0, u1, v0, v1 = bounds
    return RevolutionSurface._trusted(read_curve(data["basis"], (v0, v1)), data["origin"], data["direction"], (u0, u1))


@reader("Geom_SurfaceOfLinearExtrusion")
def _extrusion(surf, bounds):
    from ..occ.analytic import read_extrusion

    data = read_extrusion(surf)
    u0, u1, v0, v1 = bounds
    return TabulatedCylinder._trusted(read_curve(data["basis"], (u0, u1)), data["direction"], (v0, v1))


@reader("Geom_RectangularTrimmedSurface")
def _trimmed(surf, bounds):
    from ..occ.analytic import read_trimmed_surface

    # a rectangular trim only restricts where OCCT evaluates its basis: the face's own
    # bounds say where the face lives, so the basis is read as it is
    return read_surface(read_trimmed_surface(surf)["basis"], bounds)


@reader("Geom_OffsetSurface")
def _offset(surf, bounds):
    from ..occ.analytic import read_offset

    data = read_offset(surf)
    return OffsetSurface(read_surface(data["basis"], bounds), data["distance"])
