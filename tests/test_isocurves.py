"""Iso-curves: exact B-spline iso-curves, surface-evaluated iso-curves for other surfaces,
both equal to OCCT's UIso/VIso; polylines; bad input."""

from __future__ import annotations

import numpy as np
import pytest

import surfmod as sm
from surfmod.gallery.synthetic import wavy_net
from surfmod.occ.sample import sample_curve
from surfmod.occ.geom import iso_curve


def _nurbs():
    w = np.ones((6, 6))
    w[2:4, 2:4] = 4.0
    w[0, :] = 0.5
    return sm.BSplineSurface(wavy_net(6, 6), (3, 3), weights=w)


def test_bspline_isocurves_are_exact_and_match_occt():
    s = _nurbs()
    iso = sm.isocurves(s, 5, 4)
    assert iso.exact and len(iso.u_curves) == 5 and len(iso.v_curves) == 4
    t = np.linspace(0, 1, 41)
    scale = np.abs(s.control_points).max()
    for u, c in zip(iso.u_values, iso.u_curves):
        assert isinstance(c, sm.BSplineCurve)
        np.testing.assert_allclose(c.points(t), s.points(u, t), atol=1e-12 * scale)
        occt = sample_curve(iso_curve(s.geom(), 0, u), 0.0, 1.0, len(t))
        np.testing.assert_allclose(c.points(t), occt, atol=1e-12 * scale)
    for v, c in zip(iso.v_values, iso.v_curves):
        np.testing.assert_allclose(c.points(t), s.points(t, v), atol=1e-12 * scale)
        occt = sample_curve(iso_curve(s.geom(), 1, v), 0.0, 1.0, len(t))
        np.testing.assert_allclose(c.points(t), occt, atol=1e-12 * scale)
    np.testing.assert_array_equal(iso.u_values, np.linspace(0, 1, 5))


def test_isocurves_of_a_sphere_are_exact_meridians_and_parallels():
    r = 2.5
    s = sm.sphere(r)
    iso = sm.isocurves(s, 4, 5)
    assert not iso.exact and isinstance(iso.u_curves[0], sm.IsoCurve)
    (u0, u1), (v0, v1) = s.domain
    # meridian u = const: (r cos v cos u, r cos v sin u, r sin v); parallel v = const
    t = np.linspace(v0, v1, 33)
    u = iso.u_values[1]
    expected = np.stack([r * np.cos(t) * np.cos(u), r * np.cos(t) * np.sin(u), r * np.sin(t)], axis=1)
    np.testing.assert_allclose(iso.u_curves[1].points(t), expected, atol=1e-13 * r)
    tu = np.linspace(u0, u1, 33)
    v = iso.v_values[1]
    np.testing.assert_allclose(np.linalg.norm(iso.v_curves[1].points(tu)[:, :2], axis=1), r * np.cos(v), rtol=1e-13)
    # OCCT twin: UIso/VIso, same parametrization, checked by the parametric cross-check
    for c in (iso.u_curves[1], iso.v_curves[2]):
        res = sm.crosscheck(c)
        assert res.passed and res.mode == "parametric", res


def test_isocurve_derivatives_are_surface_partials():
    s = sm.torus(3.0, 1.0)
    c = sm.IsoCurve(s, 1, 0.7)  # v fixed: a curve in u
    t = np.linspace(0.1, 6.0, 7)
    d = c.derivatives(t, 2)
    sd = s.derivatives(t, np.full_like(t, 0.7), 2)
    np.testing.assert_allclose(d[:, 1], sd[:, 1, 0], atol=1e-13)
    np.testing.assert_allclose(d[:, 2], sd[:, 2, 0], atol=1e-13)
    moved = c.translated((1, 2, 3))
    np.testing.assert_allclose(moved.points(t), c.points(t) + [1, 2, 3], atol=1e-13)


def test_polylines_are_grid_samples():
    s = _nurbs()
    iso = sm.isocurves(s, 3, 2)
    ul, vl = iso.polylines(7)
    assert ul.shape == (3, 7, 3) and vl.shape == (2, 7, 3)
    np.testing.assert_allclose(ul[1], s.points(0.5, np.linspace(0, 1, 7)), atol=1e-13)
    np.testing.assert_allclose(vl[1], s.points(np.linspace(0, 1, 7), 1.0), atol=1e-13)
    ul0, vl0 = sm.isocurves(s, 0, 2).polylines(5)
    assert ul0.shape == (0, 5, 3) and vl0.shape == (2, 5, 3)


def test_isocurves_of_a_build123d_face_and_edges():
    s = _nurbs()
    iso = sm.isocurves(s.face(), 2, 2)
    assert iso.exact
    edges = iso.edges()
    assert len(edges) == 4
    np.testing.assert_allclose(edges[0].length, iso.u_curves[0].length(), rtol=1e-6)


@pytest.mark.parametrize(
    "nu, nv, match",
    [(1, 3, "nu"), (3, 1, "nv"), (-1, 3, "nu"), (2.5, 3, "nu"), (3, None, "nv")],
)
def test_bad_counts(nu, nv, match):
    with pytest.raises(sm.SurfmodError, match=match):
        sm.isocurves(_nurbs(), nu, nv)


def test_bad_surface_and_isocurve_arguments():
    with pytest.raises(sm.SurfmodError, match="s: expected"):
        sm.isocurves("sphere", 3, 3)
    with pytest.raises(sm.SurfmodError, match="direction"):
        sm.IsoCurve(sm.sphere(1.0), 2, 0.1)
    with pytest.raises(sm.SurfmodError, match="u: parameters must lie"):
        sm.IsoCurve(sm.sphere(1.0), 0, 10.0)
    with pytest.raises(sm.SurfmodError, match="surface"):
        sm.IsoCurve("x", 0, 0.0)
    with pytest.raises(sm.SurfmodError, match="samples"):
        sm.isocurves(_nurbs(), 2, 2).polylines(1)
