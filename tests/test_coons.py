"""Coons patches: against OCCT's GeomFill_BSplineCurves (Coons style) pole for pole, and
against the Coons formula evaluated on OCCT's own curves point for point."""

from __future__ import annotations

import numpy as np
import pytest

import surfmod as sm
from surfmod.occ.geom import read_bspline_surface
from surfmod.occ.sample import curve_d2

CORNERS = np.array([[0, 0, 0.0], [3, 0, 0.2], [0, 2, 0.1], [3, 2.5, 1.0]])


def _curve(p0, p1, n, degree, seed, knots=None, weights=None):
    rng = np.random.default_rng(seed)
    t = np.linspace(0, 1, n)[:, None]
    inner = (t * (1 - t) > 0).astype(float)
    pts = p0 + (p1 - p0) * t + rng.normal(0, 0.3, (n, 3)) * inner
    return sm.BSplineCurve(pts, degree, knots, weights)


def _network(seed, sizes=((6, 3), (4, 2), (5, 3), (7, 4))):
    p00, p10, p01, p11 = CORNERS
    ends = ((p00, p10), (p01, p11), (p00, p01), (p10, p11))
    return [_curve(a, b, n, d, seed * 10 + k) for k, ((a, b), (n, d)) in enumerate(zip(ends, sizes))]


def _occt_values(curve, t):
    return curve_d2(curve.geom(), t)[:, 0]


@pytest.mark.parametrize("seed", range(6))
def test_hermite_blend_equals_occt_coons_style_pole_for_pole(seed):
    rng = np.random.default_rng(seed)
    sizes = [(int(rng.integers(4, 9)), int(rng.integers(2, 5))) for _ in range(4)]
    sizes = [(max(n, d + 1), d) for n, d in sizes]
    c0, c1, d0, d1 = _network(seed, sizes)
    s = sm.coons(c0, c1, d0, d1, blend="hermite")
    occ = read_bspline_surface(s.occt_fill())
    assert occ["degree"] == s.degree
    assert occ["control_points"].shape == s.control_points.shape
    scale = np.abs(s.control_points).max()
    assert np.abs(occ["control_points"] - s.control_points).max() <= 1e-12 * scale
    for ours, theirs in zip(s.knots, occ["knots"]):
        np.testing.assert_allclose(ours, theirs, rtol=0, atol=1e-14)


def test_linear_blend_equals_occt_on_a_translational_network():
    # c1 = c0 + a and d1 = d0 + b: both blends give c0(u) + d0(v) - P00
    a, b = np.array([0.3, 2.0, 0.5]), np.array([3.0, -0.2, 0.4])
    rng = np.random.default_rng(7)
    c0_pts = np.linspace((0, 0, 0), b, 6) + rng.normal(0, 0.2, (6, 3)) * [[0], [1], [1], [1], [1], [0]]
    d0_pts = np.linspace((0, 0, 0), a, 5) + rng.normal(0, 0.2, (5, 3)) * [[0], [1], [1], [1], [0]]
    c0 = sm.BSplineCurve(c0_pts, 3)
    d0 = sm.BSplineCurve(d0_pts, 2, [0, 0, 0, 0.3, 0.6, 1, 1, 1])
    c1, d1 = c0.translated(a), d0.translated(b)
    s = sm.coons(c0, c1, d0, d1)
    occ = read_bspline_surface(s.occt_fill())
    assert np.abs(occ["control_points"] - s.control_points).max() <= 1e-12 * np.abs(s.control_points).max()
    (u0, u1), (v0, v1) = s.domain
    u, v = np.meshgrid(np.linspace(u0, u1, 9), np.linspace(v0, v1, 7), indexing="ij")
    expected = c0.points(u) + d0.points(v) - c0.points(u0)
    assert np.abs(s.points(u, v) - expected).max() <= 1e-12 * np.abs(expected).max()


@pytest.mark.parametrize("seed", range(4))
def test_linear_blend_is_the_coons_formula_on_occt_curve_values(seed):
    c0, c1, d0, d1 = _network(seed)
    s = sm.coons(c0, c1, d0, d1)
    (u0, u1), (v0, v1) = s.domain
    rng = np.random.default_rng(seed)
    sp, tp = rng.random(200), rng.random(200)
    u, v = u0 + sp * (u1 - u0), v0 + tp * (v1 - v0)

    def at(c, x):  # each curve at the same normalized parameter, evaluated by OCCT
        a, b = c.domain
        return _occt_values(c, a + x * (b - a))

    p00, p10, p01, p11 = CORNERS
    s_, t_ = sp[:, None], tp[:, None]
    expected = ((1 - t_) * at(c0, sp) + t_ * at(c1, sp) + (1 - s_) * at(d0, tp) + s_ * at(d1, tp)
                - (1 - s_) * (1 - t_) * p00 - s_ * (1 - t_) * p10 - (1 - s_) * t_ * p01 - s_ * t_ * p11)
    assert np.abs(s.points(u, v) - expected).max() <= 1e-12 * np.abs(expected).max()
    # and the surface is its own OCCT twin
    assert sm.crosscheck(s, samples=12).passed


@pytest.mark.parametrize("blend", ["linear", "hermite"])
def test_boundaries_are_interpolated_exactly(blend):
    c0, c1, d0, d1 = _network(3)
    s = sm.coons(c0, c1, d0, d1, blend=blend)
    (u0, u1), (v0, v1) = s.domain
    x = np.linspace(0, 1, 11)
    for curve, pts in ((c0, s.points(u0 + x * (u1 - u0), v0)), (c1, s.points(u0 + x * (u1 - u0), v1)),
                       (d0, s.points(u0, v0 + x * (v1 - v0))), (d1, s.points(u1, v0 + x * (v1 - v0)))):
        a, b = curve.domain
        assert np.abs(pts - curve.points(a + x * (b - a))).max() <= 1e-13 * 4


def test_rational_boundaries_quarter_circles():
    # a spherical-looking patch bounded by circular arcs (rational quadratics, end weights 1)
    import build123d as bd

    r = 2.0
    c0 = bd.Edge.make_circle(r, bd.Plane.XZ, 0, 90)          # (2,0,0) -> (0,0,2)... in XZ
    arcs = [sm.from_edge(c0)]
    a = arcs[0]
    p_start, p_end = a.points(np.array(a.domain))
    c1 = sm.Line(p_start + (0, 3, 0), p_end + (0, 3, 0))
    d0 = sm.Line(p_start, p_start + (0, 3, 0))
    d1 = sm.Line(p_end, p_end + (0, 3, 0))
    s = sm.coons(a, c1, d0, d1)
    assert s.rational
    (u0, u1), (v0, _) = s.domain
    t = np.linspace(*a.domain, 9)
    assert np.abs(s.points(u0 + (t - t[0]) / (t[-1] - t[0]) * (u1 - u0), v0) - a.points(t)).max() < 1e-13
    # a cylinder: every point at v0 lies on the circle of radius 2 in the XZ plane
    mid = s.points(np.linspace(u0, u1, 9), v0)
    np.testing.assert_allclose(np.hypot(mid[:, 0], mid[:, 2]), r, atol=1e-13)
    assert sm.crosscheck(s, samples=10).passed


def test_build123d_edges_are_accepted():
    import build123d as bd

    e = [bd.Edge.make_line((0, 0, 0), (2, 0, 0)), bd.Edge.make_line((0, 2, 0), (2, 2, 1)),
         bd.Edge.make_line((0, 0, 0), (0, 2, 0)), bd.Edge.make_line((2, 0, 0), (2, 2, 1))]
    s = sm.coons(*e)
    (u0, u1), (v0, v1) = s.domain
    np.testing.assert_allclose(s.points(u1, v1), (2, 2, 1), atol=1e-14)
    np.testing.assert_allclose(s.points((u0 + u1) / 2, (v0 + v1) / 2), (1, 1, 0.25), atol=1e-14)


def test_corner_mismatch_names_the_curves():
    c0, c1, d0, d1 = _network(1)
    with pytest.raises(sm.SurfmodError, match=r"d1: its start is .* from the end of c0"):
        sm.coons(c0, c1, d0, d1.translated((0, 0, 0.01)))
    with pytest.raises(sm.SurfmodError, match=r"d0: .*c1"):
        sm.coons(c0, c1.translated((0, 0, 0.001)), d0, d1)
    with pytest.raises(sm.SurfmodError, match="blend"):
        sm.coons(c0, c1, d0, d1, blend="cubic")
    with pytest.raises(sm.SurfmodError, match="c1: expected a surfmod curve"):
        sm.coons(c0, "top", d0, d1)


def _random_boundary(data, p0, p1):
    from hypothesis import strategies as st
    from strategies import clamped_knots

    degree = data.draw(st.integers(1, 5))
    n = data.draw(st.integers(degree + 1, degree + 5))
    knots = data.draw(clamped_knots(n, degree))
    rng = np.random.default_rng(data.draw(st.integers(0, 2**31 - 1)))
    t = np.linspace(0, 1, n)[:, None]
    pts = p0 + (p1 - p0) * t + rng.normal(0, 0.4, (n, 3)) * (t * (1 - t) > 0)
    return sm.BSplineCurve(pts, degree, knots)


def test_hermite_blend_equals_occt_on_random_curves():
    from hypothesis import given, settings
    from hypothesis import strategies as st

    @settings(max_examples=40, deadline=None)
    @given(data=st.data())
    def check(data):
        p00, p10, p01, p11 = CORNERS
        c0, c1 = _random_boundary(data, p00, p10), _random_boundary(data, p01, p11)
        d0, d1 = _random_boundary(data, p00, p01), _random_boundary(data, p10, p11)
        s = sm.coons(c0, c1, d0, d1, blend="hermite")
        if min(s.control_points.shape[:2]) < 4 or min(len(c.control_points) for c in (c0, c1, d0, d1)) < 4:
            return  # OCCT's Coons style refuses fewer than 4 poles; surfmod elevates first
        occ = read_bspline_surface(s.occt_fill())
        assert occ["control_points"].shape == s.control_points.shape
        assert np.abs(occ["control_points"] - s.control_points).max() <= 1e-12 * np.abs(s.control_points).max()
        for ours, theirs in zip(s.knots, occ["knots"]):
            np.testing.assert_allclose(ours, theirs, rtol=0, atol=1e-13 * max(1.0, np.abs(ours).max()))

    check()
