"""Ruled surface: compatible B-splines (degree elevation, knot merging) and OCCT's GeomFill."""

from __future__ import annotations

import math

import numpy as np
import pytest

import surfmod as sm
from surfmod.nets.elevate import compatible, elevated, make_compatible
from surfmod.occ.sample import curve_d2, surface_d0


def _grid(domain, n=9, m=5):
    (u0, u1), (v0, v1) = domain
    uu, vv = np.meshgrid(np.linspace(u0, u1, n), np.linspace(v0, v1, m), indexing="ij")
    return uu.ravel(), vv.ravel()


def area(s, n=48):
    """Gauss-Legendre quadrature of |Su x Sv| per knot span (independent of OCCT)."""
    x, w = np.polynomial.legendre.leggauss(n)
    (u0, u1), (v0, v1) = s.domain
    breaks = np.unique(np.clip(s.knots[0], u0, u1))
    total = 0.0
    for a, b in zip(breaks[:-1], breaks[1:]):
        d = s.grid_derivatives((x + 1) / 2 * (b - a) + a, (x + 1) / 2 * (v1 - v0) + v0, 1)
        jac = np.linalg.norm(np.cross(d[:, :, 1, 0], d[:, :, 0, 1]), axis=-1)
        total += np.einsum("i,j,ij", w, w, jac) * (b - a) * (v1 - v0) / 4
    return total


def _assert_matches_geomfill(s):
    occ = s.occt_ruled()
    u0, u1, v0, v1 = occ.Bounds()
    np.testing.assert_allclose(np.ravel(s.domain), (u0, u1, v0, v1), rtol=0, atol=1e-14)
    uu, vv = _grid(s.domain)
    dev = np.abs(s.points(uu, vv) - surface_d0(occ, uu, vv)).max()
    scale = np.abs(s.control_points).max()
    assert dev <= 1e-13 * scale, dev
    return dev


CASES = {
    "cubic_vs_arc": (
        sm.BSplineCurve([(0, 0, 0), (1, 1, 0), (2, 0, 0), (3, 1, 0)], 3),
        sm.Arc((1, 1, 3), (0, 0, 1), 1.0, 0, 270),
    ),
    "quadratic_knots_vs_cubic": (
        sm.BSplineCurve([(0, 0, 0), (1, 1, 0), (2, 0, 0), (3, 1, 0)], 2, [0, 0, 0, 0.3, 1, 1, 1]),
        sm.BSplineCurve([(0, 0, 2), (1, 2, 2), (2, -1, 2), (3, 1, 2), (4, 0, 2)], 3, [0, 0, 0, 0, 0.6, 1, 1, 1, 1]),
    ),
    "line_vs_bezier": (
        sm.Line((0, 0, 0), (4, 0, 0)),
        sm.BezierCurve([(0, 2, 1), (1, 3, 2), (3, 3, 0), (4, 2, 1), (5, 2, 2)]),
    ),
    "two_circles": (sm.Circle((0, 0, 0), (0, 0, 1), 2.0), sm.Circle((0, 0, 3), (0, 0, 1), 1.0)),
    "rational_different_weights": (
        sm.BSplineCurve([(0, 0, 0), (1, 2, 0), (3, 2, 0), (4, 0, 0)], 3, weights=[1, 3, 0.5, 1]),
        sm.BSplineCurve([(0, 0, 2), (2, 1, 2), (4, 0, 2)], 2, weights=[1, 0.4, 2]),
    ),
}


@pytest.mark.parametrize("name", sorted(CASES))
def test_matches_geomfill_pole_for_pole(name):
    g, q = CASES[name]
    s = sm.ruled(g, q)
    assert isinstance(s, sm.RuledSurface) and s.degree[1] == 1
    _assert_matches_geomfill(s)
    r = sm.crosscheck(s, samples=16)
    assert r.passed, r.details


def test_polynomial_case_is_the_lecture_formula():
    g = sm.BSplineCurve([(0, 0, 0), (1, 1, 0), (2, 0, 1), (3, 1, 0)], 3, [0, 0, 0, 0, 2, 2, 2, 2])
    q = sm.BSplineCurve([(0, 0, 2), (1, 2, 2), (2, -1, 2), (3, 1, 3)], 2, [0, 0, 0, 1, 2, 2, 2])
    s = sm.ruled(g, q)
    u = np.linspace(0, 2, 11)
    for v in (0.0, 0.3, 1.0):
        np.testing.assert_allclose(s.points(u, v), (1 - v) * g.points(u) + v * q.points(u), atol=1e-14)


def test_rational_rulings_are_segments_between_the_curves():
    g, q = CASES["rational_different_weights"]
    s = sm.ruled(g, q)
    u = np.linspace(0, 1, 7)
    a, b = g.points(u), q.points(u)
    for v in (0.25, 0.5, 0.75):
        p = s.points(u, v)
        cross = np.linalg.norm(np.cross(p - a, b - a), axis=1)
        assert cross.max() < 1e-13
    np.testing.assert_allclose(s.points(u, 0.0), a, atol=1e-14)
    np.testing.assert_allclose(s.points(u, 1.0), b, atol=1e-14)


def test_cone_frustum_between_two_circles_has_the_closed_form_area():
    s = sm.ruled(sm.Circle((0, 0, 0), (0, 0, 1), 2.0), sm.Circle((0, 0, 3), (0, 0, 1), 1.0))
    slant = math.hypot(3.0, 1.0)
    assert area(s) == pytest.approx(math.pi * (2.0 + 1.0) * slant, rel=1e-13)
    x, y, z = np.moveaxis(s.grid(np.linspace(*s.domain[0], 40), np.linspace(0, 1, 7)), -1, 0)
    np.testing.assert_allclose(np.hypot(x, y), 2.0 - z / 3.0, atol=1e-14)


def test_build123d_edges_are_accepted():
    import build123d as bd

    e1 = bd.Edge.make_spline([(0, 0, 0), (1, 1, 0), (2, 0, 0), (3, 1, 0)])
    e2 = bd.Edge.make_line((0, 0, 2), (3, 0, 2))
    s = sm.ruled(e1, e2)
    _assert_matches_geomfill(s)
    t0, t1 = s.domain[0]
    np.testing.assert_allclose(s.points(t0, 1.0), (0, 0, 2), atol=1e-12)
    np.testing.assert_allclose(s.points(t1, 0.0), (3, 1, 0), atol=1e-12)


def test_degree_elevation_matches_occt_increase_degree():
    c = sm.BSplineCurve([(0, 0, 0), (1, 2, 0), (3, 2, 1), (4, 0, 0), (5, 1, 1)], 2, [0, 0, 0, 0.4, 0.4, 1, 1, 1], weights=[1, 2, 1, 0.5, 1])
    e = elevated(c, 5)
    assert e.degree == 5
    values, counts = np.unique(e.knots, return_counts=True)
    np.testing.assert_allclose(values, [0, 0.4, 1])
    assert counts.tolist() == [6, 5, 6]
    t = np.linspace(0, 1, 101)
    np.testing.assert_allclose(e.points(t), c.points(t), atol=1e-14)
    g = c.geom()
    g.IncreaseDegree(5)
    np.testing.assert_allclose(e.derivatives(t, 2), curve_d2(g, t), rtol=0, atol=1e-11)


def test_make_compatible_shares_degree_domain_and_knots():
    a = sm.BSplineCurve([(0, 0, 0), (1, 1, 0), (2, 0, 0)], 2, [0, 0, 0, 1, 1, 1])
    b = sm.BSplineCurve([(0, 0, 1), (1, 2, 1), (2, 0, 1), (3, 1, 1)], 1, [0, 0, 1, 2.5, 3, 3])
    ca, cb = make_compatible([a, b])
    assert ca.degree == cb.degree == 2
    assert ca.domain == cb.domain == (0.0, 3.0)
    np.testing.assert_array_equal(ca.knots, cb.knots)
    np.testing.assert_allclose(ca.points(np.linspace(0, 3, 7)), a.points(np.linspace(0, 1, 7)), atol=1e-14)


def _rational_pair():
    rng = np.random.default_rng(11)
    a = sm.BSplineSurface(rng.normal(size=(5, 6, 3)), (2, 3), ([0, 0, 0, 0.5, 0.8, 1, 1, 1], [0, 0, 0, 0, 0.3, 0.6, 1, 1, 1, 1]),
                          1 + rng.random((5, 6)))
    b = sm.BSplineSurface(rng.normal(size=(5, 4, 3)), (3, 2), ([0, 0, 0, 0, 0.5 + 1e-12, 1, 1, 1, 1], [0, 0, 0, 0.3, 1, 1, 1]),
                          1 + rng.random((5, 4)))
    return a, b


@pytest.mark.parametrize("axis", [0, 1])
def test_compatible_nets_along_either_axis_share_snapped_knots(axis):
    """Gordon's terms and the blend's rows go through the one home with a net axis: the
    surfaces do not change, and knots within the tolerance become the first's knot in
    every output (``tol=0`` keeps both)."""
    a, b = _rational_pair()
    nets = [(s.knots[axis], s.degree[axis], s._homogeneous) for s in (a, b)]
    degree, knots, out = compatible(nets, axis=axis)
    assert degree == 3
    u, v = np.meshgrid(np.linspace(0, 1, 13), np.linspace(0, 1, 11), indexing="ij")
    for s, h in zip((a, b), out):
        deg, kv = list(s.degree), list(s.knots)
        deg[axis], kv[axis] = degree, knots
        same = sm.BSplineSurface(h[..., :3] / h[..., 3:], tuple(deg), tuple(kv), h[..., 3])
        np.testing.assert_allclose(same.points(u, v), s.points(u, v), rtol=0, atol=1e-10)
    if axis == 0:
        assert np.unique(knots[(knots > 0.4) & (knots < 0.6)]).tolist() == [0.5]
        _, exact, _ = compatible(nets, tol=0.0)
        assert np.unique(exact[(exact > 0.4) & (exact < 0.6)]).tolist() == [0.5, 0.5 + 1e-12]


@pytest.mark.parametrize(
    "call, name",
    [
        (lambda: sm.ruled("edge", sm.Line((0, 0, 0), (1, 0, 0))), "g"),
        (lambda: sm.ruled(sm.Line((0, 0, 0), (1, 0, 0)), np.zeros((3, 3))), "q"),
    ],
)
def test_bad_input(call, name):
    with pytest.raises(sm.SurfmodError, match=name):
        call()


from hypothesis import given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

from strategies import clamped_knots  # noqa: E402


@st.composite
def bspline_curves(draw, max_degree=5):
    p = draw(st.integers(1, max_degree))
    n = draw(st.integers(p + 1, p + 4))
    rng = np.random.default_rng(draw(st.integers(0, 2**31 - 1)))
    pts = rng.uniform(-5, 5, (n, 3))
    w = 10.0 ** rng.uniform(-0.7, 0.7, n) if draw(st.booleans()) else None
    return sm.BSplineCurve(pts, p, draw(clamped_knots(n, p)), w)


@settings(max_examples=25, deadline=None)
@given(bspline_curves(), bspline_curves())
def test_random_curves_match_geomfill(g, q):
    s = sm.ruled(g, q)
    _assert_matches_geomfill(s)
    # the boundary rows are the input curves, reparametrized onto the common interval
    (u0, u1), _ = s.domain
    t = np.linspace(0, 1, 9)
    for v, c in ((0.0, g), (1.0, q)):
        c0, c1 = c.domain
        np.testing.assert_allclose(s.points(u0 + t * (u1 - u0), v), c.points(c0 + t * (c1 - c0)), atol=1e-12)
