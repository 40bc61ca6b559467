"""Circle, Arc, Ellipse, Line: OCCT's parametrization, exact rational B-spline forms."""

from __future__ import annotations

import math

import numpy as np
import pytest

import surfmod as sm
from twins.transformed import default_x_dir as occ_x_dir
from twins.transformed import transformed as occ_transformed
from surfmod.occ.sample import curve_d2
from surfmod.transforms import mirror_matrix, rotation_matrix, scale_matrix, translation_matrix

NORMALS = [(0, 0, 1), (1, 0, 0), (0, 1, 0), (1, 2, 3), (3, -2, 1), (-1, -1, 0.5), (0.2, 0.1, -1), (0, 0, -1)]
SIMILARITIES = {
    "rigid": rotation_matrix((1, 2, 3), (1, 1, 0), 37) @ translation_matrix((1, -2, 0.5)),
    "mirror": mirror_matrix((1, 0, 0), (1, 2, 3)),
    "scale": scale_matrix(2.5, (1, 1, 1)),
    "point_mirror": scale_matrix(-1.5, (0, 1, 0)),
}


def _occ_points(curve, t):
    return curve_d2(curve.geom(), t)


@pytest.mark.parametrize("normal", NORMALS)
def test_default_x_direction_is_gp_ax2_rule(normal):
    c = sm.Circle((1, 2, 3), normal, 2.0)
    np.testing.assert_allclose(c.x_dir, occ_x_dir(normal), atol=1e-15)
    t = np.linspace(0, 2 * math.pi, 33)
    occ = _occ_points(c, t)
    np.testing.assert_allclose(c.derivatives(t, 2), occ, rtol=0, atol=1e-14 * 4)


def test_circle_closed_form_and_crosscheck():
    c = sm.Circle((1, -1, 2), (0, 0, 1), 3.0)
    t = np.linspace(0, 2 * math.pi, 17)
    expected = np.stack([1 + 3 * np.cos(t), -1 + 3 * np.sin(t), np.full_like(t, 2.0)], axis=1)
    np.testing.assert_allclose(c.points(t), expected, atol=1e-14)
    r = sm.crosscheck(c)
    assert r.passed and r.max_deviation < 1e-14


@pytest.mark.parametrize(
    "curve",
    [
        sm.Circle((1, 2, 3), (1, 1, 0), 2.0),
        sm.Arc((0, 0, 0), (0, 0, 1), 1.5, -90, 120),
        sm.Arc((0, 0, 0), (1, 2, 2), 1.0, 10, 370),
        sm.Arc((0, 0, 0), (0, 1, 0), 4.0, 0, 30),
    ],
)
def test_to_bspline_is_exact_rational_quadratic(curve):
    nurbs = curve.to_bspline()
    assert nurbs.degree == 2 and nurbs.rational
    assert nurbs.domain == pytest.approx(curve.domain, abs=1e-15)
    t = np.linspace(*nurbs.domain, 1001)
    pts = nurbs.points(t)
    dist = np.linalg.norm(pts - curve.center, axis=1)
    np.testing.assert_allclose(dist, curve.radius, rtol=1e-14, atol=0)
    np.testing.assert_allclose((pts - curve.center) @ curve.normal, 0.0, atol=1e-14 * curve.radius)
    # same end points, and the NURBS runs the same way round
    np.testing.assert_allclose(nurbs.points(np.array(curve.domain)), curve.points(np.array(curve.domain)), atol=1e-14)
    mid = 0.5 * sum(curve.domain)
    ang = lambda p: math.atan2((p - curve.center) @ curve.y_dir, (p - curve.center) @ curve.x_dir)  # noqa: E731
    assert abs((ang(nurbs.points(mid)) - ang(curve.points(mid)) + math.pi) % (2 * math.pi) - math.pi) < 0.2
    assert sm.crosscheck(nurbs).passed


def test_arc_parametrization_matches_geom_trimmed_curve():
    a = sm.Arc((1, 0, 0), (0, 0, 1), 2.0, -90, 45)
    assert a.domain == pytest.approx((math.radians(270), math.radians(405)))
    np.testing.assert_allclose(a.points(a.domain[0]), (1, -2, 0), atol=1e-14)
    r = sm.crosscheck(a)
    assert r.passed and r.max_deviation < 1e-14
    assert a.edge().length == pytest.approx(2.0 * math.radians(135), rel=1e-12)


def test_arc_through_three_points():
    p0, p1, p2 = np.array([3.0, 1, 1]), np.array([1.0, 3, 1]), np.array([-1.0, 1, 1])
    a = sm.Arc.through(p0, p1, p2)
    np.testing.assert_allclose(a.center, (1, 1, 1), atol=1e-14)
    assert a.radius == pytest.approx(2.0, rel=1e-14)
    np.testing.assert_allclose(a.points(np.array(a.domain)), [p0, p2], atol=1e-14)
    assert a.domain[1] == pytest.approx(math.pi)
    # p1 is on the arc, half way
    np.testing.assert_allclose(a.points(math.pi / 2), p1, atol=1e-14)


def test_ellipse_matches_occt_and_implicit():
    e = sm.Ellipse((1, 2, 0), (0, 1, 1), 3.0, 1.0)
    r = sm.crosscheck(e)
    assert r.passed and r.max_deviation < 1e-13
    t = np.linspace(0, 2 * math.pi, 50)
    np.testing.assert_allclose(e.implicit(e.points(t)), 0.0, atol=1e-14)
    nurbs = e.to_bspline()
    np.testing.assert_allclose(e.implicit(nurbs.points(np.linspace(*nurbs.domain, 300))), 0.0, atol=1e-14)


def test_line_curve_matches_geom_line():
    c = sm.Line.through((1, 2, 3), (1, 1, 0), (-2, 3))
    assert sm.crosscheck(c).passed
    np.testing.assert_allclose(c.points(-2.0), np.array([1, 2, 3]) - 2 * np.array([1, 1, 0]) / math.sqrt(2), atol=1e-14)
    b = c.to_bspline()
    np.testing.assert_allclose(b.points(np.linspace(-2, 3, 9)), c.points(np.linspace(-2, 3, 9)), atol=1e-14)


@pytest.mark.parametrize(
    "curve",
    [sm.Parabola((1, 2, 3), (0, 1, 1), 0.7, (-2, 3)), sm.Hyperbola((1, 2, 3), (0, 1, 1), 2.0, 1.0, (-1.5, 2))],
    ids=["parabola", "hyperbola"],
)
def test_parabola_and_hyperbola(curve):
    assert sm.crosscheck(curve).passed
    b = curve.to_bspline()
    assert b.degree == 2 and sm.crosscheck(b).passed
    t = np.linspace(*b.domain, 301)
    d = b.points(t) - curve.center
    x, y = d @ curve.x_dir, d @ curve.y_dir
    np.testing.assert_allclose(d @ curve.normal, 0.0, atol=1e-14)
    if isinstance(curve, sm.Parabola):  # polynomial: even the parametrization is the same
        np.testing.assert_allclose(b.points(t), curve.points(t), atol=1e-14)
        np.testing.assert_allclose(x, y * y / (4 * curve.focal), atol=1e-13)
    else:
        np.testing.assert_allclose((x / curve.a) ** 2 - (y / curve.b) ** 2, 1.0, atol=1e-13)
    for m in SIMILARITIES.values():
        out = curve.transformed(m)
        tt = np.linspace(*out.domain, 9)
        np.testing.assert_allclose(out.derivatives(tt, 2), curve_d2(occ_transformed(curve.geom(), m), tt), atol=1e-12)


@pytest.mark.parametrize("name", sorted(SIMILARITIES))
@pytest.mark.parametrize(
    "curve",
    [sm.Circle((1, 2, 3), (1, 1, 0), 2.0), sm.Arc((0, 0, 0), (0, 0, 1), 1.0, -90, 120), sm.Line.through((0, 0, 0), (1, 1, 0), (-1, 2))],
)
def test_similarity_transforms_match_gp_trsf(curve, name):
    m = SIMILARITIES[name]
    out = curve.transformed(m)
    assert type(out) is type(curve)
    t = np.linspace(*out.domain, 9)
    occ = curve_d2(occ_transformed(curve.geom(), m), t)
    np.testing.assert_allclose(out.derivatives(t, 2), occ, atol=1e-13 * 10)


def test_non_uniform_scale_gives_exact_nurbs_ellipse():
    c = sm.Circle((0, 0, 0), (0, 0, 1), 1.0)
    e = c.scaled((3.0, 2.0, 1.0))
    assert isinstance(e, sm.BSplineCurve)
    p = e.points(np.linspace(*e.domain, 200))
    np.testing.assert_allclose((p[:, 0] / 3) ** 2 + (p[:, 1] / 2) ** 2, 1.0, atol=1e-14)


@pytest.mark.parametrize(
    "call, name",
    [
        (lambda: sm.Circle((0, 0, 0), (0, 0, 0), 1.0), "normal"),
        (lambda: sm.Circle((0, 0, 0), (0, 0, 1), 0.0), "radius"),
        (lambda: sm.Circle((0, 0, 0), (0, 0, 1), 1.0, x_dir=(0, 0, 2)), "x_dir"),
        (lambda: sm.Circle((0, 0, np.nan), (0, 0, 1), 1.0), "center"),
        (lambda: sm.Arc((0, 0, 0), (0, 0, 1), 1.0, 90, 90), "end_angle"),
        (lambda: sm.Arc((0, 0, 0), (0, 0, 1), 1.0, 0, 400), "end_angle"),
        (lambda: sm.Arc.through((0, 0, 0), (1, 1, 1), (2, 2, 2)), "p2"),
        (lambda: sm.Arc.through((0, 0, 0), (0, 0, 0), (2, 2, 2)), "p1"),
        (lambda: sm.Ellipse((0, 0, 0), (0, 0, 1), 1.0, 2.0), "minor"),
        (lambda: sm.Line.through((0, 0, 0), (0, 0, 0)), "direction"),
        (lambda: sm.Line.through((0, 0, 0), (1, 0, 0), (2, 1)), "t_range"),
        (lambda: sm.Parabola((0, 0, 0), (0, 0, 1), 0.0, (0, 1)), "focal"),
        (lambda: sm.Hyperbola((0, 0, 0), (0, 0, 1), 1.0, 1.0, (1, 1)), "t_range"),
    ],
)
def test_bad_input(call, name):
    with pytest.raises(sm.SurfmodError, match=name):
        call()
