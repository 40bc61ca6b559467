"""Tabulated cylinder: Geom_SurfaceOfLinearExtrusion and the prism face."""

from __future__ import annotations

import math

import numpy as np
import pytest

import surfmod as sm
from twins.transformed import transformed as occ_transformed
from surfmod.occ.sample import surface_d0, surface_d2
from surfmod.transforms import mirror_matrix, rotation_matrix, scale_matrix


def _grid(domain, n=9, m=5):
    (u0, u1), (v0, v1) = domain
    uu, vv = np.meshgrid(np.linspace(u0, u1, n), np.linspace(v0, v1, m), indexing="ij")
    return uu.ravel(), vv.ravel()


SPLINE = sm.BSplineCurve([(0, 0, 0), (1, 2, 0), (3, -1, 0), (4, 1, 0)], 3, [0, 0, 0, 0, 2, 2, 2, 2])


@pytest.mark.parametrize(
    "curve",
    [SPLINE, sm.Circle((1, 1, 0), (0, 0, 1), 2.0), sm.Arc((0, 0, 0), (0, 0, 1), 1.0, 30, 200), sm.Line((0, 0, 0), (2, 1, 0))],
)
def test_closed_form_and_occt(curve):
    d = np.array([0.0, 1.0, 2.0])
    s = sm.tabulated_cylinder(curve, d, 3.0)
    assert s.domain == (curve.domain, (0.0, 3.0))
    uu, vv = _grid(s.domain)
    unit = d / np.linalg.norm(d)
    np.testing.assert_allclose(s.points(uu, vv), curve.points(uu) + vv[:, None] * unit, atol=1e-14)
    r = sm.crosscheck(s, samples=16)
    assert r.passed and r.max_deviation < 1e-13, r.details
    occ = surface_d2(s.geom(), uu, vv)
    np.testing.assert_allclose(s.derivatives(uu, vv, 2)[:, [0, 1, 0, 2, 0, 1], [0, 0, 1, 0, 2, 1]],
                               occ[:, [0, 1, 0, 2, 0, 1], [0, 0, 1, 0, 2, 1]], atol=1e-13)


def test_cylinder_area_and_nurbs_form():
    s = sm.tabulated_cylinder(sm.Circle((0, 0, 0), (0, 0, 1), 2.0), (0, 0, 1), 5.0)
    assert s.face().area == pytest.approx(2 * math.pi * 2.0 * 5.0, rel=1e-9)
    n = s.to_nurbs()
    assert sm.crosscheck(n, samples=16).passed
    p = n.grid(np.linspace(*n.domain[0], 50), np.linspace(0, 5, 5))
    np.testing.assert_allclose(np.hypot(p[..., 0], p[..., 1]), 2.0, rtol=1e-14)
    np.testing.assert_allclose(n.points(0.0, 5.0), s.points(0.0, 5.0), atol=1e-14)


def test_same_parametrization_as_the_build123d_prism_face():
    import build123d as bd

    edge = bd.Edge.make_spline([(0, 0, 0), (1, 2, 0), (3, -1, 0), (4, 1, 0)])
    face = bd.Face.extrude(edge, bd.Vector(0, 0.6, 0.8) * 2.5)  # BRepPrimAPI_MakePrism
    back = sm.from_face(face)
    assert isinstance(back.surface, sm.TabulatedCylinder)
    # BRepSweep stores the prism surface with the reversed direction and v in [-L, 0]
    np.testing.assert_allclose(back.direction, (0, -0.6, -0.8), atol=1e-15)
    assert back.v_range == pytest.approx((-2.5, 0.0))
    s = sm.tabulated_cylinder(edge, (0, 0.6, 0.8), 2.5)
    assert s.domain[0] == pytest.approx(back.domain[0], abs=1e-12)
    uu, vv = _grid(s.domain)
    np.testing.assert_allclose(s.points(uu, vv), surface_d0(back.geom(), uu, -vv), atol=1e-12)
    assert sm.crosscheck(face).passed


@pytest.mark.parametrize(
    "m",
    [rotation_matrix((1, 2, 3), (1, 1, 0), 37), mirror_matrix((1, 0, 0), (1, 2, 3)), scale_matrix(-2.0, (1, 0, 0))],
)
def test_similarity_transforms_match_gp_trsf(m):
    s = sm.tabulated_cylinder(sm.Arc((0, 0, 0), (0, 0, 1), 1.0, 30, 200), (0, 1, 1), 3.0)
    t = s.transformed(m)
    assert isinstance(t, sm.TabulatedCylinder)
    uu, vv = _grid(t.domain)
    np.testing.assert_allclose(t.points(uu, vv), surface_d0(occ_transformed(s.geom(), m), uu, vv), atol=1e-13)


def test_non_uniform_scale_goes_through_the_bspline_form():
    s = sm.tabulated_cylinder(SPLINE, (0, 0, 1), 2.0)
    t = s.scaled((1.0, 2.0, 3.0))
    assert isinstance(t, sm.BSplineSurface)
    uu, vv = _grid(s.domain)
    np.testing.assert_allclose(t.points(uu, vv), s.points(uu, vv) * (1, 2, 3), atol=1e-13)


@pytest.mark.parametrize(
    "call, name",
    [
        (lambda: sm.tabulated_cylinder(sm.BSplineCurve([(0, 0, 0), (1, 0, 0), (1, 1, 0), (1, 1, 1)], 3), (0, 0, 1), 1.0), "curve"),
        (lambda: sm.tabulated_cylinder(SPLINE, (0, 0, 0), 1.0), "direction"),
        (lambda: sm.tabulated_cylinder(SPLINE, (1, 1, 0), 1.0), "direction"),
        (lambda: sm.tabulated_cylinder(sm.Line((0, 0, 0), (1, 0, 0)), (2, 0, 0), 1.0), "direction"),
        (lambda: sm.tabulated_cylinder(SPLINE, (0, 0, 1), 0.0), "length"),
        (lambda: sm.tabulated_cylinder(SPLINE, (0, 0, 1), -1.0), "length"),
        (lambda: sm.tabulated_cylinder([1, 2, 3], (0, 0, 1), 1.0), "curve"),
    ],
)
def test_bad_input(call, name):
    with pytest.raises(sm.SurfmodError, match=name):
        call()


def test_grid_fast_path_equals_scattered_evaluation():
    s = sm.tabulated_cylinder(SPLINE, (0, 1, 2), 3.0)
    us, vs = np.linspace(0, 2, 7), np.linspace(0, 3, 5)
    uu, vv = np.meshgrid(us, vs, indexing="ij")
    np.testing.assert_allclose(s.grid_derivatives(us, vs, 2), s.derivatives(uu, vv, 2), atol=1e-14)
