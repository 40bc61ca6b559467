"""Gallery entries for the analytic and swept-analytic surfaces (issue 4): ruled surface,
tabulated cylinder, surface of revolution (and its NURBS form), sphere, ellipsoid, torus,
offset surface."""

from __future__ import annotations

import math

from ..construct.conics import Arc
from ..construct.elementary import ConicalSurface
from ..construct.extrusion import tabulated_cylinder
from ..construct.offset_surface import OffsetSurface
from ..construct.quadrics import ellipsoid, sphere, torus
from ..construct.revolution import revolution
from ..construct.ruled import ruled
from ..nets.bspline import BSplineCurve, BSplineSurface
from . import entry
from .synthetic import wavy_net


@entry("ruled", "ruled surface (1-v)G(u) + vQ(u)", "sm.ruled(g, q)")
def _ruled():
    g = BSplineCurve([(0, 0, 0), (3, 4, 0), (6, -2, 0), (10, 2, 0)], 3)
    q = Arc((5, 2, 6), (0, 0, 1), 4.0, 180, 360)
    return ruled(g, q)


@entry("tabulated_cylinder", "tabulated cylinder", "sm.tabulated_cylinder(curve, direction, length)")
def _tabulated():
    c = BSplineCurve([(0, 0, 0), (3, 4, 0), (6, -2, 0), (10, 2, 0), (12, 0, 0)], 3)
    return tabulated_cylinder(c, (0.2, 0.3, 1.0), 6.0)


@entry("revolution", "surface of revolution", "sm.revolution(profile, origin, axis, 270)")
def _revolution():
    profile = BSplineCurve([(2, 0, 0), (5, 0, 1), (3, 0, 4), (4, 0, 7), (1.5, 0, 9)], 3)
    return revolution(profile, (0, 0, 0), (0, 0, 1), 270)


@entry("revolution_nurbs", "surface of revolution, exact NURBS form", "sm.revolution(...).to_nurbs()")
def _revolution_nurbs():
    return _revolution().to_nurbs()


@entry("sphere", "sphere (quadric)", "sm.sphere(4)")
def _sphere():
    return sphere(4.0, center=(0, 0, 4))


@entry("ellipsoid", "ellipsoid (exact rational B-spline)", "sm.ellipsoid(6, 4, 2.5)")
def _ellipsoid():
    return ellipsoid(6.0, 4.0, 2.5)


@entry("torus", "torus (quadric of revolution)", "sm.torus(6, 1.5)")
def _torus():
    return torus(6.0, 1.5, axis=(0, 1, 1))


@entry("cone", "cone frustum (OCCT frame)", "sm.ConicalSurface(semi_angle, r)")
def _cone():
    return ConicalSurface(math.radians(20), 3.0, v_range=(0.0, 8.0))


@entry("offset", "offset surface S + dN", "sm.OffsetSurface(surface, d)")
def _offset():
    return OffsetSurface(BSplineSurface(wavy_net(6, 5, 0.4), (3, 3)), 1.0)
