"""B-spline / NURBS surfaces and curves: NumPy evaluator vs OCCT and vs the textbook."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import reference as ref
import surfmod as sm
from strategies import bspline_surfaces, clamped_knots, parameters_with_knots
from surfmod.nets.bezier import bezier_patches, bezier_pieces
from surfmod.nets.knots import smooth_mask
from surfmod.occ.sample import curve_d2, surface_d2, surface_props


def _scale(s):
    """Net size times the conditioning of the rational quotient (sqrt of the weight ratio):
    both evaluators round the homogeneous sums, OCCT and we differ by that much."""
    size = max(1.0, float(np.abs(s.control_points).max()))
    if s.weights is None:
        return size
    return size * float(np.sqrt(s.weights.max() / s.weights.min()))


@settings(max_examples=60, deadline=None)
@given(s=bspline_surfaces())
def test_positions_and_derivatives_match_occt(s):
    us, vs = parameters_with_knots(s, 6)
    uu, vv = (a.ravel() for a in np.meshgrid(us, vs, indexing="ij"))
    mine = s.derivatives(uu, vv, 2)
    occ = surface_d2(s.geom(), uu, vv)
    scale = _scale(s)
    np.testing.assert_allclose(mine[:, 0, 0], occ[:, 0, 0], rtol=0, atol=1e-12 * scale)
    (p, q), (ku, kv) = s.degree, s.knots
    for k, l in [(1, 0), (0, 1), (2, 0), (1, 1), (0, 2)]:
        ok = smooth_mask(ku, p, uu, k) & smooth_mask(kv, q, vv, l)
        d_scale = max(np.abs(occ[:, k, l]).max(), 1.0)
        np.testing.assert_allclose(mine[ok, k, l], occ[ok, k, l], rtol=0, atol=1e-9 * d_scale)


@settings(max_examples=30, deadline=None)
@given(s=bspline_surfaces())
def test_grid_equals_scattered_evaluation(s):
    us, vs = parameters_with_knots(s, 5)
    grid = s.grid_derivatives(us, vs, 2)
    uu, vv = np.meshgrid(us, vs, indexing="ij")
    scattered = s.derivatives(uu, vv, 2)
    scale = max(1.0, np.abs(scattered).max())
    np.testing.assert_allclose(grid, scattered, rtol=0, atol=1e-11 * scale)


@settings(max_examples=25, deadline=None)
@given(s=bspline_surfaces(max_degree=4))
def test_positions_match_textbook(s):
    us, vs = parameters_with_knots(s, 4)
    (p, q), (ku, kv) = s.degree, s.knots
    expected = np.array(
        [[ref.bspline_surface_point(s.control_points, p, q, ku, kv, u, v, s.weights) for v in vs] for u in us]
    )
    np.testing.assert_allclose(s.grid(us, vs), expected, rtol=0, atol=1e-11 * _scale(s))


@settings(max_examples=30, deadline=None)
@given(s=bspline_surfaces(max_degree=5))
def test_normals_and_curvatures_match_geomlprop(s):
    (u0, u1), (v0, v1) = s.domain
    us = np.linspace(u0, u1, 7)[1:-1]
    vs = np.linspace(v0, v1, 7)[1:-1]
    uu, vv = (a.ravel() for a in np.meshgrid(us, vs, indexing="ij"))
    normals, curv = surface_props(s.geom(), uu, vv)
    ok = np.all(np.isfinite(curv), axis=1)
    ders = s.derivatives(uu, vv, 1)
    cross = np.linalg.norm(np.cross(ders[:, 1, 0], ders[:, 0, 1]), axis=1)
    ok &= cross > 1e-3 * np.linalg.norm(ders[:, 1, 0], axis=1) * np.linalg.norm(ders[:, 0, 1], axis=1)
    np.testing.assert_allclose(s.normals(uu, vv)[ok], normals[ok], atol=1e-9)
    c = s.curvatures(uu, vv)
    mine = np.stack([c.gaussian, c.mean, c.k1, c.k2], axis=1)[ok]
    kscale = max(1.0, np.abs(curv[ok, 1:]).max()) if ok.any() else 1.0
    np.testing.assert_allclose(mine[:, 1:], curv[ok, 1:], atol=1e-7 * kscale)
    np.testing.assert_allclose(mine[:, 0], curv[ok, 0], atol=1e-7 * kscale**2)


def test_third_derivatives_match_occt_d3():
    from OCP.gp import gp_Pnt, gp_Vec

    rng = np.random.default_rng(3)
    net = rng.uniform(-2, 2, (6, 5, 3))
    w = 10.0 ** rng.uniform(-1, 1, (6, 5))
    s = sm.BSplineSurface(net, (4, 3), ([0] * 5 + [0.4] + [1] * 5, [0] * 4 + [0.7] + [1] * 4), w)
    g = s.geom()
    vecs = [gp_Vec() for _ in range(9)]
    p = gp_Pnt()
    for u, v in [(0.1, 0.2), (0.4, 0.7), (0.9, 0.95), (1.0, 0.0)]:
        g.D3(u, v, p, *vecs)
        d = s.derivatives(u, v, 3)
        # OCCT order: D1U D1V D2U D2V D2UV D3U D3V D3UUV D3UVV
        expected = {(3, 0): vecs[5], (0, 3): vecs[6], (2, 1): vecs[7], (1, 2): vecs[8]}
        for (k, l), vec in expected.items():
            e = np.array([vec.X(), vec.Y(), vec.Z()])
            np.testing.assert_allclose(d[k, l], e, rtol=1e-9, atol=1e-9 * max(1, np.abs(e).max()))


def test_uniform_cubic_is_lecture_matrix_form(rng):
    net = rng.uniform(-3, 3, (7, 6, 3))
    s = sm.BSplineSurface.uniform_cubic(net)
    assert s.domain == ((0.0, 4.0), (0.0, 3.0))
    us = np.linspace(0, 4, 17)
    vs = np.linspace(0, 3, 13)
    expected = np.array([[ref.uniform_cubic_point(net, u, v) for v in vs] for u in us])
    np.testing.assert_allclose(s.grid(us, vs), expected, atol=1e-13)
    assert sm.crosscheck(s).passed


def test_knot_insertion_keeps_the_surface(rng):
    s = sm.BSplineSurface(rng.uniform(-1, 1, (6, 5, 3)), (3, 2), weights=rng.uniform(0.5, 2, (6, 5)))
    t = s.insert_knot(u=0.3, v=0.55, times=2)
    assert t.control_points.shape == (8, 7, 3)
    us = np.linspace(0, 1, 11)
    np.testing.assert_allclose(t.grid(us, us), s.grid(us, us), atol=1e-13)
    with pytest.raises(sm.SurfmodError, match="times"):
        s.insert_knot(u=0.3, times=4)


def test_bezier_extraction_reproduces_the_surface(rng):
    ku = [0, 0, 0, 0, 0.25, 0.6, 1, 1, 1, 1]
    kv = [0, 0, 0, 0.5, 0.5, 1, 1, 1]
    s = sm.BSplineSurface(rng.uniform(-1, 1, (6, 5, 3)), (3, 2), (ku, kv))
    patches = bezier_patches(s)
    assert len(patches) == 3 * 2
    for (u0, u1), (v0, v1), patch in patches:
        a = np.linspace(0, 1, 5)
        np.testing.assert_allclose(patch.grid(a, a), s.grid(u0 + a * (u1 - u0), v0 + a * (v1 - v0)), atol=1e-13)


def test_segment_matches_occt_segment(rng):
    s = sm.BSplineSurface.uniform_cubic(rng.uniform(-1, 1, (7, 6, 3)))
    seg = s.segment((0.5, 3.2), (0.25, 2.0))
    g = s.geom()
    g.Segment(0.5, 3.2, 0.25, 2.0)
    uu, vv = (a.ravel() for a in np.meshgrid(np.linspace(0.5, 3.2, 9), np.linspace(0.25, 2.0, 7), indexing="ij"))
    np.testing.assert_allclose(seg.points(uu, vv), surface_d2(g, uu, vv)[:, 0, 0], atol=1e-12)
    np.testing.assert_allclose(seg.points(uu, vv), s.points(uu, vv), atol=1e-13)
    assert seg.domain == ((0.5, 3.2), (0.25, 2.0))


@settings(max_examples=40, deadline=None)
@given(p=st.integers(1, 7), extra=st.integers(0, 5), rational=st.booleans(), data=st.data())
def test_curves_match_occt(p, extra, rational, data):
    n = p + 1 + extra
    knots = data.draw(clamped_knots(n, p))
    rng = np.random.default_rng(data.draw(st.integers(0, 10**6)))
    w = 10.0 ** rng.uniform(-1, 1, n) if rational else None
    c = sm.BSplineCurve(rng.uniform(-4, 4, (n, 3)), p, knots, w)
    t = np.unique(np.concatenate([np.linspace(*c.domain, 11), knots[p : n + 1]]))
    occ = curve_d2(c.geom(), t)
    mine = c.derivatives(t, 2)
    np.testing.assert_allclose(mine[:, 0], occ[:, 0], atol=1e-12 * 4)
    for k in (1, 2):
        np.testing.assert_allclose(mine[:, k], occ[:, k], atol=1e-9 * max(1, np.abs(occ[:, k]).max()))


def test_isocurve_is_exact(rng):
    s = sm.BSplineSurface(rng.uniform(-1, 1, (5, 6, 3)), (2, 3), weights=rng.uniform(0.5, 2, (5, 6)))
    t = np.linspace(0, 1, 9)
    np.testing.assert_allclose(s.isocurve(u=0.37).points(t), s.points(0.37, t), atol=1e-13)
    np.testing.assert_allclose(s.isocurve(v=0.81).points(t), s.points(t, 0.81), atol=1e-13)


def test_curve_segment_and_bezier_pieces(rng):
    c = sm.BSplineCurve(rng.uniform(-1, 1, (7, 3)), 3, [0, 0, 0, 0, 0.3, 0.5, 0.8, 1, 1, 1, 1], rng.uniform(1, 2, 7))
    seg = c.segment(0.2, 0.9)
    t = np.linspace(0.2, 0.9, 13)
    np.testing.assert_allclose(seg.points(t), c.points(t), atol=1e-13)
    pieces = bezier_pieces(c)
    assert [span for span, _ in pieces] == [(0.0, 0.3), (0.3, 0.5), (0.5, 0.8), (0.8, 1.0)]
    for (t0, t1), piece in pieces:
        a = np.linspace(0, 1, 5)
        np.testing.assert_allclose(piece.points(a), c.points(t0 + a * (t1 - t0)), atol=1e-13)
