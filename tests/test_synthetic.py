"""Bézier, Hermite bicubic and the three-point plane: textbook forms and OCCT."""

from __future__ import annotations

import numpy as np
import pytest

import reference as ref
import surfmod as sm


@pytest.mark.parametrize("shape", [(2, 2), (3, 5), (8, 4), (26, 26)])
@pytest.mark.parametrize("rational", [False, True])
def test_bezier_matches_bernstein_sum_and_occt(rng, shape, rational):
    net = rng.uniform(-1, 1, (*shape, 3))
    w = 10.0 ** rng.uniform(-1, 1, shape) if rational else None
    s = sm.BezierSurface(net, w)
    assert s.degree == (shape[0] - 1, shape[1] - 1)
    a = np.linspace(0, 1, 6)
    expected = np.array([[ref.bezier_point(net, u, v, w) for v in a] for u in a])
    np.testing.assert_allclose(s.grid(a, a), expected, atol=1e-12)
    r = sm.crosscheck(s, samples=12)
    assert r.mode == "parametric" and r.passed, r.details
    assert type(s.geom()).__name__ == "Geom_BezierSurface"


def test_bezier_degree_limit():
    with pytest.raises(sm.SurfmodError, match="control_points.*25"):
        sm.BezierSurface(np.zeros((27, 3, 3)))


def test_quarter_circle_as_rational_quadratic():
    """Textbook: (1,0), (1,1), (0,1) with weights 1, 1/sqrt2, 1 is a quarter circle."""
    c = sm.BezierCurve([(1, 0, 0), (1, 1, 0), (0, 1, 0)], [1, np.sqrt(0.5), 1])
    r = np.linalg.norm(c.points(np.linspace(0, 1, 50)), axis=1)
    np.testing.assert_allclose(r, 1.0, atol=1e-15)
    assert sm.crosscheck(c).passed


def _hermite_data(rng):
    return [rng.uniform(-2, 2, (2, 2, 3)) for _ in range(4)]


def test_hermite_matches_lecture_matrix_form(rng):
    corners, du, dv, twist = _hermite_data(rng)
    s = sm.HermiteBicubic(corners, du, dv, twist)
    a = np.linspace(0, 1, 9)
    expected = np.array([[ref.hermite_point(corners, du, dv, twist, u, v) for v in a] for u in a])
    np.testing.assert_allclose(s.grid(a, a), expected, atol=1e-13)


def test_hermite_interpolates_its_data(rng):
    corners, du, dv, twist = _hermite_data(rng)
    s = sm.HermiteBicubic(corners, du, dv, twist)
    for i in (0, 1):
        for j in (0, 1):
            d = s.derivatives(float(i), float(j), 1)
            np.testing.assert_allclose(d[0, 0], corners[i, j], atol=1e-13)
            np.testing.assert_allclose(d[1, 0], du[i, j], atol=1e-12)
            np.testing.assert_allclose(d[0, 1], dv[i, j], atol=1e-12)
            np.testing.assert_allclose(d[1, 1], twist[i, j], atol=1e-12)
    assert sm.crosscheck(s).passed


def test_hermite_transform_stays_hermite(rng):
    s = sm.HermiteBicubic(*_hermite_data(rng))
    t = s.rotated((1, 2, 3), (0, 1, 1), 40).scaled(2.5)
    assert isinstance(t, sm.HermiteBicubic)
    a = np.linspace(0, 1, 5)
    m = np.eye(4)
    m[:3, :3] = 2.5 * np.eye(3)
    expected = s.rotated((1, 2, 3), (0, 1, 1), 40).grid(a, a) * 2.5
    np.testing.assert_allclose(t.grid(a, a), expected, atol=1e-12)


@pytest.mark.parametrize("name", ["corners", "du", "dv", "twist"])
def test_hermite_bad_shapes(rng, name):
    data = dict(zip(["corners", "du", "dv", "twist"], _hermite_data(rng)))
    data[name] = np.zeros((2, 3, 3))
    with pytest.raises(sm.SurfmodError, match=name):
        sm.HermiteBicubic(**data)


def test_plane_through_three_points(rng):
    p0, p1, p2 = rng.uniform(-5, 5, (3, 3))
    s = sm.plane(p0, p1, p2)
    u, v = rng.uniform(0, 1, (2, 20))
    np.testing.assert_allclose(s.points(u, v), p0 + u[:, None] * (p1 - p0) + v[:, None] * (p2 - p0), atol=1e-13)
    np.testing.assert_allclose(s.implicit(s.points(u, v)), 0.0, atol=1e-12)
    n = np.cross(p1 - p0, p2 - p0)
    np.testing.assert_allclose(s.normals(0.2, 0.9), n / np.linalg.norm(n), atol=1e-14)
    assert sm.crosscheck(s).passed
    assert abs(s.face().area - np.linalg.norm(n)) < 1e-9 * np.linalg.norm(n)


def test_plane_rejects_collinear_points():
    with pytest.raises(sm.SurfmodError, match="p2.*collinear"):
        sm.plane((0, 0, 0), (1, 1, 1), (2, 2, 2))
    with pytest.raises(sm.SurfmodError, match="p1"):
        sm.plane((0, 0, 0), (0, 0, 0), (2, 2, 2))


def test_line_matches_occt():
    line = sm.Line((1, 2, 3), (4, 6, 3))
    assert line.domain == (0.0, 5.0)
    np.testing.assert_allclose(line.points(5.0), (4, 6, 3))
    assert sm.crosscheck(line).passed
    b = line.to_bspline()
    np.testing.assert_allclose(b.points([0, 2.5, 5]), line.points([0, 2.5, 5]), atol=1e-14)
    edge = line.edge()
    assert abs(edge.length - 5.0) < 1e-12
