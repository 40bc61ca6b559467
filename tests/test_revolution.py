"""Surface of revolution: Geom_SurfaceOfRevolution's parametrization, exact NURBS form,
closed forms (cone, torus)."""

from __future__ import annotations

import math

import numpy as np
import pytest

import surfmod as sm
from reference import surface_area as area
from twins.transformed import transformed as occ_transformed
from surfmod.occ.sample import surface_d0
from surfmod.transforms import mirror_matrix, rotation_matrix, scale_matrix


def _grid(domain, n=9, m=7):
    (u0, u1), (v0, v1) = domain
    uu, vv = np.meshgrid(np.linspace(u0, u1, n), np.linspace(v0, v1, m), indexing="ij")
    return uu.ravel(), vv.ravel()


def test_revolved_line_is_a_cone():
    r1, r2, h = 1.0, 2.5, 3.0
    s = sm.revolution(sm.Line((r1, 0, 0), (r2, 0, h)), (0, 0, 0), (0, 0, 1))
    assert s.domain[0] == pytest.approx((0.0, 2 * math.pi))
    uu, vv = _grid(s.domain)
    slant = math.hypot(r2 - r1, h)
    rho = r1 + (r2 - r1) * vv / slant
    expected = np.stack([rho * np.cos(uu), rho * np.sin(uu), h * vv / slant], axis=1)
    np.testing.assert_allclose(s.points(uu, vv), expected, atol=1e-14)
    assert area(s) == pytest.approx(math.pi * (r1 + r2) * slant, rel=1e-13)
    r = sm.crosscheck(s, samples=16)
    assert r.passed and r.max_deviation < 1e-13
    # and it is OCCT's cone on the same frame (semi-angle measured from the axis)
    cone = sm.ConicalSurface(math.atan2(r2 - r1, h), r1, v_range=(0, slant))
    np.testing.assert_allclose(cone.points(uu, vv), expected, atol=1e-14)


def test_revolved_circle_is_a_torus_with_area_4pi2Rr():
    big, small = 3.0, 1.0
    s = sm.revolution(sm.Circle((big, 0, 0), (0, 1, 0), small), (0, 0, 0), (0, 0, 1))
    assert area(s) == pytest.approx(4 * math.pi**2 * big * small, rel=1e-13)
    torus = sm.torus(big, small)
    uu, vv = _grid(s.domain, 21, 21)
    np.testing.assert_allclose(torus.implicit(s.points(uu, vv)), 0.0, atol=1e-12)
    nurbs = s.to_nurbs()
    assert nurbs.degree == (2, 2) and nurbs.rational
    np.testing.assert_allclose(torus.implicit(nurbs.points(*_grid(nurbs.domain, 41, 41))), 0.0, atol=1e-12)
    assert area(nurbs) == pytest.approx(4 * math.pi**2 * big * small, rel=1e-12)
    assert sm.crosscheck(nurbs, samples=16).passed


def test_matches_geom_surface_of_revolution_for_a_spline_profile():
    prof = sm.BSplineCurve([(1, 0, 0), (2, 0, 1), (1.5, 0, 2), (2.5, 0, 3)], 3)
    s = sm.revolution(prof, (0, 0, 0), (0, 0, 1), angle=250)
    assert s.domain == ((0.0, math.radians(250)), (0.0, 1.0))
    r = sm.crosscheck(s, samples=16)
    assert r.passed and r.max_deviation < 1e-13, r.details
    # NURBS form: same surface as a set (points stay at the profile's radius/height)
    n = s.to_nurbs()
    uu, vv = _grid(n.domain)
    p = n.points(uu, vv)
    q = prof.points(vv)
    np.testing.assert_allclose(np.hypot(p[:, 0], p[:, 1]), np.hypot(q[:, 0], q[:, 1]), atol=1e-14)
    np.testing.assert_allclose(p[:, 2], q[:, 2], atol=1e-14)


def test_same_parametrization_as_build123d_revolve():
    import build123d as bd

    edge = bd.Edge.make_spline([(1, 0, 0), (2, 0, 1), (1.5, 0, 2), (2.5, 0, 3)])
    face = bd.Face.revolve(edge, 200, bd.Axis.Z)  # BRepPrimAPI_MakeRevol
    back = sm.from_face(face)
    assert isinstance(back.surface, sm.RevolutionSurface)
    s = sm.revolution(edge, (0, 0, 0), (0, 0, 1), 200)
    uu, vv = _grid(s.domain)
    np.testing.assert_allclose(s.points(uu, vv), surface_d0(back.geom(), uu, vv), atol=1e-12)
    assert sm.crosscheck(face).passed


def test_sphere_from_a_half_circle_touching_the_axis():
    arc = sm.Arc((0, 0, 0), (0, -1, 0), 2.0, -90, 90, x_dir=(1, 0, 0))
    s = sm.revolution(arc, (0, 0, 0), (0, 0, 1))
    uu, vv = _grid(s.domain)
    np.testing.assert_allclose(np.linalg.norm(s.points(uu, vv), axis=1), 2.0, rtol=1e-15)
    # the arc's parameter starts at -90 degrees brought into [0, 360): 270 degrees
    assert s.domain[1] == pytest.approx((1.5 * math.pi, 2.5 * math.pi))
    np.testing.assert_allclose(s.points(uu, vv), sm.sphere(2.0).points(uu, vv - 2 * math.pi), atol=1e-14)
    assert area(s) == pytest.approx(4 * math.pi * 4.0, rel=1e-13)


@pytest.mark.parametrize(
    "m",
    [rotation_matrix((1, 2, 3), (1, 1, 0), 37), mirror_matrix((1, 0, 0), (1, 2, 3)), scale_matrix(-2.0, (1, 0, 0))],
    ids=["rigid", "mirror", "point_mirror"],
)
def test_similarity_transforms_match_gp_trsf(m):
    s = sm.revolution(sm.BSplineCurve([(1, 0, 0), (2, 0, 1), (1.5, 0, 2)], 2), (0, 0, 0), (0, 0, 1), 200)
    t = s.transformed(m)
    assert isinstance(t, sm.RevolutionSurface)
    uu, vv = _grid(t.domain)
    np.testing.assert_allclose(t.points(uu, vv), surface_d0(occ_transformed(s.geom(), m), uu, vv), atol=1e-13)
    np.testing.assert_allclose(t.points(uu, vv), s.points(uu, vv) @ m[:3, :3].T + m[:3, 3], atol=1e-13)


def test_non_uniform_scale_maps_the_nurbs_form():
    s = sm.revolution(sm.Circle((3, 0, 0), (0, 1, 0), 1.0), (0, 0, 0), (0, 0, 1))
    t = s.scaled((1.0, 2.0, 1.0))
    assert isinstance(t, sm.BSplineSurface)
    p = t.points(*_grid(t.domain, 21, 21)) / (1.0, 2.0, 1.0)
    np.testing.assert_allclose(sm.torus(3.0, 1.0).implicit(p), 0.0, atol=1e-12)


SPLINE_XZ = sm.BSplineCurve([(1, 0, 0), (2, 0, 1), (1.5, 0, 2)], 2)


@pytest.mark.parametrize(
    "call, name",
    [
        (lambda: sm.revolution(sm.Line((-1, 0, 0), (1, 0, 1)), (0, 0, 0), (0, 0, 1)), "profile"),
        (lambda: sm.revolution(sm.BSplineCurve([(1, 0, 0), (2, 1, 1), (1, 0, 2)], 2), (0, 0, 0), (0, 0, 1)), "profile"),
        (lambda: sm.revolution(sm.Line((1, 0, 0), (1, 1, 1)), (0, 0, 0), (0, 0, 1)), "profile"),
        (lambda: sm.revolution(sm.Line((0, 0, 0), (0, 0, 1)), (0, 0, 0), (0, 0, 1)), "profile"),
        (lambda: sm.revolution(SPLINE_XZ, (0, 0, 0), (0, 0, 0)), "axis_direction"),
        (lambda: sm.revolution(SPLINE_XZ, (0, 0, np.inf), (0, 0, 1)), "axis_origin"),
        (lambda: sm.revolution(SPLINE_XZ, (0, 0, 0), (0, 0, 1), angle=0), "angle"),
        (lambda: sm.revolution(SPLINE_XZ, (0, 0, 0), (0, 0, 1), angle=400), "angle"),
        (lambda: sm.revolution(42, (0, 0, 0), (0, 0, 1)), "profile"),
    ],
    ids=["crosses_axis", "non_planar", "skew_to_axis", "on_axis", "zero_axis", "inf_origin", "zero_angle", "big_angle", "not_a_curve"],
)
def test_bad_input(call, name):
    with pytest.raises(sm.SurfmodError, match=name):
        call()


def test_grid_fast_path_equals_scattered_evaluation():
    s = sm.revolution(sm.BSplineCurve([(1, 0, 0), (2, 0, 1), (1.5, 0, 2)], 2), (0, 0, 0), (0, 0, 1), 200)
    (u0, u1), (v0, v1) = s.domain
    us, vs = np.linspace(u0, u1, 7), np.linspace(v0, v1, 5)
    uu, vv = np.meshgrid(us, vs, indexing="ij")
    np.testing.assert_allclose(s.grid_derivatives(us, vs, 2), s.derivatives(uu, vv, 2), atol=1e-14)
