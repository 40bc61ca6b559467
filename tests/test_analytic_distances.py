"""Closed-form distances (surfmod.construct.elementary_closest, the surfaces read by
surfmod.meshing.analytic_distance) equal OCCT's projection distance:
planes, spheres, cylinders, cones and tori, and surfaces of revolution of a circle or a
line lying in a plane through the axis (a torus, a sphere, a cone, a cylinder, a plane);
a line skew to the axis (a hyperboloid) and an ellipse get no closed form."""

from __future__ import annotations

import numpy as np
import pytest
from OCP.GC import GC_MakeCircle, GC_MakeEllipse, GC_MakeLine
from OCP.Geom import (
    Geom_ConicalSurface,
    Geom_CylindricalSurface,
    Geom_Plane,
    Geom_SphericalSurface,
    Geom_SurfaceOfRevolution,
    Geom_ToroidalSurface,
)
from OCP.GeomAPI import GeomAPI_ProjectPointOnSurf
from OCP.gp import gp_Ax1, gp_Ax2, gp_Ax3, gp_Dir, gp_Elips, gp_Pnt

from surfmod.construct import elementary_closest as closed
from surfmod.meshing import analytic_distance as analytic

AXIS = gp_Ax1(gp_Pnt(0.5, -1.0, 0.2), gp_Dir(0.2, 0.3, 0.9))


def _occt_distances(surf, points):
    out = []
    for p in points:
        proj = GeomAPI_ProjectPointOnSurf(gp_Pnt(*p), surf)
        out.append(proj.LowerDistance())
    return np.array(out)


def _frame(origin, normal, x=None):
    ax2 = gp_Ax2(gp_Pnt(*origin), gp_Dir(*normal)) if x is None else gp_Ax2(gp_Pnt(*origin), gp_Dir(*normal),
                                                                             gp_Dir(*x))
    return ax2


def _in_axis_plane(radial_offset, height):
    """A point at ``radial_offset`` from AXIS, ``height`` along it, and the plane's normal."""
    o = np.array(AXIS.Location().Coord())
    a = np.array(AXIS.Direction().Coord())
    e = np.cross(a, [1.0, 0, 0])
    e /= np.linalg.norm(e)
    return o + height * a + radial_offset * e, np.cross(a, e)


def _revolutions():
    a = np.array(AXIS.Direction().Coord())
    centre, normal = _in_axis_plane(3.0, 1.0)
    on_axis, _ = _in_axis_plane(0.0, 1.0)
    start, _ = _in_axis_plane(2.0, -1.0)
    tip, _ = _in_axis_plane(1.2, 2.5)
    across, _ = _in_axis_plane(4.0, -1.0)
    skew = start + 0.7 * normal
    return {
        "torus": (GC_MakeCircle(_frame(centre, normal), 0.8).Value(), closed.TORUS),
        "sphere": (GC_MakeCircle(_frame(on_axis, normal), 1.5).Value(), closed.SPHERE),
        "cone": (GC_MakeLine(gp_Pnt(*start), gp_Pnt(*tip)).Value(), closed.CONE),
        "cylinder": (GC_MakeLine(gp_Pnt(*start), gp_Pnt(*(start + 2.0 * a))).Value(), closed.CYLINDER),
        "plane": (GC_MakeLine(gp_Pnt(*start), gp_Pnt(*across)).Value(), closed.PLANE),
        "hyperboloid": (GC_MakeLine(gp_Pnt(*skew), gp_Pnt(*tip)).Value(), None),
        "ellipse": (GC_MakeEllipse(gp_Elips(_frame(centre, normal), 1.0, 0.5)).Value(), None),
    }


def _points(n=200):
    rng = np.random.default_rng(2)
    o = np.array(AXIS.Location().Coord())
    return o + rng.uniform(-5, 5, (n, 3))


@pytest.mark.parametrize("name", list(_revolutions()))
def test_revolved_circles_and_lines_are_their_analytic_surfaces(name):
    curve, kind = _revolutions()[name]
    surf = Geom_SurfaceOfRevolution(curve, AXIS)
    params = analytic.parameters(surf)
    if kind is None:
        assert params is None
        return
    assert params[0] == kind
    pts = _points()
    ours = closed.distances(np.array([params[0]]), np.array([params[1]], float), np.array([params[2]], float),
                            pts, np.zeros(len(pts), int))
    np.testing.assert_allclose(ours, _occt_distances(surf, pts), rtol=0, atol=1e-9)


def test_elementary_surfaces_and_batched_triangles_equal_occt():
    ax3 = gp_Ax3(gp_Pnt(0.3, 0.1, -0.4), gp_Dir(0.1, -0.4, 0.9))
    surfaces = [Geom_Plane(ax3), Geom_SphericalSurface(ax3, 2.0), Geom_CylindricalSurface(ax3, 1.5),
                Geom_ConicalSurface(ax3, 0.4, 1.0), Geom_ToroidalSurface(ax3, 3.0, 1.0)]
    pts = _points(120)
    params = [analytic.parameters(s) for s in surfaces]
    kinds = np.array([p[0] for p in params])
    frames = np.array([p[1] for p in params], float)
    sizes = np.array([p[2] for p in params], float)
    for f, surf in enumerate(surfaces):
        ours = closed.distances(kinds, frames, sizes, pts, np.full(len(pts), f))
        np.testing.assert_allclose(ours, _occt_distances(surf, pts), rtol=0, atol=1e-9)
    # triangles: the max over their samples, each sample's distance as above
    tri = np.arange(len(pts)).reshape(-1, 3)
    bary = np.array([[0.2, 0.3, 0.5], [0.6, 0.2, 0.2], [1 / 3, 1 / 3, 1 / 3]])
    faces = np.array([[f, 8 * f, 8 * f + 8] for f in range(5)])
    got = closed.triangle_distances(kinds, frames, sizes, pts, tri, faces, bary)
    for f in range(5):
        samples = np.einsum("kj,tjd->tkd", bary, pts[tri[8 * f:8 * f + 8]]).reshape(-1, 3)
        expect = closed.distances(kinds, frames, sizes, samples, np.full(len(samples), f))
        np.testing.assert_allclose(got[8 * f:8 * f + 8], expect.reshape(8, 3).max(axis=1), rtol=1e-13, atol=1e-13)
